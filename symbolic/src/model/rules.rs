//! Cross-object rules of a model file, each stated above its check. Every violation is
//! collected; nothing stops at the first.
//!
//! The rules run on what the schema pass built. Entries it left out (already reported) are
//! listed in [`Incomplete`] and treated as present, so that one mistake gives one message.

use rustc_hash::FxHashSet;

use super::ast::{Expr, FUNCTIONS};
use super::diagnostic::{Diagnostic, Diagnostics};
use super::elements::{self, Depends};
use super::file::{BalanceKind, BodyKind, GROUND_FRAME, ModelFile, Parameter};
use super::located::{Located, Location};
use super::parser::{closest, eval_expr, identifiers};
use super::schema::{self, Incomplete, UNRAW_KEYWORDS};
use super::vectors;

mod expressions;
mod frames;
mod mechanism;
mod names;
mod references;
#[cfg(test)]
mod tests;

/// Runs every rule on `file`.
///
/// # Errors
/// Every violation, sorted by location.
pub fn check(file: &ModelFile) -> Result<(), Vec<Diagnostic>> {
    check_partial(file, &Incomplete::default())
}

/// Runs every rule on a model that the schema pass built only in part, without reporting
/// what depends on the entries it left out (see [`Incomplete`]).
///
/// # Errors
/// Every violation, sorted by location.
pub fn check_partial(file: &ModelFile, incomplete: &Incomplete) -> Result<(), Vec<Diagnostic>> {
    let (mut list, units) = check_parts(file, incomplete);
    list.extend(units);
    if list.is_empty() {
        return Ok(());
    }
    list.sort_by_key(|d| d.location);
    Err(list)
}

/// [`check_partial`]'s diagnostics in two lists: the rules' and the units' (a unit mistake
/// at the place of a rule's mistake left out). A file whose only mistakes are units is sound
/// to derive ([`super::load`] then reports what the derivation finds too).
pub(crate) fn check_parts(
    file: &ModelFile,
    incomplete: &Incomplete,
) -> (Vec<Diagnostic>, Vec<Diagnostic>) {
    let mut checker = Checker::new(file, incomplete);
    checker.names();
    checker.presence();
    checker.expressions();
    checker.dimensions();
    checker.frames();
    checker.references();
    checker.masses();
    checker.balances();
    checker.hand_equations();
    checker.reference_checks();
    checker.floquet_references();
    checker.constraints();
    checker.speeds();
    for spring in &file.springs {
        spring.rules(&mut checker);
    }
    for damper in &file.dampers {
        damper.rules(&mut checker);
    }
    for contact in &file.contacts {
        contact.rules(&mut checker);
    }
    for force in &file.forces {
        force.rules(&mut checker);
    }
    for torque in &file.torques {
        torque.rules(&mut checker);
    }
    for interaction in &file.interactions {
        interaction.rules(&mut checker);
    }
    checker.outputs();
    let units = super::unit_check::check(file);
    // A unit mistake at the place of another mistake is its consequence (`initial: { theta:
    // x }` is not constant, and so not in rad either): one message per mistake.
    let list = checker.diagnostics.finish().err().unwrap_or_default();
    let taken: Vec<Location> = list.iter().map(|d| d.location).collect();
    let units = units
        .into_iter()
        .filter(|d| !taken.contains(&d.location))
        .collect();
    (list, units)
}

/// The value of a constant expression at the parameters' defaults (`None` if it uses
/// anything but numbers, `pi`, functions and these parameters).
///
/// A NaN or infinite result is returned as such (`1/0` is `inf`).
pub fn evaluate(expr: &Expr, parameters: &[Parameter]) -> Option<f64> {
    eval_expr(expr, &|n| {
        parameters
            .iter()
            .find(|p| p.name.value == n)
            .map(|p| p.value)
    })
    .ok()
}

struct Checker<'f> {
    file: &'f ModelFile,
    incomplete: &'f Incomplete,
    diagnostics: Diagnostics,
    params: Vec<&'f str>,
    coords: Vec<&'f str>,
    rates: Vec<String>,
    accelerations: Vec<String>,
    multipliers: Vec<String>,
    points: Vec<&'f str>,
    bodies: Vec<&'f str>,
    /// Whether `omega_<frame>_<axis>` may be read: in expressions the derivation lowers, not
    /// in the conserved quantities of `checks:`, which are evaluated from the state alone.
    angular_velocities: bool,
    /// Whether the vector functions (`dot(P - O, …)`) may be used: not in the positions of
    /// points and the rotations of frames, which define the points they would read.
    vectors: bool,
    /// Whether `r` and `r_dot` name an interaction's distance and its rate (in its
    /// magnitude).
    interaction: bool,
    /// The names above as sets, for lookups in time independent of their number (the lists
    /// keep the file's order for suggestions and help).
    sets: NameSets,
}

/// Parameter, coordinate, rate, speed, acceleration and multiplier names, hashed.
#[derive(Default)]
struct NameSets {
    params: FxHashSet<String>,
    coords: FxHashSet<String>,
    rates: FxHashSet<String>,
    /// Generalized speeds (`speeds:`), which read like rates.
    speeds: FxHashSet<String>,
    accelerations: FxHashSet<String>,
    multipliers: FxHashSet<String>,
}

impl<'f> Checker<'f> {
    fn new(file: &'f ModelFile, incomplete: &'f Incomplete) -> Self {
        let coords: Vec<&str> = file
            .coordinates
            .iter()
            .map(|c| c.name.value.as_str())
            .collect();
        let mut checker = Self {
            file,
            incomplete,
            diagnostics: Diagnostics::new(),
            params: file
                .parameters
                .iter()
                .map(|p| p.name.value.as_str())
                .collect(),
            rates: coords.iter().map(|c| format!("{c}_dot")).collect(),
            accelerations: coords.iter().map(|c| format!("{c}_ddot")).collect(),
            multipliers: file
                .constraint_names()
                .iter()
                .map(|k| format!("lambda_{}", k.value))
                .collect(),
            coords,
            points: file.points.iter().map(|p| p.name.value.as_str()).collect(),
            bodies: file.bodies.iter().map(|b| b.name.value.as_str()).collect(),
            angular_velocities: true,
            vectors: true,
            interaction: false,
            sets: NameSets::default(),
        };
        let owned = |v: &[&str]| v.iter().map(|s| s.to_string()).collect();
        let sets = NameSets {
            params: owned(&checker.params),
            coords: owned(&checker.coords),
            rates: checker.rates.iter().cloned().collect(),
            speeds: file.speeds.iter().map(|s| s.name.value.clone()).collect(),
            accelerations: checker.accelerations.iter().cloned().collect(),
            multipliers: checker.multipliers.iter().cloned().collect(),
        };
        checker.sets = sets;
        checker
    }

    fn error(&mut self, d: Diagnostic) {
        self.diagnostics.push(d);
    }

    /// Whether a whole section may be missing from the model because of a reported error.
    fn section_lost(&self, section: &str, built_empty: bool) -> bool {
        built_empty && self.incomplete.has_section(section)
    }
}

pub use crate::model::elements::body::inertia::{
    InertiaProblem, inertia_problem, mass_problem, planar_inertia_problem,
};

/// The rules pass as an element's context ([`elements::Rules`]).
impl elements::Rules for Checker<'_> {
    fn point(&mut self, name: &Located<String>) {
        Checker::point(self, name);
    }
    fn frame(&mut self, name: &Located<String>) {
        let frames = frames::frame_names(self.file);
        Checker::frame(self, name, &frames);
    }
    fn unknown_frame(&self, name: &Located<String>, frames: &[&str]) -> Diagnostic {
        self.unknown_frame_message(name, frames)
    }
    fn body(&self, name: &str) -> elements::BodyLookup {
        use elements::BodyLookup;
        let file = self.file;
        match file.bodies.iter().find(|b| b.name.value == name) {
            Some(b) => BodyLookup::Found(b.kind.shape()),
            None if self.incomplete.has_name(name)
                || self.section_lost("bodies", file.bodies.is_empty()) =>
            {
                BodyLookup::Excused
            }
            None => BodyLookup::Unknown(closest(name, &self.bodies).map(str::to_string)),
        }
    }
    fn expression(&mut self, e: &Expr, depends: Depends, what: &str) {
        self.resolve(e, depends, what);
    }
    fn expression_of_distance(&mut self, e: &Expr, depends: Depends, what: &str) {
        self.interaction = true;
        self.resolve(e, depends, what);
        self.interaction = false;
    }
    fn name_kind(&self, n: &str) -> Option<&'static str> {
        if self.sets.params.contains(n) {
            Some("a parameter")
        } else if self.sets.coords.contains(n) {
            Some("a coordinate")
        } else if n == "r_dot" && self.sets.rates.contains(n) {
            Some("the rate of coordinate `r`")
        } else if self.points.contains(&n) {
            Some("a point")
        } else {
            None
        }
    }
    fn value(&self, e: &Expr) -> Option<f64> {
        evaluate(e, &self.file.parameters)
    }
    fn dimension(&self) -> Option<usize> {
        self.file.dimension
    }
    fn coordinates(&self) -> Vec<String> {
        (self.file.coordinates.iter())
            .map(|c| c.name.value.clone())
            .collect()
    }
    fn section_incomplete(&self, key: &str) -> bool {
        self.incomplete.has_section(key)
    }
    fn error(&mut self, d: Diagnostic) {
        Checker::error(self, d);
    }
}
