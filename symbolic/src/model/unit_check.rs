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
use super::file::{BalanceKind, ModelFile};
use super::located::Location;
use super::parser::identifiers;
use super::units::{Dimension, Rational, parse_unit};

mod dimensions;
mod sections;
mod solution;
#[cfg(test)]
mod tests;

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
    /// The units of the generalized speeds (`speeds:`), their definitions', once visited in
    /// this pass (first of all).
    speeds: Vec<(String, Option<Dim>)>,
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
            speeds: Vec::new(),
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
        if let Some((_, unit)) = self.speeds.iter().find(|(k, _)| k == n) {
            return unit.clone();
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
}
