//! Dimensional checks of a model file that declares `units: SI`.
//!
//! A file opts in with the top-level key `units: SI`. Then:
//!
//! - every parameter has a unit, written in its trailing comment before the first `,`
//!   (`k: 100.0  # N/m, spring`) or as `k: { value: 100.0, unit: N/m }`
//!   ([`super::units::parse_unit`] gives the syntax);
//! - a coordinate's unit is the `unit:` of `- { name: x, unit: m }`, else the start of its
//!   trailing comment when that is a unit (`- x  # m, cart position`), else it is inferred
//!   from its use (a point `[x, 0]` makes `x` a length, `sin(theta)` makes `theta` a pure
//!   number); rates `x_dot` are the unit of `x` per s, accelerations `x_ddot` per s²; `t` is
//!   in s;
//! - every expression is dimensionally consistent: the terms of a sum and the sides of an
//!   equation alike, the arguments of `sin`, `cos`, `exp`, `ln`, … pure numbers (rad is a
//!   pure number), powers with numeric exponents (`sqrt` is `^(1/2)`);
//! - every key has its physical unit: `kinetic` and `potential` J, point positions m,
//!   `gravity` m/s², masses kg, inertias kg·m², body angles rad, spring stiffnesses N/m,
//!   rest lengths m, damping coefficients N·s/m, forces N, torques N·m, a generalized force
//!   J per unit of its coordinate (N for a length, N·m for an angle), initial values and
//!   equilibria the unit of their coordinate (per s for a rate), and in `checks:` natural
//!   frequencies rad/s, damping ratios 1, a period and `t` s;
//! - a value written with numbers only (`0`, `-1`, `pi/2`) is in the unit of its key; inside
//!   a larger expression a number is a pure number, except that `0` fits any unit.
//!
//! Unknown units (coordinates not declared, parameters without a unit) are solved from the
//! requirements, key units first, then homogeneity, one unknown at a time; a parameter
//! without a unit is still an error, whose help names the unit its use implies. All
//! problems of a file are reported at once. Without `units:`, nothing here runs and units
//! are documentation.

use std::collections::HashMap;

use super::ast::{BinOp, Expr, ExprKind};
use super::diagnostic::Diagnostic;
use super::file::{BalanceKind, BodyKind, InertiaTensor, ModelFile, TorqueValue};
use super::located::Location;
use super::parser::identifiers;
use super::units::{Dimension, Rational, parse_unit};

/// Checks the units of `file` if it declares `units:`; an empty list otherwise.
///
/// Names the schema pass left out (already reported) take any unit, so that one mistake
/// gives one message.
pub fn check(file: &ModelFile) -> Vec<Diagnostic> {
    if file.units.is_none() {
        return Vec::new();
    }
    let cx = Checker::run(file, None);
    if cx.diagnostics.len() < 2 {
        return cx.diagnostics;
    }
    root_cause(file, cx)
}

/// A declared unit (a parameter's, or a coordinate's) that its uses contradict is one
/// mistake, not one per use: `g: 9.81  # m/s` used in `gravity`, the potential and a hand
/// equation gave three errors, the first at `gravity`, none at the declaration.
///
/// Rule: a name declared in unit `U` and found in two or more of the failing expressions is
/// checked again as if undeclared; if its uses then imply a unit `V ≠ U` and at least two
/// errors go away, those errors are replaced by one at the declaration ("declared in m/s,
/// but its uses need m/s^2"). The name that leaves the fewest errors wins; only the eight
/// names found in the most failing expressions are tried, so a file of many parameters
/// stays linear.
fn root_cause<'f>(file: &'f ModelFile, first: Checker<'f>) -> Vec<Diagnostic> {
    let mut counts: HashMap<&str, usize> = HashMap::new();
    for names in &first.failing_names {
        let mut names: Vec<&str> = names.iter().map(String::as_str).collect();
        names.sort_unstable();
        names.dedup();
        for n in names {
            *counts.entry(n).or_default() += 1;
        }
    }
    let declared = |n: &str| -> Option<(Target, Dimension)> {
        if let Some(i) = file.parameters.iter().position(|p| p.name.value == n) {
            match first.parameters.get(i) {
                Some(Unit::Known(d)) => Some((Target::Parameter(i), *d)),
                _ => None,
            }
        } else {
            let i = first.coordinate(n)?;
            match first.coordinates.get(i) {
                Some(Unit::Known(d)) => Some((Target::Coordinate(i), *d)),
                _ => None,
            }
        }
    };
    let mut candidates: Vec<(&str, usize)> = counts
        .into_iter()
        .filter(|(n, count)| *count >= 2 && declared(n).is_some())
        .collect();
    // Most failing expressions first, then by name (a deterministic order).
    candidates.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(b.0)));
    candidates.truncate(8);
    let total = first.diagnostics.len();
    let mut best: Option<(Vec<Diagnostic>, Diagnostic)> = None;
    for (name, _) in candidates {
        let Some((target, unit)) = declared(name) else {
            continue;
        };
        let again = Checker::run(file, Some(target));
        let Some(needed) = again.solution_of(target) else {
            continue;
        };
        if needed.unit == unit {
            continue;
        }
        let at = target.location(file);
        // "parameter `g` has no unit" is this run's own doing.
        let rest: Vec<Diagnostic> = again
            .diagnostics
            .into_iter()
            .filter(|d| d.location != at)
            .collect();
        let removed = total.saturating_sub(rest.len());
        if removed < 2 || best.as_ref().is_some_and(|(b, _)| b.len() <= rest.len()) {
            continue;
        }
        let (kind, spelling) = match target {
            Target::Parameter(i) => (
                "parameter",
                file.parameters
                    .get(i)
                    .and_then(|p| p.unit.as_ref())
                    .map(|u| unit_part(&u.value).trim().to_string()),
            ),
            Target::Coordinate(_) => ("coordinate", None),
        };
        let declared_text = spelling.unwrap_or_else(|| show(unit));
        let root = Diagnostic::new(
            target.unit_location(file),
            format!(
                "{kind} `{name}` is declared in {declared_text}, but its uses need {} ({} at {} and {} more)",
                needed.text(),
                needed.origin,
                needed.at,
                removed.saturating_sub(1)
            ),
        )
        .with_help(format!(
            "declare `{name}` in {} if that is its unit; otherwise correct the formulas that use it",
            needed.text()
        ));
        best = Some((rest, root));
    }
    match best {
        Some((mut rest, root)) => {
            rest.push(root);
            rest.sort_by_key(|d| d.location);
            rest
        }
        None => first.diagnostics,
    }
}

/// A name whose declared unit [`root_cause`] sets aside.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Target {
    /// Parameter `i` of the file.
    Parameter(usize),
    /// Coordinate `i` of the file.
    Coordinate(usize),
}

impl Target {
    /// Where its name is (a "has no unit" error of a run without its unit is there).
    fn location(self, file: &ModelFile) -> Location {
        match self {
            Target::Parameter(i) => file.parameters.get(i).map(|p| p.name.location),
            Target::Coordinate(i) => file.coordinates.get(i).map(|c| c.name.location),
        }
        .unwrap_or_default()
    }

    /// Where its unit is declared (the name's location when the unit has none).
    fn unit_location(self, file: &ModelFile) -> Location {
        let unit = match self {
            Target::Parameter(i) => file.parameters.get(i).and_then(|p| p.unit.as_ref()),
            Target::Coordinate(i) => file.coordinates.get(i).and_then(|c| c.unit.as_ref()),
        };
        unit.map_or_else(|| self.location(file), |u| u.location)
    }
}

/// A dimension `known · Π xᵢ^cᵢ` in the unknown units `xᵢ` (sorted by index, no zero `cᵢ`).
#[derive(Debug, Clone, PartialEq)]
struct Dim {
    known: Dimension,
    unknowns: Vec<(usize, Rational)>,
    /// Pass 2: the solved unknowns that `known` depends on (for the help of a message).
    inferred: Vec<usize>,
}

impl Dim {
    fn of(known: Dimension) -> Self {
        Self {
            known,
            unknowns: Vec::new(),
            inferred: Vec::new(),
        }
    }

    fn var(i: usize) -> Self {
        Self {
            known: Dimension::ONE,
            unknowns: vec![(i, Rational::ONE)],
            inferred: Vec::new(),
        }
    }

    fn combine(&self, o: &Self, sign: Rational) -> Option<Self> {
        let known = if sign == Rational::ONE {
            self.known.checked_mul(o.known)?
        } else {
            self.known.checked_div(o.known)?
        };
        let mut unknowns = self.unknowns.clone();
        for &(i, c) in &o.unknowns {
            let c = c.checked_mul(sign)?;
            match unknowns.iter_mut().find(|(j, _)| *j == i) {
                Some((_, d)) => *d = d.checked_add(c)?,
                None => unknowns.push((i, c)),
            }
        }
        unknowns.retain(|(_, c)| !c.is_zero());
        unknowns.sort_by_key(|(i, _)| *i);
        Some(Self {
            known,
            unknowns,
            inferred: union(&self.inferred, &o.inferred),
        })
    }

    fn mul(&self, o: &Self) -> Option<Self> {
        self.combine(o, Rational::ONE)
    }

    fn div(&self, o: &Self) -> Option<Self> {
        self.combine(o, Rational::integer(-1))
    }

    fn pow(&self, p: Rational) -> Option<Self> {
        let mut unknowns = Vec::new();
        for &(i, c) in &self.unknowns {
            let c = c.checked_mul(p)?;
            if !c.is_zero() {
                unknowns.push((i, c));
            }
        }
        Some(Self {
            known: self.known.pow(p)?,
            unknowns,
            inferred: self.inferred.clone(),
        })
    }
}

/// The sorted union of two lists of unknowns.
fn union(a: &[usize], b: &[usize]) -> Vec<usize> {
    let mut all = [a, b].concat();
    all.sort_unstable();
    all.dedup();
    all
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Mode {
    /// Collect requirements that involve unknowns.
    Infer,
    /// Report requirements that fail.
    Report,
}

/// What a name's unit is.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Unit {
    /// Declared or solved.
    Known(Dimension),
    /// Unknown number `i` (pass 1 only).
    Var(usize),
    /// Anything: an unknown left unsolved, or a unit that did not parse (already reported).
    Any,
}

/// Requirements against a key's unit are solved before homogeneity requirements.
const KEY: u8 = 0;
const HOMOGENEITY: u8 = 1;

/// A requirement `dim = 1` with unknowns, and where it comes from.
struct Equation {
    priority: u8,
    dim: Dim,
    origin: String,
    at: Location,
    /// How the key spells its unit (`N*s/m`), when the expression is a lone name.
    spelling: Option<String>,
}

/// An unknown unit solved from an equation.
#[derive(Debug, Clone)]
struct Solved {
    unit: Dimension,
    origin: String,
    at: Location,
    spelling: Option<String>,
}

impl Solved {
    /// The unit as its key spells it (`N*s/m`), else canonical (`kg/s`).
    fn text(&self) -> String {
        self.spelling.clone().unwrap_or_else(|| show(self.unit))
    }
}

struct Checker<'f> {
    file: &'f ModelFile,
    mode: Mode,
    diagnostics: Vec<Diagnostic>,
    parameters: Vec<Unit>,
    coordinates: Vec<Unit>,
    /// For each unknown: is it a coordinate (else a parameter), and its index there.
    unknowns: Vec<(bool, usize)>,
    /// Pass 1: requirements with unknowns.
    equations: Vec<Equation>,
    /// The units of the constraints visited so far in this pass, for their multipliers
    /// (`lambda_<name>`): `(name, unit, holonomic)`.
    constraints: Vec<(String, Option<Dim>, bool)>,
    /// How the key being checked spells its unit, while its value is a lone name.
    spelling: Option<String>,
    solution: Vec<Option<Solved>>,
    /// Pass 2: the names of the expression being checked (see [`Self::top`]).
    names: Vec<String>,
    /// Pass 2: for each failed requirement, the names of its expression.
    failing_names: Vec<Vec<String>>,
    /// Whether `r` and `r_dot` are an interaction's distance (m) and its rate (m/s).
    interaction: bool,
}

/// `kg`, `N/m`: a dimension for messages.
fn show(d: Dimension) -> String {
    d.to_string()
}

/// A load's unit: `N*m` rather than `J` for a torque.
fn show_load(d: Dimension) -> String {
    if d == Dimension::JOULE {
        "N*m".to_string()
    } else {
        show(d)
    }
}

/// A coordinate's unit in prose: `m`, `a pure number (rad)`.
fn show_coordinate(d: Dimension) -> String {
    if d.is_one() {
        "a pure number (rad)".to_string()
    } else {
        show(d)
    }
}

/// An expression as text for messages (shortened past 48 characters).
fn text(e: &Expr) -> String {
    let full = write_expr(e, 0);
    if full.chars().count() > 48 {
        let short: String = full.chars().take(45).collect();
        format!("{short}...")
    } else {
        full
    }
}

/// Writes `e` with the parentheses its operators need inside a context of precedence
/// `outer` (0 sum, 1 product, 2 unary minus, 3 power base).
fn write_expr(e: &Expr, outer: u8) -> String {
    let (s, own) = match &e.kind {
        ExprKind::Number { text, .. } => (text.clone(), 4),
        ExprKind::Ident(n) => (n.clone(), 4),
        ExprKind::Neg(a) => (format!("-{}", write_expr(a, 2)), 2),
        ExprKind::Call { func, args } => (
            format!(
                "{func}({})",
                args.iter()
                    .map(|a| write_expr(a, 0))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            4,
        ),
        ExprKind::Binary { op, lhs, rhs, .. } => match op {
            BinOp::Add | BinOp::Sub => {
                let sign = if *op == BinOp::Add { " + " } else { " - " };
                (
                    format!("{}{sign}{}", write_expr(lhs, 0), write_expr(rhs, 1)),
                    0,
                )
            }
            BinOp::Mul | BinOp::Div => {
                let sign = if *op == BinOp::Mul { "*" } else { "/" };
                (
                    format!("{}{sign}{}", write_expr(lhs, 1), write_expr(rhs, 2)),
                    1,
                )
            }
            BinOp::Pow => (format!("{}^{}", write_expr(lhs, 3), write_expr(rhs, 2)), 3),
        },
    };
    if own < outer { format!("({s})") } else { s }
}

/// Whether `e` is written with numbers only (then it takes the unit of its key).
fn numbers_only(e: &Expr) -> bool {
    let mut ids = Vec::new();
    identifiers(e, &mut ids);
    ids.iter().all(|(n, _)| n == "pi")
}

/// The exact value of an exponent written with numbers and `+ - * /` (`2`, `-1`, `1/2`).
fn numeric_exponent(e: &Expr) -> Option<Rational> {
    match &e.kind {
        ExprKind::Number { text, .. } => Rational::from_decimal(text),
        ExprKind::Neg(a) => numeric_exponent(a)?.checked_neg(),
        ExprKind::Binary { op, lhs, rhs, .. } => {
            let (a, b) = (numeric_exponent(lhs)?, numeric_exponent(rhs)?);
            match op {
                BinOp::Add => a.checked_add(b),
                BinOp::Sub => a.checked_sub(b),
                BinOp::Mul => a.checked_mul(b),
                BinOp::Div => a.checked_div(b),
                BinOp::Pow => None,
            }
        }
        _ => None,
    }
}

/// The terms of a sum `a + b - c` (signs dropped: they do not change units).
fn terms<'e>(e: &'e Expr, out: &mut Vec<&'e Expr>) {
    match &e.kind {
        ExprKind::Binary {
            op: BinOp::Add | BinOp::Sub,
            lhs,
            rhs,
            ..
        } => {
            terms(lhs, out);
            terms(rhs, out);
        }
        _ => out.push(e),
    }
}

/// The unit text of a parameter's comment or `unit:`: what precedes the first `,`.
fn unit_part(text: &str) -> &str {
    text.split(',').next().unwrap_or_default()
}

/// Component names for messages.
const AXES: [&str; 3] = ["x", "y", "z"];

impl<'f> Checker<'f> {
    /// Both passes over `file`, with the unit of `undeclared` (if any) treated as unknown.
    fn run(file: &'f ModelFile, undeclared: Option<Target>) -> Self {
        let mut cx = Checker::new(file);
        match undeclared {
            Some(Target::Parameter(i)) => {
                if let Some(u) = cx.parameters.get_mut(i) {
                    cx.unknowns.push((false, i));
                    *u = Unit::Var(cx.unknowns.len() - 1);
                }
            }
            Some(Target::Coordinate(i)) => {
                if let Some(u) = cx.coordinates.get_mut(i) {
                    cx.unknowns.push((true, i));
                    *u = Unit::Var(cx.unknowns.len() - 1);
                }
            }
            None => {}
        }
        cx.solution = vec![None; cx.unknowns.len()];
        // Pass 1: requirements in the unknowns; solve them.
        cx.walk();
        cx.solve();
        // Pass 2: every unknown solved or left free; report.
        cx.mode = Mode::Report;
        cx.walk();
        cx.undeclared();
        cx
    }

    /// The unit solved for `target`, when it was an unknown.
    fn solution_of(&self, target: Target) -> Option<Solved> {
        let key = match target {
            Target::Parameter(i) => (false, i),
            Target::Coordinate(i) => (true, i),
        };
        let k = self.unknowns.iter().position(|u| *u == key)?;
        self.solution.get(k).cloned().flatten()
    }

    /// Notes the names of the expression `e` about to be checked, for [`root_cause`].
    fn top(&mut self, e: &Expr) {
        if self.mode == Mode::Report {
            let mut ids = Vec::new();
            identifiers(e, &mut ids);
            self.names = ids.into_iter().map(|(n, _)| n).collect();
        }
    }

    fn new(file: &'f ModelFile) -> Self {
        let mut diagnostics = Vec::new();
        let mut unknowns = Vec::new();
        let mut parameters = Vec::new();
        for (i, p) in file.parameters.iter().enumerate() {
            let unit = match &p.unit {
                None => {
                    unknowns.push((false, i));
                    Unit::Var(unknowns.len() - 1)
                }
                Some(u) => match parse_unit(unit_part(&u.value)) {
                    Ok(d) => Unit::Known(d),
                    Err(e) => {
                        let mut d = Diagnostic::new(
                            u.location.offset(e.offset),
                            e.message_for(&format!("parameter `{}`", p.name.value)),
                        )
                        .with_help(e.help);
                        if u.value.contains(' ') && !u.value.contains(',') {
                            d.help = d.help.map(|h| {
                                format!("{h}; a comment gives the unit first, then a `,` and any description: `# N/m, spring`")
                            });
                        }
                        diagnostics.push(d);
                        Unit::Any
                    }
                },
            };
            parameters.push(unit);
        }
        let mut coordinates = Vec::new();
        for (i, c) in file.coordinates.iter().enumerate() {
            let declared = match &c.unit {
                Some(u) => match parse_unit(&u.value) {
                    Ok(d) => Some(Unit::Known(d)),
                    Err(e) => {
                        diagnostics.push(
                            Diagnostic::new(
                                u.location.offset(e.offset),
                                e.message_for(&format!("coordinate `{}`", c.name.value)),
                            )
                            .with_help(e.help),
                        );
                        Some(Unit::Any)
                    }
                },
                // A comment that does not start with a unit only describes the coordinate.
                None => c
                    .comment
                    .as_deref()
                    .and_then(|t| parse_unit(unit_part(t)).ok())
                    .map(Unit::Known),
            };
            coordinates.push(declared.unwrap_or_else(|| {
                unknowns.push((true, i));
                Unit::Var(unknowns.len() - 1)
            }));
        }
        Self {
            file,
            mode: Mode::Infer,
            diagnostics,
            parameters,
            coordinates,
            solution: vec![None; unknowns.len()],
            unknowns,
            equations: Vec::new(),
            constraints: Vec::new(),
            spelling: None,
            names: Vec::new(),
            failing_names: Vec::new(),
            interaction: false,
        }
    }

    /// The unit of `u` in the current pass.
    fn unit(&self, u: Unit) -> Option<Dim> {
        match (u, self.mode) {
            (Unit::Known(d), _) => Some(Dim::of(d)),
            (Unit::Var(i), Mode::Infer) => Some(Dim::var(i)),
            (Unit::Var(i), Mode::Report) => {
                let solved = self.solution.get(i).cloned().flatten()?;
                Some(Dim {
                    inferred: vec![i],
                    ..Dim::of(solved.unit)
                })
            }
            (Unit::Any, _) => None,
        }
    }

    fn coordinate(&self, name: &str) -> Option<usize> {
        self.file
            .coordinates
            .iter()
            .position(|c| c.name.value == name)
    }

    /// The unit of a coordinate (`x`), rate (`x_dot`) or acceleration (`x_ddot`).
    fn motion(&self, name: &str) -> Option<Option<Dim>> {
        let (base, per) = if let Some(b) = name.strip_suffix("_ddot") {
            (b, -2)
        } else if let Some(b) = name.strip_suffix("_dot") {
            (b, -1)
        } else {
            (name, 0)
        };
        let i = self.coordinate(base)?;
        let u = self.coordinates.get(i).copied().unwrap_or(Unit::Any);
        Some(
            self.unit(u)
                .and_then(|d| d.mul(&Dim::of(Dimension::integers(0, 0, per)))),
        )
    }

    fn name(&self, n: &str) -> Option<Dim> {
        match n {
            "pi" => return Some(Dim::of(Dimension::ONE)),
            "t" => return Some(Dim::of(Dimension::SECOND)),
            "r" if self.interaction => return Some(Dim::of(Dimension::METRE)),
            "r_dot" if self.interaction => {
                return Some(Dim::of(Dimension::integers(1, 0, -1)));
            }
            _ => {}
        }
        if let Some(i) = self.file.parameters.iter().position(|p| p.name.value == n) {
            return self.unit(self.parameters.get(i).copied().unwrap_or(Unit::Any));
        }
        if let Some(c) = n.strip_prefix("lambda_")
            && let Some((_, unit, holonomic)) = self.constraints.iter().find(|(k, _, _)| k == c)
        {
            // `M q̈ = F − Jᵀ λ` with `J = ∂Φ/∂q` (holonomic) or `∂g/∂q̇` (non-holonomic):
            // `λ` is J per unit of `Φ`, or W per unit of `g`.
            let work = if *holonomic {
                Dimension::JOULE
            } else {
                Dimension::WATT
            };
            return Dim::of(work).div(unit.as_ref()?);
        }
        if self.file.angular_velocity_name(n).is_some() {
            return Some(Dim::of(Dimension::FREQUENCY));
        }
        // Names already reported take any unit.
        self.motion(n).flatten()
    }

    /// Requires `got = want` (`what` at `at` says where); `report` builds the diagnostic
    /// from the two units.
    fn require(
        &mut self,
        got: Option<&Dim>,
        want: Option<&Dim>,
        (priority, what, at): (u8, &str, Location),
        report: impl FnOnce(Dimension, Dimension) -> Diagnostic,
    ) {
        let (Some(got), Some(want)) = (got, want) else {
            return;
        };
        match self.mode {
            Mode::Infer => {
                if let Some(dim) = got.div(want)
                    && !dim.unknowns.is_empty()
                {
                    self.equations.push(Equation {
                        priority,
                        dim,
                        origin: what.to_string(),
                        at,
                        spelling: self.spelling.clone(),
                    });
                }
            }
            Mode::Report => {
                if got.unknowns.is_empty() && want.unknowns.is_empty() && got.known != want.known {
                    let mut d = report(got.known, want.known);
                    let notes: Vec<String> = union(&got.inferred, &want.inferred)
                        .iter()
                        .filter_map(|&i| self.inference_note(i))
                        .collect();
                    if !notes.is_empty() {
                        let help = d.help.take().unwrap_or_default();
                        d.help = Some(format!("{help} ({})", notes.join("; ")));
                    }
                    self.diagnostics.push(d);
                    self.failing_names.push(self.names.clone());
                }
            }
        }
    }

    /// "`x` is taken to be m^2/s from `kinetic` at 8:10; declare its unit if it is not".
    fn inference_note(&self, i: usize) -> Option<String> {
        let solved = self.solution.get(i).cloned().flatten()?;
        let &(is_coordinate, index) = self.unknowns.get(i)?;
        let name = if is_coordinate {
            &self.file.coordinates.get(index)?.name.value
        } else {
            &self.file.parameters.get(index)?.name.value
        };
        Some(format!(
            "the unit of `{name}`, {}, is inferred from {} at {}; declare the unit of `{name}` if it is another",
            solved.text(),
            solved.origin,
            solved.at
        ))
    }

    /// The unit of `e`, checking its sums, function arguments and powers; `None` when it
    /// can be anything (`0`, a name already reported, an inconsistent sum).
    fn dim(&mut self, e: &Expr, what: &str) -> Option<Dim> {
        match &e.kind {
            ExprKind::Number { value, .. } => (*value != 0.0).then(|| Dim::of(Dimension::ONE)),
            ExprKind::Ident(n) => self.name(n),
            ExprKind::Neg(a) => self.dim(a, what),
            ExprKind::Binary {
                op: BinOp::Add | BinOp::Sub,
                ..
            } => self.sum(e, what),
            ExprKind::Binary {
                op: op @ (BinOp::Mul | BinOp::Div),
                lhs,
                rhs,
                ..
            } => {
                let a = self.dim(lhs, what);
                let b = self.dim(rhs, what);
                match op {
                    BinOp::Mul => a?.mul(&b?),
                    _ => a?.div(&b?),
                }
            }
            ExprKind::Binary { lhs, rhs, .. } => self.power(e, lhs, rhs, what),
            ExprKind::Call { func, args } => self.call(func, args, what),
        }
    }

    fn sum(&mut self, e: &Expr, what: &str) -> Option<Dim> {
        let mut parts = Vec::new();
        terms(e, &mut parts);
        let dims: Vec<Option<Dim>> = parts.iter().map(|t| self.dim(t, what)).collect();
        let (first, reference) = parts
            .iter()
            .zip(&dims)
            .find_map(|(t, d)| d.as_ref().map(|d| (*t, d.clone())))?;
        let before = self.diagnostics.len();
        for (t, d) in parts.iter().zip(&dims) {
            if std::ptr::eq(*t, first) {
                continue;
            }
            let (first_text, term_text, at) = (text(first), text(t), t.location);
            self.require(d.as_ref(), Some(&reference), (HOMOGENEITY, what, at), |got, want| {
                Diagnostic::new(
                    at,
                    format!(
                        "sum of unlike units in {what}: `{first_text}` is {} but `{term_text}` is {}",
                        show(want),
                        show(got)
                    ),
                )
                .with_help("every term of a sum has the same unit; check the formula and the units of its parameters")
            });
        }
        // An inconsistent sum has no unit: no second message about the same mistake.
        (self.diagnostics.len() == before).then_some(reference)
    }

    fn power(&mut self, e: &Expr, base: &Expr, exponent: &Expr, what: &str) -> Option<Dim> {
        let b = self.dim(base, what);
        if let Some(p) = numeric_exponent(exponent) {
            return b?.pow(p);
        }
        let x = self.dim(exponent, what);
        let one = Dim::of(Dimension::ONE);
        let before = self.diagnostics.len();
        let (exponent_text, power_text, at) = (text(exponent), text(e), exponent.location);
        self.require(x.as_ref(), Some(&one), (HOMOGENEITY, what, at), |got, _| {
            Diagnostic::new(
                at,
                format!("the exponent `{exponent_text}` in {what} is {}, but an exponent is a pure number", show(got)),
            )
            .with_help("divide it by a quantity of the same unit")
        });
        let base_text = text(base);
        self.require(b.as_ref(), Some(&one), (HOMOGENEITY, what, base.location), |got, _| {
            Diagnostic::new(
                base.location,
                format!("`{power_text}` in {what} raises `{base_text}`, which is {}, to a power that is not a number", show(got)),
            )
            .with_help("only a pure number can be raised to a symbolic power; write the exponent as a number, as in `x^2` or `x^(1/2)`")
        });
        // A wrong power has no unit: no second message about the same mistake.
        (self.diagnostics.len() == before).then_some(one)
    }

    /// The unit of a vector expression of the points (their positions in m): a sum takes
    /// the unit of its terms, `vel` divides by s, `cross` multiplies; anything else is
    /// [`Self::dim`]. (The rules checked the shapes: vectors and numbers are where they
    /// belong.)
    fn vector_dim(&mut self, e: &Expr, what: &str) -> Option<Dim> {
        let vector = |cx: &Self, e: &Expr| {
            let points: Vec<&str> = cx
                .file
                .points
                .iter()
                .map(|p| p.name.value.as_str())
                .collect();
            super::vectors::shape_of(e, &points, cx.file.dimension.unwrap_or(2))
                == Some(super::vectors::Shape::Vector)
        };
        match &e.kind {
            ExprKind::Ident(n) if self.file.points.iter().any(|p| p.name.value == *n) => {
                Some(Dim::of(Dimension::METRE))
            }
            ExprKind::Neg(a) => self.vector_dim(a, what),
            ExprKind::Binary {
                op: BinOp::Add | BinOp::Sub,
                lhs,
                rhs,
                ..
            } => {
                let (a, b) = (self.vector_dim(lhs, what), self.vector_dim(rhs, what));
                let (l, r, at) = (text(lhs), text(rhs), rhs.location);
                self.require(
                    b.as_ref(),
                    a.as_ref(),
                    (HOMOGENEITY, what, at),
                    |got, want| {
                        Diagnostic::new(
                            at,
                            format!(
                                "sum of unlike units in {what}: `{l}` is {} but `{r}` is {}",
                                show(want),
                                show(got)
                            ),
                        )
                        .with_help("every term of a sum of vectors has the same unit")
                    },
                );
                a.or(b)
            }
            ExprKind::Binary {
                op: op @ (BinOp::Mul | BinOp::Div),
                lhs,
                rhs,
                ..
            } => {
                let a = if vector(self, lhs) {
                    self.vector_dim(lhs, what)
                } else {
                    self.dim(lhs, what)
                };
                let b = if vector(self, rhs) {
                    self.vector_dim(rhs, what)
                } else {
                    self.dim(rhs, what)
                };
                match op {
                    BinOp::Mul => a?.mul(&b?),
                    _ => a?.div(&b?),
                }
            }
            ExprKind::Call { func, args } if func == "vel" => {
                let a = self.vector_dim(args.first()?, what);
                a?.div(&Dim::of(Dimension::SECOND))
            }
            ExprKind::Call { func, args } if func == "cross" => {
                let dims: Vec<Option<Dim>> =
                    args.iter().map(|a| self.vector_dim(a, what)).collect();
                match dims.as_slice() {
                    [Some(a), Some(b)] => a.mul(b),
                    _ => None,
                }
            }
            _ => self.dim(e, what),
        }
    }

    fn call(&mut self, func: &str, args: &[Expr], what: &str) -> Option<Dim> {
        if super::vectors::is_vector_function(func) {
            let dims: Vec<Option<Dim>> = args.iter().map(|a| self.vector_dim(a, what)).collect();
            return match (func, dims.as_slice()) {
                ("dot" | "cross", [Some(a), Some(b)]) => a.mul(b),
                ("norm", [a]) => a.clone(),
                ("distance", [a, b]) => {
                    let (l, r, at) = (text(&args[0]), text(&args[1]), args[1].location);
                    self.require(b.as_ref(), a.as_ref(), (HOMOGENEITY, what, at), |got, want| {
                        Diagnostic::new(
                            at,
                            format!("the arguments of `distance` in {what} have unlike units: `{l}` is {} but `{r}` is {}", show(want), show(got)),
                        )
                        .with_help("`distance(A, B)` is the length of `A - B`: both are positions")
                    });
                    a.clone().or_else(|| b.clone())
                }
                _ => None,
            };
        }
        let dims: Vec<Option<Dim>> = args.iter().map(|a| self.dim(a, what)).collect();
        let one = Dim::of(Dimension::ONE);
        match (func, args, dims.as_slice()) {
            ("sqrt", _, [d]) => d.as_ref()?.pow(Rational::new(1, 2)?),
            ("abs", _, [d]) => d.clone(),
            ("sign" | "step", _, _) => Some(one),
            ("atan2", [y, x], [dy, dx]) => {
                let (y_text, x_text, at) = (text(y), text(x), x.location);
                self.require(dx.as_ref(), dy.as_ref(), (HOMOGENEITY, what, at), |got, want| {
                    Diagnostic::new(
                        at,
                        format!(
                            "the arguments of `atan2` in {what} have unlike units: `{y_text}` is {} but `{x_text}` is {}",
                            show(want),
                            show(got)
                        ),
                    )
                    .with_help("`atan2(y, x)` is the angle of the vector (x, y): both components have one unit")
                });
                Some(one)
            }
            (_, [a], [d]) => {
                let (arg_text, at) = (text(a), a.location);
                self.require(d.as_ref(), Some(&one), (HOMOGENEITY, what, at), |got, _| {
                    Diagnostic::new(
                        at,
                        format!(
                            "the argument of `{func}` in {what} is {}, but it must be a pure number (rad)",
                            show(got)
                        ),
                    )
                    .with_help(format!(
                        "`{func}` takes a pure number, such as an angle in rad: `{arg_text}` lacks a factor of unit {}, or a parameter in it has the wrong unit",
                        Dimension::ONE.checked_div(got).map_or_else(|| "?".to_string(), show)
                    ))
                });
                Some(one)
            }
            _ => None,
        }
    }

    /// Checks `e` against the unit its key requires; a value written with numbers only is
    /// in that unit.
    fn key(
        &mut self,
        e: &Expr,
        want: Option<Dim>,
        what: &str,
        report: impl FnOnce(Dimension, Dimension) -> Diagnostic,
    ) {
        if numbers_only(e) {
            return;
        }
        self.top(e);
        let got = self.dim(e, what);
        self.require(got.as_ref(), want.as_ref(), (KEY, what, e.location), report);
    }

    /// Checks `e` against a fixed unit: "`what` is got, but `kind` is want_text" with `help`,
    /// plus the parameter's declaration when `e` is a lone parameter.
    fn fixed(
        &mut self,
        e: &Expr,
        want: Dimension,
        what: &str,
        kind: &str,
        want_text: &str,
        help: &str,
    ) {
        let lone = match &e.kind {
            ExprKind::Ident(n) => self.file.parameters.iter().find(|p| &p.name.value == n),
            _ => None,
        };
        let spelling = want_text.split(" (").next().unwrap_or(want_text);
        let advice = match lone {
            Some(p) => format!(
                "{help}; if `{n}` is one, declare it so: `{n}: {}  # {spelling}`",
                write_expr(&p.default, 0),
                n = p.name.value
            ),
            None => help.to_string(),
        };
        let at = e.location;
        self.spelling = lone.map(|_| spelling.to_string());
        self.key(e, Some(Dim::of(want)), what, |got, _| {
            Diagnostic::new(
                at,
                format!("{what} is {}, but {kind} is {want_text}", show(got)),
            )
            .with_help(advice)
        });
        self.spelling = None;
    }

    /// Checks a value of coordinate `name` or of its rate (`initial:`, `equilibria:`,
    /// `final_state:`).
    fn value_of(&mut self, name: &str, e: &Expr, what: &str) {
        let Some(want) = self.motion(name).flatten() else {
            return;
        };
        let at = e.location;
        let name = name.to_string();
        self.key(e, Some(want), what, |got, want| {
            Diagnostic::new(
                at,
                format!(
                    "{what} is {}, but `{name}` is {}",
                    show(got),
                    show_coordinate(want)
                ),
            )
            .with_help(format!(
                "write it in the unit of `{name}`, or fix the units of its parameters"
            ))
        });
    }

    /// Checks that `e` is consistent in itself (its sums, functions and powers).
    fn homogeneous(&mut self, e: &Expr, what: &str) {
        self.top(e);
        self.dim(e, what);
    }

    /// Both passes visit every expression of the file in the same order.
    // One piece (about 200 lines): a list, one call per place in the file where an expression
    // stands, with the dimension it must have and how the message names it. Both passes rely
    // on this one order; split by section it would only be a longer list.
    fn walk(&mut self) {
        let file = self.file;
        let j = Dimension::JOULE;
        if let Some(k) = &file.kinetic {
            self.fixed(
                k,
                j,
                "`kinetic`",
                "an energy",
                "J",
                "kinetic energy is mass × speed² / 2, kg*(m/s)^2 = J: check the powers of the rates and the units of the parameters",
            );
        }
        if let Some(v) = &file.potential {
            self.fixed(
                v,
                j,
                "`potential`",
                "an energy",
                "J",
                "potential energy is force × length, N*m = J, as in `m*g*h` or `k*x^2/2`",
            );
        }
        for (k, q) in &file.generalized_forces {
            let Some(coordinate) = self.motion(&k.value).flatten() else {
                self.homogeneous(q, &format!("the generalized force of `{}`", k.value));
                continue;
            };
            let want = Dim::of(j).div(&coordinate);
            let (name, at) = (k.value.clone(), q.location);
            let what = format!("the generalized force of `{name}`");
            self.key(q, want, &what, |got, want| {
                Diagnostic::new(
                    at,
                    format!(
                        "{what} is {}, but `{name}` is {}, so it must be {}",
                        show(got),
                        show_coordinate(j.checked_div(want).unwrap_or(Dimension::ONE)),
                        show_load(want)
                    ),
                )
                .with_help(format!(
                    "the virtual work `Q δ{name}` is an energy (J), so a generalized force is J per unit of its coordinate: N for a length, N*m for an angle"
                ))
            });
        }
        for p in &file.points {
            let relative = p.relative.iter().flat_map(|r| &r.vectors);
            let in_frames = relative.flat_map(|(_, v)| AXES.iter().zip(v));
            for (axis, c) in AXES.iter().zip(&p.position).chain(in_frames) {
                self.fixed(
                    c,
                    Dimension::METRE,
                    &format!("the {axis} component of point `{}`", p.name.value),
                    "a position",
                    "m",
                    "positions are lengths: check the units of the parameters in it",
                );
            }
        }
        for p in &file.points {
            if let Some(wheel) = &p.wheel {
                self.fixed(
                    &wheel.radius,
                    Dimension::METRE,
                    &format!("the wheel radius of point `{}`", p.name.value),
                    "a length",
                    "m",
                    "a wheel's radius is a length",
                );
            }
        }
        for f in &file.frames {
            for r in &f.rotations {
                self.fixed(
                    &r.angle,
                    Dimension::ONE,
                    &format!("the rotation angle of frame `{}`", f.name.value),
                    "an angle",
                    "rad (a pure number)",
                    "a rotation angle is an angle coordinate, or a function of the coordinates that gives a pure number",
                );
            }
        }
        for b in &file.bodies {
            let name = &b.name.value;
            let (mass, inertia_angle) = match &b.kind {
                BodyKind::Particle { mass, .. } => (mass, None),
                BodyKind::Spatial { mass, inertia, .. } => {
                    for (key, e) in InertiaTensor::KEYS.iter().zip(&inertia.entries) {
                        if let Some(e) = e {
                            self.fixed(
                                e,
                                Dimension::INERTIA,
                                &format!("the `{key}` inertia of body `{name}`"),
                                "a moment of inertia",
                                "kg*m^2",
                                "an entry of an inertia tensor is mass × length², as in `m*r^2/2` for a disc about its axis",
                            );
                        }
                    }
                    (mass, None)
                }
                BodyKind::Rigid {
                    mass,
                    inertia,
                    angle,
                    ..
                } => (mass, Some((inertia, angle))),
            };
            self.fixed(
                mass,
                Dimension::KILOGRAM,
                &format!("the mass of body `{name}`"),
                "a mass",
                "kg",
                "a body's mass is in kg",
            );
            if let Some((inertia, angle)) = inertia_angle {
                self.fixed(
                    inertia,
                    Dimension::INERTIA,
                    &format!("the inertia of body `{name}`"),
                    "a moment of inertia",
                    "kg*m^2",
                    "a moment of inertia is mass × length², as in `m*l^2/12` for a uniform bar about its centre",
                );
                self.fixed(
                    angle,
                    Dimension::ONE,
                    &format!("the angle of body `{name}`"),
                    "an angle",
                    "rad (a pure number)",
                    "a body's angle is an angle coordinate, or a function of the coordinates that gives a pure number",
                );
            }
        }
        if let Some(g) = &file.gravity {
            for (axis, c) in AXES.iter().zip(&g.value) {
                self.fixed(
                    c,
                    Dimension::ACCELERATION,
                    &format!("the {axis} component of `gravity`"),
                    "an acceleration",
                    "m/s^2",
                    "gravity is the acceleration of free fall, as in `[0, -g]` with `g: 9.81  # m/s^2`",
                );
            }
        }
        for s in &file.springs {
            let name = &s.name.value;
            self.fixed(
                &s.stiffness,
                Dimension::STIFFNESS,
                &format!("the stiffness of spring `{name}`"),
                "a spring stiffness",
                "N/m",
                "a spring pulls with stiffness × stretch, N/m × m = N",
            );
            if let Some(l) = &s.rest_length {
                self.fixed(
                    l,
                    Dimension::METRE,
                    &format!("the rest length of spring `{name}`"),
                    "a length",
                    "m",
                    "a rest length is the distance between the spring's points when it is relaxed",
                );
            }
        }
        for d in &file.dampers {
            self.fixed(
                &d.coefficient,
                Dimension::DAMPING,
                &format!("the coefficient of damper `{}`", d.name.value),
                "a damping coefficient",
                "N*s/m",
                "a damper pushes with coefficient × rate of stretch, N*s/m × m/s = N",
            );
        }
        for f in &file.forces {
            for (axis, c) in AXES.iter().zip(&f.vector) {
                self.fixed(
                    c,
                    Dimension::NEWTON,
                    &format!("the {axis} component of force `{}`", f.name.value),
                    "a force",
                    "N",
                    "a force is mass × acceleration, kg*m/s^2 = N",
                );
            }
        }
        self.interaction = true;
        for i in &file.interactions {
            self.fixed(
                &i.magnitude,
                Dimension::NEWTON,
                &format!("the magnitude of interaction `{}`", i.name.value),
                "a force",
                "N",
                "an interaction's magnitude is a force, with `r` in m and `r_dot` in m/s",
            );
        }
        self.interaction = false;
        for o in &file.outputs {
            self.homogeneous(&o.value, &format!("output `{}`", o.name.value));
        }
        for t in &file.torques {
            for (i, e) in t.value.expressions().into_iter().enumerate() {
                let what = match &t.value {
                    TorqueValue::Planar(_) => format!("torque `{}`", t.name.value),
                    TorqueValue::Spatial { .. } => {
                        format!("the {} component of torque `{}`", AXES[i], t.name.value)
                    }
                };
                self.fixed(
                    e,
                    Dimension::JOULE,
                    &what,
                    "a torque",
                    "N*m",
                    "a torque is force × lever arm, N*m",
                );
            }
        }
        self.constraints.clear();
        for (holonomic, list) in [(true, &file.constraints), (false, &file.nonholonomic)] {
            for (k, e) in list {
                self.top(e);
                let unit = self.dim(e, &format!("constraint `{}`", k.value));
                self.constraints.push((k.value.clone(), unit, holonomic));
            }
        }
        // A constraint on a point is a length (m), a rolling contact's rows velocities (m/s).
        for c in &file.point_constraints {
            let length = Dim::of(Dimension::METRE);
            self.constraints
                .push((c.name.value.clone(), Some(length), true));
        }
        for r in &file.rolling {
            for k in r.constraint_names() {
                let velocity = Dim::of(Dimension::integers(1, 0, -1));
                self.constraints.push((k.value, Some(velocity), false));
            }
        }
        for (k, e) in &file.initial {
            self.value_of(&k.value, e, &format!("the initial value of `{}`", k.value));
        }
        for q in &file.equilibria {
            for (c, e) in &q.values {
                self.value_of(
                    &c.value,
                    e,
                    &format!("`{}` of equilibrium `{}`", c.value, q.name.value),
                );
            }
        }
        for e in &file.events {
            self.homogeneous(
                &e.when,
                &format!("the function of event `{}`", e.name.value),
            );
        }
        for b in &file.balances {
            if let BalanceKind::Lmb { along } = &b.kind {
                for e in along {
                    self.homogeneous(e, "`along`");
                }
            }
        }
        self.checks();
    }

    fn checks(&mut self) {
        let checks = &self.file.checks;
        for (i, eq) in checks.equations_of_motion.iter().enumerate() {
            let what = format!("equation of motion {}", i + 1);
            self.top(&eq.lhs);
            let lhs = self.dim(&eq.lhs, &what);
            let Some(rhs_expr) = &eq.rhs else { continue };
            if self.mode == Mode::Report {
                let mut ids = Vec::new();
                identifiers(rhs_expr, &mut ids);
                self.names.extend(ids.into_iter().map(|(n, _)| n));
            }
            let rhs = self.dim(rhs_expr, &what);
            if numbers_only(&eq.lhs) || numbers_only(rhs_expr) {
                continue;
            }
            let (l, r, at) = (text(&eq.lhs), text(rhs_expr), rhs_expr.location);
            self.require(rhs.as_ref(), lhs.as_ref(), (HOMOGENEITY, &what, at), |got, want| {
                Diagnostic::new(
                    at,
                    format!(
                        "the sides of {what} have unlike units: `{l}` is {} but `{r}` is {}",
                        show(want),
                        show(got)
                    ),
                )
                .with_help("both sides are a generalized force of one coordinate: N for a length, N*m for an angle")
            });
        }
        for (key, check, want, want_text) in [
            (
                "natural_frequencies",
                &checks.natural_frequencies,
                Dimension::FREQUENCY,
                "rad/s",
            ),
            (
                "damping_ratios",
                &checks.damping_ratios,
                Dimension::ONE,
                "1",
            ),
        ] {
            let Some(check) = check else { continue };
            for v in &check.values {
                self.fixed(
                    v,
                    want,
                    &format!("a value of `{key}`"),
                    "it",
                    want_text,
                    "natural frequencies are in rad/s, as in `sqrt(k/m)`; damping ratios are pure numbers, as in `c/(2*sqrt(k*m))`",
                );
            }
        }
        if let Some(p) = &checks.period {
            self.fixed(
                &p.value,
                Dimension::SECOND,
                "the `value` of `period`",
                "a period",
                "s",
                "a period is a time, as in `2*pi*sqrt(l/g)`",
            );
        }
        if let Some(state) = &checks.final_state {
            self.fixed(
                &state.t,
                Dimension::SECOND,
                "the time `t` of `final_state`",
                "a time",
                "s",
                "`t` is the time of the state, in s",
            );
            for (k, v) in &state.values {
                self.value_of(
                    &k.value,
                    v,
                    &format!("the value of `{}` in `final_state`", k.value),
                );
            }
        }
        for c in &checks.conserved {
            self.homogeneous(&c.value, &format!("conserved quantity `{}`", c.name.value));
        }
    }

    /// Solves the unknowns one at a time. Every equation with exactly one unknown left,
    /// `known · x^c = 1`, proposes `x = known^(-1/c)`; the proposal that satisfies the most
    /// equations wins (ties: key requirements first, then file order), so that one wrong
    /// formula does not outvote the others.
    ///
    /// An equation with the one unknown `i` left holds for `x` exactly when it proposes `x`
    /// itself (dimensions have no roots of unity), and an equation with none left holds for
    /// every proposal alike; so the votes for `(i, x)` are counted as the equations proposing
    /// it, with each equation reduced once a round (counting by re-checking every equation
    /// for every proposal took 7.5 s for a 40-link pendulum with no coordinate units).
    fn solve(&mut self) {
        loop {
            let proposals: Vec<(usize, Dimension, &Equation)> = self
                .equations
                .iter()
                .filter_map(|eq| {
                    let (known, left) = self.reduce(&eq.dim)?;
                    let [(i, c)] = left[..] else { return None };
                    let x = Rational::integer(-1)
                        .checked_div(c)
                        .and_then(|p| known.pow(p))?;
                    Some((i, x, eq))
                })
                .collect();
            let mut votes: HashMap<(usize, Dimension), usize> = HashMap::new();
            for &(i, x, _) in &proposals {
                *votes.entry((i, x)).or_default() += 1;
            }
            let mut best: Option<(usize, u8, usize, Dimension, &Equation)> = None;
            for &(i, x, eq) in &proposals {
                let count = votes[&(i, x)];
                let better = best
                    .as_ref()
                    .is_none_or(|(v, p, ..)| count > *v || (count == *v && eq.priority < *p));
                if better {
                    best = Some((count, eq.priority, i, x, eq));
                }
            }
            let Some((_, _, i, unit, eq)) = best else {
                return;
            };
            let solved = Solved {
                unit,
                origin: eq.origin.clone(),
                at: eq.at,
                spelling: eq.spelling.clone(),
            };
            if let Some(s) = self.solution.get_mut(i) {
                *s = Some(solved);
            }
        }
    }

    /// An equation with the solved unknowns substituted: its known part and the unknowns
    /// left (`None` on exponent overflow).
    fn reduce(&self, eq: &Dim) -> Option<(Dimension, Vec<(usize, Rational)>)> {
        let mut known = eq.known;
        let mut left = Vec::new();
        for &(i, c) in &eq.unknowns {
            match self.solution.get(i).and_then(Option::as_ref) {
                Some(x) => known = known.checked_mul(x.unit.pow(c)?)?,
                None => left.push((i, c)),
            }
        }
        Some((known, left))
    }

    /// Parameters without a unit, and coordinates whose unit could not be inferred.
    fn undeclared(&mut self) {
        let file = self.file;
        for (k, &(is_coordinate, i)) in self.unknowns.iter().enumerate() {
            let implied = self.solution.get(k).cloned().flatten();
            if is_coordinate {
                if implied.is_some() {
                    continue;
                }
                let Some(c) = file.coordinates.get(i) else {
                    continue;
                };
                let n = &c.name.value;
                self.diagnostics.push(
                    Diagnostic::new(
                        c.name.location,
                        format!("the unit of coordinate `{n}` is neither declared nor implied by its use"),
                    )
                    .with_help(format!(
                        "declare it at the start of its comment, `- {n}  # m`, or as `- {{ name: {n}, unit: m }}`"
                    )),
                );
                continue;
            }
            let Some(p) = file.parameters.get(i) else {
                continue;
            };
            let n = &p.name.value;
            let value = write_expr(&p.default, 0);
            let shared = file
                .parameters
                .iter()
                .any(|o| o.name.location.line == p.name.location.line && o.name.value != *n);
            let line = if shared { " on a line of its own" } else { "" };
            let help = match implied {
                Some(u) => format!(
                    "write `{n}: {value}  # {u}`{line} (the unit its use implies), or `{n}: {{ value: {value}, unit: {u} }}`",
                    u = u.text()
                ),
                None => format!(
                    "write its unit in a trailing comment, `{n}: {value}  # N/m`{line}, or `{n}: {{ value: {value}, unit: N/m }}` (`1` for a pure number)"
                ),
            };
            self.diagnostics.push(
                Diagnostic::new(p.name.location, format!("parameter `{n}` has no unit"))
                    .with_help(help),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::model::load;

    /// `line:col: message` of every diagnostic of `src`.
    fn errors(src: &str) -> Vec<String> {
        match load("t.yaml", src) {
            Ok(_) => Vec::new(),
            Err(d) => d
                .iter()
                .map(|d| format!("{}: {}", d.location, d.message))
                .collect(),
        }
    }

    fn helps(src: &str) -> Vec<String> {
        load("t.yaml", src)
            .err()
            .unwrap_or_default()
            .into_iter()
            .filter_map(|d| d.help)
            .collect()
    }

    const OSCILLATOR: &str = "name: a\nunits: SI\nparameters:\n  m: 1.0  # kg\n  k: 4.0  # N/m\n  c: 0.1  # N*s/m\ncoordinates: [x]\n";

    #[test]
    fn a_consistent_file_passes_and_infers_its_coordinate() {
        let src = format!(
            "{OSCILLATOR}kinetic: m*x_dot^2/2\npotential: k*x^2/2\ngeneralized_forces: {{ x: -c*x_dot }}\ninitial: {{ x: 0.1 }}\n"
        );
        assert_eq!(errors(&src), Vec::<String>::new());
    }

    #[test]
    fn without_units_nothing_is_checked() {
        let src =
            "name: a\nparameters: { m: 1, k: 2 }\ncoordinates: [x]\nkinetic: (m + k)*x_dot^2\n";
        assert_eq!(errors(src), Vec::<String>::new());
    }

    #[test]
    fn energies_and_sums() {
        let src = format!("{OSCILLATOR}  - x  # m\nkinetic: m*x_dot/2\npotential: k*x^2/2 + m\n");
        let src = src.replace("coordinates: [x]\n", "coordinates:\n");
        assert_eq!(
            errors(&src),
            [
                "9:10: `kinetic` is kg*m/s, but an energy is J",
                "10:22: sum of unlike units in `potential`: `k*x^2/2` is J but `m` is kg",
            ]
        );
    }

    #[test]
    fn an_inferred_unit_comes_from_the_most_uses_and_is_named_in_the_help() {
        // `x` is a length by its point and its potential energy (two votes), not m^2/s by
        // the wrong kinetic energy (one vote).
        let src = format!(
            "{OSCILLATOR}kinetic: m*x_dot/2\npotential: k*x^2/2\npoints: {{ P: [x, 0] }}\n"
        );
        assert_eq!(
            errors(&src),
            ["8:10: `kinetic` is kg*m/s, but an energy is J"]
        );
        let help = &helps(&src)[0];
        assert!(
            help.ends_with("(the unit of `x`, m, is inferred from `potential` at 9:12; declare the unit of `x` if it is another)"),
            "{help}"
        );
    }

    #[test]
    fn functions_and_powers() {
        let src = "name: a\nunits: SI\nparameters:\n  m: 1.0  # kg\n  l: 1.0  # m\n  g: 9.81  # m/s^2\ncoordinates:\n  - x  # m\nkinetic: m*x_dot^2/2\npotential: m*g*l*cos(x) + m*g*l*exp(x/l) + m*g*l^x/l^x + m*g*sqrt(l*x) + m*g*l*atan2(x, t)\n";
        assert_eq!(
            errors(src),
            [
                "10:22: the argument of `cos` in `potential` is m, but it must be a pure number (rad)",
                "10:48: `l^x` in `potential` raises `l`, which is m, to a power that is not a number",
                "10:50: the exponent `x` in `potential` is m, but an exponent is a pure number",
                "10:52: `l^x` in `potential` raises `l`, which is m, to a power that is not a number",
                "10:54: the exponent `x` in `potential` is m, but an exponent is a pure number",
                "10:89: the arguments of `atan2` in `potential` have unlike units: `x` is m but `t` is s",
            ]
        );
    }

    #[test]
    fn parameters_without_a_unit_name_the_unit_their_use_implies() {
        let src = "name: a\nunits: SI\nparameters:\n  m: 1.0  # kg\n  k: 100.0\ncoordinates:\n  - x  # m\nkinetic: m*x_dot^2/2\npotential: k*x^2/2\n";
        assert_eq!(errors(src), ["5:3: parameter `k` has no unit"]);
        assert_eq!(
            helps(src),
            [
                "write `k: 100.0  # N/m` (the unit its use implies), or `k: { value: 100.0, unit: N/m }`"
            ]
        );
    }

    #[test]
    fn map_forms_and_bad_units() {
        let src = "name: a\nunits: SI\nparameters:\n  m: { value: 1.0, unit: kg }\n  k: 4.0  # N/mm, spring\ncoordinates:\n  - { name: x, unit: m }\n  - { name: y, unit: furlong }\nkinetic: m*(x_dot^2 + y_dot^2)/2\n";
        assert_eq!(
            errors(src),
            [
                "5:15: unknown unit `mm` in the unit of parameter `k`",
                "8:22: unknown unit `furlong` in the unit of coordinate `y`",
            ]
        );
        // Issue 28: "in the unit in the unit of parameter" is said once.
        let src = "name: a\nunits: SI\nparameters:\n  m: { value: 1.0, unit: kg }\n  k: { value: 1.0, unit: N/m) }\n  c: { value: 1.0, unit: (N*s/m }\n  d: { value: 1.0, unit: N%m }\ncoordinates:\n  - { name: x, unit: m }\nkinetic: m*x_dot^2/2\n";
        assert_eq!(
            errors(src),
            [
                "5:29: unexpected `)` in the unit of parameter `k`: it closes no `(`",
                "6:32: unclosed `(` in the unit of parameter `c`",
                "7:27: unexpected `%` in the unit of parameter `d`",
            ]
        );
    }

    #[test]
    fn constraint_forces_numbers_and_equations() {
        // The rod's multiplier is J per m of `Φ` = N: comparing it with a weight is right,
        // with a mass wrong. A number alone is in the unit of its key; inside an expression
        // it is a pure number, except 0.
        let src = "name: a\nunits: SI\nparameters:\n  m: 1.0  # kg\n  l: 1.0  # m\n  g: 9.81  # m/s^2\ncoordinates:\n  - x  # m\n  - y  # m\npoints: { O: [0, 0], P: [x, y], Q: [x - 1, y + 0] }\nbodies: { bob: { mass: m, at: P } }\ngravity: [0, -g]\nconstraints: { rod: sqrt(x^2 + y^2) - l }\nevents:\n  taut: lambda_rod - m*g\n  wrong: lambda_rod - m\ninitial: { x: 1, y: 0 }\nchecks:\n  equations_of_motion:\n    - m*x_ddot = -m*g*x/l\n    - m*y_ddot = -m*g*l\n";
        assert_eq!(
            errors(src),
            [
                "10:41: sum of unlike units in the x component of point `Q`: `x` is m but `1` is 1",
                "16:23: sum of unlike units in the function of event `wrong`: `lambda_rod` is N but `m` is kg",
                "21:18: the sides of equation of motion 2 have unlike units: `m*y_ddot` is N but `-m*g*l` is J",
            ]
        );
    }

    #[test]
    fn bad_units_key() {
        let src = "name: a\nunits: imperial\ncoordinates: [x]\nkinetic: x_dot^2\n";
        assert_eq!(
            errors(src),
            ["2:8: `units` must be one of SI, found `imperial`"]
        );
    }
}
