//! The rolling phase: the contact force and the friction it needs along the run, by
//! Newton–Euler on the constrained model's accelerations, and where the friction ratio peaks or
//! passes the given coefficients.

use super::*;

/// `a_G` (m/s²) at every sample but the first and the last: a five-point central
/// difference in time of `v_G` over the states at `t_i + k h`, `k = −2..2`, from a further
/// run sampled there, with `h = min(Δt/5, 1e-4 t_lift)` whatever the sampling (so that the
/// truncation `h⁴ a⁽⁵⁾/30` and the rounding of the dense output over `h` both stay near
/// 1e-9 of the forces).
pub(super) fn centre_accelerations(
    model: &mut dyn ModelInfo,
    samples: &[(f64, Vec<f64>)],
    centre: usize,
    options: &RollingContactOptions,
) -> Result<Vec<Option<[f64; 2]>>, RollingContactError> {
    let name = model.description().name.to_string();
    let count = samples.len();
    let t_last = samples[count - 1].0;
    let h = (t_last / (count - 1) as f64 / 5.0).min(1e-4 * t_last);
    let mut times = Vec::with_capacity(5 * count);
    for (t, _) in &samples[1..count - 1] {
        times.extend((-2..=2).map(|k| t + f64::from(k) * h));
    }
    let sampled = SimulationOptions {
        method: Method::Dop853,
        t_end: options.t_end,
        rtol: options.rtol,
        atol: options.rtol,
        output: OutputTimes::At(times),
        ..SimulationOptions::default()
    };
    let run = run(model, &name, &sampled, None)?;
    let solution = &run.solution;
    let velocity = |j: usize| {
        point_velocity(
            model,
            &solution.y[j * solution.dim..(j + 1) * solution.dim],
            centre,
        )
    };
    let mut out = vec![None; count];
    for (i, slot) in out.iter_mut().enumerate().take(count - 1).skip(1) {
        let first = 5 * (i - 1);
        if first + 5 > solution.t.len() {
            break;
        }
        let v: Vec<[f64; 2]> = (first..first + 5).map(velocity).collect();
        let a = |k: usize| (-v[4][k] + 8.0 * v[3][k] - 8.0 * v[1][k] + v[0][k]) / (12.0 * h);
        *slot = Some([a(0), a(1)]);
    }
    Ok(out)
}

/// The rolling phase's report from its `samples` `(t, [q; q̇])` (uniform, the last at the
/// lift-off `end`), the first run's `events` (the friction thresholds' crossings) and the
/// centre's `accelerations` (m/s², `None` at the ends): the contact forces and `μ` at every
/// sample ([`contact_samples`]), the Newton–Euler check ([`newton_euler`]), the peaks and
/// final rise of `μ` ([`mu_extrema`]), the thresholds' first exceedances ([`exceedances`])
/// and the state of the forces at the lift-off.
pub(super) fn rolling_phase(
    model: &mut dyn ModelInfo,
    samples: &[(f64, Vec<f64>)],
    end: &Event,
    events: &[Event],
    accelerations: &[Option<[f64; 2]>],
    [ground, normal]: [usize; 2],
    options: &RollingContactOptions,
) -> Result<RollingPhase, RollingContactError> {
    let name = model.description().name.to_string();
    let (mass, gravity) = mass_and_gravity(model, &samples[0].1, ground, normal, options)?;
    let (mut out, energies) = contact_samples(model, &name, samples, [ground, normal])?;
    // Newton–Euler at the interior samples.
    let count = out.len();
    let dt = (samples[count - 1].0 - samples[0].0) / (count - 1) as f64;
    let newton_euler = newton_euler(&mut out, accelerations, (mass, gravity), &name, options)?;
    let max_normal_force = newton_euler.max_normal_force;
    let (peaks, final_rise_from) = mu_extrema(&out, dt);
    let max_peak = peaks.iter().copied().max_by(|a, b| a.mu.total_cmp(&b.mu));
    let exceedances = exceedances(&out, events, options);
    let last = &out[count - 1];
    let rate = (3.0 * last.normal_force - 4.0 * out[count - 2].normal_force
        + out[count - 3].normal_force)
        / (2.0 * dt);
    Ok(RollingPhase {
        model: name,
        coordinates: model
            .description()
            .coordinate_names()
            .iter()
            .map(|s| s.to_string())
            .collect(),
        ground: options.ground.clone(),
        normal: options.normal.clone(),
        lift_off_time: end.t,
        lift_off_state: end.y.clone(),
        normal_force_at_lift_off: last.normal_force,
        friction_force_at_lift_off: last.friction_force,
        normal_force_rate_at_lift_off: rate,
        mu_diverges: last.friction_force.abs() > 1e-9 * max_normal_force,
        energy_drift: drift(&energies),
        samples: out,
        peaks,
        max_peak,
        final_rise_from,
        exceedances,
        newton_euler,
    })
}

/// The contact forces from the multipliers ([`contact_force`]: `F_t`, `N` in N), `μ = |F_t|/N`
/// where `N > 0`, and `T + V` (J) at each of the rolling phase's `samples` `(t, [q; q̇])`,
/// their Newton–Euler fields left `None`; and the `(T + V, T + |V|)` pairs for [`drift`].
/// A force that cannot be computed ([`RollingContactError::ConstraintForces`]) or is not
/// finite ([`RollingContactError::NonFinite`]) is an error of the model `name`.
fn contact_samples(
    model: &mut dyn ModelInfo,
    name: &str,
    samples: &[(f64, Vec<f64>)],
    [ground, normal]: [usize; 2],
) -> Result<ContactRows, RollingContactError> {
    let n = model.num_dofs();
    let mut out: Vec<ContactSample> = Vec::with_capacity(samples.len());
    let mut energies = Vec::with_capacity(samples.len());
    for (t, y) in samples {
        let [friction, normal_force] =
            contact_force(model, *t, y, ground, normal).map_err(|source| {
                RollingContactError::ConstraintForces {
                    model: name.to_string(),
                    t: *t,
                    source,
                }
            })?;
        for (what, value) in [("normal force", normal_force), ("friction force", friction)] {
            if !value.is_finite() {
                return Err(RollingContactError::NonFinite {
                    model: name.to_string(),
                    what,
                    value,
                });
            }
        }
        let (kinetic, potential) = (model.kinetic_energy(*t, y), model.potential_energy(*t, y));
        energies.push((kinetic + potential, kinetic + potential.abs()));
        out.push(ContactSample {
            t: *t,
            q: y[..n].to_vec(),
            qdot: y[n..2 * n].to_vec(),
            energy: kinetic + potential,
            normal_force,
            friction_force: friction,
            mu: (normal_force > 0.0).then(|| friction.abs() / normal_force),
            normal_force_newton_euler: None,
            friction_force_newton_euler: None,
        });
    }
    Ok((out, energies))
}

/// Newton–Euler against the multipliers: at each sample with an acceleration `a_G` (m/s²),
/// `(F_t, N) = m (a_G − g)` from `(mass, gravity)` (kg, m/s²) is written into the sample and
/// compared with the multipliers' forces; the largest differences relative to the largest
/// `|N|` are checked against [`RollingContactOptions::newton_euler_tolerance`]. A relative
/// difference that is not finite is [`RollingContactError::NonFinite`] (of the model `name`).
fn newton_euler(
    out: &mut [ContactSample],
    accelerations: &[Option<[f64; 2]>],
    (mass, gravity): (f64, [f64; 2]),
    name: &str,
    options: &RollingContactOptions,
) -> Result<NewtonEulerAgreement, RollingContactError> {
    let (mut max_normal_difference, mut max_friction_difference) = (0.0_f64, 0.0_f64);
    for (s, a) in out.iter_mut().zip(accelerations) {
        let Some(a) = a else { continue };
        let friction = mass * (a[0] - gravity[0]);
        let normal_force = mass * (a[1] - gravity[1]);
        max_normal_difference = max_normal_difference.max((normal_force - s.normal_force).abs());
        max_friction_difference = max_friction_difference.max((friction - s.friction_force).abs());
        s.normal_force_newton_euler = Some(normal_force);
        s.friction_force_newton_euler = Some(friction);
    }
    let max_normal_force = out.iter().fold(0.0_f64, |m, s| m.max(s.normal_force.abs()));
    let relative =
        max_normal_difference.max(max_friction_difference) / max_normal_force.max(1e-300);
    if !relative.is_finite() {
        return Err(RollingContactError::NonFinite {
            model: name.to_string(),
            what: "Newton–Euler difference",
            value: relative,
        });
    }
    Ok(NewtonEulerAgreement {
        mass,
        gravity,
        max_normal_difference,
        max_friction_difference,
        max_normal_force,
        relative,
        tolerance: options.newton_euler_tolerance,
        passed: relative <= options.newton_euler_tolerance,
    })
}

/// The local maxima of `μ(t)` over the samples `out` (spaced `dt` s), each refined by the
/// parabola through its three samples, and the time (s) of the last local minimum from which
/// `μ` rises to the lift-off (`None` if a maximum follows it).
fn mu_extrema(out: &[ContactSample], dt: f64) -> (Vec<MuPeak>, Option<f64>) {
    let count = out.len();
    // The local maxima and the last local minimum of μ over consecutive finite samples.
    let mut peaks = Vec::new();
    let mut final_rise_from = None;
    for i in 1..count.saturating_sub(1) {
        let (Some(a), Some(b), Some(c)) = (out[i - 1].mu, out[i].mu, out[i + 1].mu) else {
            continue;
        };
        let curvature = a - 2.0 * b + c;
        let offset = if curvature != 0.0 {
            ((a - c) / (2.0 * curvature)).clamp(-0.5, 0.5)
        } else {
            0.0
        };
        if b >= a && b > c {
            peaks.push(MuPeak {
                t: out[i].t + offset * dt,
                mu: b - (a - c) * offset / 4.0,
            });
        } else if b <= a && b < c {
            final_rise_from = Some(out[i].t + offset * dt);
        }
    }
    if let (Some(rise), Some(last)) = (final_rise_from, peaks.last())
        && last.t > rise
    {
        // μ does not rise to the end: the last extremum is a maximum.
        final_rise_from = None;
    }
    (peaks, final_rise_from)
}

/// For each of the options' friction thresholds, when `μ(t)` first reaches it: the start if
/// `μ(0)` already does, else its rising event `rolling_contact_mu_{i}` among `events` (s).
fn exceedances(
    out: &[ContactSample],
    events: &[Event],
    options: &RollingContactOptions,
) -> Vec<Exceedance> {
    options
        .thresholds
        .iter()
        .enumerate()
        .map(|(i, mu)| Exceedance {
            mu: *mu,
            // Already reached at the start (`F_t² ≥ μ² N²` there, `μ(0) ≥ μ`): the rising
            // event cannot fire from a value ≥ 0, and the body slips from the first instant.
            t: if out[0].friction_force.powi(2) >= (mu * out[0].normal_force).powi(2) {
                Some(out[0].t)
            } else {
                events
                    .iter()
                    .find(|e| e.name == format!("rolling_contact_mu_{i}"))
                    .map(|e| e.t)
            },
        })
        .collect()
}
