//! Cross-object rules of a model file, each stated above its check. Every violation is
//! collected; nothing stops at the first.
//!
//! The rules run on what the schema pass built. Entries it left out (already reported) are
//! listed in [`Incomplete`] and treated as present, so that one mistake gives one message.

use rustc_hash::FxHashSet;

use super::ast::{Expr, FUNCTIONS};
use super::diagnostic::{Diagnostic, Diagnostics};
use super::elements::{self, Depends};
use super::file::{
    Axis, BalanceKind, BodyKind, GROUND_FRAME, InertiaTensor, ModelFile, Parameter, RollingContact,
};
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

/// Parameter, coordinate, rate, acceleration and multiplier names, hashed.
#[derive(Default)]
struct NameSets {
    params: FxHashSet<String>,
    coords: FxHashSet<String>,
    rates: FxHashSet<String>,
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

/// What is wrong with the mass `m` (kg) of body `body`: `None` for a positive mass.
pub fn mass_problem(body: &str, m: f64) -> Option<String> {
    (m.is_nan() || m <= 0.0).then(|| format!("body `{body}` has non-positive mass `{m:?}` (kg)"))
}

/// What is wrong with the centroidal moment of inertia `i` (kg·m²) of the planar body
/// `body`: `None` for `i ≥ 0`.
pub fn planar_inertia_problem(body: &str, i: f64) -> Option<String> {
    (i.is_nan() || i < 0.0).then(|| format!("body `{body}` has negative inertia `{i:?}` (kg·m²)"))
}

/// Why a 3-D inertia tensor is not a rigid body's ([`inertia_problem`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum InertiaProblem {
    /// Not positive definite (or not finite): the message.
    NotPositiveDefinite(String),
    /// Positive definite, but its principal moments break `I₃ ≤ I₁ + I₂`: the message.
    NotARigidBody(String),
}

/// What is wrong with the inertia tensor `[xx, yy, zz, xy, yz, xz]` (kg·m², about the centre
/// of mass) of body `body`, by the rules every rigid body meets: finite entries, positive
/// definite (Sylvester's criterion on the leading minors of the tensor scaled by its largest
/// entry, each above `64ε`, so that neither 1e300 nor 1e-300 kg·m² overflows and a needle
/// whose axial moment is 1e-12 of the others passes, while a rotated zero moment does not),
/// and principal moments within the triangle inequality `I₃ ≤ I₁ + I₂` to 0.1 % of `I₃`.
/// `None` for a rigid body's tensor. The messages end where a caller says at which
/// parameter values.
pub fn inertia_problem(body: &str, e: [f64; 6]) -> Option<InertiaProblem> {
    if let Some((name, v)) = ["xx", "yy", "zz", "xy", "yz", "xz"]
        .iter()
        .zip(e)
        .find(|(_, v)| !v.is_finite())
    {
        return Some(InertiaProblem::NotPositiveDefinite(format!(
            "the inertia of body `{body}` is not finite: its entry {name} is {v}"
        )));
    }
    // Scaled by the largest entry, so that neither 1e300 nor 1e-300 kg·m² overflows or
    // underflows in the minors and moments below.
    let scale = e.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let [xx, yy, zz, xy, yz, xz] = e.map(|v| if scale > 0.0 { v / scale } else { v });
    let minors = [
        xx,
        xx * yy - xy * xy,
        xx * (yy * zz - yz * yz) - xy * (xy * zz - yz * xz) + xz * (xy * yz - yy * xz),
    ];
    // Each scaled minor carries a rounding error of a few ε: above 64ε it is positive, so a
    // needle whose smallest moment is 1e-12 of the others is definite, and the rounding of a
    // singular tensor (a rotated zero moment) is not taken for definiteness.
    // A diagonal tensor has no rounding to tell apart: positive moments are definite
    // (`diag(1e-14, 1, 1)`, a needle).
    let diagonal = xy == 0.0 && yz == 0.0 && xz == 0.0;
    let definite = scale > 0.0
        && if diagonal {
            xx > 0.0 && yy > 0.0 && zz > 0.0
        } else {
            minors.iter().all(|m| *m > 64.0 * f64::EPSILON)
        };
    if !definite {
        let [exx, eyy, ezz, exy, eyz, exz] = e.map(short);
        return Some(InertiaProblem::NotPositiveDefinite(format!(
            "the inertia of body `{body}` is not positive definite: [[{exx}, {exy}, {exz}], [{exy}, {eyy}, {eyz}], [{exz}, {eyz}, {ezz}]] kg·m²"
        )));
    }
    // The triangle inequality of the principal moments: `I₃ = ∫(x² + y²) dm ≤ ∫(y² + z²) dm
    // + ∫(x² + z²) dm = I₁ + I₂` in principal axes (equal for a flat body). Refused beyond
    // 0.1 % of `I₃`: a flat body's moments typed to four digits may miss the equality by a
    // few parts in 10⁴, and the moments computed here carry `√ε` where two coincide.
    let [a, b, c] = principal_moments([xx, yy, zz, xy, yz, xz]).map(|v| v * scale);
    let excess = c - (a + b);
    (excess > 1e-3 * c).then(|| {
        InertiaProblem::NotARigidBody(format!(
            "the inertia of body `{body}` is not a rigid body's: its principal moments {}, {} and {} kg·m² break the triangle inequality I₃ ≤ I₁ + I₂ by {} kg·m²",
            short(a),
            short(b),
            short(c),
            short(excess)
        ))
    })
}

/// A number in a diagnostic: 6 decimals between 1e-3 and 1e6 (trailing zeros dropped, as `1`,
/// `-0.5`, `0.001235`), 6 significant digits outside (`1.20000e-7`).
pub(crate) fn short(v: f64) -> String {
    if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e6) {
        format!("{v:.5e}")
    } else {
        let s = format!("{v:.6}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// The eigenvalues of the symmetric 3 × 3 tensor `[xx, yy, zz, xy, yz, xz]`, ascending, by
/// the trigonometric solution of its characteristic cubic (Smith, *Eigenvalues of a symmetric
/// 3 × 3 matrix*, Commun. ACM 4(4), 1961): to rounding of the largest where they are apart,
/// to about `√ε` of it where two (nearly) coincide (the `acos` near ±1).
fn principal_moments([xx, yy, zz, xy, yz, xz]: [f64; 6]) -> [f64; 3] {
    let off = xy * xy + yz * yz + xz * xz;
    let mut e = if off == 0.0 {
        [xx, yy, zz]
    } else {
        let q = (xx + yy + zz) / 3.0;
        let p = ((xx - q).powi(2) + (yy - q).powi(2) + (zz - q).powi(2) + 2.0 * off) / 6.0;
        let p = p.sqrt();
        // B = (A − qI)/p; det B / 2 = cos 3φ.
        let (bxx, byy, bzz) = ((xx - q) / p, (yy - q) / p, (zz - q) / p);
        let (bxy, byz, bxz) = (xy / p, yz / p, xz / p);
        let det = bxx * (byy * bzz - byz * byz) - bxy * (bxy * bzz - byz * bxz)
            + bxz * (bxy * byz - byy * bxz);
        let phi = (det / 2.0).clamp(-1.0, 1.0).acos() / 3.0;
        let largest = q + 2.0 * p * phi.cos();
        let smallest = q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos();
        [smallest, 3.0 * q - largest - smallest, largest]
    };
    e.sort_by(f64::total_cmp);
    e
}

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
        use elements::{BodyLookup, BodyShape};
        let file = self.file;
        match file.bodies.iter().find(|b| b.name.value == name) {
            Some(b) => BodyLookup::Found(match b.kind {
                BodyKind::Particle { .. } => BodyShape::Particle,
                BodyKind::Rigid { .. } => BodyShape::Planar,
                BodyKind::Spatial { .. } => BodyShape::Spatial,
            }),
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
    fn dimension(&self) -> usize {
        self.file.dimension.unwrap_or(2)
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
