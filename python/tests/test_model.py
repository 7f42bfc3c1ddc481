"""The Python API against closed forms, independent derivations and the command line's JSON.

Tolerances: results computed by the same library call as the command line's are compared
exactly (the JSON prints the shortest decimal that reads back to the same f64); results
against closed forms at the analysis' own accuracy (stated per test).
"""

import json
import math
import pathlib
import pickle
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import eomgen


def assert_report_equals_json(got, want, path="report"):
    """A study's report (numeric lists as arrays, tables as columns) equals the command
    line's JSON object exactly: the same keys, the same numbers (None in the JSON where the
    array has NaN)."""
    if isinstance(got, np.ndarray):
        expected = np.array([np.nan if v is None else v for v in np.ravel(np.array(want, dtype=object))],
                            dtype=float).reshape(np.shape(want))
        np.testing.assert_array_equal(got, expected, err_msg=path)
    elif isinstance(got, dict) and isinstance(want, list):
        assert len(want) > 0 and all(isinstance(r, dict) for r in want), path
        assert set(got) == set(want[0]), path
        for key in got:
            if key != "wall_time_s":  # a measured time differs from run to run
                assert_report_equals_json(got[key], [r[key] for r in want], f"{path}.{key}")
    elif isinstance(got, dict):
        assert set(got) == set(want), (path, set(got) ^ set(want))
        for key in got:
            if key != "wall_time_s":
                assert_report_equals_json(got[key], want[key], f"{path}.{key}")
    elif isinstance(got, list):
        assert len(got) == len(want), path
        for i, (a, b) in enumerate(zip(got, want)):
            assert_report_equals_json(a, b, f"{path}[{i}]")
    else:
        assert got == want, (path, got, want)


def run_cli(cli, *args):
    """`eomgen ARGS --json`, parsed (the exit status is returned too)."""
    out = subprocess.run([cli, *args, "--json"], capture_output=True, text=True, timeout=600)
    return out.returncode, json.loads(out.stdout)


# --- opening models --------------------------------------------------------------------------


def test_the_methods_are_the_command_lines_with_their_help(cli):
    """METHODS and METHOD_SUMMARIES are the library's method table: the names and help lines
    that `eomgen simulate --help` lists, in its order."""
    text = subprocess.run([cli, "simulate", "--help"], capture_output=True, text=True, check=True).stdout
    for name, summary in eomgen.METHOD_SUMMARIES.items():
        assert f"- {name}:" in text and summary.split(",")[0] in text
    assert list(eomgen.METHOD_SUMMARIES) == list(eomgen.METHODS)
    assert eomgen.METHODS[:5] == ("euler", "midpoint", "rk4", "bs32", "dp54")
    assert "Dormand–Prince 5(4)" in eomgen.METHOD_SUMMARIES["dp54"]


def test_bundled_model_names_parameters_and_coordinates():
    m = eomgen.load("double_pendulum")
    assert m.name == "double_pendulum"
    assert m.coordinates == ["theta1", "theta2"]
    assert m.parameters == {"m1": 1.0, "m2": 1.0, "l1": 1.0, "l2": 1.0, "g": 10.0}
    assert m.num_dofs == 2
    assert "double_pendulum" in eomgen.bundled_models()
    assert m.path == "models/double_pendulum.yaml"


def test_a_file_runs_the_same_bits_as_the_bundled_model(model_file):
    bundled = eomgen.load("double_pendulum")
    loaded = eomgen.load(model_file("double_pendulum"))
    assert loaded.path.endswith("double_pendulum.yaml") and loaded.path != bundled.path
    a = bundled.simulate(t_end=2.0, rtol=1e-10, atol=1e-10)
    b = loaded.simulate(t_end=2.0, rtol=1e-10, atol=1e-10)
    assert np.array_equal(a.t, b.t) and np.array_equal(a.y, b.y)


def test_with_parameters_returns_a_copy():
    m = eomgen.load("simple_pendulum")
    name = next(iter(m.parameters))
    m2 = m.with_parameters({name: 2.5})
    assert m2.parameters[name] == 2.5
    assert m.parameters[name] != 2.5
    assert m2.with_parameters(**{name: 3.0}).parameters[name] == 3.0


def test_an_unknown_or_non_finite_parameter_raises():
    m = eomgen.load("double_pendulum")
    with pytest.raises(eomgen.ParameterError, match="no_such"):
        m.with_parameters(no_such=1.0)
    with pytest.raises(eomgen.ParameterError, match="finite"):
        m.with_parameters(g=float("nan"))
    with pytest.raises(ValueError):  # ParameterError is a ValueError
        m.with_parameters(g=float("inf"))


def test_an_unknown_name_raises_model_error():
    with pytest.raises(eomgen.ModelError, match="double_pendulm") as info:
        eomgen.load("double_pendulm")
    assert "double_pendulum" in str(info.value)  # the suggestion
    assert info.value.diagnostics == []


def test_a_broken_file_raises_located_diagnostics(model_file, cli):
    text = eomgen.load("simple_pendulum").text
    broken = text.replace("coordinates:", "coordinates:\n  - q\n  - q\nbogus_key: 1\ncoordinates_x:", 1)
    path = model_file("broken", broken)
    with pytest.raises(eomgen.ModelError) as info:
        eomgen.load(path)
    diagnostics = info.value.diagnostics
    assert diagnostics, "a broken file must carry its diagnostics"
    for d in diagnostics:
        assert d["file"] == path
        assert d["line"] >= 1 and d["column"] >= 1
        assert d["message"]
    # The same diagnostics as the command line's JSON error.
    status, cli_json = run_cli(cli, "check", path)
    assert status == 2
    assert cli_json["diagnostics"] == diagnostics


# --- simulation --------------------------------------------------------------------------------


def test_simulate_shapes_and_output_times():
    m = eomgen.load("double_pendulum")
    sol = m.simulate(t_end=10.0, t_out=[1.0, 2.0, 5.0], method="dop853", rtol=1e-12, atol=1e-12)
    assert sol.t.tolist() == [1.0, 2.0, 5.0]
    assert sol.q.shape == (3, 2) and sol.qdot.shape == (3, 2) and sol.energy.shape == (3,)
    assert sol.y.shape == (3, 4)
    assert set(sol.stats) >= {"steps", "rejected", "rhs_evals"}
    # A conservative model at 1e-12: the energy stays put to well below 1e-9 relative.
    assert abs(sol.energy[-1] - sol.energy[0]) <= 1e-9 * abs(sol.energy[0]) + 1e-9


def test_simulate_equals_the_command_line_json(cli):
    m = eomgen.load("double_pendulum")
    sol = m.simulate(t_end=3.0, method="dop853", rtol=1e-10, atol=1e-10)
    status, expected = run_cli(cli, "simulate", "double_pendulum", "--t-end", "3", "--method", "dop853",
                               "--rtol", "1e-10", "--atol", "1e-10")
    assert status == 0
    got = json.loads(json.dumps(sol.summary))
    got["stats"].pop("wall_time_s")
    assert got == expected


def test_simulate_defaults_are_the_command_line_defaults(cli):
    sol = eomgen.load("simple_pendulum").simulate()
    status, expected = run_cli(cli, "simulate", "simple_pendulum")
    assert status == 0
    got = json.loads(json.dumps(sol.summary))
    got["stats"].pop("wall_time_s")
    assert got == expected


def test_a_constrained_model_gives_multipliers_and_drift(cli):
    m = eomgen.load("four_bar")
    sol = m.simulate(t_end=1.0, t_out=[0.5, 1.0], stabilization="projection")
    assert sol.lagrange_multipliers.shape[0] == 2
    assert sol.constraint_drift.shape == (2, 2)
    status, expected = run_cli(cli, "simulate", "four_bar", "--t-end", "1", "--t-out", "0.5,1",
                               "--stabilization", "projection")
    assert status == 0
    got = json.loads(json.dumps(sol.summary))
    got["stats"].pop("wall_time_s")
    assert got == expected


def test_the_taylor_method_follows_a_constrained_model(cli):
    # The index-1 system's series, with projection after each step: the same run as the
    # command line's, within 1e-9 of DOP853 at 1e-13, on the constraints to 1e-12.
    m = eomgen.load("rolling_disc")
    sol = m.simulate(t_end=1.0, t_out=[0.5, 1.0], method="taylor", rtol=1e-11, atol=1e-11,
                     stabilization="projection")
    reference = m.simulate(t_end=1.0, t_out=[0.5, 1.0], method="dop853", rtol=1e-13, atol=1e-13)
    assert np.max(np.abs(sol.y - reference.y)) < 1e-9
    assert np.max(sol.constraint_drift) < 1e-12
    status, expected = run_cli(cli, "simulate", "rolling_disc", "--t-end", "1", "--t-out", "0.5,1",
                               "--method", "taylor", "--rtol", "1e-11", "--atol", "1e-11",
                               "--stabilization", "projection")
    assert status == 0
    got = json.loads(json.dumps(sol.summary))
    got["stats"].pop("wall_time_s")
    assert got == expected
    with pytest.raises(ValueError, match="baumgarte"):
        m.simulate(t_end=1.0, method="taylor", stabilization="baumgarte")


def test_initial_values_by_name():
    m = eomgen.load("double_pendulum")
    y0 = m.initial_state({"theta1": 0.25, "theta2_dot": -1.0})
    assert y0[0] == 0.25 and y0[3] == -1.0
    sol = m.simulate(t_end=0.5, t_out=[0.0, 0.5], initial={"theta1": 0.25, "theta2_dot": -1.0})
    assert np.array_equal(sol.y[0], y0)
    with pytest.raises(ValueError, match="theta3"):
        m.initial_state({"theta3": 1.0})


def test_events_stop_a_run():
    # A pendulum released at 0.5 rad turns back at -0.5 rad after half a period.
    m = eomgen.load("simple_pendulum")
    sol = m.simulate(t_end=10.0, initial=[0.5, 0.0], stop_when=["q_dot = 0, rising"], rtol=1e-12, atol=1e-12)
    assert len(sol.events) == 1
    # Energy conservation: the turning points lie symmetrically about the hanging position.
    hanging = m.modes(at="hanging").equilibrium[0]
    assert abs((sol.events[0]["q"][0] + 0.5) / 2 - hanging) < 1e-9


def test_a_bouncing_ball_lists_its_impacts_and_rests():
    # Dropped from h = 1 m with e = 0.8: impacts at t1 = sqrt(2h/g), then after flights of
    # 2 e^k v0/g; they accumulate at t_inf = t1 + (2 e v0/g)/(1 - e), where the contact
    # closes and the ball rests (y = 0) for the rest of the run.
    g, e = 9.81, 0.8
    t1, v0 = math.sqrt(2 / g), math.sqrt(2 * g)
    sol = eomgen.load("bouncing_ball").simulate(t_end=6.0, rtol=1e-12, atol=1e-12)
    impacts = [tr for tr in sol.transitions if tr["kind"] == "impact"]
    assert abs(impacts[0]["t"] - t1) < 1e-9
    assert abs(impacts[1]["t"] - (t1 + 2 * e * v0 / g)) < 1e-9
    assert abs(impacts[0]["normal_velocity"][1] + e * impacts[0]["normal_velocity"][0]) < 1e-12
    closes = sol.transitions[-1]
    assert closes["kind"] == "closes" and abs(closes["t"] - (t1 + 2 * e * v0 / g / (1 - e))) < 1e-5
    assert sol.contact_stop is None
    assert abs(sol.q[-1, 1]) < 1e-9 and sol.t[-1] == 6.0


def test_a_failing_integration_raises_with_the_partial_solution():
    m = eomgen.load("triple_pendulum")
    with pytest.raises(eomgen.IntegrationError) as info:
        m.simulate(method="rk4", dt=0.5)
    e = info.value
    assert e.t is not None and 0 < e.t < 10.0
    assert "triple_pendulum" in str(e) and e.reason
    assert isinstance(e.solution, eomgen.Solution)
    assert len(e.solution.t) >= 1 and e.solution.t[-1] <= e.t
    assert np.all(np.isfinite(e.solution.y))


def test_bad_options_raise_value_errors():
    m = eomgen.load("simple_pendulum")
    with pytest.raises(ValueError, match="dp54"):
        m.simulate(method="no-such-method")
    with pytest.raises(ValueError):
        m.simulate(t_end=-1.0)
    with pytest.raises(ValueError):
        m.simulate(rtol=2.0)
    with pytest.raises(ValueError):
        m.simulate(t_out=[2.0, 1.0])


def test_output_times_are_read_in_any_form():
    # A time, a tuple, a strided array and an integer array are the list they hold.
    m = eomgen.load("simple_pendulum")
    reference = m.simulate(t_end=1.0, t_out=[0.0, 0.5, 1.0])
    times = np.linspace(0.0, 1.0, 5)
    for t_out in ((0.0, 0.5, 1.0), times[::2]):
        assert np.array_equal(m.simulate(t_end=1.0, t_out=t_out).y, reference.y), t_out
    assert np.array_equal(m.simulate(t_end=1.0, t_out=1.0).y, reference.y[[2]])
    assert np.array_equal(m.simulate(t_end=1.0, t_out=np.array([0, 1])).t, [0.0, 1.0])
    for bad in ("0.5", b"\x00\x01", bytearray(b"\x01"), np.zeros((2, 2)), [[0.5]], [0.5, "x"]):
        with pytest.raises(TypeError, match="t_out must be a time or a 1-D sequence"):
            m.simulate(t_end=1.0, t_out=bad)


def test_a_solution_pickles_with_its_summary():
    # The summary's dicts are made on first use; a pickled solution carries them made.
    sol = eomgen.load("double_pendulum").simulate(t_end=1.0)
    again = pickle.loads(pickle.dumps(sol))
    assert again.summary_header == sol.summary_header and again.stats["steps"] > 0
    assert np.array_equal(again.y, sol.y) and np.array_equal(again.q, sol.q)
    assert again.q.base is again.y or again.q.base is again.y.base
    # A solution pickled by an earlier version (its summary as `summary_header`, `q` and
    # `qdot` as arrays) unpickles with its summary.
    old = {k: v for k, v in sol.__dict__.items() if not k.startswith("_")}
    old.update(summary_header=sol.summary_header, q=sol.q.copy(), qdot=sol.qdot.copy(),
               _solved=None, _summary=None)
    earlier = eomgen.Solution.__new__(eomgen.Solution)
    earlier.__setstate__(old)
    assert earlier.stats == sol.stats and np.array_equal(earlier.qdot, sol.qdot)


# --- evaluations --------------------------------------------------------------------------------


def test_mass_matrix_and_forcing_equal_the_hand_derivation():
    # HW19's double pendulum derived by hand (tools/double_pendulum_reference.py): two uniform
    # bars, absolute angles from +x, gravity −y.
    m = eomgen.load("double_pendulum")
    p = m.parameters
    m1, m2, l1, l2, g = p["m1"], p["m2"], p["l1"], p["l2"], p["g"]
    rng = np.random.default_rng(5)
    for _ in range(10):
        t1, t2, w1, w2 = rng.uniform(-3, 3, 4)
        mass = m.mass_matrix([t1, t2])
        expected = np.array([[m1 * l1**2 / 3 + m2 * l1**2, m2 * l1 * l2 / 2 * math.cos(t1 - t2)],
                             [m2 * l1 * l2 / 2 * math.cos(t1 - t2), m2 * l2**2 / 3]])
        np.testing.assert_allclose(mass, expected, rtol=1e-14, atol=1e-14)
        forcing = m.forcing([t1, t2], [w1, w2])
        f1 = -m2 * l1 * l2 / 2 * math.sin(t1 - t2) * w2**2 - (m1 / 2 + m2) * g * l1 * math.cos(t1)
        f2 = m2 * l1 * l2 / 2 * math.sin(t1 - t2) * w1**2 - m2 * g * l2 / 2 * math.cos(t2)
        np.testing.assert_allclose(forcing, [f1, f2], rtol=1e-13, atol=1e-12)
        dy = m.rhs(0.0, [t1, t2, w1, w2])
        np.testing.assert_allclose(dy[:2], [w1, w2], rtol=0, atol=0)
        np.testing.assert_allclose(dy[2:], np.linalg.solve(expected, [f1, f2]), rtol=1e-12, atol=1e-12)


def test_rhs_drives_scipy_to_the_same_answer():
    scipy_integrate = pytest.importorskip("scipy.integrate")
    m = eomgen.load("double_pendulum")
    y0 = m.initial_state()
    ours = m.simulate(t_end=2.0, t_out=[2.0], method="dop853", rtol=1e-12, atol=1e-12)
    theirs = scipy_integrate.solve_ivp(m.rhs, (0.0, 2.0), y0, method="DOP853", rtol=1e-12, atol=1e-12)
    # Two integrators at 1e-12 over a chaotic 2 s: agreement to 1e-7 (their own errors).
    np.testing.assert_allclose(theirs.y[:, -1], ours.y[-1], rtol=0, atol=1e-7)


def test_wrong_lengths_raise():
    m = eomgen.load("double_pendulum")
    with pytest.raises(ValueError):
        m.rhs(0.0, [0.0, 1.0])
    with pytest.raises(ValueError):
        m.mass_matrix([0.0])


# --- modes ----------------------------------------------------------------------------------------


def test_modes_equal_the_closed_form_and_are_mass_normalised():
    # HW28: three equal masses between four equal springs: ω² = (2 − √2), 2, (2 + √2) k/m.
    m = eomgen.load("three_masses")
    k, mass = m.parameters["k"], m.parameters["m"]
    modes = m.modes()
    expected = np.sqrt(np.array([2 - math.sqrt(2), 2.0, 2 + math.sqrt(2)]) * k / mass)
    np.testing.assert_allclose(modes.natural_frequencies, expected, rtol=1e-12)
    psi = modes.mode_shapes
    assert psi.shape == (3, 3)
    np.testing.assert_allclose(psi.T @ modes.mass_matrix @ psi, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(psi.T @ modes.stiffness_matrix @ psi, np.diag(expected**2), atol=1e-12)


def test_modes_equal_the_command_line_json(cli):
    m = eomgen.load("double_pendulum")
    modes = m.modes(at="hanging")
    status, expected = run_cli(cli, "modes", "double_pendulum", "--at", "hanging")
    assert status == 0
    expected.pop("charts")
    expected.pop("animation")
    assert json.loads(json.dumps(modes.summary)) == expected


def test_modes_from_a_guess_and_at_a_steady_motion():
    m = eomgen.load("simple_pendulum")
    hanging = m.modes()
    guessed = m.modes(at={m.coordinates[0]: 0.1})
    np.testing.assert_allclose(guessed.natural_frequencies, hanging.natural_frequencies, rtol=1e-12)
    with pytest.raises(eomgen.AnalysisError):
        eomgen.load("cannonball").modes()
    steady = eomgen.load("chaplygin_sleigh").modes()
    assert isinstance(steady, eomgen.SteadyMotion)
    assert steady.eigenvalues.size >= 1
    assert steady.turning is None and steady.found_rates == []


def test_a_coin_in_a_steady_turn():
    """The rolling disc's steady turn from Python: the same report as the command line, the
    turning frame and the rates found, and the nodding frequency of the Kane derivation
    (``tools/coin_turn_reference.py``) to 1e-9."""
    turn = eomgen.load("rolling_disc").modes("turning")
    assert isinstance(turn, eomgen.SteadyMotion)
    assert turn.turning["angle"] == "yaw" and turn.turning["plane"] == ["x", "y"]
    assert turn.turning["rate"] == -1.0 and abs(turn.turning["radius"] - 1.5) < 1e-13
    assert turn.found_rates == ["x_dot", "y_dot"] and turn.held_coordinates == []
    nonzero = turn.eigenvalues[np.abs(turn.eigenvalues) > 0]
    assert np.allclose(np.abs(nonzero.imag), 9.6499221962793447639, rtol=0, atol=1e-9)
    page = turn._repr_html_()
    assert "constant in the frame turned by yaw" in page and "rates found x_dot = 1.5" in page


# --- derivations -------------------------------------------------------------------------------


def test_check_equals_the_command_line_json(cli):
    m = eomgen.load("double_pendulum_points")
    report = m.check()
    assert report["passed"] is True
    status, expected = run_cli(cli, "check", "double_pendulum_points")
    assert status == 0
    assert report == expected


def test_equations_as_text_and_latex(cli):
    m = eomgen.load("double_pendulum")
    text = m.equations()
    out = subprocess.run([cli, "equations", "double_pendulum"], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0
    assert text + "\n" == out.stdout or text == out.stdout
    latex = m.equations(latex=True)
    assert "\\" in latex and latex == latex.latex
    # Jupyter's LaTeX: the listing inside math delimiters.
    shown = text._repr_latex_()
    assert shown.startswith("$$\\begin{gathered}") and shown.endswith("\\end{gathered}$$")
    assert latex.latex.strip() in shown
    status, expected = run_cli(cli, "equations", "double_pendulum")
    assert status == 0 and text.listing == expected
    with pytest.raises(ValueError, match="momentum"):
        eomgen.load("simple_pendulum").equations(method="momentum")


# --- pickling ------------------------------------------------------------------------------------


def test_models_pickle_by_text_and_parameters(model_file, tmp_path):
    m = eomgen.load("double_pendulum").with_parameters(g=9.81)
    m2 = pickle.loads(pickle.dumps(m))
    assert m2 == m and m2.parameters["g"] == 9.81
    a, b = m.simulate(t_end=1.0), m2.simulate(t_end=1.0)
    assert np.array_equal(a.y, b.y)
    # A file's model travels as its text: the file may be gone when it is unpickled.
    path = model_file("simple_pendulum")
    f = eomgen.load(path).with_parameters(g=3.0)
    data = pickle.dumps(f)
    (tmp_path / "simple_pendulum.yaml").unlink()
    f2 = pickle.loads(data)
    assert f2.parameters["g"] == 3.0 and f2.path == path
    assert np.array_equal(f.simulate(t_end=1.0).y, f2.simulate(t_end=1.0).y)


def test_exceptions_pickle_with_their_attributes():
    try:
        eomgen.load("triple_pendulum").simulate(method="rk4", dt=0.5)
    except eomgen.IntegrationError as e:
        e2 = pickle.loads(pickle.dumps(e))
        assert (e2.t, e2.reason, str(e2)) == (e.t, e.reason, str(e))
        assert np.array_equal(e2.solution.y, e.solution.y)
    error = eomgen.ModelError("bad", [{"file": "f", "line": 1, "column": 2, "message": "m", "help": None}])
    again = pickle.loads(pickle.dumps(error))
    assert again.diagnostics == error.diagnostics and str(again) == "bad"


# --- batches -------------------------------------------------------------------------------------


def test_simulate_many_equals_the_serial_loop_bit_for_bit():
    m = eomgen.load("double_pendulum")
    y0 = m.initial_state()
    states = np.tile(y0, (24, 1))
    states[:, 0] += np.linspace(-0.3, 0.3, 24)
    batch = m.simulate_many(initial_states=states, t_end=2.0, t_out=[1.0, 2.0], rtol=1e-10, atol=1e-10)
    assert batch.y.shape == (24, 2, 4) and batch.q.shape == (24, 2, 2) and batch.energy.shape == (24, 2)
    assert batch.ok.all() and not batch.failures
    for i, state in enumerate(states):
        serial = m.simulate(t_end=2.0, t_out=[1.0, 2.0], initial=state, rtol=1e-10, atol=1e-10)
        assert np.array_equal(batch.y[i], serial.y), i
        assert batch.stats["steps"][i] == serial.stats["steps"]
    one_thread = m.simulate_many(initial_states=states, t_end=2.0, t_out=[1.0, 2.0], rtol=1e-10, atol=1e-10, threads=1)
    assert np.array_equal(one_thread.y, batch.y)


def test_simulate_many_over_parameters():
    m = eomgen.load("simple_pendulum")
    gs = np.array([1.0, 4.0, 9.0])
    batch = m.simulate_many(parameters={"g": gs}, t_end=1.0)
    for i, g in enumerate(gs):
        assert np.array_equal(batch.y[i], m.with_parameters(g=g).simulate(t_end=1.0, t_out=[1.0]).y)
    with pytest.raises(eomgen.ParameterError):
        m.simulate_many(parameters=[{"nope": 1.0}], t_end=1.0)
    with pytest.raises(ValueError):
        m.simulate_many(t_end=1.0)


def test_simulate_many_keeps_or_raises_failures():
    m = eomgen.load("triple_pendulum")
    y0 = m.initial_state()
    with pytest.raises(eomgen.IntegrationError):
        m.simulate_many(initial_states=[y0, y0], method="rk4", dt=0.5)
    batch = m.simulate_many(initial_states=[y0, y0], method="rk4", dt=0.5, errors="keep")
    assert not batch.ok.any() and len(batch.failures) == 2
    assert np.isnan(batch.y[:, -1]).all()


def test_long_calls_release_the_interpreter():
    # While one thread integrates, another must run Python: with the interpreter held for
    # the whole call, no bytecode of the main thread could run inside the call's interval.
    # Even then the main thread may run for one switch interval just after the call starts
    # and just before it ends, so ticks count only away from both ends by two intervals, and
    # the call must be long against them (100 runs: about 0.25 s in a release build, 4 s in
    # CI's debug wheel).
    m = eomgen.load("double_pendulum")
    states = np.tile(m.initial_state(), (100, 1))
    interval = {}

    def work():
        interval["start"] = time.perf_counter()
        m.simulate_many(initial_states=states, t_end=10.0, rtol=1e-11, atol=1e-11, threads=1)
        interval["end"] = time.perf_counter()

    worker = threading.Thread(target=work)
    worker.start()
    ticks = []
    while worker.is_alive():
        ticks.append(time.perf_counter())
    worker.join()
    start, end = interval["start"], interval["end"]
    margin = 2 * sys.getswitchinterval()
    assert end - start > 10 * margin, f"the call took {end - start:.3f} s: too short to tell"
    inside = [t for t in ticks if start + margin < t < end - margin]
    assert inside, f"no Python ran in the main thread during a {end - start:.3f} s call"


# --- studies -----------------------------------------------------------------------------------


def test_frf_equals_the_closed_form():
    # m x'' + c x' + k x = A cos wt: |X/A| = (1/k)/sqrt((1 − r²)² + (2ζr)²).
    m = eomgen.load("forced_oscillator")
    p = m.parameters
    zeta = p["c"] / (2 * math.sqrt(p["k"] * p["m"]))
    wn = math.sqrt(p["k"] / p["m"])
    report = m.frf("A", frequencies=[0.5, 1.0, 2.0], points=50)
    assert isinstance(report["frequencies"], np.ndarray) and report["frequencies"].shape == (50,)
    for e in report["evaluations"]:
        r = e["frequency"] / wn
        expected = (1 / p["k"]) / math.sqrt((1 - r**2) ** 2 + (2 * zeta * r) ** 2)
        assert abs(e["response"]["x"]["amplitude"] - expected) < 1e-12 * expected


def test_parameter_sweep_finds_the_rolling_disc_critical_speed():
    # The rolling disc upright is stable above v = sqrt(g r / 3).
    m = eomgen.load("rolling_disc")
    report = m.parameter_sweep("v", np.linspace(0.2, 2.0, 10), at="rolling")
    changes = report["stability_changes"]
    assert changes
    r, g = m.parameters.get("r"), m.parameters.get("g")
    critical = math.sqrt(g * r / 3)
    assert min(abs(c["value"] - critical) for c in changes) < 1e-9


def test_work_precision_errors_fall_with_the_tolerance():
    m = eomgen.load("simple_pendulum")
    report = m.work_precision(methods=["dp54", "rk4"], tolerances=[1e-4, 1e-8], steps=[100, 1000], t_end=2.0,
                              samples=10, repeats=1, min_time_s=0.0)
    by_method = {entry["method"]: entry["runs"] for entry in report["methods"]}
    dp54, rk4 = by_method["dp54"], by_method["rk4"]
    # The runs come as columns (dict of arrays).
    assert isinstance(dp54["error"], np.ndarray) and dp54["tol"].tolist() == [1e-4, 1e-8]
    assert dp54["error"][1] < dp54["error"][0]
    # RK4 over 10x more steps: the error falls by about 10^4 (order 4); at least 10^3.
    assert rk4["error"][1] < rk4["error"][0] / 1e3


def test_floquet_multipliers_of_the_mathieu_pendulum(cli):
    # Undamped and Hamiltonian: det Φ(T) = exp(∫ tr A dt) = 1 (Liouville), so the multipliers'
    # product is 1; at the file's values the shaken upright pendulum is stable.
    m = eomgen.load("mathieu_pendulum")
    report = m.floquet()
    mu = report["multipliers"]["re"] + 1j * report["multipliers"]["im"]
    assert abs(np.prod(mu) - 1.0) < 1e-9
    assert report["spectral_radius"] <= 1.0 + 1e-6 and report["stable"]
    status, expected = run_cli(cli, "study", "floquet", "mathieu_pendulum")
    assert status == 0
    assert_report_equals_json(report, expected)
    assert "kapitza" in report  # the file's `floquet:` reference, evaluated


def test_studies_equal_the_command_line_json(cli):
    cases = [
        (eomgen.load("three_masses").free_response(), ("study", "free-response", "three_masses")),
        (eomgen.load("three_masses_damped").modal_damping(), ("study", "modal-damping", "three_masses_damped")),
        (eomgen.load("simple_pendulum_cartesian").constraint_methods(t_end=2.0),
         ("study", "constraint-methods", "simple_pendulum_cartesian", "--t-end", "2")),
        (eomgen.load("forced_oscillator").frf("A", frequencies=[0.5, 2.0]),
         ("frf", "forced_oscillator", "--input", "A", "--frequency", "0.5", "--frequency", "2")),
    ]
    for report, args in cases:
        status, expected = run_cli(cli, *args)
        assert status == 0, args
        expected.pop("chart", None)
        expected.pop("charts", None)
        assert_report_equals_json(report, expected, " ".join(args))


def test_free_response_four_ways_agree():
    # Superposed modes two ways, e^{At} and DOP853 on the linearisation: the same response
    # (HW28), to the integration's tolerance.
    report = eomgen.load("three_masses").free_response()
    assert report["max_differences"]["displacement_relative"].max() < 1e-9
    assert report["max_differences"]["velocity_relative"].max() < 1e-9


def test_modal_damping_integration_agrees_with_the_exact_response():
    report = eomgen.load("three_masses_damped").modal_damping()
    for case in report["cases"]:
        assert case["integration_vs_exact"] < 1e-8


def test_a_missing_or_binary_file_raises_model_error(tmp_path):
    with pytest.raises(eomgen.ModelError) as missing:
        eomgen.load(str(tmp_path / "absent.yaml"))
    assert "absent.yaml" in str(missing.value) and missing.value.diagnostics == []
    binary = tmp_path / "binary.yaml"
    binary.write_bytes(b"name: x\n\xff\xfe\n")
    with pytest.raises(eomgen.ModelError) as info:
        eomgen.load(str(binary))
    (d,) = info.value.diagnostics
    assert d["line"] == 2 and d["file"] == str(binary)


def test_a_failure_says_what_the_model_shows_there():
    # m1 = −1: det M = m2²/9 − m2² cos²(θ1 − θ2)/4 + m1 m2/9 vanishes when cos² = 8/9; the
    # integration stops there, and the exception names the negative mass. The double
    # pendulum in energy form: with bodies, the value is refused when it is set (below).
    path = pathlib.Path(__file__).resolve().parents[2] / "tests" / "fixtures" / "energy_double_pendulum.yaml"
    m = eomgen.load(str(path)).with_parameters(m1=-1.0)
    with pytest.raises(eomgen.IntegrationError) as info:
        m.simulate()
    assert info.value.solution.cause is not None
    assert "m1 = -1" in str(info.value)


def test_parameters_meet_the_body_rules():
    # The rules the file's defaults meet hold for values set later: the heavy top with l = 1
    # has centroidal moments I1 − m l² = −0.98; the free body with I3 = 3.5 breaks
    # I3 ≤ I1 + I2; a batch run with such values is refused before any run.
    with pytest.raises(eomgen.ParameterError, match="body `top` is not positive definite"):
        eomgen.load("heavy_top").with_parameters(l=1.0)
    with pytest.raises(eomgen.ParameterError, match="triangle inequality"):
        eomgen.load("free_rigid_body").with_parameters(I3=3.5)
    body = eomgen.load("free_rigid_body")
    body.with_parameters(I3=5.0, I1=3.0)  # an impossible body on the way is no matter
    with pytest.raises(eomgen.ParameterError, match="I3=3.5"):
        body.simulate_many(parameters=[{"I3": 3.0}, {"I3": 3.5}], t_end=0.1)


def test_bad_values_are_value_errors_and_sizes_are_bounded():
    # Issue 49: a NaN initial value was an IntegrationError, t = nan accepted, a one-element
    # baumgarte an IndexError, an unknown parameter listed the parameters twice; the CLI's
    # size limits did not apply (1e7 output times, 20,001 sweep values, 10,000 threads, and
    # a batch whose result could not be allocated aborted the interpreter).
    m = eomgen.load("double_pendulum")
    with pytest.raises(ValueError, match="finite"):
        m.simulate(initial={"theta1": float("nan")})
    with pytest.raises(ValueError, match="finite"):
        m.simulate(initial=[0.0, float("inf"), 0.0, 0.0])
    with pytest.raises(ValueError, match="finite"):
        m.modes(t=float("nan"))
    with pytest.raises(ValueError, match="two gains"):
        m.simulate(stabilization="baumgarte", baumgarte=(1.0,))
    with pytest.raises(eomgen.ParameterError) as info:
        m.with_parameters(mass=1.0)
    assert str(info.value).count("m1, m2") == 1, str(info.value)
    with pytest.raises(ValueError, match="at most 100000"):
        m.simulate(t_end=1.0, t_out=np.linspace(0.0, 1.0, 100_001))
    with pytest.raises(ValueError, match="threads must be 1 to 256"):
        m.simulate_many(parameters={"m1": [1.0, 2.0]}, t_end=0.1, threads=10_000)
    with pytest.raises(ValueError, match="a batch may return"):
        m.simulate_many(parameters={"m1": np.linspace(1.0, 2.0, 100_000)},
                        t_end=1.0, t_out=np.linspace(0.0, 1.0, 100_000))
    with pytest.raises(ValueError, match="at most 10000"):
        m.parameter_sweep("m1", np.linspace(1.0, 2.0, 10_001), at="hanging")


# --- animations ------------------------------------------------------------------------------


def test_animate_writes_the_command_line_page(cli, tmp_path):
    m = eomgen.load("double_pendulum")
    animation = m.animate(t_end=2.0, fps=15)
    page = tmp_path / "dp.html"
    out = subprocess.run([cli, "animate", "double_pendulum", "--t-end", "2", "--fps", "15", "-o", str(page)],
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    assert animation.html == page.read_text(encoding="utf-8")
    assert animation.html.startswith("<!DOCTYPE html>")
    shown = animation._repr_html_()
    assert shown.startswith("<iframe srcdoc=") and "&lt;!DOCTYPE html&gt;" in shown
    saved = tmp_path / "saved.html"
    animation.save(str(saved))
    assert saved.read_text(encoding="utf-8") == animation.html


def test_animate_modes_writes_the_command_line_page(cli, tmp_path):
    page = tmp_path / "modes.html"
    out = subprocess.run([cli, "modes", "three_masses", "--animate", str(page)], capture_output=True, text=True,
                         timeout=600)
    assert out.returncode == 0, out.stderr
    assert eomgen.load("three_masses").animate_modes().html == page.read_text(encoding="utf-8")


def test_a_3d_model_is_animated_in_webgl_as_the_command_line_does(cli, tmp_path):
    page = tmp_path / "top.html"
    out = subprocess.run([cli, "animate", "heavy_top", "--t-end", "1", "-o", str(page)], capture_output=True,
                         text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    html = eomgen.load("heavy_top").animate(t_end=1.0).html
    assert html == page.read_text(encoding="utf-8")
    # The 3-D view's canvas, three.js and the top's disc (its file's `draw: shapes:`).
    assert '<canvas id="view3d"' in html and 'id="three-gz"' in html
    assert '"solid":["cylinder",' in html


def test_a_failed_animation_keeps_its_frames(cli, tmp_path):
    page = tmp_path / "tp.html"
    out = subprocess.run([cli, "animate", "triple_pendulum", "--method", "rk4", "--dt", "0.5", "-o", str(page)],
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 1
    with pytest.raises(eomgen.IntegrationError) as info:
        eomgen.load("triple_pendulum").animate(method="rk4", dt=0.5)
    assert info.value.animation is not None
    assert info.value.animation.html == page.read_text(encoding="utf-8")


def test_animate_refuses_what_it_cannot_draw(model_file):
    with pytest.raises(ValueError, match="fps"):
        eomgen.load("double_pendulum").animate(fps=0.0)
    with pytest.raises(ValueError, match="no point"):
        eomgen.load("double_pendulum").animate(trace=["nowhere"])
    energy_form = "name: bare\nparameters: { k: 1.0 }\ncoordinates: [x]\nkinetic: x_dot^2/2\npotential: k*x^2/2\n"
    with pytest.raises(eomgen.AnalysisError, match="no points"):
        eomgen.load(model_file("bare", energy_form)).animate(t_end=1.0)


def test_a_terminal_event_ends_a_batch_run_without_failing_it():
    # The eccentric cylinder's `lift_off` event is terminal: the run ends there, not at t_end.
    m = eomgen.load("eccentric_cylinder")
    t_out = np.linspace(0.0, 10.0, 11)
    batch = m.simulate_many(initial_states=[m.initial_state()], t_end=10.0, t_out=t_out)
    single = m.simulate(t_end=10.0, t_out=t_out)
    (index, t, event), = batch.stopped_by_event
    assert (index, event) == (0, single.events[-1]["name"]) and single.events[-1]["terminal"]
    assert t == single.events[-1]["t"] == batch.t_final[0] < 10.0
    assert batch.ok[0] and not batch.failures
    reached = len(single.t)
    assert np.array_equal(batch.y[0, :reached], single.y)
    assert np.isnan(batch.y[0, reached:]).all()


def test_a_batch_refuses_shared_options_and_keeps_runs_that_cannot_start():
    m = eomgen.load("simple_pendulum_cartesian")
    y0 = m.initial_state()
    for keep in ("raise", "keep"):
        with pytest.raises(ValueError, match="outside"):
            m.simulate_many(initial_states=[y0, y0], t_end=1.0, t_out=[0.5, 2.0], errors=keep)
    bad = np.array([y0, [5.0, 5.0, 0.0, 0.0], y0])
    with pytest.raises(eomgen.AnalysisError, match="run 1"):
        m.simulate_many(initial_states=bad, t_end=1.0)
    batch = m.simulate_many(initial_states=bad, t_end=1.0, errors="keep")
    assert batch.ok.tolist() == [True, False, True]
    (index, t, reason), = batch.failures
    assert index == 1 and math.isnan(t) and "violates" in reason and "initial=" in reason
    assert np.isnan(batch.y[1]).all() and np.isfinite(batch.y[[0, 2]]).all()
    with pytest.raises(ValueError, match="threads"):
        m.simulate_many(initial_states=[y0], threads=0)
    with pytest.raises(ValueError, match="shape"):
        m.simulate_many(initial_states=np.zeros((2, 2, 4)))


def test_evaluations_refuse_values_that_are_not_finite():
    m = eomgen.load("double_pendulum")
    for call in (lambda: m.rhs(0.0, [math.nan, 0, 0, 0]), lambda: m.mass_matrix([math.nan, 0.0]),
                 lambda: m.forcing([0.0, 0.0], [math.inf, 0.0]), lambda: m.energy([0, 0, math.nan, 0]),
                 lambda: m.rhs(math.nan, [0, 0, 0, 0]), lambda: m.modes(at=[math.nan, 0.0])):
        with pytest.raises(ValueError, match="finite"):
            call()


def test_an_undamped_resonance_is_nan_in_an_array():
    # c = 0: |H| is unbounded at ω = ωn = 1; the amplitude array holds NaN there (the JSON's
    # null) and the closed form 1/|k − m ω²| elsewhere.
    m = eomgen.load("forced_oscillator").with_parameters(c=0.0)
    report = m.frf("A", frequency_range=(0.5, 2.0), points=3)
    amplitude = report["responses"][0]["amplitude"]
    assert isinstance(amplitude, np.ndarray) and np.isnan(amplitude[1])
    np.testing.assert_allclose(amplitude[[0, 2]], [1 / (1 - 0.25), 1 / (4 - 1)], rtol=1e-12)


def test_a_model_without_freedom_has_no_modes(model_file):
    text = ("name: fixed\nparameters: { m: 1.0, g: 10.0, l: 1.0 }\ncoordinates: [x, y]\n"
            "points: { O: [0, 0], P: [x, y] }\nbodies: { bob: { mass: m, at: P } }\ngravity: [0, -g]\n"
            "constraints: { cx: x - l, cy: y }\ninitial: { x: l, y: 0 }\n")
    m = eomgen.load(model_file("fixed", text))
    assert np.isfinite(m.simulate(t_end=1.0).y).all()
    with pytest.raises(eomgen.AnalysisError, match="no degree of freedom"):
        m.modes()


def test_the_docs_session_runs():
    # docs/python.md's "A session" block, run as written (its first Python block).
    import pathlib
    import re

    page = pathlib.Path(__file__).resolve().parents[2] / "docs" / "python.md"
    if not page.is_file():
        pytest.skip("docs/python.md is not beside the tests (an installed copy of the tests)")
    blocks = re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), re.S)
    session = next(b for b in blocks if "A session" in b or "m.check()" in b)
    namespace = {}
    exec(compile(session, str(page), "exec"), namespace)
    assert namespace["sol"].q.shape == (3, 2)
    # Hanging bars (m = l = 1, g = 10): M = [[4/3, 1/2], [1/2, 1/3]], K = diag(15, 5), so
    # ω⁴ − 60 ω² + 2700/7 = 0: the page's [2.7059…, 7.2579…].
    w2 = 30 + np.array([-1.0, 1.0]) * math.sqrt(900 - 2700 / 7)
    np.testing.assert_allclose(namespace["modes"].natural_frequencies, np.sqrt(w2), rtol=1e-12)


def test_state_space_of_the_forced_oscillator_is_its_closed_form():
    """``Model.state_space`` (``modes --input``): ``A = [0 1; -k/m -c/m]``, ``B = [0; 1/m]``."""
    model = eomgen.load("forced_oscillator").with_parameters(m=2.0, c=0.5, k=3.0)
    ss = model.state_space("A", outputs=["x", "x_dot"])
    np.testing.assert_allclose(ss["a"], [[0.0, 1.0], [-1.5, -0.25]], rtol=0, atol=1e-15)
    np.testing.assert_allclose(ss["b"], [[0.0], [0.5]], rtol=0, atol=1e-15)
    np.testing.assert_array_equal(ss["c"], np.eye(2))
    np.testing.assert_array_equal(ss["d"], np.zeros((2, 1)))
    assert ss["inputs"] == ["A"] and ss["outputs"] == ["x", "x_dot"]
    with pytest.raises(eomgen.AnalysisError, match="not a coordinate"):
        model.state_space("A", outputs=["y"])


def test_rich_displays_show_the_modes_the_verdict_and_the_run():
    """Jupyter's displays: the modes' table and verdict, a steady motion's eigenvalues, a
    solution's summary and last state; ``.eigenvalues`` of a steady motion hold each complex
    eigenvalue with its conjugate, as the state matrix's spectrum does."""
    modes = eomgen.load("double_pendulum").modes("hanging")
    page = modes._repr_html_()
    assert "<table>" in page and "marginally stable" in page and "2.705943" in page
    s = modes.state_eigenvalues
    assert len(s) == 4 and np.allclose(sorted(s.imag), [-7.257952078965088, -2.705943757628079, 2.705943757628079, 7.257952078965088])
    steady = eomgen.load("rolling_disc").modes()
    assert isinstance(steady, eomgen.SteadyMotion)
    full, half = steady.eigenvalues, steady.damped_eigenvalues
    assert len(full) == len(half) + int(np.sum(half.imag != 0.0))
    assert np.allclose(np.sort_complex(full), np.sort_complex(np.conj(full)))
    assert "<table>" in steady._repr_html_() and "stability" in steady._repr_html_()
    run = eomgen.load("double_pendulum").simulate(t_end=0.5)
    page = run._repr_html_()
    assert "double_pendulum" in page and "theta2" in page and f"{run.q[-1, 1]:.10g}" in page


def test_plots_draw_one_panel_per_coordinate():
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    run = eomgen.load("heavy_top").simulate(t_end=0.5)
    fig = run.plot(rates=True)
    assert len(fig.axes) == 2 * 3
    assert [ax.get_ylabel() for ax in fig.axes[::2]] == run.summary_header["coordinates"]
    fig = run.plot(["theta"])
    assert len(fig.axes) == 1
    with pytest.raises(ValueError, match="not a coordinate"):
        run.plot(["nope"])
    fig = eomgen.load("double_pendulum").modes("hanging").plot()
    assert len(fig.axes[0].lines) == 2 + 1
