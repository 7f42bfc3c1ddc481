"""The course's studies from Python (`Model.rayleigh`, `convolution`, `launch`,
`periodic_orbit`, `rolling_contact`, `eomgen.expm_study`, `eomgen.reduce`) against the command
line's `--json` and against closed forms or independent computations.

Tolerances: a report computed by the same library call as the command line's is compared
exactly (the JSON prints the shortest decimal that reads back to the same f64); physics at the
study's own accuracy, stated per test.
"""

import math

import numpy as np
import pytest

import eomgen
from test_model import assert_report_equals_json, run_cli


def cli_report(cli, *args):
    """`eomgen ARGS --json`, which must exit 0."""
    status, report = run_cli(cli, *args)
    assert status == 0, args
    return report


# --- study rayleigh ----------------------------------------------------------------------------


def test_rayleigh_equals_the_command_line_json(cli):
    m = eomgen.load("string_chain")
    for shape in ["sin(pi*i/(n+1))", "i*(n+1-i)"]:
        assert_report_equals_json(m.rayleigh(shape), cli_report(cli, "study", "rayleigh", "string_chain",
                                                                  "--shape", shape), shape)
    three = eomgen.load("three_masses")
    assert_report_equals_json(three.rayleigh([1.0, 1.0, 1.0]),
                              cli_report(cli, "study", "rayleigh", "three_masses", "--shape", "1,1,1"))


def test_rayleigh_of_the_exact_mode_is_the_natural_frequency():
    # The chain's first mode is sin(πi/(n+1)) exactly, so √R = ω₁; both come from the same
    # M and K, rounding apart (1e-12 relative: a few ulps of R through the square root).
    m = eomgen.load("string_chain")
    n = m.num_dofs
    shape = np.sin(np.pi * np.arange(1, n + 1) / (n + 1))
    report = m.rayleigh(shape)
    assert abs(report["frequency_estimate"] - report["natural_frequency"]) < 1e-12 * report["natural_frequency"]
    # The text form gives the same shape, hence the same quotient.
    assert m.rayleigh("sin(pi*i/(n+1))")["rayleigh_quotient"] == pytest.approx(report["rayleigh_quotient"], rel=1e-15)
    # Any other shape lies above ω₁² (the bound), its error second order in the shape's.
    rough = m.rayleigh("i*(n+1-i)")
    assert rough["bound_holds"] and rough["rayleigh_quotient"] > rough["natural_frequency"] ** 2


def test_rayleigh_of_a_uniform_shape_on_three_masses():
    # Three equal masses m between four springs k: v = (1, 1, 1) gives vᵀKv = 2k, vᵀMv = 3m.
    m = eomgen.load("three_masses")
    p = m.parameters
    report = m.rayleigh([1, 1, 1])
    assert report["rayleigh_quotient"] == pytest.approx(2 * p["k"] / (3 * p["m"]), rel=1e-14)
    assert report["natural_frequency"] ** 2 == pytest.approx((2 - math.sqrt(2)) * p["k"] / p["m"], rel=1e-12)


def test_rayleigh_refuses_a_shape_of_the_wrong_length():
    m = eomgen.load("three_masses")
    with pytest.raises(eomgen.AnalysisError, match="3"):
        m.rayleigh([1.0, 1.0])
    with pytest.raises(ValueError):
        m.rayleigh("1,2,unknown_name")


# --- study convolution -------------------------------------------------------------------------


def test_convolution_equals_the_command_line_json(cli):
    m = eomgen.load("forced_oscillator")
    for forcing in ["step", "impulse", "sin(2*t)"]:
        report = m.convolution("A", forcing, t_end=10.0, intervals=400)
        expected = cli_report(cli, "study", "convolution", "forced_oscillator", "--input", "A", "--forcing", forcing,
                              "--t-end", "10", "--intervals", "400")
        assert_report_equals_json(report, expected, forcing)


def test_a_step_by_convolution_equals_dop853_and_the_closed_form():
    # m x'' + c x' + k x = H(t): x(t) = (1/k)(1 − e^{−ζωt}(cos ω_d t + ζ/√(1−ζ²) sin ω_d t)).
    # Duhamel's integral agrees with DOP853 on the same equations within Richardson's estimate
    # of its quadrature error (the DOP853 run at 1e-12 adds nothing visible), and with the
    # closed form computed here independently within the same estimate.
    m = eomgen.load("forced_oscillator")
    p = m.parameters
    report = m.convolution("A", "step", t_end=20.0, intervals=1000)
    estimate = report["quadrature"]["error_estimate"]
    assert 0 < estimate < 1e-6
    x = report["convolution"][:, 0]
    assert np.max(np.abs(x - report["direct"][:, 0])) <= 2 * estimate + 1e-10
    w = math.sqrt(p["k"] / p["m"])
    zeta = p["c"] / (2 * math.sqrt(p["k"] * p["m"]))
    wd = w * math.sqrt(1 - zeta**2)
    t = report["times"]
    exact = (1 - np.exp(-zeta * w * t) * (np.cos(wd * t) + zeta / math.sqrt(1 - zeta**2) * np.sin(wd * t))) / p["k"]
    assert np.max(np.abs(x - exact)) <= 2 * estimate + 1e-10


def test_a_python_forcing_function_equals_the_expression():
    # The same f(t) as a Python function and as text: the same grid values, so the same sums
    # (to rounding of sin in the two evaluators, 1e-15 relative).
    m = eomgen.load("forced_oscillator")
    by_text = m.convolution("A", "sin(2*t)", t_end=5.0, intervals=200)
    by_function = m.convolution("A", lambda t: math.sin(2 * t), t_end=5.0, intervals=200, label="sin(2*t)")
    assert by_function["forcing"] == "sin(2*t)"
    np.testing.assert_allclose(by_function["convolution"], by_text["convolution"], rtol=0, atol=1e-14)


def test_convolution_errors():
    m = eomgen.load("forced_oscillator")
    with pytest.raises(eomgen.AnalysisError, match="nothing"):
        m.convolution("nothing", "step")
    with pytest.raises(ValueError, match="forcing"):
        m.convolution("A", "sin(2*")
    with pytest.raises(ValueError, match="forcing"):
        m.convolution("A", "sin(omega*t)")

    def failing(t):
        raise ZeroDivisionError("from the forcing")

    with pytest.raises(ZeroDivisionError, match="from the forcing"):
        m.convolution("A", failing, t_end=1.0, intervals=8)


# --- study launch ------------------------------------------------------------------------------


def test_launch_equals_the_command_line_json(cli):
    m = eomgen.load("projectile_drag").with_parameters(c2=0.0)
    report = m.launch(speeds=[1.0, 10.0], angles=17)
    expected = cli_report(cli, "study", "launch", "projectile_drag", "--set", "c2=0", "--speeds", "1,10",
                          "--angles", "17")
    assert_report_equals_json(report, expected)
    # The shape angle as an expression, as the command line takes it.
    again = m.launch(speeds=[10.0], angles=17, shape_angle="pi/3")
    expected = cli_report(cli, "study", "launch", "projectile_drag", "--set", "c2=0", "--speeds", "10",
                          "--angles", "17", "--shape-angle", "pi/3")
    assert_report_equals_json(again, expected)


def test_launch_in_vacuum_is_best_at_45_degrees():
    # Without drag R(θ) = v² sin 2θ / g: θ* = π/4, R* = v²/g. The range is flat at θ*, so
    # the search's angle is good to about √(ε) (1e-6 rad at rtol 1e-12, the options' doc)
    # while the range is good to the integration's 1e-12 (1e-10 relative allowed).
    m = eomgen.load("projectile_drag").with_parameters(c1=0.0, c2=0.0)
    g = m.parameters["g"]
    report = m.launch(speeds=[3.0, 30.0], angles=9)
    for entry in report["speeds"]:
        v = entry["speed"]
        assert entry["best"]["range"] == pytest.approx(v * v / g, rel=1e-10)
        assert abs(entry["best"]["angle"] - math.pi / 4) < 1e-5


def test_launch_errors():
    m = eomgen.load("projectile_drag")
    with pytest.raises(eomgen.ParameterError, match="no_such"):
        m.launch(speeds=[1.0], angle_parameter="no_such")
    with pytest.raises(eomgen.AnalysisError, match="speed"):
        m.launch(speeds=[-1.0])
    with pytest.raises(eomgen.AnalysisError, match="no_event"):
        m.launch(speeds=[1.0], event="no_event")


# --- study periodic-orbit ----------------------------------------------------------------------

#: Newton's start of docs/course/particles.md: Simó's data moved by about 1e-3.
PERTURBED = {"x1": -0.971, "y1": 0.2441, "x3_dot": 0.933, "y2_dot": -0.4334}
PERTURBED_ARGS = ("--guess", "x1=-0.971,y1=0.2441,x3_dot=0.933,y2_dot=-0.4334")


def test_periodic_orbit_equals_the_command_line_json(cli):
    m = eomgen.load("figure_eight")
    assert_report_equals_json(m.periodic_orbit(), cli_report(cli, "study", "periodic-orbit", "figure_eight"))
    assert_report_equals_json(m.periodic_orbit(guess=PERTURBED),
                              cli_report(cli, "study", "periodic-orbit", "figure_eight", *PERTURBED_ARGS))


def test_the_figure_eight_found_from_a_perturbed_start_closes():
    # Simó's period is 6.32591398 to 8 decimals; those decimals fix the energy, and with it
    # T ∝ |E|^{-3/2}, to about 3e-8 (docs/course/particles.md), so 5e-8 is allowed. The orbit
    # is checked independently: one period of a plain DOP853 run from y₀ returns to y₀ within
    # the integration's error (1e-12 per unit time over 6.3 s, 1e-8 allowed).
    m = eomgen.load("figure_eight")
    report = m.periodic_orbit(guess=PERTURBED)
    period = report["period"]
    assert abs(period - 6.32591398) < 5e-8
    assert report["residual"] < 1e-10
    y0 = report["initial_state"]
    solution = m.simulate(t_end=period, t_out=[period], method="dop853", rtol=1e-12, atol=1e-12, initial=y0)
    back = np.concatenate([solution.q[-1], solution.qdot[-1]])
    assert np.max(np.abs(back - y0)) < 1e-8
    # The energy is the level asked for: the model's initial state's.
    assert abs(sum(m.energy(y0)) - sum(m.energy(m.initial_state()))) < 1e-10


def test_periodic_orbit_errors():
    # string_chain's file gives no period in its checks.
    with pytest.raises(ValueError, match="period"):
        eomgen.load("string_chain").periodic_orbit()
    with pytest.raises(ValueError):
        eomgen.load("figure_eight").periodic_orbit(guess={"nothing": 1.0})
    with pytest.raises(eomgen.AnalysisError):
        eomgen.load("figure_eight").periodic_orbit(period=-1.0)


# --- gaits ---------------------------------------------------------------------------------------


def test_a_gait_equals_the_command_line_json(cli):
    m = eomgen.load("rimless_wheel")
    assert_report_equals_json(m.periodic_orbit(guess={"theta_dot": 2.0}),
                              cli_report(cli, "study", "periodic-orbit", "rimless_wheel", "--guess", "theta_dot=2"))


def test_the_rimless_wheel_rolls_at_its_closed_form_with_eigenvalue_cos_squared_two_alpha():
    # omega* = cot(2 alpha) sqrt(4 (g/l) sin(alpha) sin(gamma)), the return map's eigenvalue
    # cos^2(2 alpha) = 0.5 for eight spokes (Coleman, Chatterjee & Ruina 1997), to 1e-9.
    alpha, gamma, g = np.pi / 8, 0.1, 9.81
    gait = eomgen.load("rimless_wheel").periodic_orbit(guess={"theta_dot": 2.0})
    omega = np.sqrt(4 * g * np.sin(alpha) * np.sin(gamma)) / np.tan(2 * alpha)
    assert abs(gait["state"][1] - omega) < 1e-9
    eigenvalues = gait["eigenvalues"]["re"] + 1j * gait["eigenvalues"]["im"]
    assert abs(eigenvalues[0] - 0.5) < 1e-9
    assert gait["stability"] == "asymptotically_stable"


def test_the_simplest_walker_period_doubles_near_gamma_0_0151():
    sweep = eomgen.load("simplest_walker").parameter_sweep("gamma", np.linspace(0.012, 0.017, 3))
    [change] = sweep["stability_changes"]
    assert change["kind"] == "period_doubling" and change["stable_below"]
    assert abs(change["value"] - 0.015088438) < 1e-7
    with pytest.raises(eomgen.ParameterError):
        eomgen.load("simplest_walker").parameter_sweep("slope", [0.01])


# --- study rolling-contact ---------------------------------------------------------------------


def test_rolling_contact_equals_the_command_line_json(cli):
    m = eomgen.load("eccentric_cylinder")
    assert_report_equals_json(m.rolling_contact(samples=401),
                              cli_report(cli, "study", "rolling-contact", "eccentric_cylinder", "--samples", "401"))
    assert_report_equals_json(m.rolling_contact(after_lift_off=True, samples=401),
                              cli_report(cli, "study", "rolling-contact", "eccentric_cylinder", "--after-lift-off",
                                         "--samples", "401"))


def test_rolling_contact_forces_agree_with_newton_euler():
    # The contact forces from the multipliers against Newton–Euler on the body (an independent
    # computation from the sampled motion): within the study's stated tolerance (1e-6 of max
    # |N|); μ(t) grows without bound as N → 0 at the lift-off.
    report = eomgen.load("eccentric_cylinder").rolling_contact(samples=801)
    rolling = report["rolling"]
    ne = rolling["newton_euler"]
    assert ne["passed"] and ne["relative"] <= ne["tolerance"]
    assert rolling["mu_diverges"]
    assert abs(rolling["normal_force_at_lift_off"]) < 1e-9
    times = rolling["exceedances"]["t"]
    assert np.all(np.diff(times) > 0)  # μ = 0.2, 0.5, 1 are exceeded in that order


def test_rolling_contact_errors():
    with pytest.raises(eomgen.AnalysisError):
        eomgen.load("simple_pendulum").rolling_contact()
    with pytest.raises(eomgen.AnalysisError, match="nowhere"):
        eomgen.load("eccentric_cylinder").rolling_contact(ground="nowhere")
    with pytest.raises(eomgen.ModelError):
        eomgen.load("eccentric_cylinder").rolling_contact(after_lift_off=True, flight="no_such_flight_model")


# --- study expm --------------------------------------------------------------------------------


def test_expm_equals_the_command_line_json(cli):
    assert_report_equals_json(eomgen.expm_study(), cli_report(cli, "study", "expm"))
    assert_report_equals_json(eomgen.expm_study(n=4, seed=7, t=2.0, samples=5),
                              cli_report(cli, "study", "expm", "--n", "4", "--seed", "7", "--t", "2", "--samples", "5"))
    assert_report_equals_json(eomgen.expm_study(matrix=[[0, 1], [-1, 0]]),
                              cli_report(cli, "study", "expm", "--matrix", "0,1;-1,0"))


def test_expm_routes_agree_and_equal_the_rotation():
    # The three routes agree within their stated bounds on the random 10 × 10 A.
    report = eomgen.expm_study()
    assert all(report["differences"]["passed"])
    # ż = [[0, 1], [−1, 0]] z from (1, 0): z(t) = (cos t, −sin t); e^{At} z₀ to rounding
    # (1e-14: a few ulps of the scaling and squaring).
    t = np.linspace(0.0, 3.0, 7)
    rotation = eomgen.expm_study(matrix=np.array([[0.0, 1.0], [-1.0, 0.0]]), z0=[1.0, 0.0], times=t)
    np.testing.assert_allclose(rotation["exponential"], np.column_stack([np.cos(t), -np.sin(t)]), rtol=0, atol=1e-14)
    np.testing.assert_allclose(rotation["integration"], rotation["exponential"], rtol=0, atol=1e-11)


def test_expm_errors():
    with pytest.raises(eomgen.AnalysisError):
        eomgen.expm_study(n=0)
    with pytest.raises(eomgen.AnalysisError):
        eomgen.expm_study(tol=2.0)
    with pytest.raises(ValueError, match="square"):
        eomgen.expm_study(matrix=[[1.0, 2.0]], z0=[1.0])


# --- reduce ------------------------------------------------------------------------------------


def test_reduce_equals_the_command_line_json(cli):
    reduced = eomgen.reduce("simple_pendulum_cartesian", keep="x", initial={"x": "l/2"})
    expected = cli_report(cli, "reduce", "simple_pendulum_cartesian", "--keep", "x", "--initial", "x=l/2")
    assert reduced.summary == expected
    # A model or its text give the same file.
    m = eomgen.load("simple_pendulum_cartesian")
    assert eomgen.reduce(m, ["x"], initial={"x": "l/2"}).text == reduced.text
    assert eomgen.reduce(m.text, ["x"], initial={"x": "l/2"}).kept == ["x"]


def test_the_reduced_pendulum_has_the_pendulum_frequency():
    # Kept x, hanging at x = 0: ω = √(g/ℓ) (modal analysis of the reduced, compiled file, to
    # its eigen-solver's rounding, 1e-12 relative).
    reduced = eomgen.reduce("simple_pendulum_cartesian", keep="x", initial={"x": "l/2"})
    model = reduced.load()
    assert model.coordinates == ["x"]
    p = model.parameters
    omega = model.modes(at=[0.0]).natural_frequencies[0]
    assert omega == pytest.approx(math.sqrt(p["g"] / p["l"]), rel=1e-12)


def test_reduce_errors():
    with pytest.raises(ValueError, match="nothing"):
        eomgen.reduce("simple_pendulum_cartesian", keep="nothing")
    with pytest.raises(eomgen.AnalysisError, match="singular"):
        eomgen.reduce("simple_pendulum_cartesian", keep="x")
    with pytest.raises(eomgen.AnalysisError, match="holonomic"):
        eomgen.reduce("simple_pendulum", keep="theta")
    with pytest.raises(eomgen.ModelError):
        eomgen.reduce("name: broken\ncoordinates: [\n", keep="x")
