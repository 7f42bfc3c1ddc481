//! Model elements, one module each.
//!
//! An element module owns everything about one kind of entry of a model file: its typed
//! form, how it is read and written (side by side), its rules, its equations of dimension
//! under `units: SI`, its kinematics, and what it gives the derivations and the description.
//! It names none of the stages (it may use the kinematics engine's pure helpers,
//! `mechanics::frames::{cross, tensor_times}`). Each stage hands it a context through one of
//! the traits below, which the stage implements (`Rules` by the rules pass, `Units` by the unit check,
//! `Lower` by the lowering in `mechanics`). So an element sits below the stages that
//! iterate over it and above the scaffolds it reads and writes with (the schema's `Ctx`,
//! its `Fields`, the `Writer`), and a new kind is one module plus one line in each stage's
//! loop and one row in the schema's `SECTIONS`.
//!
//! The kinds here: [`point`] (the points, which every other element reads), [`frame`]
//! (reference frames), [`body`] (particles, planar and 3-D rigid bodies), [`contact`]
//! (unilateral contacts) and its [`support`] (a change of support), [`spring`], [`damper`],
//! [`force`], [`torque`], [`interaction`], [`gravity`] and the written [`energy`], the
//! holonomic [`constraint`]s and the [`nonholonomic`] ones with the rolling contacts.
//! ARCHITECTURE.md's recipe says how a kind is added.

pub mod body;
pub mod constraint;
pub mod contact;
pub mod damper;
pub mod energy;
pub mod force;
pub mod frame;
pub mod gravity;
pub mod interaction;
pub mod nonholonomic;
pub mod point;
pub mod shape;
pub mod speed;
pub mod spring;
pub mod support;
pub mod torque;

use super::ast::Expr;
use super::diagnostic::Diagnostic;
use super::located::Located;
use super::units::Dimension;
use crate::expr::{ExprArena, ExprId};
use crate::model::schema::entries::get;
use crate::model::schema::walk::{Ctx, Fields, Keyed};
use crate::model::schema::write::{NotRewritten, Writer, flow};
use crate::model::yaml::YamlNode;

/// The names of a vector's components, in order (messages: "the x component of …").
pub(crate) const AXES: [&str; 3] = ["x", "y", "z"];

/// The name of the ground (Newtonian) frame, predefined in every 3-D model.
pub const GROUND_FRAME: &str = "N";

/// `, in: F` for a frame other than the ground's, else nothing: how a vector written in a
/// frame ends its entry.
pub(crate) fn in_frame(frame: Option<&Located<String>>) -> String {
    match frame {
        Some(f) if f.value != GROUND_FRAME => format!(", in: {}", f.value),
        _ => String::new(),
    }
}

/// An axis of a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// The frame's x axis.
    X,
    /// The frame's y axis.
    Y,
    /// The frame's z axis.
    Z,
}

impl Axis {
    /// 0, 1, 2 for x, y, z.
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }

    /// `x`, `y` or `z`.
    pub fn letter(self) -> char {
        ['x', 'y', 'z'][self.index()]
    }
}

/// The frame `in: F` of an entry written in a frame: `Some(None)` when the entry has none,
/// `None` (reported) when it is not a name.
pub(crate) fn read_in(
    cx: &mut Ctx<'_>,
    f: &crate::model::schema::entries::Entries,
) -> Option<Option<Located<String>>> {
    match get(f, "in") {
        Some(n) => cx.name(n, "`in`").map(Some),
        None => Some(None),
    }
}

/// What an expression of a model file may depend on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Depends {
    /// Parameters, numbers, `pi` and functions.
    Constant,
    /// Also coordinates and `t` (a configuration).
    Position,
    /// Also rates (`x_dot`).
    Motion,
    /// Also accelerations (`x_ddot`): only equations of motion written by hand.
    Acceleration,
    /// Also constraint forces (`lambda_<constraint>`): only event functions.
    Event,
}

/// What kind of body a name is, for the rules of the loads on bodies ([`Rules::body`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum BodyShape {
    /// A particle (`at:`).
    Particle,
    /// A planar rigid body (`inertia` a number, `angle`).
    Planar,
    /// A 3-D rigid body (`frame`, an inertia tensor).
    Spatial,
}

/// What [`Rules::body`] finds under a name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum BodyLookup {
    /// A body of this kind.
    Found(BodyShape),
    /// None, but an error already reported explains it (the name or the section was lost).
    Excused,
    /// None: no such body, with the closest name if one is close.
    Unknown(Option<String>),
}

/// What an element's rules ask of the file around it (the rules pass implements it).
pub(crate) trait Rules {
    /// Reports `name` unless it is a point of the model (or one left out for an error
    /// already reported).
    fn point(&mut self, name: &Located<String>);
    /// Reports `name` unless it is a frame of the model or the ground (or one left out for
    /// an error already reported).
    fn frame(&mut self, name: &Located<String>);
    /// "unknown frame `name`", with the closest of `frames` (the frames it may name there).
    fn unknown_frame(&self, name: &Located<String>, frames: &[&str]) -> Diagnostic;
    /// The body called `name`: its kind, or why there is none.
    fn body(&self, name: &str) -> BodyLookup;
    /// Checks the names and functions of `e` and that it depends on no more than `depends`;
    /// `what` names it in messages ("the restitution of contact `floor`").
    fn expression(&mut self, e: &Expr, depends: Depends, what: &str);
    /// [`Rules::expression`] of an interaction's magnitude, where `r` and `r_dot` are the
    /// distance of its points and its rate.
    fn expression_of_distance(&mut self, e: &Expr, depends: Depends, what: &str);
    /// What of the model `name` is ("a parameter", "a coordinate", "a point", or for
    /// `r_dot` "the rate of coordinate `r`"), if anything.
    fn name_kind(&self, name: &str) -> Option<&'static str>;
    /// The value of `e` with the parameters at their defaults; `None` if it is not constant
    /// or names what is not known (reported by [`Rules::expression`]).
    fn value(&self, e: &Expr) -> Option<f64>;
    /// The spatial dimension of the model's points (2 or 3); `None` when it has none.
    fn dimension(&self) -> Option<usize>;
    /// The model's coordinates, in file order.
    fn coordinates(&self) -> Vec<String>;
    /// Whether the section `key` was left incomplete by an error already reported (so what
    /// it lacks is not reported again).
    fn section_incomplete(&self, key: &str) -> bool;
    /// Reports a mistake.
    fn error(&mut self, d: Diagnostic);
}

/// What an element's equations of dimension ask of the unit check (`units: SI`).
pub(crate) trait Units {
    /// Checks that `e` has the dimension `want`: "`what` is …, but `kind` is `want_text`",
    /// with `help`.
    fn fixed(
        &mut self,
        e: &Expr,
        want: Dimension,
        what: &str,
        kind: &str,
        want_text: &str,
        help: &str,
    );
    /// Checks that `q` has the dimension of a generalized force of the coordinate `name`: J
    /// per the coordinate's unit (N for a length, N·m for an angle).
    fn generalized_force(&mut self, name: &Located<String>, q: &Expr);
    /// From `on` until it is called with `false`, `r` and `r_dot` are an interaction's
    /// distance (m) and its rate (m/s).
    fn distance(&mut self, on: bool);
}

/// What an element's kinematics ask of the lowering into the expression arena.
pub(crate) trait Lower {
    /// The arena the model's expressions live in.
    fn arena(&mut self) -> &mut ExprArena;
    /// `e` lowered into the arena.
    fn expr(&mut self, e: &Expr) -> ExprId;
    /// `e` lowered with the names of `locals` standing for their expressions.
    fn expr_with(&mut self, e: &Expr, locals: &[(&str, ExprId)]) -> ExprId;
    /// The position of the point `name` in the ground frame's components (2 or 3); `None` if
    /// there is no such point.
    fn point(&self, name: &str) -> Option<Vec<ExprId>>;
    /// The index of the point `name` among the model's points; `None` if there is none.
    fn point_index(&self, name: &str) -> Option<usize>;
    /// The position of the point of index `i` (from [`Lower::point_index`]).
    fn point_at(&self, i: usize) -> Vec<ExprId>;
    /// The index of the frame `name` among the model's frames (0: the ground); `None` if
    /// there is no such frame (reported by the rules).
    fn frame_index(&self, name: &str) -> Option<usize>;
    /// The vector of components `v` in the frame of index `from` as components in the frame
    /// of index `to`.
    fn express(&mut self, v: [ExprId; 3], from: usize, to: usize) -> [ExprId; 3];
    /// `^N ω^F`, the angular velocity of the frame of index `frame` in the ground frame, in
    /// the components of `frame` itself (rad/s), linear in the rates.
    fn angular_velocity(&mut self, frame: usize) -> [ExprId; 3];
    /// The index of the body `name` among the model's bodies.
    fn body_index(&self, name: &str) -> Option<usize>;
    /// The index of the point at the centre of mass of the body `name` (a particle's own
    /// point); `None` if there is no such body.
    fn body_centre(&self, name: &str) -> Option<usize>;
    /// The angle `θ` of the planar rigid body `name`; `None` if it is not one.
    fn planar_angle(&self, name: &str) -> Option<ExprId>;
    /// The index, the frame's index and the angular velocity (in the body frame's
    /// components, linear in the rates) of the 3-D rigid body `name`; `None` if it is not
    /// one.
    fn rigid_body_3d(&self, name: &str) -> Option<(usize, usize, [ExprId; 3])>;
    /// The model's coordinates, in file order.
    fn coordinate_names(&self) -> Vec<String>;
    /// Reports a mistake found while lowering.
    fn error(&mut self, d: Diagnostic);
}

/// The end points' indices of a load `between: [A, B]` and `d = r_A − r_B`; `None` (with
/// the mistake reported at `name`) if either is not a point: "`kind` `name` names an
/// unknown point".
pub(crate) fn between(
    cx: &mut dyn Lower,
    ends: &[Located<String>; 2],
    name: &Located<String>,
    kind: &str,
) -> Option<([usize; 2], Vec<ExprId>)> {
    let (Some(a), Some(b)) = (
        cx.point_index(&ends[0].value),
        cx.point_index(&ends[1].value),
    ) else {
        cx.error(Diagnostic::new(
            name.location,
            format!("{kind} `{}` names an unknown point", name.value),
        ));
        return None;
    };
    let (ra, rb) = (cx.point_at(a), cx.point_at(b));
    Some(([a, b], difference(cx.arena(), &ra, &rb)))
}

/// The expressions of a section of constraints, by name, in file order.
pub type Expressions = Vec<(Located<String>, Expr)>;

/// A section of constraints whose entries are expressions or maps of one kind
/// (`constraints:`, `nonholonomic:`): `name: e` (`item` names it in messages), or
/// `name: { … }` read by `map`; the expressions and what `map` read, each in file order.
pub(crate) fn read_expressions_or<T>(
    cx: &mut Ctx<'_>,
    node: &YamlNode,
    (what, example, item): (&str, &str, &str),
    mut map: impl FnMut(&mut Ctx<'_>, &Located<String>, &YamlNode) -> Option<T>,
) -> (Expressions, Vec<T>) {
    let spec = Keyed {
        what,
        example,
        names: None,
        drop: false,
    };
    let mut maps = Vec::new();
    let expressions = cx.keyed(node, spec, |cx, k, v| {
        if matches!(v.kind, crate::model::yaml::YamlKind::Map(_)) {
            if let Some(m) = map(cx, k, v) {
                maps.push(m);
            }
            return None;
        }
        cx.expr(v, item).map(|e| (k.clone(), e))
    });
    (expressions, maps)
}

/// The axes of a constraint on a point or a rolling contact (`what`, as "constraint
/// `floor`"): in a planar model it has no frame `in:` and no `z` axis (`along_help` says
/// what `along` is there), in 3-D its frame is one of the model's.
pub(crate) fn axes_rules(
    what: &str,
    (frame, along): (Option<&Located<String>>, &[Located<Axis>]),
    along_help: &str,
    cx: &mut dyn Rules,
) {
    if cx.dimension() != Some(2) {
        if let Some(frame) = frame {
            cx.frame(frame);
        }
        return;
    }
    if let Some(frame) = frame {
        cx.error(
            Diagnostic::new(
                frame.location,
                format!("{what} is in a planar model, which has no frames"),
            )
            .with_help("leave out `in`: the axes are the plane's x and y"),
        );
    }
    for a in along.iter().filter(|a| a.value == Axis::Z) {
        cx.error(
            Diagnostic::new(
                a.location,
                format!("{what} is planar, so it has no `z` axis"),
            )
            .with_help(along_help),
        );
    }
}

/// Constraints written as expressions depend on no more than `depends`.
pub(crate) fn expression_rules(
    expressions: &[(Located<String>, Expr)],
    depends: Depends,
    cx: &mut dyn Rules,
) {
    for (k, e) in expressions {
        cx.expression(e, depends, &format!("constraint `{}`", k.value));
    }
}

/// Constraints written as expressions, lowered, by name in file order.
pub(crate) fn expression_rows(
    expressions: &[(Located<String>, Expr)],
    cx: &mut dyn Lower,
) -> Vec<(String, ExprId)> {
    expressions
        .iter()
        .map(|(k, e)| (k.value.clone(), cx.expr(e)))
        .collect()
}

/// A load between two points with one expression, as read: its name, its points and the
/// expression.
pub(crate) type BetweenEntry = (Located<String>, [Located<String>; 2], Expr);

/// The entries of a section of loads between two points with one expression each,
/// `section: { name: { between: [A, B], <key>: e } }`, in file order (`fields` the entry's
/// keys, `example` a name for the section's example); `what(name)` says what the
/// expression is, in messages.
pub(crate) fn read_between(
    cx: &mut Ctx<'_>,
    node: &YamlNode,
    (section, fields, example): (&str, &Fields, &str),
    key: &str,
    what: impl Fn(&str) -> String,
) -> Vec<BetweenEntry> {
    let example = format!("{section}: {{ {example}: {} }}", fields.example);
    let spec = Keyed {
        what: &format!("`{section}`"),
        example: &example,
        names: None,
        drop: false,
    };
    cx.keyed(node, spec, |cx, k, v| {
        let f = cx.fields(k, v, fields)?;
        let between = get(f, "between").and_then(|n| cx.point_pair(n, "`between`"));
        let value = get(f, key).and_then(|n| cx.expr(n, &what(&k.value)));
        Some((k.clone(), between?, value?))
    })
}

/// `section:` of loads between two points with one expression each, in the form
/// [`read_between`] reads: `name: { between: [A, B], <key>: e }` (`kind` names an entry in a
/// note on what could not be written).
pub(crate) fn write_between<'e>(
    w: &mut Writer<'_>,
    (section, kind, key): (&str, &str, &str),
    entries: impl IntoIterator<Item = (&'e Located<String>, &'e [Located<String>; 2], &'e Expr)>,
) -> Result<(), NotRewritten> {
    let mut entries = entries.into_iter().peekable();
    if entries.peek().is_none() {
        return Ok(());
    }
    w.line(format_args!("{section}:"));
    for (name, [a, b], e) in entries {
        let place = format!("{kind} `{}`", name.value);
        let value = w.expr(e, &place)?;
        w.line(format_args!(
            "  {}: {{ between: [{}, {}], {key}: {} }}",
            name.value,
            a.value,
            b.value,
            flow(&value)
        ));
    }
    Ok(())
}

/// Per symbol `sᵢ` of `symbols`, `v·∂r/∂sᵢ` (times `scale` if given), `None` where the
/// projection is 0: the generalized forces `Qᵢ = F·∂r_P/∂qᵢ` of a force `F` at a point `r_P`
/// (the partial velocities), or `Qᵢ = τ·∂ω/∂q̇ᵢ` of a torque with the rates as symbols.
/// Each symbol's terms are built before the next symbol's.
pub(crate) fn projections(
    arena: &mut ExprArena,
    symbols: &[crate::expr::SymbolId],
    (v, r): (&[ExprId], &[ExprId]),
    scale: Option<ExprId>,
) -> Vec<Option<ExprId>> {
    (symbols.iter())
        .map(|&s| {
            let partial: Vec<ExprId> = r.iter().map(|x| arena.diff(*x, s)).collect();
            let projection = dot(arena, v, &partial);
            (!arena.is_zero(projection)).then(|| match scale {
                Some(scale) => arena.times(scale, projection),
                None => projection,
            })
        })
        .collect()
}

/// `a − b`, component by component.
pub(crate) fn difference(arena: &mut ExprArena, a: &[ExprId], b: &[ExprId]) -> Vec<ExprId> {
    a.iter().zip(b).map(|(x, y)| arena.minus(*x, *y)).collect()
}

/// `a · b`.
pub(crate) fn dot(arena: &mut ExprArena, a: &[ExprId], b: &[ExprId]) -> ExprId {
    let terms: Vec<ExprId> = a.iter().zip(b).map(|(x, y)| arena.times(*x, *y)).collect();
    arena.sum(&terms)
}

/// `√x`, exact where `x` is the square of a rational (`|[0, 2]| = 2`, not `sqrt(4)`: the
/// listing reads as a textbook's).
pub(crate) fn exact_sqrt(arena: &mut ExprArena, x: ExprId) -> ExprId {
    if let Some(crate::expr::Constant::Rational { num, den }) = arena.as_constant(x)
        && let (Some(a), Some(b)) = (integer_sqrt(num), integer_sqrt(den))
    {
        return arena.constant(crate::expr::Constant::Rational { num: a, den: b });
    }
    arena.sqrt(x)
}

/// `√n` if `n ≥ 0` is a perfect square.
fn integer_sqrt(n: i64) -> Option<i64> {
    let r = (n.max(0) as f64).sqrt().round() as i64;
    (n >= 0 && r.checked_mul(r) == Some(n)).then_some(r)
}
