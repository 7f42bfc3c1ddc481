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
use super::file::{BodyKind, ModelFile, TorqueValue};
use super::parser::{eval_expr, parse_expr};
use super::{BinOp, Location};
use crate::expr::print::{Printer, Syntax};
use crate::expr::{Constant, ExprArena, ExprId, Func, Node, SymbolId, SymbolKind};

mod singular;
mod solve;
#[cfg(test)]
mod tests;
mod write;

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
    check_options(options)?;
    if file.constraints.is_empty() {
        return Err(ReduceError::NoConstraints {
            model: file.name.value.clone(),
        });
    }
    let (kept, dependent) = split_coordinates(file, keep)?;
    let mut r = Reducer::new(file);
    let eliminations = r.solve(&dependent, options)?;
    check_branches_used(&eliminations, options)?;
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
    let reduced = load_reduced(&name, &text)?;
    Ok(ReducedModel {
        text,
        file: reduced,
        kept,
        eliminations,
        notes,
    })
}

/// Checks the options of [`reduce`] on their own: the name of the reduced model is an
/// identifier and no coordinate is given two branches.
fn check_options(options: &ReduceOptions) -> Result<(), ReduceError> {
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
    Ok(())
}

/// The coordinates kept (names, in the file's order) and the indices of those eliminated,
/// after checking that `keep` names coordinates of the file and leaves as many to eliminate
/// as the file has holonomic constraints.
fn split_coordinates(
    file: &ModelFile,
    keep: &[&str],
) -> Result<(Vec<String>, Vec<usize>), ReduceError> {
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
    Ok((kept, dependent))
}

/// Checks that every branch of the options chose the solution of an eliminated coordinate
/// that has branches.
fn check_branches_used(
    eliminations: &[Elimination],
    options: &ReduceOptions,
) -> Result<(), ReduceError> {
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
    Ok(())
}

/// Loads the reduced file's `text` (named `name`) and checks that the compilers accept it:
/// it loads, its derivation finishes and its mass matrix passes their check.
fn load_reduced(name: &str, text: &str) -> Result<ModelFile, ReduceError> {
    let invalid = |d: Vec<super::Diagnostic>| ReduceError::Invalid {
        messages: d
            .iter()
            .map(|d| format!("{}:{}: {}", d.location.line, d.location.column, d.message))
            .collect(),
    };
    let reduced = super::load(&format!("{name}.yaml"), text).map_err(invalid)?;
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
    Ok(reduced)
}

/// The YAML text of `file` as [`reduce`] writes its results, with nothing eliminated: the
/// schema's writer ([`super::schema::write_file`], the table that reads a file) with
/// the reducer's expressions, so that a reduced file can be loaded and written again (a
/// round trip gives the same equations). Every section is written, 3-D frames, bodies and
/// rolling contacts included; comments are not kept (the parameters' and coordinates' units
/// are); what is left out is listed in the second value (`checks: equations_of_motion`,
/// `floquet:`, `balances:`).
///
/// # Errors
/// [`ReduceError::UnknownName`]; [`ReduceError::Invalid`] if the text written does not
/// load.
pub fn write_model(file: &ModelFile) -> Result<(String, Vec<String>), ReduceError> {
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

/// The parts of the format [`reduce`] does not eliminate through: the writer writes them as
/// they are ([`write_model`]), but eliminating coordinates there is not checked.
fn unsupported(file: &ModelFile) -> Result<(), ReduceError> {
    let feature = |f: &str| {
        Err(ReduceError::Unsupported {
            feature: f.to_string(),
        })
    };
    if !file.frames.is_empty() {
        return feature("`frames:`");
    }
    // (Its `initial:` and state are in the speeds, which the eliminated constraints' auxiliary
    // speeds complete: eliminate in the rates.)
    if !file.speeds.is_empty() {
        return feature("`speeds:`");
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
}
