//! The search for a steady motion: Gauss–Newton with a trust region on the coordinates and
//! rates it finds, its polish to rounding, and the checks that the motion found moves only
//! cyclic coordinates (and, for a steady turn, that the equations are symmetric under
//! turning). The linearisation about the motion found is in the parent module.

use nalgebra::{DMatrix, DVector};

use super::super::turning::TurningFrame;
use super::{SteadyMotion, SteadyMotionError, SteadyMotionSpec};
use crate::model_info::ModelInfo;
use crate::ode::RhsError;

/// `[q̈; Φ; V]` at the state `y = (q, q̇)` (length `2n`): the residuals of a steady motion,
/// the plane's `q̈` less the turn's `Ω S q̇` in a steady turn.
fn steady_residuals(
    model: &mut dyn ModelInfo,
    t: f64,
    y: &[f64],
    turning: Option<&TurningFrame>,
) -> Result<Vec<f64>, RhsError> {
    let n = y.len() / 2;
    let mut dy = vec![0.0; 2 * n];
    model.as_ode_mut().rhs(t, y, &mut dy)?;
    let mut r = dy[n..].to_vec();
    if let Some(frame) = turning {
        frame.residuals(y, &mut r);
    }
    if !model.description().constraints.is_empty() {
        let c = model.constraint_equations(t, y);
        r.extend(c.phi.iter());
        r.extend(c.velocity.iter());
    }
    Ok(r)
}

/// The name of residual `i` of [`steady_residuals`].
fn residual_name(model: &dyn ModelInfo, i: usize) -> String {
    let d = model.description();
    let n = d.coordinates.len();
    let m_h = d.holonomic_constraints;
    if i < n {
        format!("{}_ddot", d.coordinates[i])
    } else if i < n + m_h {
        format!("constraint `{}`", d.constraints[i - n])
    } else {
        let k = i - n - m_h;
        format!("velocity of constraint `{}`", d.constraints[k])
    }
}

/// Largest absolute entry and its index.
fn largest(v: &[f64]) -> (f64, usize) {
    v.iter().enumerate().fold((0.0, 0), |(m, k), (i, x)| {
        if x.abs() > m || x.is_nan() {
            (x.abs(), i)
        } else {
            (m, k)
        }
    })
}

/// Finds a steady motion near `guess` (length `n`) with the rates `rates` (length `n`)
/// held: Gauss–Newton on the coordinates that are not `ignorable` (indices) so that
/// `q̈ = 0`, `Φ = 0` and the velocity constraints hold; [`find_steady_motion_with`] with
/// [`SteadyMotionSpec::holding`]. An equilibrium is the case `rates = 0`.
///
/// # Errors
/// As [`find_steady_motion_with`].
pub fn find_steady_motion(
    model: &mut dyn ModelInfo,
    t: f64,
    guess: &[f64],
    rates: &[f64],
    ignorable: &[usize],
) -> Result<SteadyMotion, SteadyMotionError> {
    find_steady_motion_with(
        model,
        t,
        guess,
        &SteadyMotionSpec::holding(rates, ignorable),
    )
}

/// Finds the steady motion `spec` describes near `guess` (length `n`): Gauss–Newton on the
/// coordinates neither ignorable nor held and on the rates to be found, so that `q̈ = 0`
/// (for a steady turn, the plane's `q̈ = Ω S q̇`), `Φ = 0` and the velocity constraints hold,
/// with central-difference Jacobians and least-squares steps (SVD, singular values below
/// `1e-12 σ_max` dropped, so that directions the residuals do not see stay at their guess).
///
/// The steps are held in a trust region (Dennis & Schnabel, *Numerical Methods for
/// Unconstrained Optimization and Nonlinear Equations*, 1983, §6.4): each unknown moves
/// at most `Δ·max(1, |yⱼ|)`, `Δ` starting at 0.25, halved when the residual falls
/// by less than a tenth of what the linear model predicts (or cannot be evaluated) and
/// doubled when the prediction holds. So the motion found is the one the guess leads to,
/// not one a flat stretch of the residual throws the first step to (a top's nutation
/// `θ = 0.5` near the residual's maximum gave `θ = 8π − 0.9`). Once the largest residual is
/// below `1e-11 (1 + s)`, `s` its size at the guess, full steps continue while they reduce
/// it: the unknowns are found to rounding, not to the tolerance.
///
/// # Errors
/// [`SteadyMotionError::NotSteady`] naming the largest residual when it does not converge
/// within 50 iterations or no step reduces it; [`SteadyMotionError::Unevaluable`] when the
/// search is stopped by a point where the equations cannot be evaluated (a singularity of
/// the coordinates, as Euler angles at `θ = 0`); [`SteadyMotionError::Rhs`] when they cannot
/// be evaluated at the guess; [`SteadyMotionError::HeldRateNotIgnorable`] when the motion
/// moves a coordinate not declared ignorable; [`SteadyMotionError::NotCyclic`] when a moving
/// coordinate changes the equations, [`SteadyMotionError::NotSymmetric`] when the turn does;
/// [`SteadyMotionError::InSpeeds`] for a model in generalized speeds.
pub fn find_steady_motion_with(
    model: &mut dyn ModelInfo,
    t: f64,
    guess: &[f64],
    spec: &SteadyMotionSpec,
) -> Result<SteadyMotion, SteadyMotionError> {
    if model.description().has_speeds() {
        return Err(SteadyMotionError::InSpeeds);
    }
    let n = guess.len();
    spec.check(n)?;
    let names = owned_state_names(model);
    let held: Vec<f64> = (0..n)
        .map(|i| match spec.solved_rates.contains(&i) {
            true => 0.0,
            false => spec.rates.get(i).copied().unwrap_or(0.0),
        })
        .collect();
    check_held_rates(&names, n, &held, &spec.ignorable)?;
    let turning = spec.turning.as_ref();
    let free = spec.unknowns(n);
    let mut y: Vec<f64> = guess.iter().chain(&spec.rates).copied().collect();
    y.resize(2 * n, 0.0);
    let mut r = steady_residuals(model, t, &y, turning)?;
    let scale = 1.0 + largest(&r).0;
    let mut radius = FIRST_RADIUS;
    let mut iterations = 0;
    // The last point the equations could not be evaluated at: near it the search was held
    // back, and a search that fails is blamed on it.
    let mut refused: Option<(Vec<f64>, RhsError)> = None;
    // The step and its predicted change at the current `y`, kept while a refused trial
    // only shrinks the region (the Jacobian costs 2 k evaluations of the equations).
    let mut at_y: Option<(DVector<f64>, DVector<f64>)> = None;
    loop {
        let (worst, at) = largest(&r);
        if !worst.is_finite() {
            return Err(SteadyMotionError::NonFinite);
        }
        if worst <= 1e-11 * scale {
            break;
        }
        if free.is_empty() {
            check_steady_as_held(model, &spec.rates, iterations, (worst, at))?;
            break;
        }
        let stuck = radius < 1e-15;
        if iterations == 50 || stuck {
            return Err(search_failed(
                model,
                &names,
                &free,
                refused,
                iterations,
                (worst, at),
            ));
        }
        iterations += 1;
        let (step, predicted) = match at_y.take() {
            Some(cached) => cached,
            None => gauss_newton_step(model, t, &y, turning, &free, &r)?,
        };
        let size = relative_step(&y, &free, &step);
        // Converged as far as rounding allows: Newton would move the unknowns by less
        // than their rounding, with the residual small and within reach of the step (an
        // exact guess whose residual is the rounding of large terms, a hoop spun at
        // 1000 rad/s). A residual the unknowns cannot change (an acceleration no free
        // coordinate affects) is not rounding, however small the step.
        let reachable = within_reach(&r, &predicted, worst);
        if size <= 1e-14 && worst <= 1e-8 * scale && reachable {
            break;
        }
        let fraction = if size > radius { radius / size } else { 1.0 };
        let trial = moved_by(&y, &free, &step, fraction);
        match steady_residuals(model, t, &trial, turning) {
            Ok(rt) if largest(&rt).0.is_finite() => {
                let ratio = reduction_ratio(&r, &rt, &predicted, fraction);
                // A NaN ratio (no predicted reduction) shrinks the region too.
                if ratio.is_nan() || ratio < 0.1 {
                    radius = fraction * size / 2.0;
                    at_y = Some((step, predicted));
                    continue;
                }
                if ratio >= 0.75 {
                    radius = radius.max(2.0 * fraction * size);
                }
                y = trial;
                r = rt;
            }
            Ok(_) => {
                radius = fraction * size / 2.0;
                at_y = Some((step, predicted));
            }
            Err(e) => {
                radius = fraction * size / 2.0;
                refused = Some((trial, e));
                at_y = Some((step, predicted));
            }
        }
    }
    polish(model, t, &mut y, &mut r, turning, &free)?;
    let (q, rates) = (y[..n].to_vec(), y[n..].to_vec());
    // A rate found must move only an ignorable coordinate, as a held one.
    check_held_rates(&names, n, &rates, &spec.ignorable)?;
    let mut moving = moving_coordinates(n, &rates);
    if let Some(frame) = turning {
        // The turn moves its angle together with the plane's rates: checked as a symmetry.
        moving.retain(|&i| i != frame.angle);
        check_turning_symmetry(model, t, &y, frame)?;
    }
    check_cyclic(model, t, &q, &rates, &moving)?;
    Ok(SteadyMotion {
        q,
        qdot: rates,
        iterations,
        residual: largest(&r).0,
    })
}

/// The names of `model`'s states (length `2n`: the coordinates, then their rates), owned.
fn owned_state_names(model: &dyn ModelInfo) -> Vec<String> {
    let d = model.description();
    (0..2 * d.coordinates.len())
        .map(|i| d.state_name(i))
        .collect()
}

/// Checks that a steady turn is one: that the accelerations at the state turned by the
/// angle `s` ([`TurningFrame::turn_state`]) are those at `y` turned by `s`, at the turn `y`
/// and at a state near it, for the shifts [`CYCLIC_SHIFTS`], within 1e-9 of the largest
/// acceleration over all of them (as [`check_cyclic`]: at the turn itself the accelerations
/// are the turn's `Ω |v|` and rounding, which a turn near straight running makes tiny). A
/// state where the equations fail is skipped.
///
/// # Errors
/// [`SteadyMotionError::NotSymmetric`].
fn check_turning_symmetry(
    model: &mut dyn ModelInfo,
    t: f64,
    y: &[f64],
    frame: &TurningFrame,
) -> Result<(), SteadyMotionError> {
    let n = y.len() / 2;
    let near: Vec<f64> = (y.iter().enumerate())
        .map(|(k, v)| v + 0.1 * (1.0 + (k as f64 * 0.618_033_988_749_895).fract()))
        .collect();
    let mut accelerations = |y: &[f64]| -> Option<Vec<f64>> {
        let mut dy = vec![0.0; 2 * n];
        model.as_ode_mut().rhs(t, y, &mut dy).ok()?;
        dy[n..]
            .iter()
            .all(|v| v.is_finite())
            .then(|| dy[n..].to_vec())
    };
    // (shift, the accelerations turned, the accelerations at the turned state).
    let mut compared: Vec<(f64, Vec<f64>, Vec<f64>)> = Vec::new();
    for base in [y.to_vec(), near] {
        let Some(at_base) = accelerations(&base) else {
            continue;
        };
        for shift in CYCLIC_SHIFTS {
            if let Some(turned) = accelerations(&frame.turn_state(&base, n, shift)) {
                compared.push((shift, frame.turn_accelerations(&at_base, shift), turned));
            }
        }
    }
    let size = (compared.iter())
        .flat_map(|(_, a, b)| a.iter().chain(b))
        .fold(0.0f64, |m, v| m.max(v.abs()));
    for (shift, expected, turned) in &compared {
        let change = (expected.iter().zip(turned)).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
            / size.max(f64::MIN_POSITIVE);
        if change > 1e-9 {
            let names = model.description().coordinate_names();
            let name = |i: usize| {
                names
                    .get(i)
                    .map_or_else(|| i.to_string(), |c| c.to_string())
            };
            return Err(SteadyMotionError::NotSymmetric {
                angle: name(frame.angle),
                plane_a: name(frame.plane[0]),
                plane_b: name(frame.plane[1]),
                change,
                shift: *shift,
            });
        }
    }
    Ok(())
}

/// The coordinates (indices among the first `n`) whose held rate is nonzero: those that
/// move in the steady motion.
fn moving_coordinates(n: usize, rates: &[f64]) -> Vec<usize> {
    (0..n.min(rates.len()))
        .filter(|&i| rates[i] != 0.0)
        .collect()
}

/// Checks that every rate held nonzero (of the first `n`) is that of an `ignorable`
/// coordinate, `names` naming the coordinates.
///
/// # Errors
/// [`SteadyMotionError::HeldRateNotIgnorable`] naming the first that is not.
fn check_held_rates(
    names: &[String],
    n: usize,
    rates: &[f64],
    ignorable: &[usize],
) -> Result<(), SteadyMotionError> {
    if let Some(i) = (0..n.min(rates.len())).find(|&i| rates[i] != 0.0 && !ignorable.contains(&i)) {
        return Err(SteadyMotionError::HeldRateNotIgnorable {
            coordinate: names.get(i).cloned().unwrap_or_else(|| i.to_string()),
            rate: rates[i],
        });
    }
    Ok(())
}

/// With no free coordinate to adjust, whether the held state is steady as it is: its largest
/// residual `worst` (at index `at`) within `1e-10 (1 + max q̇ᵢ²)`.
///
/// # Errors
/// [`SteadyMotionError::NotSteady`] naming the residual when it is not.
fn check_steady_as_held(
    model: &dyn ModelInfo,
    rates: &[f64],
    iterations: usize,
    (worst, at): (f64, usize),
) -> Result<(), SteadyMotionError> {
    // Nothing to adjust: the held state must be steady as it is, its residual at
    // rounding of the rates' own accelerations (`q̇²`), not of its own size (a
    // Chaplygin sleigh spinning in place has `v̇ = d ω²`, and is no steady motion).
    // The ignorable coordinates' values are arbitrary and do not enter.
    let natural = rates.iter().fold(0.0f64, |m, r| m.max(r * r));
    if worst <= 1e-10 * (1.0 + natural) {
        return Ok(());
    }
    Err(SteadyMotionError::NotSteady {
        iterations,
        residual: worst,
        worst: residual_name(model, at),
    })
}

/// The error of a search that ran out of iterations or of trust region, its largest residual
/// `worst` at index `at`: [`SteadyMotionError::Unevaluable`] at the last point `refused`, if
/// any, else [`SteadyMotionError::NotSteady`].
fn search_failed(
    model: &dyn ModelInfo,
    names: &[String],
    free: &[usize],
    refused: Option<(Vec<f64>, RhsError)>,
    iterations: usize,
    (worst, at): (f64, usize),
) -> SteadyMotionError {
    if let Some((point, source)) = refused {
        return SteadyMotionError::Unevaluable {
            at: named_values(names, &point, free),
            source,
        };
    }
    SteadyMotionError::NotSteady {
        iterations,
        residual: worst,
        worst: residual_name(model, at),
    }
}

/// The largest move of a `free` entry of the state `y` by `step` relative to `max(1, |yⱼ|)`.
fn relative_step(y: &[f64], free: &[usize], step: &DVector<f64>) -> f64 {
    free.iter()
        .enumerate()
        .map(|(col, &j)| step[col].abs() / y[j].abs().max(1.0))
        .fold(0.0f64, f64::max)
}

/// Whether the full step's predicted residual `r + J δ` (`predicted` = `J δ`) is within
/// `1e-3` of the largest residual `worst`: the residual is one the coordinates can change.
fn within_reach(r: &[f64], predicted: &DVector<f64>, worst: f64) -> bool {
    linear_prediction(r, predicted, 1.0)
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        <= 1e-3 * worst
}

/// The trust region's ratio: the reduction of the sum of squares from `r` to `rt` achieved
/// by the step `fraction · δ`, over the one predicted by `r + fraction · J δ`
/// (`predicted` = `J δ`); NaN when none is predicted.
fn reduction_ratio(r: &[f64], rt: &[f64], predicted: &DVector<f64>, fraction: f64) -> f64 {
    // Sum-of-squares reduction, achieved against predicted by `r + J δ`.
    let now = sum_of_squares(r);
    let expected = now - sum_of_squares(&linear_prediction(r, predicted, fraction));
    (now - sum_of_squares(rt)) / expected
}

/// The trust region's first radius in [`find_steady_motion`], relative to `max(1, |qⱼ|)`:
/// a quarter of a radian for an angle, so that the first steps stay on the guess's branch.
const FIRST_RADIUS: f64 = 0.25;

/// Full Gauss–Newton steps after convergence, each kept only if it lowers the largest
/// residual and moves the unknowns by more than 1e-12 of their size (at most four: the
/// convergence is quadratic).
fn polish(
    model: &mut dyn ModelInfo,
    t: f64,
    y: &mut Vec<f64>,
    r: &mut Vec<f64>,
    turning: Option<&TurningFrame>,
    free: &[usize],
) -> Result<(), SteadyMotionError> {
    for _ in 0..4 {
        if free.is_empty() || largest(r).0 == 0.0 {
            break;
        }
        let (step, _) = gauss_newton_step(model, t, y, turning, free, r)?;
        // A step below 1e-12 of the unknowns moves them within the rounding of the
        // differenced Jacobian's solve: an exact guess (the heavy top's precession at π/6)
        // stays where it is, though such a step may lower a residual that is rounding.
        if relative_step(y, free, &step) <= 1e-12 {
            break;
        }
        let trial = moved_by(y, free, &step, 1.0);
        match steady_residuals(model, t, &trial, turning) {
            Ok(rt) if largest(&rt).0 < largest(r).0 => {
                *y = trial;
                *r = rt;
            }
            _ => break,
        }
    }
    Ok(())
}

/// The least-squares Gauss–Newton step `δ` (on the `free` entries of the state `y`) that
/// makes `r + J δ` smallest, `J` by central differences, and `J δ`.
fn gauss_newton_step(
    model: &mut dyn ModelInfo,
    t: f64,
    y: &[f64],
    turning: Option<&TurningFrame>,
    free: &[usize],
    r: &[f64],
) -> Result<(DVector<f64>, DVector<f64>), SteadyMotionError> {
    let mut jac = DMatrix::zeros(r.len(), free.len());
    for (col, &j) in free.iter().enumerate() {
        let h = 1e-6 * y[j].abs().max(1.0);
        let (mut up, mut down) = (y.to_vec(), y.to_vec());
        up[j] += h;
        down[j] -= h;
        let (ru, rd) = (
            steady_residuals(model, t, &up, turning)?,
            steady_residuals(model, t, &down, turning)?,
        );
        for i in 0..r.len() {
            jac[(i, col)] = (ru[i] - rd[i]) / (2.0 * h);
        }
    }
    if !jac.iter().all(|v| v.is_finite()) {
        return Err(SteadyMotionError::NonFinite);
    }
    let svd = jac.clone().svd(true, true);
    let cut = 1e-12 * svd.singular_values.max();
    let step = -svd
        .solve(&DVector::from_vec(r.to_vec()), cut)
        .map_err(|_| SteadyMotionError::NonFinite)?;
    let predicted = &jac * &step;
    Ok((step, predicted))
}

/// `y` with its `free` entries moved by `fraction · step`.
fn moved_by(y: &[f64], free: &[usize], step: &DVector<f64>, fraction: f64) -> Vec<f64> {
    let mut out = y.to_vec();
    for (col, &j) in free.iter().enumerate() {
        out[j] += fraction * step[col];
    }
    out
}

/// `r + fraction · J δ`: the residual the linear model predicts after the step.
fn linear_prediction(r: &[f64], j_step: &DVector<f64>, fraction: f64) -> Vec<f64> {
    r.iter()
        .zip(j_step.iter())
        .map(|(a, b)| a + fraction * b)
        .collect()
}

fn sum_of_squares(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum()
}

/// `name = value, …` for the `free` entries of the state `y`, `names` naming them.
fn named_values(names: &[String], y: &[f64], free: &[usize]) -> String {
    free.iter()
        .map(|&j| {
            let name = names.get(j).cloned().unwrap_or_else(|| j.to_string());
            format!("{name} = {:e}", y[j])
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The part of [`check_cyclic`] shifted along the motion only: the holonomic constraints'
/// residuals.
const JOINT_PART: &str = "the constraints' residuals Φ";

/// The parts of the equations [`check_cyclic`] compares, by name, each flattened.
type Parts = Vec<(&'static str, DVector<f64>)>;

/// Shifts (in the coordinate's units) by which [`check_cyclic`] moves a coordinate:
/// irrational-looking and of both signs, so that no periodic dependence hides in all.
const CYCLIC_SHIFTS: [f64; 3] = [0.271_828, 1.523_7, -0.731_3];

/// Checks that each of the `moving` coordinates is cyclic: `M`, `F` and the constraints'
/// `Φ`, `J`, velocity terms and `γ` do not change when it is shifted ([`CYCLIC_SHIFTS`]), at
/// the steady motion `(q, rates)` and at a state near it (every entry moved by 0.1–0.2, which
/// catches a dependence multiplied by a rate that is 0 at the steady motion, as the
/// Coriolis force `−2 m r ṙ θ̇` of a particle running in at θ̇ = 0). Relative to each
/// part's largest entry, above 1e-9 (the time-dependence check's tolerance): numerically,
/// because derived expressions keep cyclic coordinates that cancel only in value
/// (`cos² φ + sin² φ`). A state where the equations are not finite is skipped.
///
/// # Errors
/// [`SteadyMotionError::NotCyclic`] naming the coordinate and the part that depends on it.
fn check_cyclic(
    model: &dyn ModelInfo,
    t: f64,
    q: &[f64],
    rates: &[f64],
    moving: &[usize],
) -> Result<(), SteadyMotionError> {
    if moving.is_empty() {
        return Ok(());
    }
    let steady: Vec<f64> = q.iter().chain(rates).copied().collect();
    let near: Vec<f64> = steady
        .iter()
        .enumerate()
        .map(|(k, v)| v + 0.1 * (1.0 + (k as f64 * 0.618_033_988_749_895).fract()))
        .collect();
    let constrained = !model.description().constraints.is_empty();
    let parts = |y: &[f64]| cyclic_parts(model, t, constrained, y);
    // Each part's size over both states: at the steady motion itself `F = M q̈` and `Φ` are
    // at rounding, against which a cancellation of a cyclic coordinate in value
    // (`cos² φ + sin² φ`) would look like a change.
    let bases: Vec<(&Vec<f64>, Parts)> = [&steady, &near]
        .into_iter()
        .filter_map(|y| Some((y, parts(y)?)))
        .collect();
    let sizes: Vec<f64> = bases.first().map_or_else(Vec::new, |(_, first)| {
        (0..first.len())
            .map(|p| {
                bases
                    .iter()
                    .fold(0.0f64, |m, (_, at)| m.max(at[p].1.amax()))
            })
            .collect()
    });
    // Each moving coordinate alone, for every part but the constraints' residuals Φ; Φ
    // along the motion, every moving coordinate by `shift · q̇ᵢ/max |q̇|` (a belt
    // `phi1 − phi2` between pulleys turning together is kept by that, not by one alone).
    let fastest = moving.iter().fold(0.0f64, |m, &i| m.max(rates[i].abs()));
    let along = [usize::MAX];
    for (base, at_base) in &bases {
        for &i in moving.iter().chain(&along) {
            for shift in CYCLIC_SHIFTS {
                let mut y = (*base).clone();
                if i == usize::MAX {
                    for &j in moving {
                        y[j] += shift * rates[j] / fastest;
                    }
                } else {
                    y[i] += shift;
                }
                let Some(shifted) = parts(&y) else { continue };
                for (p, ((part, a), (_, b))) in at_base.iter().zip(&shifted).enumerate() {
                    if (*part == JOINT_PART) != (i == usize::MAX) {
                        continue;
                    }
                    let scale = sizes[p].max(b.amax());
                    let change = if scale == 0.0 {
                        0.0
                    } else {
                        (a - b).amax() / scale
                    };
                    if change > 1e-9 {
                        let (coordinate, rate) = moved_coordinate(model, rates, moving, fastest, i);
                        return Err(SteadyMotionError::NotCyclic {
                            coordinate,
                            rate,
                            part: (*part).to_string(),
                            change,
                            shift,
                        });
                    }
                }
            }
        }
    }
    Ok(())
}

/// The parts of the equations [`check_cyclic`] compares at the state `y` (length `2n`):
/// `M` and `F`, and when `constrained` the constraints' velocity terms and `γ`, `Φ`
/// ([`JOINT_PART`]) and `J`, each flattened; `None` when one is not finite.
fn cyclic_parts(model: &dyn ModelInfo, t: f64, constrained: bool, y: &[f64]) -> Option<Parts> {
    let (m, f) = model.mass_matrix_and_forcing(t, y);
    let mut out = vec![
        (
            "the mass matrix M",
            DVector::from_column_slice(m.as_slice()),
        ),
        ("the forces F", f),
    ];
    if constrained {
        let c = model.constraint_equations(t, y);
        out.push((
            "the constraints' velocity terms and γ",
            DVector::from_iterator(
                c.velocity.len() + c.gamma.len(),
                c.velocity.iter().chain(c.gamma.iter()).copied(),
            ),
        ));
        // Last: shifted along the motion only (see below).
        out.push((JOINT_PART, c.phi.clone()));
        out.push((
            "the constraint Jacobian J",
            DVector::from_column_slice(c.jacobian.as_slice()),
        ));
    }
    out.iter()
        .all(|(_, v)| v.iter().all(|x| x.is_finite()))
        .then_some(out)
}

/// The name and rate [`SteadyMotionError::NotCyclic`] reports for the coordinate `i` of
/// [`check_cyclic`]: its own name and held rate, or for `i = usize::MAX` (every `moving`
/// coordinate shifted together along the motion) all their names and the `fastest` rate.
fn moved_coordinate(
    model: &dyn ModelInfo,
    rates: &[f64],
    moving: &[usize],
    fastest: f64,
    i: usize,
) -> (String, f64) {
    let names = model.description().coordinate_names();
    let name = |i: usize| {
        names
            .get(i)
            .map_or_else(|| i.to_string(), |c| c.to_string())
    };
    if i == usize::MAX {
        let all: Vec<String> = moving.iter().map(|&j| name(j)).collect();
        (
            format!("{} (together, along the motion)", all.join(", ")),
            fastest,
        )
    } else {
        (name(i), rates[i])
    }
}
