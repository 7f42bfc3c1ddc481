//! The study itself: the rolling phase to the lift-off, then the flight, with the runs'
//! tally.

use super::flight::flight_phase;
use super::rolling::{centre_accelerations, rolling_phase};
use super::*;

/// Runs the study: the rolling phase of `rolling` to its lift-off with the friction it needs
/// and the Newton–Euler check, then, when `flight` is given, the flight from the lift-off
/// state to the landing with its closed-form checks (see the module documentation).
///
/// The lift-off and landing events are made terminal for the study and restored afterwards.
/// A check that fails does not make an error: [`RollingContact::failed_checks`] lists it.
///
/// # Shapes and units
/// Every state is `[q; q̇]` (`2n` entries) in the model's units (m, rad, s); forces in N.
///
/// # Errors
/// [`RollingContactError`]: options out of range, names the models do not have, a rolling
/// model without constraints or not one body translated by the two coordinates, a flight
/// model with other coordinates, a failed integration, no lift-off within `t_end`, or
/// constraint forces that cannot be computed.
///
/// # Examples
/// ```
/// use eomgen::analysis::rolling_contact::{RollingContactOptions, rolling_contact};
///
/// let mut rolling = (eomgen::models::find("eccentric_cylinder").unwrap().make)();
/// let mut flight = (eomgen::models::find("eccentric_cylinder_flight").unwrap().make)();
/// let options = RollingContactOptions { samples: 401, ..Default::default() };
/// let study = rolling_contact(rolling.as_mut(), Some(flight.as_mut()), &options)?;
/// assert!((study.rolling.lift_off_time - 2.21505).abs() < 1e-5);
/// assert!(study.rolling.mu_diverges);            // F_t ≠ 0 where N = 0
/// assert!(study.failed_checks().is_empty(), "{:?}", study.failed_checks());
/// // Released there, the cylinder presses on the ramp at once: no flight.
/// let release = study.flight.unwrap().release_normal_acceleration;
/// assert!(release < -1.8);
///
/// // A ring-like cylinder on a steeper ramp flies and lands.
/// for model in [&mut rolling, &mut flight] {
///     model.set_parameter("e", 0.2).unwrap();
///     model.set_parameter("IG", 0.6).unwrap();
///     model.set_parameter("gamma", 0.9).unwrap();
/// }
/// let study = rolling_contact(rolling.as_mut(), Some(flight.as_mut()), &options)?;
/// let flight = study.flight.unwrap();
/// assert!(flight.flies && flight.checks.iter().all(|c| c.passed));
/// assert!((flight.flight_time.unwrap() - 0.4953).abs() < 1e-4);
/// # Ok::<(), eomgen::analysis::rolling_contact::RollingContactError>(())
/// ```
pub fn rolling_contact(
    rolling: &mut dyn ModelInfo,
    flight: Option<&mut dyn ModelInfo>,
    options: &RollingContactOptions,
) -> Result<RollingContact, RollingContactError> {
    check_options(options)?;
    if let Some(model) = std::iter::once(&*rolling)
        .chain(flight.as_deref())
        .find(|m| m.description().has_speeds())
    {
        return Err(RollingContactError::InSpeeds {
            model: model.description().name.to_string(),
        });
    }
    let name = rolling.description().name.to_string();
    let ground = coordinate(rolling, "ground", &options.ground)?;
    let normal = coordinate(rolling, "normal", &options.normal)?;
    let angle = coordinate(rolling, "angle", &options.angle)?;
    if rolling.description().constraints.is_empty() {
        return Err(RollingContactError::NoConstraints { model: name });
    }
    let centre = centre_of_mass(rolling)?;
    let was_terminal = event(rolling, &options.lift_off)?;
    if let Some(flight) = &flight {
        let (a, b) = (
            rolling.description().coordinate_names(),
            flight.description().coordinate_names(),
        );
        if a != b {
            return Err(RollingContactError::CoordinatesDiffer {
                rolling: name,
                rolling_coordinates: a.iter().map(|s| s.to_string()).collect(),
                flight: flight.description().name.to_string(),
                flight_coordinates: b.iter().map(|s| s.to_string()).collect(),
            });
        }
        event(&**flight, &options.landing)?;
        centre_of_mass(&**flight)?;
    }

    rolling.set_event_terminal(&options.lift_off, true);
    let mut thresholds = Thresholds {
        mu: &options.thresholds,
        ground,
        normal,
    };
    let phase = run_phase(
        rolling,
        None,
        &options.lift_off,
        None,
        options,
        Some(&mut thresholds),
    );
    let accelerations = match &phase {
        Ok((samples, Some(_), _)) => Some(centre_accelerations(rolling, samples, centre, options)),
        _ => None,
    };
    rolling.set_event_terminal(&options.lift_off, was_terminal);
    let (samples, end, events) = phase?;
    let (Some(end), Some(accelerations)) = (end, accelerations) else {
        return Err(RollingContactError::NoLiftOff {
            model: name,
            event: options.lift_off.clone(),
            t_end: options.t_end,
        });
    };
    let rolling_phase = rolling_phase(
        rolling,
        &samples,
        &end,
        &events,
        &accelerations?,
        [ground, normal],
        options,
    )?;
    let flight_phase = match flight {
        Some(flight) => Some(flight_phase(
            flight,
            rolling,
            &rolling_phase,
            angle,
            normal,
            options,
        )?),
        None => None,
    };
    Ok(RollingContact {
        rolling: rolling_phase,
        flight: flight_phase,
    })
}
