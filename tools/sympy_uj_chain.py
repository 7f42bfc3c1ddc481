"""SymPy's Kane's method on the chain of `eomgen new universal-joint-chain N`, beside
`eomgen check` of the same file, in one interleaved run (issue 52). Not used by the product.

Same model as `symbolic/src/model/templates.rs` (`universal_joint_chain`): N equal bars
hanging from a fixed point O; bar i turns from bar i - 1 (the ground for i = 1) by a_i about
x and then b_i about the new y (relative angles); its centre of mass G_i is half a length down
its z axis and the next joint P_i a length down; inertia about G_i diag(m l^2/12, m l^2/12,
m w^2/6) in the bar's frame; gravity g along -z. SymPy builds the same frames with
`orientnew('Axis', ...)`, the points with `locatenew` and their velocities with `v2pt_theory`,
and derives M and F with `KanesMethod.kanes_equations` (generalized speeds u = q').

For each N it prints the wall time of SymPy's derivation (frames, velocities and
`kanes_equations`) and of the whole `eomgen check FILE` process (both of eomgen's
derivations, their cross-check at 200 states and the power balance; one thread, as SymPy),
the median of --reps runs of each, alternated, and their ratio. eomgen's check does more than SymPy's derivation,
so the ratio understates eomgen's lead.

Run: python3 tools/sympy_uj_chain.py [--eomgen target/release/eomgen] [--reps 3] 2 3 4
"""
import argparse
import os
import statistics
import subprocess
import tempfile
import time

import sympy as sm
import sympy.physics.mechanics as me


def kane(n):
    """SymPy's Kane's method on the n-joint chain; returns (M, F)."""
    a = me.dynamicsymbols(f"a1:{n + 1}")
    b = me.dynamicsymbols(f"b1:{n + 1}")
    ua = me.dynamicsymbols(f"ua1:{n + 1}")
    ub = me.dynamicsymbols(f"ub1:{n + 1}")
    m, l, w, g = sm.symbols("m l1 w g")
    ground = me.ReferenceFrame("N")
    origin = me.Point("O")
    origin.set_vel(ground, 0)
    parent, joint = ground, origin
    q, u, kd, bodies, loads = [], [], [], [], []
    for i in range(n):
        # Angular velocities as the generalized speeds, so that each frame's is known.
        mid = parent.orientnew(f"A{i + 1}", "Axis", (a[i], parent.x))
        mid.set_ang_vel(parent, ua[i] * parent.x)
        frame = mid.orientnew(f"B{i + 1}", "Axis", (b[i], mid.y))
        frame.set_ang_vel(mid, ub[i] * mid.y)
        centre = joint.locatenew(f"G{i + 1}", -l / 2 * frame.z)
        centre.v2pt_theory(joint, ground, frame)
        end = joint.locatenew(f"P{i + 1}", -l * frame.z)
        end.v2pt_theory(joint, ground, frame)
        inertia = me.inertia(frame, m * l**2 / 12, m * l**2 / 12, m * w**2 / 6)
        bodies.append(me.RigidBody(f"bar{i + 1}", centre, frame, m, (inertia, centre)))
        loads.append((centre, -m * g * ground.z))
        q += [a[i], b[i]]
        u += [ua[i], ub[i]]
        kd += [a[i].diff() - ua[i], b[i].diff() - ub[i]]
        parent, joint = frame, end
    method = me.KanesMethod(ground, q_ind=q, u_ind=u, kd_eqs=kd)
    method.kanes_equations(bodies, loads)
    return method.mass_matrix, method.forcing


def sympy_seconds(n):
    start = time.perf_counter()
    kane(n)
    return time.perf_counter() - start


def eomgen_seconds(binary, path):
    start = time.perf_counter()
    subprocess.run([binary, "check", path], check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sizes", type=int, nargs="+")
    parser.add_argument("--eomgen", default="target/release/eomgen")
    parser.add_argument("--reps", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        print("| joints | SymPy Kane (s) | eomgen check (s) | SymPy / eomgen |")
        print("|---|---|---|---|")
        for n in args.sizes:
            path = os.path.join(tmp, f"chain{n}.yaml")
            with open(path, "w") as f:
                f.write(
                    subprocess.run(
                        [args.eomgen, "new", "universal-joint-chain", str(n)],
                        check=True,
                        capture_output=True,
                        text=True,
                    ).stdout
                )
            s, e = [], []
            for _ in range(args.reps):
                s.append(sympy_seconds(n))
                e.append(eomgen_seconds(args.eomgen, path))
            s, e = statistics.median(s), statistics.median(e)
            ratio = s / e if e > 0 else float("inf")
            print(f"| {n} | {s:.2f} | {e:.3f} | {ratio:.0f} |", flush=True)


if __name__ == "__main__":
    main()
