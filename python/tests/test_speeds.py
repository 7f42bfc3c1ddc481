"""A model in generalized speeds from Python (``speeds:``; Kane & Levinson 1985, §2.12): its
state is ``[q; u]``, named by ``state_names``; it moves as the same body in the angles'
rates, and its modes are the same. The equations and their linearisation are tested in
Rust (``tests/speeds.rs``); this test is about the binding."""

import pathlib

import numpy as np
import pytest

import eomgen

_FIXTURES = pathlib.Path(__file__).resolve().parents[2] / "tests" / "fixtures"


def test_a_free_body_in_body_rates_moves_as_in_the_angles_rates():
    body = eomgen.load(str(_FIXTURES / "free_rigid_body_speeds.yaml"))
    assert body.speeds == ["w1", "w2", "w3"]
    assert body.state_names == ["phi", "theta", "psi", "w1", "w2", "w3"]
    assert eomgen.load("free_rigid_body").speeds == []
    run = body.simulate(t_end=2.0, t_out=[2.0], rtol=1e-12, atol=1e-14)
    reference = eomgen.load("free_rigid_body").simulate(t_end=2.0, t_out=[2.0], rtol=1e-12, atol=1e-14)
    # The angles agree to the integration error (about 1e-11 at these tolerances).
    assert np.max(np.abs(run.q[-1] - reference.q[-1])) < 1e-9
    # The second half is the speeds: the body-fixed w3 of Euler's equations, not psi_dot.
    y0 = body.initial_state({"w3": 2.0})
    assert y0[5] == 2.0
    with pytest.raises(ValueError, match="speeds: w1, w2, w3"):
        body.initial_state({"phi_dot": 1.0})


def test_a_body_on_a_ball_joint_in_speeds_has_the_closed_form_modes():
    hanging = eomgen.load(str(_FIXTURES / "hanging_body_speeds.yaml"))
    modes = hanging.modes("hanging")
    m, g, l, k = 2.0, 9.81, 0.5, 3.0
    expected = np.sqrt([m * g * l / (0.4 + m * l * l), m * g * l / (0.3 + m * l * l), k / 0.2])
    assert np.allclose(modes.natural_frequencies, expected, rtol=1e-12, atol=0)


def test_a_rolling_disc_in_body_rates_moves_as_with_multipliers_in_the_rates():
    # Kane's way for a non-holonomic system: three speeds for five coordinates, the rolling
    # contact's rows the auxiliary speeds held at 0. From the same state (the rates given by
    # the kinematic equations at the start, a lean of 0.1), the bundled disc in the rates
    # with Lagrange's multipliers keeps the same coordinates and contact forces.
    disc = eomgen.load(str(_FIXTURES / "rolling_disc_speeds.yaml"))
    assert disc.speeds == ["w1", "w2", "w3", "roll_x", "roll_y"]
    run = disc.simulate(t_end=2.0, t_out=[2.0], rtol=1e-12, atol=1e-12)
    lean, r, w2, w3 = 0.1, 0.2, 10.0, 0.5
    rates = {
        "lean": lean,
        "x_dot": r * (w2 - w3 * np.tan(lean)),
        "yaw_dot": w3 / np.cos(lean),
        "spin_dot": w2 - w3 * np.tan(lean),
    }
    reference = eomgen.load("rolling_disc").simulate(
        t_end=2.0, t_out=[2.0], rtol=1e-12, atol=1e-12, initial=rates
    )
    assert np.max(np.abs(run.q[-1] - reference.q[-1])) < 1e-8
    assert np.max(np.abs(run.qdot[-1][3:])) < 1e-12
    assert np.allclose(
        run.lagrange_multipliers[-1], reference.lagrange_multipliers[-1], rtol=1e-7, atol=1e-9
    )
