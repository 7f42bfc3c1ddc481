//! What a body's mass and inertia must be, at the parameters' values: the rules of every
//! physical body, for the model file's rules (at the defaults) and for the parameters a run
//! sets.

use crate::model::diagnostic::short;

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

#[cfg(test)]
mod tests {
    use super::*;

    /// The principal moments against diagonal tensors and a rotated one: `diag(1, 2, 3)`
    /// rotated by 30° about `z` (`xx = 1.25`, `yy = 1.75`, `xy = 0.25·√3 · (−1)`) keeps its
    /// eigenvalues 1, 2, 3 to 1e-14.
    #[test]
    fn principal_moments_are_the_eigenvalues() {
        assert_eq!(
            principal_moments([3.0, 1.0, 2.0, 0.0, 0.0, 0.0]),
            [1.0, 2.0, 3.0]
        );
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let (xx, yy, xy) = (
            c * c + 2.0 * s * s,
            s * s + 2.0 * c * c,
            (1.0 - 2.0) * c * s,
        );
        let e = principal_moments([xx, yy, 3.0, xy, 0.0, 0.0]);
        for (got, want) in e.iter().zip([1.0, 2.0, 3.0]) {
            assert!((got - want).abs() < 1e-14, "{e:?}");
        }
    }
}
