//! The unit tests of `checks.rs`.

use super::*;

/// A check's `at:` guesses are split at the commas between assignments, not inside a
/// function's arguments (`atan2(-1, 0)` was cut in two).
#[test]
fn at_guesses_split_between_assignments_only() {
    let model = (crate::models::find("double_pendulum")
        .expect("bundled")
        .make)();
    let start =
        check_start(model.as_ref(), Some("theta1=atan2(-1, 0),theta2=pi/4")).expect("parses");
    let EquilibriumStart::Guess { q, .. } = start else {
        panic!("{start:?}");
    };
    assert_eq!(
        q,
        [-std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_4]
    );
}
