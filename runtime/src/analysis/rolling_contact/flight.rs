//! The flight after the contact force reaches zero: the run in the free model from the
//! released state, its landing, and its checks against the rolling phase (momentum, energy and
//! the centre of mass's parabola).

use super::*;

/// The flight's start and what it follows, shared by the steps of [`flight_phase`].
struct Launch {
    /// The lift-off state `[q; q̇]` (`2n`), the flight's initial state.
    y0: Vec<f64>,
    /// The lift-off time (s), on the rolling phase's clock; the flight's own starts at 0.
    t0: f64,
    /// `n`, the number of coordinates.
    n: usize,
    /// The point index of the centre of mass G.
    centre: usize,
    /// The index of the angle coordinate.
    angle: usize,
    /// The index of the normal coordinate.
    normal: usize,
    /// Gravity along the ground and the normal (m/s²).
    gravity: [f64; 2],
}

/// The flight phase from the rolling phase's lift-off state: the energy jump across the join,
/// the normal acceleration at the release ([`release_acceleration`]) and, unless the body
/// presses on the ground at once, the flight to the landing ([`fly`]) with its closed-form
/// checks ([`follow_flight`]): the energy over both phases, the parabola of G and the constant
/// spin.
pub(super) fn flight_phase(
    flight: &mut dyn ModelInfo,
    rolling: &dyn ModelInfo,
    rolling_phase: &RollingPhase,
    angle: usize,
    normal: usize,
    options: &RollingContactOptions,
) -> Result<FlightPhase, RollingContactError> {
    let name = flight.description().name.to_string();
    let n = flight.num_dofs();
    let centre = centre_of_mass(flight)?;
    let ground = coordinate(flight, "ground", &options.ground)?;
    let y0 = rolling_phase.lift_off_state.clone();
    let t0 = rolling_phase.lift_off_time;
    let (_, gravity) = mass_and_gravity(flight, &y0, ground, normal, options)?;
    let energy_rolling = rolling.energy(t0, &y0);
    let energy_jump = flight.energy(0.0, &y0) - energy_rolling;
    let launch = Launch {
        y0,
        t0,
        n,
        centre,
        angle,
        normal,
        gravity,
    };
    let release_normal_acceleration = release_acceleration(flight, &name, &launch)?;
    let g_scale = gravity[0].hypot(gravity[1]).max(1e-300);
    let re_enters = release_normal_acceleration < -RISEN * g_scale;

    // The energy of the rolling phase, to which the flight's is joined.
    let energies = rolling_energies(rolling, rolling_phase);
    let tolerance = options.flight_tolerance;
    let mut phase = FlightPhase {
        model: name.clone(),
        release_normal_acceleration,
        flies: false,
        samples: Vec::new(),
        landing_time: None,
        landing_state: None,
        flight_time: None,
        max_height: 0.0,
        landing_normal_velocity: None,
        skipped_touches: 0,
        energy_jump,
        checks: Vec::new(),
    };
    if re_enters {
        // No flight: the body presses on the ground at once (it would keep contact and
        // slide); nothing to integrate.
        let scale = energies.iter().fold(0.0_f64, |m, v| m.max(v.1)).max(1e-300);
        phase.checks = vec![flight_check(
            "energy jump at the lift-off",
            energy_jump.abs() / scale,
            tolerance,
        )];
        return Ok(phase);
    }

    let Flown {
        samples,
        end,
        flies,
        skipped_touches,
    } = fly(flight, &launch, options)?;
    phase.flies = flies;
    phase.skipped_touches = skipped_touches;
    let track = follow_flight(flight, &launch, &samples);
    phase.samples = track.samples;
    phase.max_height = track.max_height;
    phase.checks = flight_checks(
        flight,
        &samples,
        energies,
        energy_jump,
        &track.deviations,
        tolerance,
    );
    if let Some(bad) = phase.checks.iter().find(|c| !c.value.is_finite()) {
        return Err(RollingContactError::NonFinite {
            model: name,
            what: bad.name,
            value: bad.value,
        });
    }
    phase.landing_time = end.as_ref().map(|e| t0 + e.t);
    phase.landing_state = end.as_ref().map(|e| e.y.clone());
    phase.flight_time = end.as_ref().map(|e| e.t);
    phase.landing_normal_velocity = end.as_ref().map(|e| e.y[n + normal]);
    Ok(phase)
}

/// A check of the flight: `value` (relative) against `tolerance`.
fn flight_check(name: &'static str, value: f64, tolerance: f64) -> FlightCheck {
    FlightCheck {
        name,
        value,
        tolerance,
        passed: value <= tolerance,
    }
}

/// The flight's checks against its closed forms, each relative and against `tolerance`: the
/// energy jump `energy_jump` (J) at the lift-off and the drift of `T + V` over both phases
/// (the rolling phase's `energies`, `(T + V, T + |V|)` pairs in J, followed by the flight's
/// at its `samples` `(τ, [q; q̇])`), both relative to the largest `T + |V|`; G's distance from
/// the parabola relative to max(1 m, its largest displacement); and the change of the spin
/// relative to max(1, |θ̇(0)|).
fn flight_checks(
    flight: &dyn ModelInfo,
    samples: &[(f64, Vec<f64>)],
    mut energies: Vec<(f64, f64)>,
    energy_jump: f64,
    deviations: &Deviations,
    tolerance: f64,
) -> Vec<FlightCheck> {
    let check = |name: &'static str, value: f64| flight_check(name, value, tolerance);
    energies.extend(samples.iter().map(|(tau, y)| {
        let (k, v) = (
            flight.kinetic_energy(*tau, y),
            flight.potential_energy(*tau, y),
        );
        (k + v, k + v.abs())
    }));
    let scale = energies.iter().fold(0.0_f64, |m, v| m.max(v.1)).max(1e-300);
    vec![
        check("energy jump at the lift-off", energy_jump.abs() / scale),
        check("energy drift over both phases", drift(&energies)),
        check(
            "centre of mass off the parabola",
            deviations.parabola_error / deviations.displacement.max(1.0),
        ),
        check(
            "angular velocity change",
            deviations.spin_error / deviations.spin0.abs().max(1.0),
        ),
    ]
}

/// The normal coordinate's acceleration (m/s²) of the flight model `name` at the lift-off
/// state: `q̈` from its right-hand side at `t = 0`. A right-hand side that fails is
/// [`RollingContactError::ConstraintForces`] at the lift-off time, one that is not finite
/// [`RollingContactError::NonFinite`].
fn release_acceleration(
    flight: &mut dyn ModelInfo,
    name: &str,
    launch: &Launch,
) -> Result<f64, RollingContactError> {
    let (n, normal) = (launch.n, launch.normal);
    // Released with no contact force, the normal coordinate's acceleration jumps from the
    // rolling value 0 to this: the friction force, which Coulomb's law cannot supply at
    // N = 0, is gone with the normal force.
    let mut dy = vec![0.0; 2 * n];
    flight
        .as_ode_mut()
        .rhs(0.0, &launch.y0, &mut dy)
        .map_err(|source| RollingContactError::ConstraintForces {
            model: name.to_string(),
            t: launch.t0,
            source,
        })?;
    let release_normal_acceleration = dy[n + normal];
    if !release_normal_acceleration.is_finite() {
        return Err(RollingContactError::NonFinite {
            model: name.to_string(),
            what: "acceleration at the release",
            value: release_normal_acceleration,
        });
    }
    Ok(release_normal_acceleration)
}

/// `(T + V, T + |V|)` (J) of the rolling model at each sample of its phase, for the drift
/// of the energy over both phases.
fn rolling_energies(rolling: &dyn ModelInfo, rolling_phase: &RollingPhase) -> Vec<(f64, f64)> {
    rolling_phase
        .samples
        .iter()
        .map(|s| {
            let y: Vec<f64> = s.q.iter().chain(&s.qdot).copied().collect();
            let (k, v) = (
                rolling.kinetic_energy(s.t, &y),
                rolling.potential_energy(s.t, &y),
            );
            (k + v, k + v.abs())
        })
        .collect()
}

/// The flight integrated: its samples `(τ, [q; q̇])` on the flight's clock, and what the run
/// saw of the landing.
struct Flown {
    /// Uniform samples up to the landing (or the longest phase), the last the landing state.
    samples: Vec<(f64, Vec<f64>)>,
    /// The landing event, `None` if the body had not come down.
    end: Option<Event>,
    /// Whether the body rose by [`RISEN`].
    flies: bool,
    /// Zeros of the landing event before the rise.
    skipped_touches: usize,
}

/// The flight from the lift-off state to the first zero of the landing event after the body
/// has risen by [`RISEN`] ([`run_phase`] with the [`Risen`] event), the landing event made
/// non-terminal for the run and restored after it (also when the run fails).
fn fly(
    flight: &mut dyn ModelInfo,
    launch: &Launch,
    options: &RollingContactOptions,
) -> Result<Flown, RollingContactError> {
    let (y0, normal) = (&launch.y0, launch.normal);
    // The gap grows as a_n τ²/2 (or as τ³ when a_n = 0) from the lift-off, so the landing
    // function starts at zero to rounding and may cross it at once: zeros before the body
    // has risen above its lift-off height by RISEN (relative) are skipped.
    let was_terminal = event(flight, &options.landing)?;
    flight.set_event_terminal(&options.landing, false);
    let mut risen = Risen {
        normal,
        level: y0[normal] + RISEN * y0[normal].abs().max(1.0),
    };
    let run = run_phase(
        flight,
        Some(y0.clone()),
        &options.landing,
        Some(RISEN_EVENT),
        options,
        Some(&mut risen),
    );
    flight.set_event_terminal(&options.landing, was_terminal);
    let (samples, end, events) = run?;
    let rise = events.iter().find(|e| e.name == RISEN_EVENT).map(|e| e.t);
    let skipped_touches = events
        .iter()
        .filter(|e| e.name == options.landing && rise.is_none_or(|r| e.t < r))
        .count();
    Ok(Flown {
        samples,
        end,
        flies: rise.is_some(),
        skipped_touches,
    })
}

/// The flight's samples for the report and how far they stray from the closed forms.
struct FlightTrack {
    /// One per sample, on the rolling phase's clock.
    samples: Vec<FlightSample>,
    /// The largest rise of the normal coordinate above its lift-off value (m).
    max_height: f64,
    /// How far G and the spin strayed.
    deviations: Deviations,
}

/// How far the flight strays from its closed forms.
struct Deviations {
    /// The largest distance of G from the parabola along either axis (m).
    parabola_error: f64,
    /// The largest displacement of G from its lift-off position along either axis (m).
    displacement: f64,
    /// The largest change of the angle's rate (rad/s).
    spin_error: f64,
    /// The angle's rate at the lift-off (rad/s).
    spin0: f64,
}

/// G (the point `launch.centre`) at each flight sample `(τ, [q; q̇])` against the parabola
/// `r_G(0) + v_G(0) τ + g τ²/2`, the angle's rate against its value at the lift-off, and the
/// samples for the report (times shifted by the lift-off time).
fn follow_flight(
    flight: &dyn ModelInfo,
    launch: &Launch,
    samples: &[(f64, Vec<f64>)],
) -> FlightTrack {
    let Launch {
        ref y0,
        t0,
        n,
        centre,
        angle,
        normal,
        gravity,
    } = *launch;
    let r0 = flight.point_positions(0.0, y0)[centre];
    let v0 = point_velocity(flight, y0, centre);
    let spin0 = y0[n + angle];
    let (mut parabola_error, mut displacement, mut spin_error) = (0.0_f64, 0.0_f64, 0.0_f64);
    let (mut max_height, mut out) = (0.0_f64, Vec::new());
    for (tau, y) in samples {
        let r = flight.point_positions(*tau, y)[centre];
        let closed = [
            r0[0] + v0[0] * tau + gravity[0] * tau * tau / 2.0,
            r0[1] + v0[1] * tau + gravity[1] * tau * tau / 2.0,
        ];
        parabola_error = parabola_error
            .max((r[0] - closed[0]).abs())
            .max((r[1] - closed[1]).abs());
        displacement = displacement
            .max((r[0] - r0[0]).abs())
            .max((r[1] - r0[1]).abs());
        spin_error = spin_error.max((y[n + angle] - spin0).abs());
        max_height = max_height.max(y[normal] - y0[normal]);
        out.push(FlightSample {
            t: t0 + tau,
            q: y[..n].to_vec(),
            qdot: y[n..2 * n].to_vec(),
            energy: flight.energy(*tau, y),
            centre_of_mass: [r[0], r[1]],
            parabola: closed,
        });
    }
    FlightTrack {
        samples: out,
        max_height,
        deviations: Deviations {
            parabola_error,
            displacement,
            spin_error,
            spin0,
        },
    }
}
