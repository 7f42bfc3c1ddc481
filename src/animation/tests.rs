//! The animation's scene and frame times: a model that cannot be drawn, and the frames' times.

use super::*;

mod undrawn {
    eomgen::model!("../../tests/fixtures/undrawn_pendulum.yaml");
}
mod energy_form {
    eomgen::model!("../../symbolic/tests/fixtures/damped_oscillator.yaml");
}

/// A model with points but no `draw:` block: an error that says what to add, naming the
/// model's points.
#[test]
fn a_model_without_draw_gets_an_error_naming_what_to_add() {
    let model = eomgen_runtime::FirstOrder::new(undrawn::UndrawnPendulum::default());
    let e = Scene::of(&model, &[]).expect_err("no draw: block");
    assert!(matches!(e, AnimationError::NothingToDraw { .. }), "{e:?}");
    let message = e.to_string();
    assert!(message.contains("has no `draw:` block"), "{message}");
    assert!(message.contains("draw: { lines: [[O, P]]"), "{message}");
    // Tracing a point is enough to animate it; a misspelt point is an error.
    let scene = Scene::of(&model, &["P".to_string()]).expect("traced point");
    assert_eq!(scene.names, ["P"]);
    let e = Scene::of(&model, &["Q".to_string()]).expect_err("no such point");
    assert!(
        e.to_string().contains("has no point `Q` (points: O, P)"),
        "{e}"
    );
    // ... also before the simulation.
    let options = AnimationOptions {
        trace: vec![" Q".to_string()],
        ..AnimationOptions::default()
    };
    let e = frame_times(&model, 1.0, &options).expect_err("no such point");
    assert_eq!(
        e.to_string(),
        "--trace  Q: `undrawn_pendulum` has no point `Q` (points: O, P)"
    );
}

/// An energy-form model has no points at all.
#[test]
fn a_model_without_points_gets_an_error() {
    let model = eomgen_runtime::FirstOrder::new(energy_form::DampedOscillator::default());
    let e = Scene::of(&model, &[]).expect_err("no points");
    assert!(e.to_string().contains("has no points"), "{e}");
}

/// Frames at `k / fps` up to `t_end`, a rounding below a frame time keeping it; with a
/// traced point four samples per frame; `fps` and the frame count checked.
#[test]
fn frame_times_are_checked_and_uniform() {
    let model = eomgen_runtime::FirstOrder::new(undrawn::UndrawnPendulum::default());
    let traced = AnimationOptions {
        fps: 10.0,
        trace: vec!["P".to_string()],
    };
    let times = frame_times(&model, 1.0 - 1e-15, &traced).expect("times");
    assert_eq!(times.len(), 41);
    assert_eq!(times[4], 0.1);
    assert_eq!(times[40], 1.0 - 1e-15);
    assert_eq!(traced.frame_count(0.95), Ok(10));
    let bad = AnimationOptions {
        fps: 0.0,
        ..AnimationOptions::default()
    };
    assert_eq!(
        bad.frame_count(1.0).unwrap_err().to_string(),
        "--fps must be a positive number of frames per second, got 0"
    );
    assert_eq!(
        AnimationOptions::default()
            .frame_count(1e4)
            .unwrap_err()
            .to_string(),
        "--t-end 10000 at --fps 30 gives more than 100000 frames; lower --fps"
    );
}

#[test]
fn grid_steps_are_round() {
    assert_eq!(grid_step(6.0), 0.5);
    assert_eq!(grid_step(1.2), 0.1);
    assert_eq!(grid_step(30.0), 2.0);
}
