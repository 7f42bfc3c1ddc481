//! Method II.2 of the constraint methods (lectures 8–10, HW13): the holonomic constraints
//! `Φ(q, t) = 0` of a model file solved for the dependent coordinates in terms of the kept
//! ones, and the solution substituted into the file, which leaves a model in minimal
//! coordinates without multipliers `λ`.
//!
//! [`reduce`] takes a loaded [`ModelFile`] and the names of the coordinates to keep. Every
//! other coordinate is eliminated with one constraint, one at a time (a dependent coordinate
//! solved from one constraint is substituted into the others before the next is solved):
//!
//! - a constraint **linear** in the coordinate, `c₁ y + c₀ = 0`, gives `y = −c₀/c₁`;
//! - a **quadratic** one, `a y² + b y + c = 0`, gives `y = (−b ± √(b² − 4ac))/(2a)`
//!   (`y = ±√(−c/a)` when `b = 0`); the sign — the branch — is the option's, else the one the
//!   file's initial state lies on (for a start given as `{ guess: … }`, the root nearest the
//!   guess), else (where the initial state is where the two branches meet) the one the first
//!   deciding entry of `equilibria:` lies on;
//! - a constraint `k √P + R = 0` with `P` polynomial in the coordinate is squared first,
//!   `k² P − R² = 0` (the rod `√(x² + y²) − ℓ = 0` gives `x² + y² − ℓ² = 0`), and a root is
//!   taken only where the constraint as written holds.
//!
//! The rates follow by the chain rule, `ẏ = Σᵢ (∂y/∂qᵢ) q̇ᵢ + ∂y/∂t` (`ẏ = x ẋ/√(ℓ² − x²)` for
//! the hanging pendulum `y = −√(ℓ² − x²)`), and a generalized force `Q_y` of the energy form
//! moves onto the kept coordinates by virtual work, `Q_x ← Q_x + Q_y ∂y/∂x`. Points, bodies,
//! loads, `kinetic:`, `potential:`, `initial:`, `equilibria:`, `events:` and the reference
//! values of `checks:` are rewritten; what no longer applies (the constraints, `minimal_twin:`,
//! the hand-derived equations, the constraint drift check) is left out and said so in
//! [`ReducedModel::notes`]. The result is the YAML text of a model file, loaded again before
//! it is returned, so that it is known to be a valid model file.
//!
//! A reduced model is singular where the branches meet (`∂y/∂x` infinite: the mass matrix
//! `m ℓ²/(ℓ² − x²)` of the pendulum at `x = ±ℓ`): HW13's point that a minimal coordinate is
//! valid only on part of the configuration space. A start there is an error
//! ([`ReduceError::SingularStart`]): [`ReduceOptions::initial`] gives the reduced file another.
//!
//! References: lecture 9 (methods of handling constraints: I stiff springs, II.1 DAE with
//! multipliers, II.2 elimination of the multipliers and dependent coordinates, II.3 minimal
//! coordinates from the start) and HW13 (the pendulum in its horizontal coordinate); E. J.
//! Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems*, Allyn and Bacon,
//! 1989, §6.3 (generalized coordinate partitioning).

use rustc_hash::FxHashMap;
use serde::Serialize;

use super::ast::{Expr, ExprKind};
use super::file::{BodyKind, Crossing, ModelFile, TorqueValue};
use super::parser::{eval_expr, parse_expr};
use super::{BinOp, Location};
use crate::expr::print::{Printer, Syntax};
use crate::expr::{Constant, ExprArena, ExprId, Func, Node, SymbolId, SymbolKind};

/// The sign taken in a quadratic constraint's solution `y = (−b ± √(b² − 4ac))/(2a)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Branch {
    /// `+√`.
    Plus,
    /// `−√`.
    Minus,
}

impl Branch {
    /// `+` or `-`.
    pub fn sign(self) -> char {
        match self {
            Branch::Plus => '+',
            Branch::Minus => '-',
        }
    }
}

impl std::str::FromStr for Branch {
    type Err = String;

    /// `+`, `plus`, `-` or `minus`.
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "+" | "plus" => Ok(Branch::Plus),
            "-" | "minus" => Ok(Branch::Minus),
            _ => Err(format!("a branch is `+` or `-`, got `{s}`")),
        }
    }
}

/// Options of [`reduce`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReduceOptions {
    /// The branch of a quadratic solution by dependent coordinate (`y` → `−`), overriding
    /// the choice by the initial state and the equilibria.
    pub branches: Vec<(String, Branch)>,
    /// New initial values of kept coordinates or their rates (`x` → `l/2`), as expressions of
    /// the parameters in the model syntax, replacing the file's in the reduced file (a start
    /// away from where the reduction is singular).
    pub initial: Vec<(String, String)>,
    /// The reduced model's `name:`; `None`: `<name>_in_<kept coordinates>`.
    pub name: Option<String>,
}

/// How the branch of a quadratic solution was chosen.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case", tag = "by", content = "name")]
pub enum BranchReason {
    /// Given in [`ReduceOptions::branches`].
    Option,
    /// The file's initial state lies on it.
    InitialState,
    /// The initial state is where the branches meet; this entry of `equilibria:` lies on it.
    Equilibrium(String),
}

/// One dependent coordinate eliminated.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Elimination {
    /// The coordinate eliminated (`y`).
    pub coordinate: String,
    /// The constraint it was solved from (`rod`).
    pub constraint: String,
    /// Its expression in the kept coordinates, model syntax (`-sqrt(l^2 - x^2)`).
    pub solution: String,
    /// Its rate by the chain rule, model syntax (`x*x_dot/sqrt(l^2 - x^2)`).
    pub rate: String,
    /// The constraint's degree in the coordinate (1 or 2), after squaring a root.
    pub degree: u32,
    /// Whether the constraint was squared first (`k √P + R = 0` → `k² P − R² = 0`).
    pub squared: bool,
    /// The branch taken and why (quadratic constraints only).
    pub branch: Option<(Branch, BranchReason)>,
}

/// The result of [`reduce`]: the reduced model file and how it was obtained.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReducedModel {
    /// The model file's YAML text.
    pub text: String,
    /// The text loaded ([`super::load`]): a valid model file.
    #[serde(skip)]
    pub file: ModelFile,
    /// The coordinates kept, in the original file's order.
    pub kept: Vec<String>,
    /// The coordinates eliminated, in the order they were solved.
    pub eliminations: Vec<Elimination>,
    /// What of the original file was left out or changed, in words.
    pub notes: Vec<String>,
}

/// Why a model could not be reduced.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ReduceError {
    /// The file has no holonomic constraints.
    #[error("`{model}` has no holonomic constraints to eliminate")]
    NoConstraints {
        /// The model's name.
        model: String,
    },
    /// A name to keep is not a coordinate of the file.
    #[error("`{name}` is not a coordinate of the model (its coordinates are {known})")]
    UnknownCoordinate {
        /// The name given.
        name: String,
        /// The coordinates, comma separated.
        known: String,
    },
    /// The number of coordinates to eliminate is not the number of holonomic constraints.
    #[error(
        "keeping {kept} leaves {dependent} coordinate(s) to eliminate, but the model has {constraints} holonomic constraint(s): keep {} coordinate(s)",
        kept_count
    )]
    WrongCount {
        /// The kept coordinates, comma separated.
        kept: String,
        /// How many would be eliminated.
        dependent: usize,
        /// How many holonomic constraints there are.
        constraints: usize,
        /// How many to keep.
        kept_count: usize,
    },
    /// The file uses a part of the model format that the elimination does not rewrite.
    #[error("the elimination does not rewrite {feature} yet")]
    Unsupported {
        /// What, as the format names it.
        feature: String,
    },
    /// A constraint cannot be solved for the coordinate.
    #[error("constraint `{constraint}` cannot be solved for `{coordinate}`: {reason}")]
    Unsolvable {
        /// The constraint.
        constraint: String,
        /// The coordinate to eliminate.
        coordinate: String,
        /// Why, in words.
        reason: String,
    },
    /// Neither the initial state nor an equilibrium decides between the two branches.
    #[error(
        "`{coordinate}` has two branches, {plus} and {minus}, and neither the initial state nor an equilibrium lies on only one: choose one with a branch option (`{coordinate}=+` or `{coordinate}=-`)"
    )]
    AmbiguousBranch {
        /// The coordinate.
        coordinate: String,
        /// The `+` solution.
        plus: String,
        /// The `−` solution.
        minus: String,
    },
    /// A branch option names no coordinate that a quadratic constraint eliminates.
    #[error(
        "a branch is given for `{coordinate}`, which is not eliminated by a quadratic constraint"
    )]
    UnusedBranch {
        /// The name given.
        coordinate: String,
    },
    /// The same coordinate is given a branch twice.
    #[error("a branch is given twice for `{coordinate}`")]
    RepeatedBranch {
        /// The coordinate.
        coordinate: String,
    },
    /// The reduced model's name is not a name.
    #[error(
        "`{name}` is not a model name: a name starts with a letter and contains letters, digits and `_`"
    )]
    BadName {
        /// The name given.
        name: String,
    },
    /// An initial value option is malformed or names no kept coordinate or rate.
    #[error("initial value `{name}`: {reason}")]
    BadInitial {
        /// The name given.
        name: String,
        /// Why.
        reason: String,
    },
    /// An expression of the file uses a name the elimination cannot rewrite.
    #[error("`{name}` in {place} cannot be rewritten in the kept coordinates")]
    UnknownName {
        /// The name.
        name: String,
        /// Where, in words.
        place: String,
    },
    /// The reduced coordinates are singular at the reduced file's start: where the two
    /// branches of a quadratic constraint meet (`∂y/∂x` infinite), or where a linear one's
    /// coefficient vanishes. The mass matrix is not finite there, so no file is written.
    #[error(
        "the reduced coordinates are singular or not real where the model starts ({detail}): the reduced mass matrix is not finite there; give the kept coordinates an initial value where the eliminated ones are real and regular"
    )]
    SingularStart {
        /// The expression that vanishes there, and which solution it belongs to.
        detail: String,
    },
    /// The written file did not load (a defect of the elimination, reported rather than
    /// written).
    #[error("the reduced model file does not load: {}", messages.join("; "))]
    Invalid {
        /// The loader's messages.
        messages: Vec<String>,
    },
}

/// Reduces `file` to the coordinates `keep` by solving its holonomic constraints for the
/// others (method II.2; see the [module documentation](self)).
///
/// `keep` names coordinates of the file (in any order; the reduced file lists them in the
/// file's order); the others, as many as the file has holonomic constraints, are eliminated.
///
/// # Errors
/// [`ReduceError::NoConstraints`], [`ReduceError::UnknownCoordinate`],
/// [`ReduceError::WrongCount`] for the arguments; [`ReduceError::Unsupported`] for a file
/// with frames, 3-D points written in frames, 3-D bodies, forces or torques in frames,
/// constraints on points or non-holonomic constraints; [`ReduceError::Unsolvable`] naming the
/// constraint and the coordinate when a constraint is not polynomial of degree ≤ 2 in it
/// (after squaring a square root) or does not contain it; [`ReduceError::AmbiguousBranch`],
/// [`ReduceError::UnusedBranch`], [`ReduceError::RepeatedBranch`], [`ReduceError::BadInitial`],
/// [`ReduceError::BadName`] for the options; [`ReduceError::SingularStart`] where the
/// eliminated coordinates are singular or not real at the start; [`ReduceError::UnknownName`];
/// [`ReduceError::Invalid`] if the result does not load.
///
/// # Examples
/// ```
/// use eomgen_symbolic::model::reduce::{ReduceOptions, reduce};
///
/// let text = "name: pendulum\nparameters: { m: 1.0, l: 1.0, g: 10.0 }\ncoordinates: [x, y]\n\
///             points: { P: [x, y] }\nbodies: { bob: { mass: m, at: P } }\ngravity: [0, -g]\n\
///             constraints: { rod: x^2 + y^2 - l^2 }\ninitial: { x: l/2, y: -sqrt(3)*l/2 }\n";
/// let file = eomgen_symbolic::model::load("pendulum.yaml", text).unwrap();
/// let reduced = reduce(&file, &["x"], &ReduceOptions::default())?;
/// assert_eq!(reduced.eliminations[0].solution, "-sqrt(l^2 - x^2)");
/// assert_eq!(reduced.file.coordinates.len(), 1);
/// # Ok::<(), eomgen_symbolic::model::reduce::ReduceError>(())
/// ```
pub fn reduce(
    file: &ModelFile,
    keep: &[&str],
    options: &ReduceOptions,
) -> Result<ReducedModel, ReduceError> {
    unsupported(file)?;
    if let Some(name) = options
        .name
        .as_ref()
        .filter(|n| !super::schema::is_identifier(n))
    {
        return Err(ReduceError::BadName { name: name.clone() });
    }
    for (i, (name, _)) in options.branches.iter().enumerate() {
        if options.branches[..i].iter().any(|(n, _)| n == name) {
            return Err(ReduceError::RepeatedBranch {
                coordinate: name.clone(),
            });
        }
    }
    if file.constraints.is_empty() {
        return Err(ReduceError::NoConstraints {
            model: file.name.value.clone(),
        });
    }
    let names: Vec<&str> = file
        .coordinates
        .iter()
        .map(|c| c.name.value.as_str())
        .collect();
    for k in keep {
        if !names.contains(k) {
            return Err(ReduceError::UnknownCoordinate {
                name: (*k).to_string(),
                known: names.join(", "),
            });
        }
    }
    let kept: Vec<String> = names
        .iter()
        .filter(|n| keep.contains(n))
        .map(|n| (*n).to_string())
        .collect();
    let dependent: Vec<usize> = (0..names.len())
        .filter(|&i| !keep.contains(&names[i]))
        .collect();
    if dependent.len() != file.constraints.len() {
        return Err(ReduceError::WrongCount {
            kept: if kept.is_empty() {
                "nothing".to_string()
            } else {
                kept.join(", ")
            },
            dependent: dependent.len(),
            constraints: file.constraints.len(),
            kept_count: names.len().saturating_sub(file.constraints.len()),
        });
    }
    let mut r = Reducer::new(file);
    let eliminations = r.solve(&dependent, options)?;
    for (name, _) in &options.branches {
        if !eliminations
            .iter()
            .any(|e| &e.coordinate == name && e.branch.is_some())
        {
            return Err(ReduceError::UnusedBranch {
                coordinate: name.clone(),
            });
        }
    }
    let initial = initial_overrides(file, &kept, options)?;
    if let Some(detail) = r.singular_start(&initial) {
        return Err(ReduceError::SingularStart { detail });
    }
    let name = options
        .name
        .clone()
        .unwrap_or_else(|| format!("{}_in_{}", file.name.value, kept.join("_")));
    let mut notes = Vec::new();
    let text = r.write(&name, &kept, &eliminations, &initial, &mut notes)?;
    let invalid = |d: Vec<super::Diagnostic>| ReduceError::Invalid {
        messages: d
            .iter()
            .map(|d| format!("{}:{}: {}", d.location.line, d.location.column, d.message))
            .collect(),
    };
    let reduced = super::load(&format!("{name}.yaml"), &text).map_err(invalid)?;
    // The compilers' own check of the mass matrix (at the start, and everywhere), so that
    // the file written is one they compile.
    let mut model = crate::mechanics::SymbolicModel::from_file(&reduced).map_err(invalid)?;
    crate::mechanics::limit_derivation(&mut model);
    let (eom, _) = crate::mechanics::preferred_equations(&mut model);
    crate::mechanics::finish_derivation(&mut model, &reduced).map_err(invalid)?;
    let problems = crate::mechanics::mass_matrix_diagnostics(&model, &eom, &reduced);
    if !problems.is_empty() {
        return Err(invalid(problems));
    }
    Ok(ReducedModel {
        text,
        file: reduced,
        kept,
        eliminations,
        notes,
    })
}

/// The YAML text of `file` as [`reduce`] writes its results, with nothing eliminated: the
/// writer of reduced files applied to any file it can write, so that a reduced file can be
/// loaded and written again (a round trip gives the same equations). Comments are not kept
/// (the parameters' and coordinates' units are); what is left out is listed in the second
/// value (`checks: equations_of_motion`, `floquet:`, `balances:`).
///
/// # Errors
/// [`ReduceError::Unsupported`] as [`reduce`]; [`ReduceError::UnknownName`];
/// [`ReduceError::Invalid`] if the text written does not load.
pub fn write_model(file: &ModelFile) -> Result<(String, Vec<String>), ReduceError> {
    unsupported(file)?;
    let kept: Vec<String> = file
        .coordinates
        .iter()
        .map(|c| c.name.value.clone())
        .collect();
    let initial: Vec<(String, Expr)> = file
        .initial
        .iter()
        .map(|(n, e)| (n.value.clone(), e.clone()))
        .collect();
    let mut notes = Vec::new();
    let mut r = Reducer::new(file);
    let text = r.write(&file.name.value, &kept, &[], &initial, &mut notes)?;
    super::load(&file.path, &text).map_err(|d| ReduceError::Invalid {
        messages: d.iter().map(|d| d.message.clone()).collect(),
    })?;
    Ok((text, notes))
}

/// The parts of the format [`reduce`] does not rewrite.
fn unsupported(file: &ModelFile) -> Result<(), ReduceError> {
    let feature = |f: &str| {
        Err(ReduceError::Unsupported {
            feature: f.to_string(),
        })
    };
    if !file.frames.is_empty() {
        return feature("`frames:`");
    }
    if file
        .points
        .iter()
        .any(|p| p.relative.is_some() || p.wheel.is_some())
    {
        return feature("points written in frames or as wheel contacts");
    }
    if file
        .bodies
        .iter()
        .any(|b| matches!(b.kind, BodyKind::Spatial { .. }))
    {
        return feature("3-D bodies");
    }
    if file.forces.iter().any(|f| f.frame.is_some()) {
        return feature("forces written in frames (`in:`)");
    }
    if file
        .torques
        .iter()
        .any(|t| matches!(t.value, TorqueValue::Spatial { .. }))
    {
        return feature("3-D torques");
    }
    if !file.point_constraints.is_empty() {
        return feature("constraints on points (`{ point: …, along: … }`)");
    }
    if !file.nonholonomic.is_empty() || !file.rolling.is_empty() {
        return feature("non-holonomic constraints");
    }
    if !file.draw.wheels.is_empty() {
        return feature("drawn wheels");
    }
    Ok(())
}

/// The initial values of the reduced file: the options' (parsed), then the file's for the
/// kept coordinates and rates, by name.
fn initial_overrides(
    file: &ModelFile,
    kept: &[String],
    options: &ReduceOptions,
) -> Result<Vec<(String, Expr)>, ReduceError> {
    let allowed = |n: &str| {
        kept.iter()
            .any(|k| k == n || n.strip_suffix("_dot") == Some(k.as_str()))
    };
    let mut out: Vec<(String, Expr)> = Vec::new();
    for (name, text) in &options.initial {
        if !allowed(name) {
            return Err(ReduceError::BadInitial {
                name: name.clone(),
                reason: format!(
                    "not a kept coordinate or its rate (kept: {})",
                    kept.join(", ")
                ),
            });
        }
        let e = parse_expr(text, Location::default()).map_err(|d| ReduceError::BadInitial {
            name: name.clone(),
            reason: d.message,
        })?;
        let lookup = |n: &str| parameter_value(file, n);
        eval_expr(&e, &lookup).map_err(|d| ReduceError::BadInitial {
            name: name.clone(),
            reason: format!(
                "{} (an initial value is an expression of the parameters)",
                d.message
            ),
        })?;
        out.retain(|(n, _)| n != name);
        out.push((name.clone(), e));
    }
    for (name, e) in &file.initial {
        if allowed(&name.value) && !out.iter().any(|(n, _)| *n == name.value) {
            out.push((name.value.clone(), e.clone()));
        }
    }
    Ok(out)
}

fn parameter_value(file: &ModelFile, name: &str) -> Option<f64> {
    file.parameters
        .iter()
        .find(|p| p.name.value == name)
        .map(|p| p.value)
}

/// The working state of one reduction: the file's expressions in one arena.
struct Reducer<'f> {
    file: &'f ModelFile,
    arena: ExprArena,
    /// `[q, q̇, q̈]` symbols per coordinate, in file order.
    coordinates: Vec<[SymbolId; 3]>,
    /// What every symbol of the eliminated coordinates becomes (`y`, `y_dot`).
    values: FxHashMap<SymbolId, ExprId>,
    /// The eliminated coordinates' solutions, for the singularity check: (coordinate, the
    /// expression that vanishes where the solution is singular, and whether it is a
    /// quadratic's discriminant, negative where there is no real solution).
    singular_where: Vec<(String, ExprId, bool)>,
    /// The names that no longer exist in the reduced file: the eliminated coordinates, their
    /// rates and accelerations, and the multipliers `lambda_<constraint>`.
    eliminated_names: Vec<String>,
}

/// A constraint's solution for one coordinate.
enum Roots {
    Linear {
        root: ExprId,
        /// The coefficient of the coordinate (singular where it vanishes).
        slope: ExprId,
    },
    Quadratic {
        plus: ExprId,
        minus: ExprId,
        /// Under the root (singular where it vanishes).
        discriminant: ExprId,
    },
}

/// Relative tolerance of the numerical tests of the branch choice.
const BRANCH_TOL: f64 = 1e-8;

impl<'f> Reducer<'f> {
    fn new(file: &'f ModelFile) -> Self {
        let mut arena = ExprArena::new();
        arena.declare("t", SymbolKind::Time);
        for p in &file.parameters {
            arena.declare(&p.name.value, SymbolKind::Parameter);
        }
        let coordinates = file
            .coordinates
            .iter()
            .map(|c| {
                arena.coordinate(&c.name.value);
                let id = |a: &ExprArena, s: &str| a.symbol_id(s).unwrap_or(SymbolId(0));
                let n = &c.name.value;
                [
                    id(&arena, n),
                    id(&arena, &format!("{n}_dot")),
                    id(&arena, &format!("{n}_ddot")),
                ]
            })
            .collect();
        Self {
            file,
            arena,
            coordinates,
            values: FxHashMap::default(),
            singular_where: Vec::new(),
            eliminated_names: Vec::new(),
        }
    }

    /// `e` in the arena, or the first name it does not know.
    fn lower(&mut self, e: &Expr) -> Result<ExprId, String> {
        Ok(match &e.kind {
            ExprKind::Number { value, text } => {
                let c = Constant::parse_decimal(text)
                    .or_else(|| Constant::float(*value))
                    .unwrap_or(Constant::ZERO);
                self.arena.constant(c)
            }
            ExprKind::Ident(name) if name == "pi" => self.arena.pi(),
            ExprKind::Ident(name) => match self.arena.symbol_id(name) {
                Some(s) => self.arena.symbol_expr(s),
                None => return Err(name.clone()),
            },
            ExprKind::Neg(a) => {
                let a = self.lower(a)?;
                self.arena.neg(a)
            }
            ExprKind::Binary { op, lhs, rhs, .. } => {
                let (a, b) = (self.lower(lhs)?, self.lower(rhs)?);
                match op {
                    BinOp::Add => self.arena.plus(a, b),
                    BinOp::Sub => self.arena.minus(a, b),
                    BinOp::Mul => self.arena.times(a, b),
                    BinOp::Div => self.arena.divide(a, b),
                    BinOp::Pow => self.arena.pow(a, b),
                }
            }
            ExprKind::Call { func, args } => {
                let args: Vec<ExprId> = args
                    .iter()
                    .map(|a| self.lower(a))
                    .collect::<Result<_, _>>()?;
                match (func.as_str(), args.as_slice()) {
                    ("sqrt", [a]) => self.arena.sqrt(*a),
                    ("atan2", [y, x]) => self.arena.atan2(*y, *x),
                    (name, [a]) => match Func::from_name(name) {
                        Some(f) => self.arena.func(f, *a),
                        None => return Err(name.to_string()),
                    },
                    (name, _) => return Err(name.to_string()),
                }
            }
        })
    }

    fn lower_in(&mut self, e: &Expr, place: &str) -> Result<ExprId, ReduceError> {
        self.lower(e).map_err(|name| ReduceError::UnknownName {
            name,
            place: place.to_string(),
        })
    }

    fn print(&self, e: ExprId) -> String {
        Printer::new(&self.arena, Syntax::Text).print(e)
    }

    /// The values of every symbol at the file's start (parameters at their defaults, `t` 0,
    /// coordinates and rates as `initial:` gives them, 0 otherwise), or at an equilibrium's
    /// coordinates.
    fn bindings(&self, values: &[(super::Located<String>, Expr)]) -> Vec<f64> {
        let mut b = vec![0.0; self.arena.symbols().len()];
        for p in &self.file.parameters {
            if let Some(s) = self.arena.symbol_id(&p.name.value) {
                b[s.index()] = p.value;
            }
        }
        let lookup = |n: &str| parameter_value(self.file, n);
        for (name, e) in values {
            if let Some(s) = self.arena.symbol_id(&name.value)
                && let Ok(v) = eval_expr(e, &lookup)
            {
                b[s.index()] = v;
            }
        }
        b
    }

    /// Solves the constraints for the coordinates `dependent`, one at a time.
    fn solve(
        &mut self,
        dependent: &[usize],
        options: &ReduceOptions,
    ) -> Result<Vec<Elimination>, ReduceError> {
        let mut constraints: Vec<(String, ExprId)> = Vec::new();
        for (name, e) in &self.file.constraints {
            let phi = self.lower_in(e, &format!("constraint `{}`", name.value))?;
            constraints.push((name.value.clone(), phi));
        }
        let mut unsolved: Vec<usize> = dependent.to_vec();
        // The solutions so far, in terms of the kept and the still unsolved coordinates.
        let mut solved: FxHashMap<SymbolId, ExprId> = FxHashMap::default();
        let mut eliminations: Vec<(usize, Elimination, ExprId)> = Vec::new();
        while !unsolved.is_empty() {
            let mut first_failure: Option<ReduceError> = None;
            let mut found = None;
            // Constraints with the fewest unsolved coordinates first.
            let mut order: Vec<(usize, Vec<usize>, ExprId)> = Vec::new();
            for (k, (_, phi)) in constraints.iter().enumerate() {
                let phi = self.arena.substitute(*phi, &solved);
                let involved: Vec<usize> = unsolved
                    .iter()
                    .copied()
                    .filter(|&i| self.arena.depends_on(phi, self.coordinates[i][0]))
                    .collect();
                order.push((k, involved, phi));
            }
            order.sort_by_key(|(_, inv, _)| inv.len());
            'search: for (k, involved, phi) in &order {
                if involved.is_empty() {
                    let (name, _) = &constraints[*k];
                    let coordinate = self.file.coordinates[unsolved[0]].name.value.clone();
                    first_failure.get_or_insert(ReduceError::Unsolvable {
                        constraint: name.clone(),
                        coordinate,
                        reason: "the constraint does not contain the coordinates to eliminate \
                                 (after the others are substituted): it constrains the kept \
                                 coordinates alone; keep other coordinates"
                            .to_string(),
                    });
                    continue;
                }
                for &i in involved {
                    match self.solve_one(&constraints[*k].0, *phi, i, options) {
                        Ok(found_one) => {
                            found = Some((*k, i, found_one));
                            break 'search;
                        }
                        Err(e) => {
                            first_failure.get_or_insert(e);
                        }
                    }
                }
            }
            let Some((k, i, (elimination, root))) = found else {
                return Err(first_failure.unwrap_or_else(|| ReduceError::Unsolvable {
                    constraint: constraints[0].0.clone(),
                    coordinate: self.file.coordinates[unsolved[0]].name.value.clone(),
                    reason: "no constraint contains it".to_string(),
                }));
            };
            let q = self.coordinates[i][0];
            let one: FxHashMap<SymbolId, ExprId> = [(q, root)].into_iter().collect();
            for v in solved.values_mut() {
                *v = self.arena.substitute(*v, &one);
            }
            solved.insert(q, root);
            constraints.remove(k);
            unsolved.retain(|&j| j != i);
            eliminations.push((i, elimination, root));
        }
        // Solutions in the kept coordinates alone, and their rates by the chain rule.
        let mut out = Vec::new();
        for (i, mut elimination, _) in eliminations {
            let [q, qd, _] = self.coordinates[i];
            let root = solved[&q];
            let rate = self.arena.time_derivative(root);
            let rate = self.arena.expand_if_cheaper(rate);
            elimination.solution = self.print(root);
            elimination.rate = self.print(rate);
            self.values.insert(q, root);
            self.values.insert(qd, rate);
            let name = &self.file.coordinates[i].name.value;
            self.eliminated_names.extend([
                name.clone(),
                format!("{name}_dot"),
                format!("{name}_ddot"),
            ]);
            out.push(elimination);
        }
        self.eliminated_names.extend(
            self.file
                .constraints
                .iter()
                .map(|(c, _)| format!("lambda_{}", c.value)),
        );
        // The singularity expressions in the kept coordinates too.
        for (_, e, _) in &mut self.singular_where {
            *e = self.arena.substitute(*e, &solved);
        }
        Ok(out)
    }

    /// Solves `phi = 0` for coordinate `i`.
    fn solve_one(
        &mut self,
        constraint: &str,
        phi: ExprId,
        i: usize,
        options: &ReduceOptions,
    ) -> Result<(Elimination, ExprId), ReduceError> {
        let coordinate = self.file.coordinates[i].name.value.clone();
        let d = self.coordinates[i][0];
        let fail = |reason: String| ReduceError::Unsolvable {
            constraint: constraint.to_string(),
            coordinate: coordinate.clone(),
            reason,
        };
        for rate in &self.coordinates[i][1..] {
            if self.arena.depends_on(phi, *rate) {
                return Err(fail("the constraint contains its rate".to_string()));
            }
        }
        let (polynomial, squared) = match polynomial_degree(&self.arena, phi, d) {
            Ok(_) => (phi, false),
            Err(at) => match self.rationalize(phi, d) {
                Some(p) => (p, true),
                None => {
                    return Err(fail(format!(
                        "`{coordinate}` appears in `{}`, which is not polynomial in it; the \
                         elimination solves constraints that are polynomials of degree ≤ 2 in \
                         the coordinate (or become one when a square root is squared), so \
                         `{coordinate}` can only be kept",
                        self.print(at)
                    )));
                }
            },
        };
        let Some(coefficients) = coefficients(&mut self.arena, polynomial, d) else {
            return Err(fail(
                "the constraint is not polynomial in it once multiplied out".to_string(),
            ));
        };
        let degree = coefficients.len().saturating_sub(1);
        let found = match degree {
            0 => {
                return Err(fail(
                    "the coordinate cancels from the constraint once multiplied out".to_string(),
                ));
            }
            1 => {
                let (c0, c1) = (coefficients[0], coefficients[1]);
                let minus_c0 = self.arena.neg(c0);
                let root = self.arena.divide(minus_c0, c1);
                let root = self.arena.expand_if_cheaper(root);
                Roots::Linear { root, slope: c1 }
            }
            2 => self.quadratic(coefficients[2], coefficients[1], coefficients[0]),
            n => {
                return Err(fail(format!(
                    "the constraint is of degree {n} in it; the elimination solves degree 1 and 2"
                )));
            }
        };
        let (root, branch, singular) = match found {
            Roots::Linear { root, slope } => (root, None, (slope, false)),
            Roots::Quadratic {
                plus,
                minus,
                discriminant,
            } => {
                let (branch, reason) =
                    self.choose_branch(&coordinate, phi, d, [plus, minus], options)?;
                let root = if branch == Branch::Plus { plus } else { minus };
                (root, Some((branch, reason)), (discriminant, true))
            }
        };
        self.singular_where
            .push((coordinate.clone(), singular.0, singular.1));
        Ok((
            Elimination {
                coordinate,
                constraint: constraint.to_string(),
                solution: String::new(),
                rate: String::new(),
                degree: degree as u32,
                squared,
                branch,
            },
            root,
        ))
    }

    /// The two roots of `a d² + b d + c = 0`.
    fn quadratic(&mut self, a: ExprId, b: ExprId, c: ExprId) -> Roots {
        // d = −h ± √(h² − c/a) with h = b/(2a): the radicand multiplied out is the
        // discriminant over 4a², free of the factor 4 that (−b ± √(b² − 4ac))/(2a) leaves
        // under the root (`l^2 - x^2` rather than `4*l^2 - 4*x^2`).
        let ar = &mut self.arena;
        let two = ar.int(2);
        let two_a = ar.times(two, a);
        let h = ar.divide(b, two_a);
        let h = ar.expand_if_cheaper(h);
        let h2 = ar.times(h, h);
        let c_over_a = ar.divide(c, a);
        let radicand = ar.minus(h2, c_over_a);
        let radicand = ar.expand(radicand);
        let root = ar.sqrt(radicand);
        let minus_h = ar.neg(h);
        let plus = ar.plus(minus_h, root);
        let minus = ar.minus(minus_h, root);
        Roots::Quadratic {
            plus,
            minus,
            discriminant: radicand,
        }
    }

    /// `k² P − R²` for `phi = k √P + R` with `P` polynomial in `d` and `k`, `R` free of it.
    fn rationalize(&mut self, phi: ExprId, d: SymbolId) -> Option<ExprId> {
        let terms: Vec<ExprId> = match self.arena.node(phi) {
            Node::Add(t) => t.to_vec(),
            _ => vec![phi],
        };
        let (with, without): (Vec<ExprId>, Vec<ExprId>) = terms
            .into_iter()
            .partition(|&t| self.arena.depends_on(t, d));
        let [term] = with.as_slice() else {
            return None;
        };
        let factors: Vec<ExprId> = match self.arena.node(*term) {
            Node::Mul(f) => f.to_vec(),
            _ => vec![*term],
        };
        let (root, k): (Vec<ExprId>, Vec<ExprId>) = factors
            .into_iter()
            .partition(|&f| self.arena.depends_on(f, d));
        let [root] = root.as_slice() else {
            return None;
        };
        let Node::Pow([p, half]) = *self.arena.node(*root) else {
            return None;
        };
        if self.arena.as_constant(half).map(Constant::to_f64) != Some(0.5)
            || polynomial_degree(&self.arena, p, d).is_err()
        {
            return None;
        }
        let ar = &mut self.arena;
        let k = ar.product(&k);
        let r = ar.sum(&without);
        let k2 = ar.times(k, k);
        let k2p = ar.times(k2, p);
        let r2 = ar.times(r, r);
        let squared = ar.minus(k2p, r2);
        Some(ar.expand(squared))
    }

    /// The branch of a quadratic solution (see the module documentation). `phi` is the
    /// constraint as written (after earlier substitutions), which the root must satisfy.
    fn choose_branch(
        &mut self,
        coordinate: &str,
        phi: ExprId,
        d: SymbolId,
        roots: [ExprId; 2],
        options: &ReduceOptions,
    ) -> Result<(Branch, BranchReason), ReduceError> {
        if let Some((_, b)) = options.branches.iter().find(|(n, _)| n == coordinate) {
            return Ok((*b, BranchReason::Option));
        }
        let decide = |this: &Self, bindings: &mut Vec<f64>| -> Option<Branch> {
            let value = bindings[d.index()];
            let mut on = [false; 2];
            let mut r = [0.0; 2];
            for (k, &root) in roots.iter().enumerate() {
                r[k] = this.arena.eval(root, bindings);
                let saved = bindings[d.index()];
                bindings[d.index()] = r[k];
                let residual = this.arena.eval(phi, bindings);
                bindings[d.index()] = saved;
                let scale = BRANCH_TOL * r[k].abs().max(1.0);
                on[k] = r[k].is_finite()
                    && residual.abs() <= scale
                    && (r[k] - value).abs() <= scale.max(1e-6 * value.abs());
            }
            let distinct = (r[0] - r[1]).abs() > BRANCH_TOL * r[0].abs().max(r[1].abs()).max(1.0);
            match (on, distinct) {
                ([true, false], true) => Some(Branch::Plus),
                ([false, true], true) => Some(Branch::Minus),
                _ => None,
            }
        };
        let mut start = self.bindings(&self.file.initial);
        if let Some(b) = decide(self, &mut start) {
            return Ok((b, BranchReason::InitialState));
        }
        // A start given as `{ guess: … }` is only near the constraint: the root nearest it
        // among those on the constraint as written (the one the start's projection finds).
        if self
            .file
            .initial_guesses
            .iter()
            .any(|g| g.value == coordinate)
        {
            let guess = start[d.index()];
            let mut near: Vec<(f64, Branch)> = Vec::new();
            for (root, branch) in roots.iter().zip([Branch::Plus, Branch::Minus]) {
                let r = self.arena.eval(*root, &start);
                start[d.index()] = r;
                let residual = self.arena.eval(phi, &start);
                start[d.index()] = guess;
                if r.is_finite() && residual.abs() <= BRANCH_TOL * r.abs().max(1.0) {
                    near.push(((r - guess).abs(), branch));
                }
            }
            near.sort_by(|a, b| a.0.total_cmp(&b.0));
            match near.as_slice() {
                [(_, b)] => return Ok((*b, BranchReason::InitialState)),
                [(da, b), (db, _)] if db - da > BRANCH_TOL * (da + db).max(1.0) => {
                    return Ok((*b, BranchReason::InitialState));
                }
                _ => {}
            }
        }
        for eq in &self.file.equilibria {
            let mut at = self.bindings(&eq.values);
            if let Some(b) = decide(self, &mut at) {
                return Ok((b, BranchReason::Equilibrium(eq.name.value.clone())));
            }
        }
        Err(ReduceError::AmbiguousBranch {
            coordinate: coordinate.to_string(),
            plus: self.print(roots[0]),
            minus: self.print(roots[1]),
        })
    }

    /// Where the reduced model's start is singular: a vanishing slope or discriminant.
    fn singular_start(&self, initial: &[(String, Expr)]) -> Option<String> {
        let located: Vec<(super::Located<String>, Expr)> = initial
            .iter()
            .map(|(n, e)| {
                (
                    super::Located::new(n.clone(), Location::default()),
                    e.clone(),
                )
            })
            .collect();
        self.singular_at(&located)
    }

    /// `e` rewritten in the kept coordinates, model syntax: the original text where it has
    /// no eliminated coordinate.
    fn rewrite(&mut self, e: &Expr, place: &str) -> Result<String, ReduceError> {
        // An expression that names nothing eliminated is written as it is (vector functions
        // of points included: the points are rewritten).
        let mut names = Vec::new();
        super::parser::identifiers(e, &mut names);
        if !names.iter().any(|(n, _)| self.eliminated_names.contains(n)) {
            return Ok(e.to_string());
        }
        let x = self.lower_in(e, place)?;
        let touched = self.values.keys().any(|s| self.arena.depends_on(x, *s));
        let ddot = self.values.keys().any(|&s| {
            self.coordinates
                .iter()
                .any(|c| c[0] == s && self.arena.depends_on(x, c[2]))
        });
        if ddot {
            return Err(ReduceError::UnknownName {
                name: "the acceleration of an eliminated coordinate".to_string(),
                place: place.to_string(),
            });
        }
        if !touched {
            return Ok(e.to_string());
        }
        let y = self.arena.substitute(x, &self.values);
        let y = self.arena.expand_if_cheaper(y);
        Ok(self.print(y))
    }

    /// The reduced file's YAML text.
    fn write(
        &mut self,
        name: &str,
        kept: &[String],
        eliminations: &[Elimination],
        initial: &[(String, Expr)],
        notes: &mut Vec<String>,
    ) -> Result<String, ReduceError> {
        use std::fmt::Write as _;
        let file = self.file;
        let mut w = String::new();
        let is_kept = |n: &str| kept.iter().any(|k| k == n);
        let is_kept_name = |n: &str| is_kept(n) || n.strip_suffix("_dot").is_some_and(is_kept);
        // A file written as it is ([`write_model`]) keeps its constraints and twin.
        let preserve = eliminations.is_empty();
        // Header.
        if !preserve {
            let _ = writeln!(
                w,
                "# `{}` reduced to the coordinates {} by eliminating the holonomic constraints",
                file.name.value,
                kept.join(", ")
            );
            let _ = writeln!(
                w,
                "# (method II.2, lectures 8-10, HW13; written by `eomgen reduce`):"
            );
            for e in eliminations {
                let how = match &e.branch {
                    None => String::new(),
                    Some((b, BranchReason::Option)) => format!(", branch {} as asked", b.sign()),
                    Some((b, BranchReason::InitialState)) => {
                        format!(", branch {} of the initial state", b.sign())
                    }
                    Some((b, BranchReason::Equilibrium(q))) => {
                        format!(", branch {} of the equilibrium `{q}`", b.sign())
                    }
                };
                let _ = writeln!(
                    w,
                    "#   {} = {}  (from `{}`{how})",
                    e.coordinate, e.solution, e.constraint
                );
                let _ = writeln!(w, "#   {}_dot = {}", e.coordinate, e.rate);
            }
            for (coordinate, e, event) in self.moving_singularities() {
                let _ = writeln!(
                    w,
                    "#   singular where {e} = 0: the kept coordinates do not determine {coordinate} there{}",
                    if event.is_some() {
                        format!(" (event `{coordinate}_singular` ends runs)")
                    } else {
                        String::new()
                    }
                );
            }
        }
        let _ = writeln!(w, "name: {name}");
        let description = if preserve {
            file.description.clone()
        } else {
            format!(
                "{} Reduced to {} (constraints eliminated).",
                file.description.trim_end(),
                kept.join(", ")
            )
        };
        let _ = writeln!(w, "description: {}", scalar(&description));
        if file.units.is_some() {
            let _ = writeln!(w, "units: SI");
        }
        if let Some(twin) = file.minimal_twin.as_ref().filter(|_| preserve) {
            let _ = writeln!(w, "minimal_twin: {}", twin.value);
        } else if file.minimal_twin.is_some() {
            notes.push("`minimal_twin:` left out (the reduced model is minimal)".to_string());
        }
        if !file.parameters.is_empty() {
            let _ = writeln!(w, "parameters:");
            for p in &file.parameters {
                let _ = write!(w, "  {}: {}", p.name.value, scalar(&p.default.to_string()));
                match &p.unit {
                    Some(u) => {
                        let _ = writeln!(w, "  # {}", u.value);
                    }
                    None => w.push('\n'),
                }
            }
        }
        let _ = writeln!(w, "coordinates:");
        for c in file.coordinates.iter().filter(|c| is_kept(&c.name.value)) {
            match (&c.unit, &c.comment) {
                (Some(u), _) => {
                    let _ = writeln!(w, "  - {{ name: {}, unit: {} }}", c.name.value, u.value);
                }
                (None, Some(comment)) => {
                    let _ = writeln!(w, "  - {}  # {}", c.name.value, comment.trim());
                }
                (None, None) => {
                    let _ = writeln!(w, "  - {}", c.name.value);
                }
            }
        }
        if let Some(t) = &file.kinetic {
            let t = self.rewrite(t, "`kinetic:`")?;
            let _ = writeln!(w, "kinetic: {}", scalar(&t));
        }
        if let Some(v) = &file.potential {
            let v = self.rewrite(v, "`potential:`")?;
            let _ = writeln!(w, "potential: {}", scalar(&v));
        }
        if !file.generalized_forces.is_empty() {
            let forces = self.generalized_forces(kept)?;
            if !forces.is_empty() {
                let _ = writeln!(w, "generalized_forces:");
                for (k, q) in forces {
                    let _ = writeln!(w, "  {k}: {}", scalar(&q));
                }
            }
        }
        if !file.points.is_empty() {
            let _ = writeln!(w, "points:");
            for p in &file.points {
                let place = format!("point `{}`", p.name.value);
                let parts = p
                    .position
                    .iter()
                    .map(|e| self.rewrite(e, &place))
                    .collect::<Result<Vec<_>, _>>()?;
                let _ = writeln!(w, "  {}: {}", p.name.value, list(&parts));
            }
        }
        if !file.bodies.is_empty() {
            let _ = writeln!(w, "bodies:");
            for b in &file.bodies {
                let place = format!("body `{}`", b.name.value);
                match &b.kind {
                    BodyKind::Particle { mass, at } => {
                        let m = self.rewrite(mass, &place)?;
                        let _ = writeln!(
                            w,
                            "  {}: {{ mass: {}, at: {} }}",
                            b.name.value,
                            flow(&m),
                            at.value
                        );
                    }
                    BodyKind::Rigid {
                        mass,
                        inertia,
                        com,
                        angle,
                    } => {
                        let m = self.rewrite(mass, &place)?;
                        let i = self.rewrite(inertia, &place)?;
                        let a = self.rewrite(angle, &place)?;
                        let _ = writeln!(
                            w,
                            "  {}: {{ mass: {}, inertia: {}, com: {}, angle: {} }}",
                            b.name.value,
                            flow(&m),
                            flow(&i),
                            com.value,
                            flow(&a)
                        );
                    }
                    BodyKind::Spatial { .. } => {}
                }
            }
        }
        if let Some(g) = &file.gravity {
            let parts = g
                .value
                .iter()
                .map(|e| self.rewrite(e, "`gravity:`"))
                .collect::<Result<Vec<_>, _>>()?;
            let _ = writeln!(w, "gravity: {}", list(&parts));
        }
        if !file.springs.is_empty() {
            let _ = writeln!(w, "springs:");
            for s in &file.springs {
                let place = format!("spring `{}`", s.name.value);
                let k = self.rewrite(&s.stiffness, &place)?;
                let _ = write!(
                    w,
                    "  {}: {{ between: [{}, {}], stiffness: {}",
                    s.name.value,
                    s.between[0].value,
                    s.between[1].value,
                    flow(&k)
                );
                if let Some(l0) = &s.rest_length {
                    let l0 = self.rewrite(l0, &place)?;
                    let _ = write!(w, ", rest_length: {}", flow(&l0));
                }
                let _ = writeln!(w, " }}");
            }
        }
        if !file.dampers.is_empty() {
            let _ = writeln!(w, "dampers:");
            for d in &file.dampers {
                let place = format!("damper `{}`", d.name.value);
                let c = self.rewrite(&d.coefficient, &place)?;
                let _ = writeln!(
                    w,
                    "  {}: {{ between: [{}, {}], coefficient: {} }}",
                    d.name.value,
                    d.between[0].value,
                    d.between[1].value,
                    flow(&c)
                );
            }
        }
        if !file.forces.is_empty() {
            let _ = writeln!(w, "forces:");
            for f in &file.forces {
                let place = format!("force `{}`", f.name.value);
                let parts = f
                    .vector
                    .iter()
                    .map(|e| self.rewrite(e, &place))
                    .collect::<Result<Vec<_>, _>>()?;
                let _ = writeln!(
                    w,
                    "  {}: {{ at: {}, vector: {} }}",
                    f.name.value,
                    f.at.value,
                    list(&parts)
                );
            }
        }
        if !file.torques.is_empty() {
            let _ = writeln!(w, "torques:");
            for t in &file.torques {
                let place = format!("torque `{}`", t.name.value);
                if let TorqueValue::Planar(e) = &t.value {
                    let v = self.rewrite(e, &place)?;
                    let _ = writeln!(
                        w,
                        "  {}: {{ body: {}, value: {} }}",
                        t.name.value,
                        t.body.value,
                        flow(&v)
                    );
                }
            }
        }
        if !file.interactions.is_empty() {
            let _ = writeln!(w, "interactions:");
            for f in &file.interactions {
                let place = format!("interaction `{}`", f.name.value);
                let magnitude = self.rewrite(&f.magnitude, &place)?;
                let _ = writeln!(
                    w,
                    "  {}: {{ between: [{}, {}], magnitude: {} }}",
                    f.name.value,
                    f.between[0].value,
                    f.between[1].value,
                    flow(&magnitude)
                );
            }
        }
        if !file.outputs.is_empty() {
            let mut block = String::new();
            for o in &file.outputs {
                let place = format!("output `{}`", o.name.value);
                match self.rewrite(&o.value, &place) {
                    Ok(v) if o.conserved => {
                        let _ = writeln!(
                            block,
                            "  {}: {{ value: {}, conserved: true, tolerance: {:e} }}",
                            o.name.value,
                            flow(&v),
                            o.tolerance
                        );
                    }
                    Ok(v) => {
                        let _ = writeln!(block, "  {}: {}", o.name.value, scalar(&v));
                    }
                    Err(e) => notes.push(format!("output `{}` left out: {e}", o.name.value)),
                }
            }
            if !block.is_empty() {
                let _ = writeln!(w, "outputs:");
                w.push_str(&block);
            }
        }
        if !file.balances.is_empty() {
            notes.push(
                "`balances:` left out: the reduced model is derived by Lagrange's equations"
                    .to_string(),
            );
        }
        if preserve && !file.constraints.is_empty() {
            let _ = writeln!(w, "constraints:");
            for (name, e) in &file.constraints {
                let _ = writeln!(w, "  {}: {}", name.value, scalar(&e.to_string()));
            }
        }
        if !preserve {
            notes.push(format!(
                "`constraints:` eliminated: {}",
                eliminations
                    .iter()
                    .map(|e| format!("`{}` gives {}", e.constraint, e.coordinate))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        // Initial values.
        if !initial.is_empty() {
            let parts: Vec<String> = initial
                .iter()
                .map(|(n, e)| {
                    if preserve && file.initial_guesses.iter().any(|g| g.value == *n) {
                        format!("{n}: {{ guess: {} }}", flow(&e.to_string()))
                    } else {
                        format!("{n}: {}", flow(&e.to_string()))
                    }
                })
                .collect();
            let _ = writeln!(w, "initial: {{ {} }}", parts.join(", "));
        }
        let dropped: Vec<&str> = file
            .initial
            .iter()
            .map(|(n, _)| n.value.as_str())
            .filter(|n| !is_kept_name(n))
            .collect();
        if dropped.iter().any(|n| n.ends_with("_dot")) {
            notes.push(format!(
                "the initial rates of eliminated coordinates ({}) are left out: the kept rates \
                 alone set the motion",
                dropped
                    .iter()
                    .filter(|n| n.ends_with("_dot"))
                    .copied()
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        if !preserve && file.initial_guesses.iter().any(|g| is_kept(&g.value)) {
            notes.push(
                "a kept coordinate's initial value was a guess; the reduced file starts at \
                 the guess"
                    .to_string(),
            );
        }
        // Drawing.
        if !file.draw.lines.is_empty() || !file.draw.trace.is_empty() {
            let lines: Vec<String> = file
                .draw
                .lines
                .iter()
                .map(|[a, b]| format!("[{}, {}]", a.value, b.value))
                .collect();
            let trace: Vec<&str> = file.draw.trace.iter().map(|p| p.value.as_str()).collect();
            let mut parts = Vec::new();
            if !lines.is_empty() {
                parts.push(format!("lines: [{}]", lines.join(", ")));
            }
            if !trace.is_empty() {
                parts.push(format!("trace: [{}]", trace.join(", ")));
            }
            let _ = writeln!(w, "draw: {{ {} }}", parts.join(", "));
        }
        // Equilibria on the chosen branches.
        let mut kept_equilibria: Vec<String> = Vec::new();
        let mut equilibria = String::new();
        for eq in &file.equilibria {
            if let Some(off) = self.off_branch(&eq.values) {
                notes.push(format!(
                    "equilibrium `{}` left out: it is not on the chosen branch ({off})",
                    eq.name.value
                ));
                continue;
            }
            if let Some(singular) = self.singular_at(&eq.values) {
                notes.push(format!(
                    "equilibrium `{}` left out: the reduced coordinates are singular there ({singular})",
                    eq.name.value
                ));
                continue;
            }
            let mut parts: Vec<String> = eq
                .values
                .iter()
                .filter(|(n, _)| is_kept_name(&n.value))
                .map(|(n, e)| format!("{}: {}", n.value, flow(&e.to_string())))
                .collect();
            let ignorable: Vec<&str> = eq
                .ignorable
                .iter()
                .map(|n| n.value.as_str())
                .filter(|n| is_kept(n))
                .collect();
            if !ignorable.is_empty() {
                parts.push(format!("ignorable: [{}]", ignorable.join(", ")));
            }
            let _ = writeln!(
                equilibria,
                "  {}: {{ {} }}",
                eq.name.value,
                parts.join(", ")
            );
            kept_equilibria.push(eq.name.value.clone());
        }
        if !equilibria.is_empty() {
            let _ = writeln!(w, "equilibria:");
            w.push_str(&equilibria);
        }
        // Events: the file's, rewritten, and one that ends runs where a linear solution's
        // slope crosses 0.
        let mut kept_events: Vec<String> = Vec::new();
        let mut events = String::new();
        for (coordinate, e, event) in self.moving_singularities() {
            let name = format!("{coordinate}_singular");
            notes.push(format!(
                "the reduced model is singular where {e} = 0 (`{coordinate}` is solved by dividing by it, or by a square root of it): the kept coordinates do not determine `{coordinate}` there, and the motion past it is not unique{}",
                if event.is_some() {
                    format!("; the event `{name}` ends runs there")
                } else {
                    "; a run that reaches it fails there".to_string()
                }
            ));
            if let Some(when) = event
                && !file.events.iter().any(|ev| ev.name.value == name)
            {
                let _ = writeln!(
                    events,
                    "  {name}: {{ when: {}, direction: both, terminal: true }}",
                    flow(&when)
                );
            }
        }
        for ev in &file.events {
            let place = format!("event `{}`", ev.name.value);
            match self.rewrite(&ev.when, &place) {
                Ok(g) => {
                    let _ = writeln!(
                        events,
                        "  {}: {{ when: {}, direction: {}, terminal: {} }}",
                        ev.name.value,
                        flow(&g),
                        match ev.direction {
                            Crossing::Rising => "rising",
                            Crossing::Falling => "falling",
                            Crossing::Both => "both",
                        },
                        ev.terminal
                    );
                    kept_events.push(ev.name.value.clone());
                }
                Err(e) => notes.push(format!("event `{}` left out: {e}", ev.name.value)),
            }
        }
        if !events.is_empty() {
            let _ = writeln!(w, "events:");
            w.push_str(&events);
        }
        if !file.floquet.is_empty() {
            notes.push("`floquet:` left out".to_string());
        }
        let checks = self.checks(&kept_equilibria, &kept_events, kept, preserve, notes)?;
        if !checks.is_empty() {
            let _ = writeln!(w, "checks:");
            w.push_str(&checks);
        }
        Ok(w)
    }

    /// The energy form's generalized forces moved onto the kept coordinates by virtual work:
    /// `Q_k + Σ_d Q_d ∂d/∂k`.
    fn generalized_forces(
        &mut self,
        kept: &[String],
    ) -> Result<Vec<(String, String)>, ReduceError> {
        let mut by_coordinate: Vec<(usize, ExprId)> = Vec::new();
        for (name, e) in &self.file.generalized_forces {
            let place = format!("generalized force `{}`", name.value);
            let q = self.lower_in(e, &place)?;
            if let Some(i) = self
                .file
                .coordinates
                .iter()
                .position(|c| c.name.value == name.value)
            {
                by_coordinate.push((i, q));
            }
        }
        let mut out = Vec::new();
        for (k, c) in self.file.coordinates.iter().enumerate() {
            if !kept.contains(&c.name.value) {
                continue;
            }
            let xk = self.coordinates[k][0];
            let mut terms = Vec::new();
            for &(i, q) in &by_coordinate {
                if i == k {
                    terms.push(q);
                } else if let Some(&root) = self.values.get(&self.coordinates[i][0]) {
                    let partial = self.arena.diff(root, xk);
                    terms.push(self.arena.times(q, partial));
                }
            }
            if terms.is_empty() {
                continue;
            }
            let sum = self.arena.sum(&terms);
            let sum = self.arena.substitute(sum, &self.values);
            let sum = self.arena.expand_if_cheaper(sum);
            if !self.arena.is_zero(sum) {
                out.push((c.name.value.clone(), self.print(sum)));
            }
        }
        Ok(out)
    }

    /// Where the solutions are singular at `values` (the slope or discriminant that vanishes
    /// there), if they are.
    fn singular_at(&self, values: &[(super::Located<String>, Expr)]) -> Option<String> {
        let bindings = self.bindings(values);
        self.singular_where
            .iter()
            .find_map(|(coordinate, e, discriminant)| {
                let v = self.arena.eval(*e, &bindings);
                // The size of the parameters the expression names (a length `l` for
                // `l² − x²`); a huge force elsewhere in the file does not make `1` small.
                let scale: f64 = self
                    .file
                    .parameters
                    .iter()
                    .filter(|p| {
                        self.arena
                            .symbol_id(&p.name.value)
                            .is_some_and(|s| self.arena.depends_on(*e, s))
                    })
                    .map(|p| p.value.abs())
                    .fold(1.0, f64::max);
                if *discriminant && v < 0.0 {
                    return Some(format!(
                        "{} = {v} < 0: no real `{coordinate}` satisfies the constraint",
                        self.print(*e)
                    ));
                }
                (v.is_nan() || v.abs() <= 1e-12 * scale * scale)
                    .then(|| format!("{} = {v} where `{coordinate}` is solved", self.print(*e)))
            })
    }

    /// The singularities of the eliminations that move with the state or the time (not a
    /// constant of the parameters): `(coordinate, expression, the event that ends runs
    /// there)`. A linear solution's slope changes sign there, and the event is the slope
    /// itself (explicit methods step over such a pole). A quadratic's discriminant reaches 0
    /// where the motion leaves the chosen branch (a pendulum kept in `x` that swings past the
    /// horizontal) and may only touch it, which no event function of the file's units can
    /// catch short of it: it is noted, and a run that reaches it fails there (the reduced
    /// mass matrix is not finite).
    fn moving_singularities(&self) -> Vec<(String, String, Option<String>)> {
        self.singular_where
            .iter()
            .filter(|(_, e, _)| {
                self.arena.symbols().iter().enumerate().any(|(i, s)| {
                    matches!(
                        s.kind,
                        SymbolKind::Coordinate(_) | SymbolKind::Velocity(_) | SymbolKind::Time
                    ) && self.arena.depends_on(*e, SymbolId(i as u32))
                })
            })
            .map(|(c, e, discriminant)| {
                let text = self.print(*e);
                let event = (!*discriminant).then(|| text.clone());
                (c.clone(), text, event)
            })
            .collect()
    }

    /// Why an equilibrium's listed values of eliminated coordinates are off their chosen
    /// solution, if they are.
    fn off_branch(&self, values: &[(super::Located<String>, Expr)]) -> Option<String> {
        let bindings = self.bindings(values);
        for (name, _) in values {
            let Some(s) = self.arena.symbol_id(&name.value) else {
                continue;
            };
            let Some(&root) = self.values.get(&s) else {
                continue;
            };
            if name.value.ends_with("_dot") {
                continue;
            }
            let (listed, solved) = (bindings[s.index()], self.arena.eval(root, &bindings));
            let off = (listed - solved).abs();
            if off.is_nan() || off > BRANCH_TOL * listed.abs().max(1.0) {
                return Some(format!(
                    "{} = {listed} there, the solution gives {solved}",
                    name.value
                ));
            }
        }
        None
    }

    /// The `checks:` block of the reduced file: the reference values that still apply.
    fn checks(
        &mut self,
        equilibria: &[String],
        events: &[String],
        kept: &[String],
        preserve: bool,
        notes: &mut Vec<String>,
    ) -> Result<String, ReduceError> {
        use std::fmt::Write as _;
        let c = &self.file.checks;
        let mut w = String::new();
        if !c.equations_of_motion.is_empty() {
            notes.push(if preserve {
                "`checks: equations_of_motion` left out".to_string()
            } else {
                "`checks: equations_of_motion` left out (written in the eliminated coordinates)"
                    .to_string()
            });
        }
        let first_kept = self
            .file
            .equilibria
            .first()
            .is_none_or(|e| equilibria.contains(&e.name.value));
        for (key, modal) in [
            ("natural_frequencies", &c.natural_frequencies),
            ("damping_ratios", &c.damping_ratios),
        ] {
            let Some(m) = modal else { continue };
            let at_ok = match &m.at {
                Some(a) => equilibria.contains(&a.value),
                None => first_kept,
            };
            if !at_ok {
                notes.push(format!(
                    "`checks: {key}` left out: its equilibrium is left out"
                ));
                continue;
            }
            let values: Vec<String> = m.values.iter().map(|e| e.to_string()).collect();
            let _ = write!(w, "  {key}: {{ ");
            if let Some(a) = &m.at {
                let _ = write!(w, "at: {}, ", a.value);
            }
            let _ = writeln!(
                w,
                "values: {}, tolerance: {:e} }}",
                list(&values),
                m.tolerance
            );
        }
        if let Some(p) = &c.period {
            if events.contains(&p.event.value) {
                let _ = writeln!(
                    w,
                    "  period: {{ event: {}, value: {}, tolerance: {:e}{} }}",
                    p.event.value,
                    flow(&p.value.to_string()),
                    p.tolerance,
                    run_settings(&p.run, true)
                );
            } else {
                notes.push("`checks: period` left out: its event is left out".to_string());
            }
        }
        if let Some(f) = &c.final_state {
            let is_kept_name = |n: &str| {
                kept.iter()
                    .any(|k| k == n || n.strip_suffix("_dot") == Some(k.as_str()))
            };
            let values: Vec<String> = f
                .values
                .iter()
                .filter(|(n, _)| is_kept_name(&n.value))
                .map(|(n, e)| format!("{}: {}", n.value, flow(&e.to_string())))
                .collect();
            if values.len() < f.values.len() {
                notes.push(
                    "`checks: final_state` keeps only the values of the kept coordinates"
                        .to_string(),
                );
            }
            if !values.is_empty() {
                let _ = writeln!(
                    w,
                    "  final_state: {{ t: {}, values: {{ {} }}, tolerance: {:e}{} }}",
                    flow(&f.t.to_string()),
                    values.join(", "),
                    f.tolerance,
                    run_settings(&f.run, false)
                );
            }
        }
        if !c.conserved.is_empty() {
            let mut block = String::new();
            for q in &c.conserved {
                let place = format!("conserved quantity `{}`", q.name.value);
                let v = self.rewrite(&q.value, &place)?;
                let _ = writeln!(
                    block,
                    "    {}: {{ value: {}, tolerance: {:e} }}",
                    q.name.value,
                    flow(&v),
                    q.tolerance
                );
            }
            let _ = writeln!(w, "  conserved:");
            w.push_str(&block);
        }
        if let Some(d) = &c.energy_drift {
            let _ = writeln!(
                w,
                "  energy_drift: {{ max: {:e}{} }}",
                d.max,
                run_settings(&d.run, true)
            );
        }
        if let Some(d) = c.constraint_drift.as_ref().filter(|_| preserve) {
            let _ = writeln!(
                w,
                "  constraint_drift: {{ max: {:e}{} }}",
                d.max,
                run_settings(&d.run, true)
            );
        } else if c.constraint_drift.is_some() {
            notes.push("`checks: constraint_drift` left out (no constraints)".to_string());
        }
        Ok(w)
    }
}

/// `, method: …, rtol: …, t_end: …` of the settings given.
fn run_settings(run: &super::file::RunSettings, t_end: bool) -> String {
    let mut s = String::new();
    if let Some(m) = &run.method {
        s.push_str(&format!(", method: {}", m.value));
    }
    if let Some(r) = run.rtol {
        s.push_str(&format!(", rtol: {r:e}"));
    }
    if t_end && let Some(t) = run.t_end {
        s.push_str(&format!(", t_end: {t:e}"));
    }
    s
}

/// The degree of `e` in `d` if `d` appears only in sums, products and powers with
/// non-negative integer exponents; else the first sub-expression where it appears otherwise.
fn polynomial_degree(arena: &ExprArena, e: ExprId, d: SymbolId) -> Result<u32, ExprId> {
    if !arena.depends_on(e, d) {
        return Ok(0);
    }
    match arena.node(e) {
        Node::Symbol(s) if *s == d => Ok(1),
        Node::Add(terms) => terms
            .iter()
            .try_fold(0, |m, &t| polynomial_degree(arena, t, d).map(|k| m.max(k))),
        Node::Mul(factors) => factors.iter().try_fold(0u32, |m, &f| {
            polynomial_degree(arena, f, d).map(|k| m.saturating_add(k))
        }),
        Node::Pow([b, x]) => match arena.as_constant(*x).and_then(Constant::as_integer) {
            Some(k) if (0..=64).contains(&k) && !arena.depends_on(*x, d) => {
                polynomial_degree(arena, *b, d).map(|m| m.saturating_mul(k as u32))
            }
            _ => Err(e),
        },
        _ => Err(e),
    }
}

/// The coefficients `[c₀, c₁, …]` of `e` as a polynomial in `d` (multiplied out), or `None`
/// if a term of the multiplied-out form is not a monomial in `d`.
fn coefficients(arena: &mut ExprArena, e: ExprId, d: SymbolId) -> Option<Vec<ExprId>> {
    let e = arena.expand(e);
    let terms: Vec<ExprId> = match arena.node(e) {
        Node::Add(t) => t.to_vec(),
        _ => vec![e],
    };
    let mut by_power: Vec<Vec<ExprId>> = Vec::new();
    for t in terms {
        let factors: Vec<ExprId> = match arena.node(t) {
            Node::Mul(f) => f.to_vec(),
            _ => vec![t],
        };
        let mut power = 0usize;
        let mut rest = Vec::new();
        for f in factors {
            if !arena.depends_on(f, d) {
                rest.push(f);
                continue;
            }
            match arena.node(f) {
                Node::Symbol(s) if *s == d => power += 1,
                Node::Pow([b, x]) if matches!(arena.node(*b), Node::Symbol(s) if *s == d) => {
                    let k = arena.as_constant(*x).and_then(Constant::as_integer)?;
                    power += usize::try_from(k).ok()?;
                }
                _ => return None,
            }
        }
        if by_power.len() <= power {
            by_power.resize(power + 1, Vec::new());
        }
        let c = arena.product(&rest);
        by_power[power].push(c);
    }
    let mut out: Vec<ExprId> = by_power
        .into_iter()
        .map(|terms| {
            let s = arena.sum(&terms);
            arena.expand(s)
        })
        .collect();
    while out.len() > 1 && out.last().is_some_and(|&c| arena.is_zero(c)) {
        out.pop();
    }
    Some(out)
}

/// A plain scalar where YAML reads it as the text, else in double quotes.
fn scalar(s: &str) -> String {
    let special = s.is_empty()
        || s.contains(": ")
        || s.contains(" #")
        || s.starts_with([
            '[', ']', '{', '}', ',', '#', '&', '*', '!', '|', '>', '\'', '"', '%', '@', '`',
        ])
        || s.starts_with("- ")
        || s.ends_with(':');
    if special { quoted(s) } else { s.to_string() }
}

/// A scalar inside a flow collection (`[…]`, `{…}`): quoted if it has a flow indicator.
fn flow(s: &str) -> String {
    if s.contains([',', '[', ']', '{', '}']) {
        quoted(s)
    } else {
        scalar(s)
    }
}

fn quoted(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\""))
}

/// `[a, b, …]` of expressions.
fn list(parts: &[String]) -> String {
    let parts: Vec<String> = parts.iter().map(|p| flow(p)).collect();
    format!("[{}]", parts.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(text: &str) -> ModelFile {
        crate::model::load("test.yaml", text).unwrap_or_else(|d| panic!("{d:?}"))
    }

    const PENDULUM: &str = "name: p\nparameters: { m: 1.0, l: 2.0, g: 10.0 }\ncoordinates: [x, y]\n\
        points: { O: [0, 0], P: [x, y] }\nbodies: { bob: { mass: m, at: P } }\ngravity: [0, -g]\n\
        constraints: { rod: sqrt(x^2 + y^2) - l }\ninitial: { x: l, y: 0 }\n\
        equilibria: { hanging: { x: 0, y: -l }, upright: { x: 0, y: l } }\n";

    /// The rod is squared, and the branch comes from the hanging equilibrium (the start
    /// `x = ℓ` is where the branches meet): `y = −√(ℓ² − x²)`. That start is singular for
    /// the reduced file, which needs another.
    #[test]
    fn pendulum_keep_x_takes_the_hanging_branch() {
        let err = reduce(&load(PENDULUM), &["x"], &ReduceOptions::default()).unwrap_err();
        assert!(
            matches!(&err, ReduceError::SingularStart { detail } if detail.contains("l^2 - x^2")),
            "{err}"
        );
        let options = ReduceOptions {
            initial: vec![("x".into(), "l/2".into())],
            ..ReduceOptions::default()
        };
        let r = reduce(&load(PENDULUM), &["x"], &options).unwrap();
        let e = &r.eliminations[0];
        assert_eq!(e.solution, "-sqrt(l^2 - x^2)");
        assert!(e.squared);
        assert_eq!(
            e.branch,
            Some((Branch::Minus, BranchReason::Equilibrium("hanging".into())))
        );
        assert!(
            r.notes.iter().any(|n| n.contains("upright")),
            "{:?}",
            r.notes
        );
    }

    /// Keeping y from the start x = ℓ, y = 0 gives x = +√(ℓ² − y²) by the initial state.
    #[test]
    fn pendulum_keep_y_takes_the_initial_branch() {
        let r = reduce(&load(PENDULUM), &["y"], &ReduceOptions::default()).unwrap();
        let e = &r.eliminations[0];
        assert_eq!(e.solution, "sqrt(l^2 - y^2)");
        assert_eq!(e.branch, Some((Branch::Plus, BranchReason::InitialState)));
    }

    #[test]
    fn transcendental_constraint_is_a_clear_error() {
        let text = PENDULUM.replace("sqrt(x^2 + y^2) - l", "y - l*sin(x + y)");
        let err = reduce(&load(&text), &["x"], &ReduceOptions::default()).unwrap_err();
        let ReduceError::Unsolvable {
            constraint,
            coordinate,
            ..
        } = &err
        else {
            panic!("{err}")
        };
        assert_eq!((constraint.as_str(), coordinate.as_str()), ("rod", "y"));
        assert!(err.to_string().contains("sin("), "{err}");
    }
}
