"""SymPy mechanics (Kane's method) on the n-link pendulum of `eomgen new n-link-pendulum N`,
for a side-by-side derivation-time and operation-count comparison (issue 4). Not used by
the product.

Same model: uniform bars (m = l = 1), absolute angles from +x, centroidal inertia m l^2/12,
gravity -y. Reports the wall time of KanesMethod.kanes_equations (derivation of M and F only,
no Jacobians) and the operation count of M and F after sympy.cse.

Run: python3 tools/sympy_n_link.py 2 5 10
"""
import sys
import time

import sympy as sm
import sympy.physics.mechanics as me


def derive(n):
    q = me.dynamicsymbols(f"q1:{n + 1}")
    u = me.dynamicsymbols(f"u1:{n + 1}")
    m, l, g = sm.symbols("m l g")
    N = me.ReferenceFrame("N")
    O = me.Point("O")
    O.set_vel(N, 0)
    bodies, loads = [], []
    joint = O
    for i in range(n):
        A = me.ReferenceFrame(f"A{i}")
        A.orient_axis(N, N.z, q[i])
        A.set_ang_vel(N, u[i] * N.z)
        G = joint.locatenew(f"G{i}", l / 2 * A.x)
        G.v2pt_theory(joint, N, A)
        P = joint.locatenew(f"P{i}", l * A.x)
        P.v2pt_theory(joint, N, A)
        I = me.inertia(A, 0, 0, m * l**2 / 12)
        bodies.append(me.RigidBody(f"B{i}", G, A, m, (I, G)))
        loads.append((G, -m * g * N.y))
        joint = P
    kd = [qi.diff() - ui for qi, ui in zip(q, u)]
    start = time.perf_counter()
    kane = me.KanesMethod(N, q_ind=q, u_ind=u, kd_eqs=kd)
    kane.kanes_equations(bodies, loads)
    derive_s = time.perf_counter() - start
    M, F = kane.mass_matrix, kane.forcing
    start = time.perf_counter()
    replacements, reduced = sm.cse([M, F])
    cse_s = time.perf_counter() - start
    ops = sum(sm.count_ops(e) for _, e in replacements) + sum(sm.count_ops(e) for e in reduced)
    return derive_s, cse_s, ops


for arg in sys.argv[1:]:
    n = int(arg)
    d, c, ops = derive(n)
    print(f"n={n}: KanesMethod {d:.3f} s, cse {c:.3f} s, {ops} operations after cse")
    sys.stdout.flush()
