"""The passive compass-gait walker's period-one gait, derived here from scratch with SymPy
(independently of eomgen): Goswami, Thuilot & Espiau, "Compass-like biped robot Part I:
Stability and bifurcation of passive gaits", INRIA RR-2996 (1996).

Model: planar, slope frame (x down the slope, y along its outward normal, gravity
(g sin gamma, -g cos gamma)), stance foot at the origin. theta is the stance leg's angle from
the slope normal, hip H = l(-sin theta, cos theta) (theta > 0: hip behind the foot); phi is the
angle between the legs, the swing leg's angle is theta - phi, swing foot
S = H + l(sin(theta - phi), -cos(theta - phi)). Point masses: M at the hip, m on the stance leg
at distance a from its foot, m on the swing leg at distance b from the hip; l = a + b.
m = 5, M = 10, a = b = 0.5, g = 9.81, gamma = pi/60 (3 degrees).

Swing phase: Lagrange's equations from T and V of the point masses. Heel strike: S_y falls
through 0 with theta < 0 (a terminal event on S_y, direction -1; at a crossing with
theta >= 0 -- the start of the step and the scuffing near mid-stance -- the integration is
resumed past it, 1 ms without events, then with the event again). Impact (plastic, no slip,
the old stance foot leaves the ground): angular momentum sum(r x m v) conserved (1) of the
whole walker about the landing foot and (2) of the old stance leg (the new swing leg) about
the hip; pre-impact velocities with the old stance foot fixed, post-impact ones with the new
one fixed, then theta+ = theta- - phi-, phi+ = -phi-.

The fixed point of the map on the state just after a heel strike (theta, theta', phi')
(phi = 2 theta there) is found from the guess (0.25, -1, -0.5) by Newton with a Jacobian by
central differences (h = 1e-6), integration by SciPy's DOP853 at rtol = atol = 1e-13; the
eigenvalues are those of that 3 x 3 Jacobian. Checks: the residual, and that the kinetic
energy lost at the strike equals the work of gravity over a step, (M + 2m) g sin(gamma) times
the centre of mass's displacement down the slope.

Run: python3 tools/compass_gait_reference.py   (needs numpy, scipy, sympy)
"""

import json
import sys
import time

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

m, M, a, b, g = 5.0, 10.0, 0.5, 0.5, 9.81
l = a + b
gamma = np.pi / 60


def points(th, ph):
    """Positions (stance foot at the origin) of stance-leg mass, hip, swing-leg mass, swing foot."""
    u = sp.Matrix([-sp.sin(th), sp.cos(th)])
    w = sp.Matrix([sp.sin(th - ph), -sp.cos(th - ph)])
    return [a * u, l * u, l * u + b * w, l * u + l * w]


def derive():
    t = sp.symbols("t")
    th, ph = sp.Function("theta")(t), sp.Function("phi")(t)
    q, qd, qdd = sp.Matrix([th, ph]), sp.Matrix([th, ph]).diff(t), sp.Matrix([th, ph]).diff(t, 2)
    p1, hip, p2, foot = points(th, ph)
    masses = [(m, p1), (M, hip), (m, p2)]
    T = sum(mi * p.diff(t).dot(p.diff(t)) for mi, p in masses) / 2
    V = sum(mi * g * (np.cos(gamma) * p[1] - np.sin(gamma) * p[0]) for mi, p in masses)
    L = T - V
    eqs = [sp.diff(L.diff(qdi), t) - L.diff(qi) for qi, qdi in zip(q, qd)]
    A = sp.Matrix([[e.diff(x) for x in qdd] for e in eqs])
    rhs = -sp.Matrix(eqs).subs({x: 0 for x in qdd})
    s = sp.symbols("th ph thd phd")
    sub2 = lambda e: e.subs({qdi: s[2 + i] for i, qdi in enumerate(qd)}).subs(dict(zip(q, s[:2])))
    acc = sp.lambdify(s, list(sub2(A.LUsolve(rhs))), "numpy")
    energy = sp.lambdify(s, [sub2(T), sub2(V)], "numpy")
    com_x = sp.lambdify(s[:2], sub2(sum(mi * p[0] for mi, p in masses) / (M + 2 * m)), "numpy")
    foot_f = sp.lambdify(s[:2], list(sub2(foot)), "numpy")

    # Impact: configuration (th, ph) before it; velocities before (thd, phd), after (u1, u2).
    th0, ph0, thd, phd, u1, u2 = sp.symbols("th0 ph0 thd phd u1 u2")
    cross = lambda r, v: r[0] * v[1] - r[1] * v[0]
    vel = lambda p, th_, ph_, w1, w2: p.jacobian([th_, ph_]) * sp.Matrix([w1, w2])
    pre = points(th0, ph0)                          # old stance foot at the origin
    S = pre[3]
    thn, phn = sp.symbols("thn phn")                # new labels, new stance foot at S
    post = [S + r for r in points(thn, phn)]        # new stance mass, hip, new swing mass
    at = {thn: th0 - ph0, phn: -ph0}
    v_pre = [vel(p, th0, ph0, thd, phd) for p in pre[:3]]
    v_post = [vel(p, thn, phn, u1, u2).subs(at) for p in post[:3]]
    post = [p.subs(at) for p in post[:3]]
    mass = [m, M, m]
    # (1) whole walker about the landing foot S
    L1_pre = sum(mi * cross(r - S, v) for mi, r, v in zip(mass, pre[:3], v_pre))
    L1_post = sum(mi * cross(r - S, v) for mi, r, v in zip(mass, post, v_post))
    # (2) old stance leg (mass pre[0], post[2]) about the hip
    L2_pre = m * cross(pre[0] - pre[1], v_pre[0])
    L2_post = m * cross(post[2] - post[1], v_post[2])
    sol = sp.solve([L1_pre - L1_post, L2_pre - L2_post], [u1, u2], dict=True)[0]
    impact = sp.lambdify((th0, ph0, thd, phd), [sol[u1], sol[u2]], "numpy")
    return acc, energy, com_x, foot_f, impact


ACC, ENERGY, COM_X, FOOT, IMPACT = derive()


def f(_t, y):
    return [y[2], y[3], *ACC(*y)]


def strike(_t, y):
    return FOOT(y[0], y[1])[1]


strike.terminal = True
strike.direction = -1
OPTS = dict(method="DOP853", rtol=1e-13, atol=1e-13)


def swing(y0):
    """Integrate from y0 to the heel strike: (time, state just before it)."""
    t, y = 0.0, np.array(y0, dtype=float)
    while t < 5:
        sol = solve_ivp(f, [t, t + 10], y, events=strike, **OPTS)
        if not sol.t_events[0].size:
            raise RuntimeError("no heel strike")
        t, y = sol.t_events[0][0], sol.y_events[0][0]
        if y[0] < 0:
            return t, y
        sol = solve_ivp(f, [t, t + 1e-3], y, **OPTS)   # past the crossing with theta >= 0
        t, y = sol.t[-1], sol.y[:, -1]
    raise RuntimeError("no heel strike")


def step(x):
    """The map: (theta, theta', phi') just after a heel strike -> the same after the next."""
    t, y = swing([x[0], 2 * x[0], x[1], x[2]])
    u = IMPACT(*y)
    return np.array([y[0] - y[1], u[0], u[1]]), t, y


def jacobian(x, h=1e-6):
    j = np.zeros((3, 3))
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        j[:, k] = (step(x + e)[0] - step(x - e)[0]) / (2 * h)
    return j


def gait(x):
    for _ in range(30):
        r = step(x)[0] - x
        if np.max(np.abs(r)) < 1e-12:
            return x
        x = x - np.linalg.solve(jacobian(x) - np.eye(3), r)
    raise RuntimeError("Newton did not converge")


def main():
    t0 = time.perf_counter()
    guess = np.array([0.25, -1.0, -0.5])   # the best of a coarse grid over the brief's region
    x = gait(guess)
    end, period, y = step(x)
    eig = sorted(np.linalg.eigvals(jacobian(x)), key=lambda z: (-abs(z), -z.imag))
    T_minus = ENERGY(*y)[0]
    T_plus = ENERGY(end[0], 2 * end[0], end[1], end[2])[0]
    lost = T_minus - T_plus
    dx = COM_X(y[0], y[1]) - COM_X(x[0], 2 * x[0])
    work = (M + 2 * m) * g * np.sin(gamma) * dx
    residual = float(np.max(np.abs(end - x)))
    assert residual < 1e-12 and abs(lost - work) < 1e-9, (residual, lost - work)
    print(json.dumps({
        "gamma": gamma,
        "theta": x[0], "phi": 2 * x[0], "theta_dot": x[1], "phi_dot": x[2],
        "period": period, "residual": residual,
        "eigenvalues": [[z.real, z.imag] for z in eig],
        "energy_lost": lost, "step_length": float(np.hypot(*FOOT(y[0], y[1]))),
        "gravity_work_per_step": work,
    }, indent=2))
    print(f"guess {guess.tolist()}, {time.perf_counter() - t0:.2f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
