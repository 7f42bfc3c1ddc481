//! The study's steps: the options checked, the model linearised at its equilibrium, the forcing
//! sampled on the grid, Duhamel's integral with Richardson's estimate, and the direct
//! integration and the closed form it is compared with.

use super::*;

/// The response of the model linearised at an equilibrium to the forcing `b f(t)` through one
/// input, from rest, by Duhamel's integral over the impulse response `h = e^{At}[0; M⁻¹b]`,
/// checked against DOP853 on the same linear equations and, for one degree of freedom with an
/// impulse or a step, against the closed form (see the [module](super) docs).
///
/// The model's parameter values are restored before returning.
///
/// # Shapes
/// See [`ConvolutionStudy`].
///
/// # Units
/// Times in s; `δq` in the coordinates' units per unit of the input (times s for the impulse).
///
/// # Errors
/// [`ConvolutionError::NoInput`], [`ConvolutionError::UnknownInput`],
/// [`ConvolutionError::Input`] (not a load amplitude), [`ConvolutionError::InputEntersThroughRate`],
/// [`ConvolutionError::OperatingPoint`], [`ConvolutionError::Linearization`],
/// [`ConvolutionError::InvalidOption`] (`t_end`, `intervals`, `rtol`),
/// [`ConvolutionError::NoDuration`], [`ConvolutionError::NonFiniteForcing`],
/// [`ConvolutionError::NotFinite`], [`ConvolutionError::Integration`].
///
/// # Examples
/// The step response of the forced oscillator (`m = k = c = 1`) tends to `b/k = 1`; at
/// Δ = 0.025 s Simpson's rule is within 1e-8 of the closed form.
/// ```
/// use eomgen_runtime::analysis::vibration::{ConvolutionOptions, Forcing, convolution_response};
/// let mut model = (eomgen::models::find("forced_oscillator").unwrap().make)();
/// let options = ConvolutionOptions {
///     input: "A".to_string(),
///     forcing: Forcing::Step,
///     t_end: Some(30.0),
///     intervals: 1200,
///     ..ConvolutionOptions::default()
/// };
/// let study = convolution_response(model.as_mut(), &options)?;
/// assert!((study.convolution.last().unwrap()[0] - 1.0).abs() < 1e-6);
/// assert!(study.closed_form.unwrap().max_difference < 1e-8);
/// # Ok::<(), eomgen_runtime::analysis::vibration::ConvolutionError>(())
/// ```
///
/// # References
/// Lecture 21 (the response to a delta function, a Heaviside function and an arbitrary
/// function by convolution); D. J. Inman, *Engineering Vibration*, chapter 3 (the impulse
/// response function and the convolution integral).
pub fn convolution_response(
    model: &mut dyn ModelInfo,
    options: &ConvolutionOptions<'_>,
) -> Result<ConvolutionStudy, ConvolutionError> {
    let input = options.input.as_str();
    let kind = check_options(model, options)?;
    let (label, guess) = options.operating_point.start.resolve_equilibrium(model)?;
    let forced = linearize_forced(model, &guess, input, &kind)?;
    let lin = &forced.linearization;
    let modes = normal_modes(lin).map_err(|e| ConvolutionError::Linearization(e.into()))?;
    let damping = modal_damping(lin, &modes);
    let t_end = duration(model, options, &modes.natural_frequencies, &label)?;
    let grid = Grid::new(t_end, options.intervals);
    let n = lin.mass_matrix.nrows();
    let a = lin
        .state_matrix()
        .map_err(|e| ConvolutionError::Linearization(e.into()))?;
    let z0 = forced
        .state_input_matrix()
        .map_err(ConvolutionError::Linearization)?
        .column(0)
        .into_owned();
    let impulse_response = impulse_response(&a, &z0, grid.step, grid.intervals, n, &grid.times)?;
    let forcing_values = sample_forcing(&options.forcing, &grid)?;
    let Convolution {
        values: convolution,
        error_estimate,
        observed_order,
    } = convolve(
        &options.forcing,
        &grid,
        (&a, &z0, n),
        &impulse_response,
        &forcing_values,
    )?;
    let direct = check_direct(&a, &z0, options, &grid.times, &convolution, error_estimate)?;
    let closed_form = compare_closed_form(
        lin,
        &forced.input_matrix,
        &options.forcing,
        &grid.times,
        &convolution,
    );
    let operating_point = OperatingPoint {
        name: label,
        coordinates: kind.coordinates,
        guess,
        t: 0.0,
        equilibrium: forced.equilibrium.clone(),
    };
    Ok(ConvolutionStudy {
        operating_point,
        input: input.to_string(),
        forcing: options.forcing.label(),
        natural_frequencies: modes.natural_frequencies.clone(),
        damping_ratios: damping.damping_ratios.clone(),
        forced,
        times: grid.times,
        impulse_response,
        convolution,
        direct: direct.values,
        max_difference: direct.max_difference,
        max_response: direct.max_response,
        quadrature: Quadrature {
            rule: "composite Simpson (3/8 rule on the last three intervals at odd points, a midpoint on the first)",
            order: 4,
            step: grid.step,
            error_estimate,
            observed_order,
        },
        closed_form,
        direct_rtol: options.rtol,
        direct_steps: direct.steps,
        direct_rhs_evals: direct.rhs_evals,
    })
}

/// What [`check_options`] learnt of the input.
struct InputKind {
    /// Whether the input is a parameter (a load amplitude) rather than a coordinate.
    parameter: bool,
    /// Whether the model has a parameter `w` that is not the input: a base motion read with
    /// it would enter through its rate too.
    has_w: bool,
    /// The model's coordinates, in order.
    coordinates: Vec<String>,
}

/// Refuses what [`convolution_response`] cannot take before any work: no input
/// ([`ConvolutionError::NoInput`]), an input that is neither a parameter nor a coordinate
/// ([`ConvolutionError::UnknownInput`]), and `t_end`, `intervals` or `rtol` out of range
/// ([`ConvolutionError::InvalidOption`]), in that order. Returns whether the input is a
/// parameter, whether a parameter `w` other than it exists, and the coordinates' names.
fn check_options(
    model: &dyn ModelInfo,
    options: &ConvolutionOptions<'_>,
) -> Result<InputKind, ConvolutionError> {
    let input = options.input.as_str();
    if input.trim().is_empty() {
        return Err(ConvolutionError::NoInput);
    }
    let description = model.description();
    let parameters = description.parameter_names();
    let coordinates: Vec<String> = description
        .coordinate_names()
        .iter()
        .map(|c| c.to_string())
        .collect();
    let parameter_input = parameters.contains(&input);
    if !parameter_input && !coordinates.iter().any(|c| c == input) {
        return Err(ConvolutionError::UnknownInput {
            model: description.name.to_string(),
            input: input.to_string(),
            parameters: parameters.join(", "),
            coordinates: coordinates.join(", "),
        });
    }
    if let Some(t_end) = options.t_end
        && !(t_end.is_finite() && t_end > 0.0)
    {
        return Err(invalid("t_end", t_end, "finite and > 0"));
    }
    if options.intervals < 4 {
        return Err(invalid("intervals", options.intervals as f64, "≥ 4"));
    }
    if !(options.rtol > 0.0 && options.rtol < 1.0) {
        return Err(invalid("rtol", options.rtol, "in (0, 1)"));
    }
    Ok(InputKind {
        parameter: parameter_input,
        has_w: parameters.contains(&"w") && input != "w",
        coordinates,
    })
}

/// `M`, `C`, `K` and the input column `b` at the equilibrium found from `guess` (`n`
/// coordinates), with the parameter values restored. An input that is not a load amplitude
/// is [`ConvolutionError::Input`], one that also enters through its rate
/// [`ConvolutionError::InputEntersThroughRate`] (the convolution takes a load `b f(t)`, not
/// `B₀ f + B₁ ḟ`); any other failure is [`ConvolutionError::Linearization`].
fn linearize_forced(
    model: &mut dyn ModelInfo,
    guess: &[f64],
    input: &str,
    kind: &InputKind,
) -> Result<ForcedLinearization, ConvolutionError> {
    // A base motion read with `w` would enter through its rate too: refused, not dropped.
    let forced = if kind.parameter && kind.has_w {
        linearize_with_input_rates(model, guess, &[input], "w")
    } else {
        linearize_with_inputs(model, guess, &[input])
    }
    .map_err(|e| match e {
        FrfError::NonlinearInput { .. }
        | FrfError::InputNotInForcing { .. }
        | FrfError::InputChangesMassMatrix { .. }
        | FrfError::UnknownParameter(_)
        | FrfError::InputRateNotConstant { .. } => ConvolutionError::Input(e),
        e => ConvolutionError::Linearization(e),
    })?;
    if forced.has_input_rates() {
        return Err(ConvolutionError::InputEntersThroughRate {
            input: input.to_string(),
        });
    }
    Ok(forced)
}

/// The end time (s): [`ConvolutionOptions::t_end`], or ten periods `10 · 2π/ω` of the lowest
/// positive natural frequency `ω` (rad/s, from the ascending `natural_frequencies`); without
/// one, [`ConvolutionError::NoDuration`] (naming the model and the `operating_point`).
fn duration(
    model: &dyn ModelInfo,
    options: &ConvolutionOptions<'_>,
    natural_frequencies: &[f64],
    operating_point: &str,
) -> Result<f64, ConvolutionError> {
    Ok(match options.t_end {
        Some(t) => t,
        None => {
            let lowest = natural_frequencies
                .iter()
                .copied()
                .find(|w| *w > 0.0)
                .ok_or_else(|| ConvolutionError::NoDuration {
                    model: model.description().name.to_string(),
                    operating_point: operating_point.to_string(),
                })?;
            10.0 * std::f64::consts::TAU / lowest
        }
    })
}

/// The grid `t_k = kΔ`, `k = 0..=N`, on `[0, t_end]`.
struct Grid {
    /// `N`, the number of intervals.
    intervals: usize,
    /// `Δ = t_end/N` (s).
    step: f64,
    /// `t_k` (s), `N + 1` of them.
    times: Vec<f64>,
}

impl Grid {
    /// `intervals` intervals of `Δ = t_end/intervals` (s); the last time is `t_end` itself,
    /// not `N Δ` (one rounding off it).
    fn new(t_end: f64, intervals: usize) -> Self {
        let step = t_end / intervals as f64;
        let times: Vec<f64> = (0..=intervals)
            .map(|k| {
                if k == intervals {
                    t_end
                } else {
                    k as f64 * step
                }
            })
            .collect();
        Self {
            intervals,
            step,
            times,
        }
    }
}

/// The forcing sampled on the grid (`N + 1` values, units of the input; empty for the
/// impulse, which needs no quadrature), each interior value the mean of two samples either
/// side of its grid point; a function is then checked to be resolved by the grid
/// ([`check_resolution`]).
///
/// # Errors
/// [`ConvolutionError::NonFiniteForcing`], [`ConvolutionError::ForcingUnresolved`].
fn sample_forcing(forcing: &Forcing<'_>, grid: &Grid) -> Result<Vec<f64>, ConvolutionError> {
    let (times, step) = (&grid.times, grid.step);
    // At an interior grid point the forcing is the mean of its values a hair (1e-7 Δ) before
    // and after: the same as f(t) for a smooth f (to `(1e-7 Δ)² f''`), and the mean of the
    // one-sided limits at a jump on the grid (`step(t - 1)`), which keeps Simpson's rule
    // second order there instead of first.
    let hair = 1e-7 * step;
    let forcing_values: Vec<f64> = match *forcing {
        Forcing::Impulse => Vec::new(),
        forcing => times
            .iter()
            .enumerate()
            .map(|(k, &t)| {
                let samples = if k == 0 { [t, t] } else { [t - hair, t + hair] };
                let mut sum = 0.0;
                for t in samples {
                    let value = forcing.value(t);
                    if !value.is_finite() {
                        return Err(ConvolutionError::NonFiniteForcing { t, value });
                    }
                    sum += value;
                }
                Ok(sum / 2.0)
            })
            .collect::<Result<_, _>>()?,
    };
    if let Forcing::Function { .. } = forcing {
        check_resolution(forcing, times, &forcing_values, step)?;
    }
    Ok(forcing_values)
}

/// Duhamel's integral on the grid and Richardson's estimate of its error.
struct Convolution {
    /// `δq(t_k)` (`N + 1` vectors of `n`; m or rad).
    values: Vec<Vec<f64>>,
    /// [`Quadrature::error_estimate`].
    error_estimate: f64,
    /// [`Quadrature::observed_order`].
    observed_order: Option<f64>,
}

/// `δq(t_k) = ∫₀^{t_k} h(t_k − τ) f(τ) dτ` from the impulse response `impulse_response`
/// (`N + 1` vectors of `n`) and the sampled forcing `forcing_values` ([`duhamel`] on the grid
/// `Δ`, with the midpoint `h(Δ/2) = (e^{AΔ/2} z0)[..n]` on the first interval), and its error
/// estimate from the same rule on `2Δ` and `4Δ`; for the impulse, `h` itself and no error.
/// `(a, z0, n)` are `A` (`2n × 2n`), `[0; M⁻¹b]` and `n`.
///
/// # Errors
/// [`ConvolutionError::NonFiniteForcing`] at `Δ/2`, [`ConvolutionError::NotFinite`] where the
/// convolution overflows.
fn convolve(
    forcing: &Forcing<'_>,
    grid: &Grid,
    (a, z0, n): (&DMatrix<f64>, &DVector<f64>, usize),
    impulse_response: &[Vec<f64>],
    forcing_values: &[f64],
) -> Result<Convolution, ConvolutionError> {
    let (step, intervals) = (grid.step, grid.intervals);
    let (convolution, error_estimate, observed_order) = match forcing {
        Forcing::Impulse => (impulse_response.to_vec(), 0.0, None),
        _ => {
            // The midpoint of the first interval, for its Simpson rule.
            let half = step / 2.0;
            let h_half = (matrix_exponential(&(a * half)) * z0).as_slice()[..n].to_vec();
            let f_half = forcing.value(half);
            if !f_half.is_finite() {
                return Err(ConvolutionError::NonFiniteForcing {
                    t: half,
                    value: f_half,
                });
            }
            let fine = duhamel(impulse_response, forcing_values, step, (&h_half, f_half));
            // The same rule on every other point (its first midpoint is the first grid point)
            // and on every fourth: the error estimate and the observed order.
            let every = |k: usize| {
                let h: Vec<Vec<f64>> = impulse_response.iter().step_by(k).cloned().collect();
                let f: Vec<f64> = forcing_values.iter().step_by(k).copied().collect();
                let mid = k / 2;
                duhamel(
                    &h,
                    &f,
                    k as f64 * step,
                    (&impulse_response[mid], forcing_values[mid]),
                )
            };
            let coarse = every(2);
            // `max |a_{k i} − b_i|` over the common points of two grids, `k` apart.
            let difference = |a: &[Vec<f64>], b: &[Vec<f64>], k: usize| {
                a.iter()
                    .step_by(k)
                    .zip(b)
                    .flat_map(|(x, y)| x.iter().zip(y).map(|(u, v)| (u - v).abs()))
                    .fold(0.0f64, f64::max)
            };
            let fine_coarse = difference(&fine, &coarse, 2);
            // The order seen between Δ, 2Δ and 4Δ, within [1, 4]: a forcing with a jump after
            // t = 0 (`step(t - 1)`) makes Simpson's rule first order, and the estimate says so.
            let observed_order = (intervals >= 8).then(|| {
                let coarsest = every(4);
                let ratio = difference(&coarse, &coarsest, 2) / fine_coarse;
                if ratio.is_finite() && ratio > 0.0 {
                    ratio.log2().clamp(1.0, 4.0)
                } else {
                    4.0
                }
            });
            let order = observed_order.unwrap_or(4.0);
            (fine, fine_coarse / (order.exp2() - 1.0), observed_order)
        }
    };
    if let Some(k) = convolution
        .iter()
        .position(|x| !x.iter().all(|v| v.is_finite()))
    {
        return Err(ConvolutionError::NotFinite {
            what: "convolution",
            t: grid.times[k],
        });
    }
    Ok(Convolution {
        values: convolution,
        error_estimate,
        observed_order,
    })
}

/// The DOP853 check of the convolution and how far the two lie apart.
struct Direct {
    /// `δq(t_k)` by DOP853 (`N + 1` vectors of `n`; m or rad).
    values: Vec<Vec<f64>>,
    /// `max |convolution|` (m or rad).
    max_response: f64,
    /// `max |convolution − direct|` (m or rad).
    max_difference: f64,
    /// DOP853's accepted steps.
    steps: usize,
    /// DOP853's right-hand-side evaluations.
    rhs_evals: usize,
}

/// DOP853 on the same linear equations ([`direct_response`], `A` and `z0 = [0; M⁻¹b]`, at
/// [`ConvolutionOptions::rtol`] and an absolute tolerance scaled by the largest `|δq|` of the
/// `convolution`) at `times`, compared with the convolution; refused
/// ([`ConvolutionError::Disagreement`]) when they differ by more than both the quadrature's
/// `error_estimate` and the check's tolerance allow, and by more than [`DISAGREEMENT_FLOOR`]
/// of the response.
///
/// # Errors
/// [`ConvolutionError::Integration`], [`ConvolutionError::Disagreement`].
fn check_direct(
    a: &DMatrix<f64>,
    z0: &DVector<f64>,
    options: &ConvolutionOptions<'_>,
    times: &[f64],
    convolution: &[Vec<f64>],
    error_estimate: f64,
) -> Result<Direct, ConvolutionError> {
    let max_response = convolution
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let (direct, direct_steps, direct_rhs_evals) =
        direct_response(a, z0, &options.forcing, times, options.rtol, max_response)?;
    let max_difference = convolution
        .iter()
        .flatten()
        .zip(direct.iter().flatten())
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    let scale = direct
        .iter()
        .flatten()
        .fold(max_response, |m, v| m.max(v.abs()));
    if max_difference > ESTIMATE_SLACK * error_estimate + CHECK_SLACK * options.rtol * scale
        && max_difference > DISAGREEMENT_FLOOR * scale
    {
        return Err(ConvolutionError::Disagreement {
            max_difference,
            scale,
            error_estimate,
        });
    }
    Ok(Direct {
        values: direct,
        max_response,
        max_difference,
        steps: direct_steps,
        rhs_evals: direct_rhs_evals,
    })
}

/// The closed form ([`closed_form`]) on the grid `times` and its largest difference from the
/// first coordinate of the `convolution` (m or rad); `None` where there is no closed form
/// (more than one degree of freedom, a general function, or not `m > 0`, `c ≥ 0`, `k > 0`).
fn compare_closed_form(
    lin: &Linearization,
    input_matrix: &DMatrix<f64>,
    forcing: &Forcing<'_>,
    times: &[f64],
    convolution: &[Vec<f64>],
) -> Option<ClosedForm> {
    closed_form(lin, input_matrix, forcing, times).map(
        |(formula, natural_frequency, damping_ratio, values)| {
            let max_difference = values
                .iter()
                .zip(convolution)
                .fold(0.0f64, |m, (v, x)| m.max((v - x[0]).abs()));
            ClosedForm {
                formula,
                natural_frequency,
                damping_ratio,
                values,
                max_difference,
            }
        },
    )
}
