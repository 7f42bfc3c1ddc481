"""Kinematics on demand of the Whipple bicycle (`models/whipple_bicycle.yaml`) against SymPy.

`python/tests/test_kinematics.py` holds `eomgen kinematics` to `sympy.physics.mechanics` on the
small bundled 3-D models; the bicycle's SymPy expressions take about a minute and a half to
build and evaluate, so its comparison runs here, on demand. The frames and points are built
from the model file as SymPy writes them (`orient_axis` chains; the front contact `CF`, a
`wheel:` point, as the centre less `rF` times the unit vector of `N.z` in the wheel's plane).
Each frame's angular velocity (in its own and in the ground's components), angular
acceleration and partial angular velocities, and each point's position, velocity,
acceleration and partial velocities, are compared at 3 random states (coordinates, rates,
accelerations and parameters in [-2, 2]) to 1e-12 relative to each vector's size. An entry
eomgen does not print (too large as a tree) is named and skipped.

    python3 tools/bicycle_kinematics_reference.py [--eomgen target/release/eomgen]

Measured on 2026-11-28: 164 vectors compared, the worst difference 9.3e-16; skipped: the
acceleration of `CF` (46,158 operations as a tree).
"""

import argparse
import json
import re
import subprocess

import numpy as np
import sympy as sp
from sympy.physics import mechanics as me


def kinematics_pairs(listing, N, frames, points, coordinates, rates):
    """Every vector of `eomgen kinematics --partial --json` beside SymPy's: a list of (what,
    eomgen's components as text, SymPy's components), for the frames `frames` and points
    `points` of a model whose ground frame is `N` and whose rates are `rates` (shared with
    python/tests/test_kinematics.py). Fails if the listing names other frames or points."""
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
    return pairs


def bicycle(q, p):
    """The model file's frames and points in SymPy: `(N, frames, points)`."""
    N = me.ReferenceFrame("N")
    frames = {}

    def frame(name, parent, axis, angle):
        f = me.ReferenceFrame(name)
        f.orient_axis(parent, axis, angle)
        frames[name] = f
        return f

    Y = frame("Y", N, N.z, q["yaw"])
    L = frame("L", Y, Y.x, q["lean"])
    B = frame("B", L, L.y, q["pitch"])
    S = frame("S", B, B.y, -p["lambda"])
    H = frame("H", S, S.z, q["steer"])
    frame("HG", H, H.y, p["lambda"])
    frame("WR", B, B.y, q["rear_wheel"])
    frame("WF", H, H.y, q["front_wheel"])
    lam, c, w, rR, rF = p["lambda"], p["c"], p["w"], p["rR"], p["rF"]
    P = q["x"] * N.x + q["y"] * N.y
    RH = P + rR * L.z
    GB = RH + p["xB"] * B.x + (p["zB"] - rR) * B.z
    A = RH + (w + c) * B.x - rR * B.z
    FH = A + (rF * sp.sin(lam) - c * sp.cos(lam)) * H.x + (c * sp.sin(lam) + rF * sp.cos(lam)) * H.z
    xh = p["xH"] - w - c
    GH = A + (xh * sp.cos(lam) + p["zH"] * sp.sin(lam)) * H.x + (p["zH"] * sp.cos(lam) - xh * sp.sin(lam)) * H.z
    down = N.z - N.z.dot(H.y) * H.y
    CF = FH - rF * down / sp.sqrt(down.dot(down))
    return N, frames, {"P": P, "RH": RH, "GB": GB, "A": A, "FH": FH, "GH": GH, "CF": CF}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--eomgen", default="target/release/eomgen")
    args = parser.parse_args()
    out = subprocess.run(
        [args.eomgen, "kinematics", "whipple_bicycle", "--partial", "--json"],
        check=True, capture_output=True, text=True)
    listing = json.loads(out.stdout)
    coordinates = listing["coordinates"]
    # The geometry the frames and points read (the kinematics take no masses or inertias).
    params = {name: sp.Symbol(name) for name in ("lambda", "c", "w", "rR", "rF", "xB", "zB", "xH", "zH")}
    t = me.dynamicsymbols._t
    q = {c: me.dynamicsymbols(c) for c in coordinates}
    N, frames, points = bicycle(q, params)
    plain = {}
    for c in coordinates:
        plain[q[c].diff(t, 2)] = sp.Symbol(c + "_ddot")
        plain[q[c].diff(t)] = sp.Symbol(c + "_dot")
        plain[q[c]] = sp.Symbol(c)
    names = {str(s): s for s in plain.values()} | dict(params)
    names["t"] = sp.Symbol("t")
    rates = [q[c].diff(t) for c in coordinates]
    pairs = kinematics_pairs(listing, N, frames, points, coordinates, rates)
    skipped = [w for w, mine, _ in pairs if any(e.startswith("[not printed") for e in mine)]
    pairs = [pair for pair in pairs if pair[0] not in skipped]
    # `lambda` (the head angle) is a Python keyword: parsed under another name.
    local = dict(names)
    local["lambda_"] = params["lambda"]
    mine = [sp.parse_expr(re.sub(r"\blambda\b", "lambda_", e.replace("^", "**")), local_dict=local)
            for _, m, _ in pairs for e in m]
    theirs = [sp.sympify(e).subs(plain) for _, _, th in pairs for e in th]
    symbols = sorted(names.values(), key=str)
    f_mine = sp.lambdify(symbols, mine, "numpy", dummify=True)
    f_theirs = sp.lambdify(symbols, theirs, "numpy", dummify=True)
    rng = np.random.default_rng(7)
    worst = 0.0
    for _ in range(3):
        values = [float(rng.uniform(-2, 2)) for _ in symbols]
        a = np.array(f_mine(*values), dtype=float)
        b = np.array(f_theirs(*values), dtype=float)
        k = 0
        for what, m, _ in pairs:
            n = len(m)
            scale = max(1.0, float(np.max(np.abs(b[k:k + n]))))
            error = float(np.max(np.abs(a[k:k + n] - b[k:k + n]))) / scale
            assert error <= 1e-12, (what, a[k:k + n], b[k:k + n])
            worst = max(worst, error)
            k += n
    print(f"{len(pairs)} vectors equal SymPy's at 3 states, the worst difference {worst:.2e}; "
          f"skipped (not printed): {', '.join(skipped) or 'none'}")


if __name__ == "__main__":
    main()
