//! Whether a linearisation's equations change with `t` at an operating point: the mass,
//! damping and stiffness matrices and the constraints sampled at offsets from `t₀`, and the
//! time-dependent forcing set aside for the modes of a forced system (lectures 22–26).

use nalgebra::{DMatrix, DVector};

use super::modal::*;
pub use super::stops::{TimeDependentForcing, TimeDependentPart};
use crate::model_info::ModelInfo;

/// Offsets (s) from `t₀` at which [`time_dependence`] samples the equations: spread over
/// three decades and irrational-looking, so that no forcing is periodic in all of them and
/// slow and fast ones both change between samples.
const TIME_OFFSETS: [f64; 6] = [0.073_1, 0.271_828, 1.523_7, 5.302_9, 19.739, 71.313];

/// A change of a part of the equations relative to its largest entry over the samples above
/// which it depends on `t`: far above the rounding of evaluating `cos(w t)` at `t ≤ 72 s`
/// (~1e-14) and far below any physical modulation.
const TIME_TOLERANCE: f64 = 1e-9;

/// The largest change of a part of the equations from its value at `t₀` (`samples[0]`) over
/// the later samples, relative to the largest entry of every sample, with the index of the
/// sample where it occurred; a NaN counts as an infinite change.
fn relative_change(samples: &[DVector<f64>]) -> (f64, usize) {
    let scale = samples.iter().fold(0.0f64, |a, v| a.max(v.amax()));
    let scales = DVector::from_element(samples[0].len(), scale);
    entrywise_change(samples, &scales)
}

/// The largest change of any entry `i` from its value at `t₀` (`samples[0]`) over the later
/// samples, relative to `scales[i]`, with the index of the sample where it occurred; a NaN,
/// or a change of an entry whose scale is 0, counts as an infinite change.
fn entrywise_change(samples: &[DVector<f64>], scales: &DVector<f64>) -> (f64, usize) {
    let at_t0 = &samples[0];
    let (mut change, mut at) = (0.0f64, 0);
    for (k, value) in samples.iter().enumerate() {
        for i in 0..value.len() {
            let d = (value[i] - at_t0[i]).abs();
            if d == 0.0 {
                continue;
            }
            let relative = if d.is_nan() || scales[i] == 0.0 {
                f64::INFINITY
            } else {
                d / scales[i]
            };
            if relative > change {
                (change, at) = (relative, k);
            }
        }
    }
    (change, at)
}

/// [`entrywise_change`] for a matrix of the linearisation (`M`, `C` or `K`, `n × n`, as
/// column-major samples): entry `(i, j)` is compared with `max(√|Xᵢᵢ Xⱼⱼ|, |Xᵢⱼ|)` over the
/// samples — its own coordinates' scale, so that a stiff coordinate elsewhere does not hide
/// the modulation of a soft one (a shaken 10 g pendulum beside a 1e9 N/m spring).
fn matrix_change(samples: &[DVector<f64>], n: usize) -> (f64, usize) {
    let mut scales = DVector::zeros(n * n);
    for value in samples {
        for j in 0..n {
            for i in 0..n {
                let own = (value[i + i * n] * value[j + j * n]).abs().sqrt();
                let s = own.max(value[i + j * n].abs());
                if s > scales[i + j * n] {
                    scales[i + j * n] = s;
                }
            }
        }
    }
    entrywise_change(samples, &scales)
}

/// Whether every entry of `v` is finite.
fn finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// The sampling of [`time_dependence`] at the operating point `q` (length `n`): `t₀` (s) and
/// the times (s) the equations are evaluated at, `t₀` first.
struct TimeSamples<'a> {
    /// The operating point (length `n`).
    q: &'a [f64],
    /// The time of the operating point (s).
    t0: f64,
    /// `t₀` and `t₀` plus each of [`TIME_OFFSETS`] (s).
    times: Vec<f64>,
}

impl TimeSamples<'_> {
    /// `Ok` when the relative change of `part`, found at sample `k`, is within
    /// [`TIME_TOLERANCE`].
    ///
    /// # Errors
    /// [`ModalError::TimeDependent`] naming the part and the time of sample `k`.
    fn refuse(
        &self,
        part: TimeDependentPart,
        (relative_change, k): (f64, usize),
    ) -> Result<(), ModalError> {
        if relative_change > TIME_TOLERANCE {
            Err(ModalError::TimeDependent {
                part,
                t0: self.t0,
                t: self.times[k],
                relative_change,
            })
        } else {
            Ok(())
        }
    }

    /// The error of parts not finite at `t₀`: [`ModalError::NotFiniteAtTime`] when they are
    /// finite at the sample `finite_at`, else [`ModalError::NonFinite`].
    fn singular(&self, finite_at: Option<usize>) -> ModalError {
        // A value that is not finite at `t₀` itself is a singularity of the equations at this
        // configuration (a 0/0: the direction of a rod of zero length, a spring's ends that
        // coincide), not a change with `t`, unless the same parts are finite at a later sample:
        // then it is the instant (a load `ln(w t)` at t = 0, `ln(w t − 1)` before t = 1/w).
        match finite_at {
            Some(k) => ModalError::NotFiniteAtTime {
                q: self.q.to_vec(),
                t: self.t0,
                finite_at: self.times[k],
            },
            None => ModalError::NonFinite { q: self.q.to_vec() },
        }
    }

    /// Checks that each of the `m` holonomic constraints (`Φ`, `J`, `Φ_t`, `γ`) of `model` at
    /// rest at `y = (q, 0)` (length `2n`) does not change over the samples.
    ///
    /// # Errors
    /// As [`TimeSamples::singular`] when they are not finite at `t₀`, and
    /// [`ModalError::TimeDependent`] naming the first constraint that changes.
    fn check_constraints(
        &self,
        model: &dyn ModelInfo,
        y: &[f64],
        m: usize,
    ) -> Result<(), ModalError> {
        let times = &self.times;
        let constraints: Vec<_> = times
            .iter()
            .map(|&t| model.constraint_equations(t, y))
            .collect();
        let at_t0 = &constraints[0];
        if ![
            at_t0.phi.as_slice(),
            at_t0.velocity.as_slice(),
            at_t0.gamma.as_slice(),
            at_t0.jacobian.as_slice(),
        ]
        .into_iter()
        .all(finite)
        {
            let later = (1..times.len()).find(|&k| {
                let c = &constraints[k];
                [c.phi.as_slice(), c.velocity.as_slice(), c.gamma.as_slice()]
                    .into_iter()
                    .all(finite)
            });
            return Err(self.singular(later));
        }
        for (i, name) in model
            .description()
            .constraint_names()
            .iter()
            .take(m)
            .enumerate()
        {
            // The Jacobian apart from Φ, Φ_t and γ: a constant J with a moving Φ is a
            // prescribed motion (base excitation), which the hint treats differently.
            let jacobian: Vec<DVector<f64>> = constraints
                .iter()
                .map(|c| c.jacobian.row(i).transpose())
                .collect();
            let rest: Vec<DVector<f64>> = constraints
                .iter()
                .map(|c| DVector::from_vec(vec![c.phi[i], c.velocity[i], c.gamma[i]]))
                .collect();
            let jacobian_change = relative_change(&jacobian);
            let part = |jacobian_changes| TimeDependentPart::Constraint {
                name: name.to_string(),
                jacobian_changes,
            };
            self.refuse(part(true), jacobian_change)?;
            self.refuse(part(false), relative_change(&rest))?;
        }
        Ok(())
    }
}

/// The explicit time dependence of `model`'s equations at rest at `q` (the operating point,
/// length `n`), from `t₀` (s): evaluated at six later times, each holonomic constraint
/// (`Φ`, `J`, `Φ_t`, `γ`), then `M(q, t)`, `∂F/∂q̇ (q, 0, t)` and `∂F/∂q (q, 0, t)` must not
/// change (relative change at most `1e-9`, entry `(i, j)` of a matrix against
/// `max(√|Xᵢᵢ Xⱼⱼ|, |Xᵢⱼ|)`, so that an unrelated stiff coordinate does not hide a modulated
/// soft one; `Fᵢ` against `max(|Fᵢ|, Σⱼ |Kᵢⱼ qⱼ|)`). A change of `F(q, 0, t)` alone is a load that
/// enters neither `M`, `C` nor `K` — the linear oscillator driven by `F₀ cos ωt` — and is
/// returned: the modes are those of the equations without the load's variation, about the
/// equilibrium under its value at `t₀` (frozen there in
/// the equilibrium. `Ok(None)` when nothing changes.
///
/// The Jacobians are those of the linearisation: an entry that is not finite where `F` is
/// (quadratic drag at rest) is differenced, as in [`linearize`], rather than read as a change.
///
/// Why numerically: the model is a compiled function of `(t, y)`; sampling its values is
/// what the Floquet study does to check a period, and it sees every route by which `t`
/// enters (a point moved with `t`, a constraint, a load).
///
/// # Errors
/// [`ModalError::NonFinite`] when a part is not finite at `t₀` itself (a singularity of the
/// equations at `q`, which is not a change with `t`); [`ModalError::NotFiniteAtTime`] when
/// it is finite at a later sample (a load such as `ln(w t)` at `t₀ = 0`);
/// [`ModalError::TimeDependent`] naming the first part found to change, in the order above
/// (a rheonomic constraint such as a rod spun at a constant rate written with `t`, a
/// parametrically excited stiffness such as a pendulum on a shaken pivot);
/// [`ModalError::DimensionMismatch`] and [`ModalError::NonHolonomic`];
/// [`ModalError::SingularKinematics`] for a model in generalized speeds whose kinematic
/// equations are singular at `q`.
pub fn time_dependence(
    model: &dyn ModelInfo,
    q: &[f64],
    t0: f64,
) -> Result<Option<TimeDependentForcing>, ModalError> {
    check_point(model, q)?;
    let n = q.len();
    let m = model.description().holonomic_constraints;
    // At rest, `q̇ = 0`: in generalized speeds `u = Z(q, t)` at each sample.
    let at_rest = |t: f64| super::speeds::rest_state(model, q, t);
    let y = at_rest(t0)?;
    let times: Vec<f64> = std::iter::once(t0)
        .chain(TIME_OFFSETS.iter().map(|offset| t0 + offset))
        .collect();
    let samples = TimeSamples { q, t0, times };
    let times = &samples.times;
    if m > 0 {
        samples.check_constraints(model, &y, m)?;
    }
    let flat = |a: &DMatrix<f64>| DVector::from_column_slice(a.as_slice());
    let (mut mass, mut forcing, mut damping, mut stiffness) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for &t in times {
        let y = at_rest(t)?;
        let (m_t, f_t) = model.mass_matrix_and_forcing(t, &y);
        let (jq, jqd, _) = forcing_jacobians(model, t, &y);
        mass.push(flat(&m_t));
        forcing.push(f_t);
        damping.push(flat(&jqd));
        stiffness.push(flat(&jq));
    }
    let all_finite = |k: usize| {
        [&mass[k], &forcing[k], &damping[k], &stiffness[k]]
            .into_iter()
            .all(|v| finite(v.as_slice()))
    };
    if !all_finite(0) {
        return Err(samples.singular((1..times.len()).find(|&k| all_finite(k))));
    }
    samples.refuse(TimeDependentPart::MassMatrix, matrix_change(&mass, n))?;
    samples.refuse(TimeDependentPart::DampingMatrix, matrix_change(&damping, n))?;
    samples.refuse(
        TimeDependentPart::StiffnessMatrix,
        matrix_change(&stiffness, n),
    )?;
    // The load, coordinate by coordinate: the rounding of `Fᵢ` is that of its terms, of the
    // order of `Σⱼ |Kᵢⱼ qⱼ|` (units of `Fᵢ`), which is the floor of the comparison with
    // `max |Fᵢ|` over the samples.
    let mut scales = DVector::zeros(n);
    for i in 0..n {
        let terms: f64 = (0..n).map(|j| (stiffness[0][i + j * n] * q[j]).abs()).sum();
        scales[i] = forcing.iter().fold(terms, |a, f| a.max(f[i].abs()));
    }
    let (change, k) = entrywise_change(&forcing, &scales);
    if change <= TIME_TOLERANCE {
        return Ok(None);
    }
    let difference = &forcing[k] - &forcing[0];
    let i = difference.iamax();
    Ok(Some(TimeDependentForcing {
        t0,
        coordinate: model.description().coordinates[i].to_string(),
        largest_change: difference[i].abs(),
        t: times[k],
    }))
}
