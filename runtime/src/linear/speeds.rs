//! Rest and the linearisation at rest of a model in generalized speeds (`y = (q, u)`), in
//! its coordinates: the same `M δq̈ + C δq̇ + K δq = 0` as the model written in the rates
//! gives, so that every analysis of a [`super::modal::Linearization`] applies unchanged.
//!
//! The speeds are `u = Y(q, t) q̇ + Z(q, t)` and the model's kinematic equations
//! `q̇ = K(q, u, t) = W (u − Z)`, `W = Y⁻¹` (Kane and Levinson, *Dynamics: Theory and
//! Applications*, 1985, §2.12). Everything below comes from `K` and its exact Jacobians
//! `K_q = ∂K/∂q`, `W = ∂K/∂u`, for speeds whose `Y` and `Z` do not depend on `t` (others are
//! refused: at their rest `u̇ = Y q̈ + ∂Z/∂t`):
//!
//! - at rest `q̇ = 0`, so `u = Z = −Y K(q, 0)`, and `P = ∂Z/∂q = −Y K_q(q, Z)`;
//! - near rest `δu = Y δq̇ + P δq` and `δu̇ = Y δq̈ + P δq̇ + E δq`, where `E δq` is
//!   `∂(Y q̈*)/∂q δq` at the rest's `q̈* = W u̇*`: since `K_q(q, Z + a) − K_q(q, Z) = ∂W/∂q · a`
//!   (`K` is affine in `u`) and `∂Y = −Y ∂W Y`, `E = −Y (K_q(q, Z + u̇*) − K_q(q, Z))`;
//! - Kane's `M_u u̇ = F(q, u)` perturbed, `M_u δu̇ = G δq + F_u δu` with
//!   `G = F_q − ∂(M_u a)/∂q |_(a = u̇*)`, then multiplied by `Yᵀ`:
//!
//! ```text
//! M = Yᵀ M_u Y,   C = Yᵀ (M_u P − F_u Y),   K = Yᵀ (M_u E − G − F_u P)
//! ```
//!
//! `Yᵀ F_u` is the generalized force in the coordinates (Kane's `Fᵣ = Σⱼ Wⱼᵣ Qⱼ`), so `M` and
//! `K` are symmetric where the model in rates has them symmetric.

use nalgebra::{DMatrix, DVector};

use crate::model_info::ModelInfo;

/// Why a model in generalized speeds has no rest or linearisation at `q`, with `q`
/// ([`super::modal::ModalError`] has a variant for each: this module is below it).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct KinematicsError {
    /// What failed.
    pub kind: KinematicsFailure,
    /// The coordinates.
    pub q: Vec<f64>,
}

/// What [`KinematicsError`] says failed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum KinematicsFailure {
    /// `W` is not finite or not invertible.
    Singular,
    /// The speeds' coefficients or offsets depend on `t`
    /// ([`crate::ModelDescription::speeds_depend_on_time`]).
    TimeDependent,
    /// The state given is not at rest: its largest `|q̇ᵢ|`.
    Moving(f64),
    /// `M_u` is not positive definite.
    SingularMassMatrix,
    /// A matrix of the linearisation is not finite.
    NonFinite,
}

/// The matrices of the linearisation at rest, in the coordinates (`n × n` each).
#[derive(Debug, Clone)]
pub(crate) struct RestMatrices {
    /// `M = Yᵀ M_u Y`.
    pub mass: DMatrix<f64>,
    /// `C = Yᵀ (M_u P − F_u Y)`.
    pub damping: DMatrix<f64>,
    /// `K = Yᵀ (M_u E − G − F_u P)`.
    pub stiffness: DMatrix<f64>,
}

/// A model in generalized speeds at rest at `q`: the speeds there and the matrices the
/// linearisation needs.
#[derive(Debug, Clone)]
pub(crate) struct Rest {
    /// `u = Z(q, t)`, the speeds with `q̇ = 0` (`n`).
    pub u: DVector<f64>,
    /// `Y = W⁻¹` (`n × n`).
    pub y: DMatrix<f64>,
    /// `P = ∂Z/∂q` (`n × n`).
    pub p: DMatrix<f64>,
    /// `K_q = ∂q̇/∂q` at `(q, Z)` (`n × n`), of which `P = −Y K_q`.
    pub rates_q: DMatrix<f64>,
    /// The condition number `σ_max/σ_min` of `W`, by which `Y`'s rounding is larger than `ε`.
    pub conditioning: f64,
}

/// The speeds at rest at `(q, t)` of a model in generalized speeds (see the module docs).
///
/// # Errors
/// [`KinematicsFailure::Singular`] where `W` is not finite or not invertible (its smallest
/// singular value below `1e-12` of its largest); [`KinematicsFailure::TimeDependent`] for
/// speeds that depend on `t` (at rest `u̇ = Y q̈ + ∂Z/∂t`, which these formulas leave out).
pub(crate) fn rest(model: &dyn ModelInfo, q: &[f64], t: f64) -> Result<Rest, KinematicsError> {
    if model.description().speeds_depend_on_time {
        return Err(failure(q, KinematicsFailure::TimeDependent));
    }
    let n = q.len();
    let singular = || failure(q, KinematicsFailure::Singular);
    let mut state: Vec<f64> = q
        .iter()
        .copied()
        .chain(std::iter::repeat_n(0.0, n))
        .collect();
    let k0 = model.coordinate_rates(t, &state);
    let (_, w) = model.coordinate_rates_jacobian(t, &state);
    if !(w.iter().all(|v| v.is_finite()) && k0.iter().all(|v| v.is_finite())) {
        return Err(singular());
    }
    let singular_values = w.singular_values();
    // Finite (checked above), so no NaN among them.
    if singular_values.min() <= 1e-12 * singular_values.max() {
        return Err(singular());
    }
    let conditioning = singular_values.max() / singular_values.min();
    let y = w.try_inverse().ok_or_else(singular)?;
    let u = -(&y * k0);
    state[n..].copy_from_slice(u.as_slice());
    let (rates_q, _) = model.coordinate_rates_jacobian(t, &state);
    let p = -(&y * &rates_q);
    if !p.iter().all(|v| v.is_finite()) {
        return Err(singular());
    }
    Ok(Rest {
        u,
        y,
        p,
        rates_q,
        conditioning,
    })
}

/// The state at rest at `(q, t)`: `(q, 0)`, or in generalized speeds `(q, Z(q, t))`.
///
/// # Errors
/// As [`rest`], for a model in generalized speeds.
pub(crate) fn rest_state(
    model: &dyn ModelInfo,
    q: &[f64],
    t: f64,
) -> Result<Vec<f64>, KinematicsError> {
    let u = match model.description().has_speeds() {
        true => rest(model, q, t)?.u.as_slice().to_vec(),
        false => vec![0.0; q.len()],
    };
    Ok(q.iter().copied().chain(u).collect())
}

/// A generalized force of Kane's equations at rest at `(q, t)` (a column of `∂F/∂p`) in the
/// model's coordinates: `Yᵀ f` in generalized speeds (the linearisation's `K` and `C` are
/// multiplied by `Yᵀ` the same way), `f` itself otherwise.
///
/// # Errors
/// As [`rest`], for a model in generalized speeds.
pub(crate) fn coordinate_force(
    model: &dyn ModelInfo,
    q: &[f64],
    t: f64,
    f: DVector<f64>,
) -> Result<DVector<f64>, KinematicsError> {
    match model.description().has_speeds() {
        true => Ok(rest(model, q, t)?.y.transpose() * f),
        false => Ok(f),
    }
}

/// Whether `u` is the rest's speeds `rest` to rounding, or all zeros (the callers' way of
/// asking for rest, `q̇ = 0`, whatever the offsets `Z`).
fn at_rest(u: &[f64], rest: &DVector<f64>) -> bool {
    let scale = rest.amax().max(1.0);
    u.iter().all(|&v| v == 0.0)
        || u.iter()
            .zip(rest.iter())
            .all(|(a, b)| (a - b).abs() <= 1e-12 * scale)
}

/// The linearisation at rest at `(q, t)` of an unconstrained model in generalized speeds,
/// in its coordinates (see the module docs); `u` is the state's second half given, which
/// must be the rest's speeds or all zeros (read as rest).
///
/// # Errors
/// [`KinematicsFailure::Moving`] if `u` is not at rest, [`KinematicsFailure::Singular`] as
/// [`rest`], [`KinematicsFailure::SingularMassMatrix`] if `M_u` is not positive definite,
/// [`KinematicsFailure::NonFinite`] for a matrix that is not finite.
pub(crate) fn linearize_at_rest(
    model: &dyn ModelInfo,
    q: &[f64],
    u: &[f64],
    t: f64,
) -> Result<RestMatrices, KinematicsError> {
    let rest = rest(model, q, t)?;
    if !at_rest(u, &rest.u) {
        let mut moving: Vec<f64> = q.to_vec();
        moving.extend_from_slice(u);
        let speed = model.coordinate_rates(t, &moving).amax();
        return Err(failure(q, KinematicsFailure::Moving(speed)));
    }
    let state: Vec<f64> = q.iter().chain(rest.u.iter()).copied().collect();
    let (mass_u, f) = model.mass_matrix_and_forcing(t, &state);
    let chol = mass_u
        .clone()
        .cholesky()
        .ok_or_else(|| failure(q, KinematicsFailure::SingularMassMatrix))?;
    let a = chol.solve(&f);
    let (f_q, f_u) = model.forcing_jacobians(t, &state);
    let g = f_q - model.mass_matrix_product_jacobian(t, &state, a.as_slice());
    let shifted: Vec<f64> = q.iter().chain((&rest.u + &a).iter()).copied().collect();
    let (k_shifted, _) = model.coordinate_rates_jacobian(t, &shifted);
    let e = -(&rest.y * (k_shifted - &rest.rates_q));
    let yt = rest.y.transpose();
    let mass_matrix = &yt * &mass_u * &rest.y;
    // Symmetric in exact arithmetic; rounding of the products is averaged out.
    let mass_matrix = (&mass_matrix + mass_matrix.transpose()) * 0.5;
    let mut damping_matrix = &yt * (&mass_u * &rest.p - &f_u * &rest.y);
    let mut stiffness_matrix = &yt * (&mass_u * &e - &g - &f_u * &rest.p);
    // The products' rounding, bounded entry by entry: `|fl(A B C) − A B C| ≤ γ |A| |B| |C|`
    // with `γ` some `n ε` (Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed.,
    // §3.5), and `Y`'s own error `cond(W) ε |Y|`. A skew part of `C` or `K` within that bound
    // is rounding of the products, not a gyroscopic or circulatory term (which the model in
    // rates would show as such): it is averaged out.
    let gamma = (4.0 * q.len() as f64 + rest.conditioning) * f64::EPSILON;
    let (abs_y, abs_yt) = (rest.y.abs(), yt.abs());
    let (abs_m, abs_fu, abs_p) = (mass_u.abs(), f_u.abs(), rest.p.abs());
    let damping_bound = &abs_yt * (&abs_m * &abs_p + &abs_fu * &abs_y) * gamma;
    let stiffness_bound = &abs_yt * (&abs_m * e.abs() + g.abs() + &abs_fu * &abs_p) * gamma;
    average_rounding(&mut damping_matrix, &damping_bound);
    average_rounding(&mut stiffness_matrix, &stiffness_bound);
    let finite = |m: &DMatrix<f64>| m.iter().all(|v| v.is_finite());
    if !(finite(&mass_matrix) && finite(&damping_matrix) && finite(&stiffness_matrix)) {
        return Err(failure(q, KinematicsFailure::NonFinite));
    }
    Ok(RestMatrices {
        mass: mass_matrix,
        damping: damping_matrix,
        stiffness: stiffness_matrix,
    })
}

/// Replaces each pair `(aᵢⱼ, aⱼᵢ)` of `a` by its mean where the two differ by no more than
/// their rounding bounds `bound` (`n × n` each) allow.
fn average_rounding(a: &mut DMatrix<f64>, bound: &DMatrix<f64>) {
    let n = a.nrows();
    for i in 0..n {
        for j in i + 1..n {
            if (a[(i, j)] - a[(j, i)]).abs() <= bound[(i, j)] + bound[(j, i)] {
                let mean = 0.5 * (a[(i, j)] + a[(j, i)]);
                a[(i, j)] = mean;
                a[(j, i)] = mean;
            }
        }
    }
}

fn failure(q: &[f64], kind: KinematicsFailure) -> KinematicsError {
    KinematicsError {
        kind,
        q: q.to_vec(),
    }
}
