"""Kinematics on demand (``Model.kinematics``, ``eomgen kinematics``) against SymPy's
``sympy.physics.mechanics`` on the bundled 3-D models: each frame's angular velocity in its
own and in the ground's components and its angular acceleration (``F.ang_vel_in(N)``,
``F.ang_acc_in(N)``), each point's position, velocity and acceleration (``r.dt(N)`` twice) and
the partial velocities (``partial_velocity``), built from the model files' frames and points
as SymPy writes them, and compared at random states to 1e-12 (relative to each vector's
size)."""

import json
import pathlib
import sys

import numpy as np
import pytest

import eomgen

sp = pytest.importorskip("sympy")
me = pytest.importorskip("sympy.physics.mechanics")
# The pairs of vectors compared, shared with tools/bicycle_kinematics_reference.py.
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "tools"))
from bicycle_kinematics_reference import kinematics_pairs  # noqa: E402


def _heavy_top(q, p):
    N = me.ReferenceFrame("N")
    B = me.ReferenceFrame("B")
    B.orient_body_fixed(N, (q["phi"], q["theta"], q["psi"]), "zxz")
    O = me.Point("O")
    return N, {"B": B}, {"O": 0 * N.x, "G": p["l"] * B.z}


def _free_rigid_body(q, p):
    N = me.ReferenceFrame("N")
    B = me.ReferenceFrame("B")
    B.orient_body_fixed(N, (q["phi"], q["theta"], q["psi"]), "zxy")
    return N, {"B": B}, {"O": 0 * N.x, "X": B.x, "Y": B.y, "Z": B.z}


def _furuta_pendulum(q, p):
    N = me.ReferenceFrame("N")
    A = me.ReferenceFrame("A")
    A.orient_axis(N, N.z, q["phi"])
    P = me.ReferenceFrame("P")
    P.orient_axis(A, A.x, q["theta"])
    r, l = p["r"], p["l"]
    T = r * A.x
    return N, {"A": A, "P": P}, {
        "O": 0 * N.x, "G1": r / 2 * A.x, "T": T, "G2": T - l / 2 * P.z, "E": T - l * P.z}


def _rolling_disc(q, p):
    N = me.ReferenceFrame("N")
    Y = me.ReferenceFrame("Y")
    Y.orient_axis(N, N.z, q["yaw"])
    L = me.ReferenceFrame("L")
    L.orient_axis(Y, Y.x, q["lean"])
    R = me.ReferenceFrame("R")
    R.orient_axis(L, L.y, q["spin"])
    r = p["r"]
    C = q["x"] * N.x + q["y"] * N.y
    G = C + r * L.z
    return N, {"Y": Y, "L": L, "R": R}, {"C": C, "G": G, "T": G + r * R.z}


MODELS = {
    "heavy_top": _heavy_top,
    "free_rigid_body": _free_rigid_body,
    "furuta_pendulum": _furuta_pendulum,
    "rolling_disc": _rolling_disc,
}


@pytest.mark.parametrize("name", sorted(MODELS))
def test_kinematics_equal_sympys(name):
    model = eomgen.load(name)
    listing = model.kinematics(partial=True)
    coordinates = listing["coordinates"]
    params = {p: sp.Symbol(p) for p in model.parameters}
    t = me.dynamicsymbols._t
    q = {c: me.dynamicsymbols(c) for c in coordinates}
    N, frames, points = MODELS[name](q, params)
    # Plain symbols for q, q̇, q̈ (named as eomgen names them), for substitution and parsing.
    plain = {}
    for c in coordinates:
        plain[q[c].diff(t, 2)] = sp.Symbol(c + "_ddot")
        plain[q[c].diff(t)] = sp.Symbol(c + "_dot")
        plain[q[c]] = sp.Symbol(c)
    names = {str(s): s for s in plain.values()} | {k: v for k, v in params.items()}
    names["t"] = sp.Symbol("t")

    def flat(expr):
        return sp.sympify(expr).subs(plain)

    def parse(text):
        return sp.parse_expr(text.replace("^", "**"), local_dict=names)

    rates = [q[c].diff(t) for c in coordinates]
    # Parsed and flattened once; each sample then replaces the symbols by numbers
    # (`xreplace`, which rebuilds the tree once and evaluates as it goes, rather than `subs`,
    # which matches subexpressions and rebuilds after each substitution: the same numbers, up
    # to the order of rounding, in a fraction of the time).
    pairs = [(what, [parse(e) for e in mine], [flat(e) for e in theirs])
             for what, mine, theirs in kinematics_pairs(listing, N, frames, points, coordinates, rates)]
    symbols = sorted(names.values(), key=str)
    rng = np.random.default_rng(7)
    for _ in range(3):
        values = {s: sp.Float(rng.uniform(-2, 2)) for s in symbols}
        for what, mine, theirs in pairs:
            a = np.array([float(e.xreplace(values)) for e in mine])
            b = np.array([float(e.xreplace(values)) for e in theirs])
            scale = max(1.0, float(np.max(np.abs(b))))
            assert np.max(np.abs(a - b)) <= 1e-12 * scale, (what, a, b)


def test_kinematics_from_the_command_line_and_unknown_names(cli):
    import subprocess

    out = subprocess.run([cli, "kinematics", "heavy_top", "--frame", "B", "--json"],
                         capture_output=True, text=True, check=True)
    listing = json.loads(out.stdout)
    mine = eomgen.load("heavy_top").kinematics(frames=["B"])
    assert listing["frames"] == mine["frames"] and listing["points"] == mine["points"]
    assert "omega (N components) = [theta_dot*cos(phi) + psi_dot*sin(theta)*sin(phi)" in mine["text"]
    bad = subprocess.run([cli, "kinematics", "heavy_top", "--point", "Q"], capture_output=True, text=True)
    assert bad.returncode == 2 and "has no point `Q` (its points: O, G)" in bad.stderr
    with pytest.raises(ValueError, match="no frame `Z`"):
        eomgen.load("heavy_top").kinematics(frames=["Z"])


def _evaluate(texts, names, values):
    return np.array([float(sp.parse_expr(e.replace("^", "**"), local_dict=names).subs(values))
                     for e in texts])


def _names(model, coordinates):
    names = {p: sp.Symbol(p) for p in model.parameters}
    for c in coordinates:
        for suffix in ("", "_dot", "_ddot"):
            names[c + suffix] = sp.Symbol(c + suffix)
    return names


def test_the_heavy_tops_pivot_reaction():
    """The heavy top's pivot at O is a ball joint: with the accelerations the equations of
    motion give (``Model.rhs``) at random states, the reaction's moment about O vanishes (to
    1e-12 of the weight's moment ``m g l``), and its force is ``m a_G − m g`` with ``a_G``
    SymPy's second derivative of ``G``'s position."""
    m = eomgen.load("heavy_top")
    listing = m.kinematics(frames=[], points=["G"], reactions=[("top", "O")])
    (reaction,) = listing["reactions"]
    assert reaction["bodies"] == ["top"] and reaction["at"] == "O"
    coordinates = listing["coordinates"]
    names = _names(m, coordinates)
    p = m.parameters
    rng = np.random.default_rng(3)
    t = me.dynamicsymbols._t
    q = {c: me.dynamicsymbols(c) for c in coordinates}
    N, _, points = _heavy_top(q, {"l": p["l"]})
    a_g = points["G"].dt(N).dt(N).to_matrix(N)
    for _ in range(3):
        state = np.concatenate([rng.uniform(0.3, 1.2, 3), rng.uniform(-2, 2, 3)])
        qdd = m.rhs(0.0, state)[3:]
        values = {names[k]: v for k, v in p.items()}
        subs = {}
        for i, c in enumerate(coordinates):
            values[names[c]], values[names[c + "_dot"]], values[names[c + "_ddot"]] = state[i], state[3 + i], qdd[i]
            subs.update({q[c].diff(t, 2): qdd[i], q[c].diff(t): state[3 + i], q[c]: state[i]})
        moment = _evaluate(reaction["moment"], names, values)
        assert np.max(np.abs(moment)) < 1e-12 * p["m"] * p["g"] * p["l"], moment
        force = _evaluate(reaction["force"], names, values)
        want = p["m"] * np.array([float(c.subs(subs)) for c in a_g]) - p["m"] * np.array([0, 0, -p["g"]])
        assert np.allclose(force, want, rtol=0, atol=1e-12 * p["m"] * p["g"]), (force, want)


def test_the_rolling_discs_contact_reaction_is_its_constraint_force():
    """The rolling disc's reaction at its contact C: along the ground it is the rolling
    constraint's force, ``−λ`` (the multipliers of a simulation, where ``M q̈ = F − Jᵀλ``),
    vertically ``m (a_Gz + g)``, and its moment about C vanishes (a point contact), at three
    samples of a run, to 1e-9 of the weight (the run's rtol)."""
    m = eomgen.load("rolling_disc")
    listing = m.kinematics(frames=[], points=[], reactions=[("disc", "C")])
    (reaction,) = listing["reactions"]
    coordinates = listing["coordinates"]
    names = _names(m, coordinates)
    p = m.parameters
    run = m.simulate(t_end=1.0, rtol=1e-11, atol=1e-11)
    n = len(coordinates)
    weight = p["m"] * p["g"]
    for k in (0, len(run.t) // 2, len(run.t) - 1):
        state = np.concatenate([run.q[k], run.qdot[k]])
        qdd = m.rhs(run.t[k], state)[n:]
        values = {names[c]: v for c, v in p.items()}
        for i, c in enumerate(coordinates):
            values[names[c]], values[names[c + "_dot"]], values[names[c + "_ddot"]] = state[i], state[n + i], qdd[i]
        force = _evaluate(reaction["force"], names, values)
        lam = run.lagrange_multipliers[k]
        assert np.allclose(force[:2], -lam, rtol=0, atol=1e-9 * weight), (force, lam)
        assert force[2] > 0.5 * weight
        moment = _evaluate(reaction["moment"], names, values)
        assert np.max(np.abs(moment)) < 1e-9 * weight * p["r"], moment
    with pytest.raises(ValueError, match="no body `wheel`"):
        m.kinematics(reactions=[("wheel", "C")])
    # "BODY@POINT" is the same request; loads the file does not attribute to bodies (a
    # written potential, a spring) are refused rather than counted as a reaction.
    assert m.kinematics(reactions=["disc@C"])["reactions"] == listing["reactions"]
    with pytest.raises(ValueError, match="written potential"):
        eomgen.load("central_force").kinematics(reactions=["particle@O"])
