"""Kinematics on demand (``Model.kinematics``, ``eomgen kinematics``) against SymPy's
``sympy.physics.mechanics`` on the bundled 3-D models: each frame's angular velocity in its
own and in the ground's components and its angular acceleration (``F.ang_vel_in(N)``,
``F.ang_acc_in(N)``), each point's position, velocity and acceleration (``r.dt(N)`` twice) and
the partial velocities (``partial_velocity``), built from the model files' frames and points
as SymPy writes them, and compared at random states to 1e-12 (relative to each vector's
size)."""

import json

import numpy as np
import pytest

import eomgen

sp = pytest.importorskip("sympy")
me = pytest.importorskip("sympy.physics.mechanics")


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
    pairs = []  # (what, eomgen's components, SymPy's components)
    for f in listing["frames"]:
        F = frames[f["name"]]
        w = F.ang_vel_in(N)
        pairs.append((f"omega {f['name']}", f["angular_velocity"], w.to_matrix(F)))
        pairs.append((f"omega {f['name']} in N", f["angular_velocity_ground"], w.to_matrix(N)))
        pairs.append((f"alpha {f['name']}", f["angular_acceleration"], F.ang_acc_in(N).to_matrix(F)))
        partials = me.partial_velocity([w], rates, N)[0]
        for c, mine, theirs in zip(coordinates, f["partial_angular_velocities"], partials):
            pairs.append((f"d omega {f['name']}/d {c}_dot", mine, theirs.to_matrix(F)))
    assert {f["name"] for f in listing["frames"]} == set(frames)
    for pt in listing["points"]:
        r = points[pt["name"]]
        v = r.dt(N)
        pairs.append((f"r {pt['name']}", pt["position"], r.to_matrix(N)))
        pairs.append((f"v {pt['name']}", pt["velocity"], v.to_matrix(N)))
        pairs.append((f"a {pt['name']}", pt["acceleration"], v.dt(N).to_matrix(N)))
        partials = me.partial_velocity([v], rates, N)[0]
        for c, mine, theirs in zip(coordinates, pt["partial_velocities"], partials):
            pairs.append((f"d v {pt['name']}/d {c}_dot", mine, theirs.to_matrix(N)))
    assert {p["name"] for p in listing["points"]} == set(points)
    symbols = sorted(names.values(), key=str)
    rng = np.random.default_rng(7)
    for _ in range(3):
        values = {s: float(rng.uniform(-2, 2)) for s in symbols}
        for what, mine, theirs in pairs:
            a = np.array([float(parse(e).subs(values)) for e in mine])
            b = np.array([float(flat(e).subs(values)) for e in theirs])
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
