"""Independent reference values for the models with rheonomic constraints and with body
angles nonlinear in q or driven in time (not used by the product).

Each model is derived here from scratch with SymPy (positions -> velocities -> T, V ->
Lagrange's equations, or Newton's law in polar coordinates), and the closed forms that the
model files' `checks:` state are verified symbolically or computed by quadrature (mpmath):

- bead_spinning_rod: a bead on a rod spun at a constant rate w about a fixed pivot, no
  gravity; Cartesian (x, y) with the rheonomic constraint x sin(w t) - y cos(w t) = 0.
  Verified: r(t) = r0 cosh(w t) solves r'' = w^2 r; x, y and their rates at t = 1/w; the
  constraint force lambda = 2 m w^2 r0 sinh(w t) (Coriolis, m a_theta = 2 m w r'), with the
  sign convention M q'' = F - J^T lambda; the Jacobi integral m v^2/2 - m w^2 r^2.
- slider_crank: crank (uniform bar r, m1) about O, connecting rod (uniform bar l, m2) at
  angle phi = -asin(r sin(theta)/l), slider m3 on the x axis, gravity -y. Verified: the
  generalized inertia M(theta) at theta = -pi/2 is r^2 (m1/3 + m2 + m3) (the rod translates
  there), the natural frequency about the hanging equilibrium theta = -pi/2, and the period
  of the release from theta = 0 at rest (swinging to theta = -pi and back) by quadrature of
  T = 2 int_{-pi}^{0} sqrt(M(theta)/(2 (E - V(theta)))) dtheta.
- rocking_disc_pendulum: a uniform bar (m, L) hinged at the centre O of a disc that is
  rocked to the angle A sin(W t); theta is the bar's angle relative to the disc (the bar's
  absolute angle is theta + A sin(W t)), gravity -y. Verified: Lagrange's equation equals
  I_O (theta'' - A W^2 sin(W t)) = -m g (L/2) sin(theta + A sin(W t)); the absolute energy
  is conserved; the period of the absolute angle for the release phi(0) = pi/2,
  phi'(0) = 0 is 4 sqrt(2 L/(3 g)) K(1/sqrt 2).

Run: python3 tools/new_models_reference.py
Compare: cargo run -- report --models bead_spinning_rod,slider_crank,rocking_disc_pendulum
"""
import mpmath as mp
import sympy as sp

t = sp.symbols("t", real=True)


def lagrange(T, V, q):
    """Lagrange's equation d/dt(dL/dq') - dL/dq for one coordinate function q(t)."""
    L = T - V
    return sp.diff(sp.diff(L, q.diff(t)), t) - sp.diff(L, q)


# --- bead_spinning_rod ---------------------------------------------------------------
m, w, r0 = sp.symbols("m w r0", positive=True)
r = r0 * sp.cosh(w * t)
assert sp.simplify(r.diff(t, 2) - w**2 * r) == 0        # 1-dof twin: m r'' = m w^2 r
x = r * sp.cos(w * t)
y = r * sp.sin(w * t)
assert sp.simplify(x * sp.sin(w * t) - y * sp.cos(w * t)) == 0   # stays on the rod
# Newton with M q'' = F - J^T lambda, J = (sin wt, -cos wt): m x'' = -lambda sin, m y'' = lambda cos.
lam = 2 * m * w**2 * r0 * sp.sinh(w * t)
assert sp.simplify(m * x.diff(t, 2) + lam * sp.sin(w * t)) == 0
assert sp.simplify(m * y.diff(t, 2) - lam * sp.cos(w * t)) == 0
jacobi = m * (x.diff(t) ** 2 + y.diff(t) ** 2) / 2 - m * w**2 * (x**2 + y**2)
assert sp.simplify(jacobi.diff(t)) == 0
at = {m: 1, w: 1, r0: 1, t: 1}
print("bead_spinning_rod (m = w = r0 = 1), t = 1:")
for name, e in [("x", x), ("y", y), ("x_dot", x.diff(t)), ("y_dot", y.diff(t)),
                ("lambda_rod", lam), ("Jacobi integral", jacobi)]:
    print(f"  {name:16} = {sp.N(e.subs(at), 17)}")

# --- slider_crank ----------------------------------------------------------------------
rc, l, m1, m2, m3, g = sp.symbols("r l m1 m2 m3 g", positive=True)
th = sp.Function("theta")(t)
phi = -sp.asin(rc * sp.sin(th) / l)                     # rod angle
B = sp.Matrix([rc * sp.cos(th), rc * sp.sin(th)])       # crank pin
C = B + l * sp.Matrix([sp.cos(phi), sp.sin(phi)])       # slider (C_y = 0)
assert sp.simplify(C[1]) == 0
G1, G2 = B / 2, (B + C) / 2
v = lambda P: P.diff(t)
T = (m1 * v(G1).dot(v(G1)) + m1 * rc**2 / 12 * th.diff(t) ** 2
     + m2 * v(G2).dot(v(G2)) + m2 * l**2 / 12 * phi.diff(t) ** 2
     + m3 * v(C).dot(v(C))) / 2
V = g * (m1 * G1[1] + m2 * G2[1])
thd, s = sp.symbols("thd s")
Mth = sp.simplify(2 * T.subs(th.diff(t), thd).subs(th, s) / thd**2)   # M(theta)
Vs = V.subs(th, s)
M_hang = sp.simplify(Mth.subs(s, -sp.pi / 2))
assert sp.simplify(M_hang - rc**2 * (m1 / 3 + m2 + m3)) == 0
assert sp.simplify(Vs.diff(s).subs(s, -sp.pi / 2)) == 0
omega2 = sp.simplify(Vs.diff(s, 2).subs(s, -sp.pi / 2) / M_hang)
assert sp.simplify(omega2 - g * (m1 + m2) / (2 * rc * (m1 / 3 + m2 + m3))) == 0
vals = {rc: sp.Rational(1, 10), l: sp.Rational(3, 10), m1: 1, m2: 1, m3: 1, g: sp.Rational(981, 100)}
print("slider_crank (r = 0.1, l = 0.3, m1 = m2 = m3 = 1, g = 9.81):")
print(f"  M(-pi/2)         = {sp.N(M_hang.subs(vals), 17)}  (r^2 (m1/3 + m2 + m3))")
print(f"  omega (hanging)  = {sp.N(sp.sqrt(omega2.subs(vals)), 17)} rad/s")
# Release from theta = 0 at rest: E = V(0) = 0; turning points 0 and -pi.
mp.mp.dps = 30
Mf = sp.lambdify(s, Mth.subs(vals), "mpmath")
Vf = sp.lambdify(s, Vs.subs(vals), "mpmath")
period = 2 * mp.quad(lambda u: mp.sqrt(Mf(u) / (-2 * Vf(u))), [-mp.pi, -mp.pi / 2, 0])
print(f"  period from theta = 0 at rest = {mp.nstr(period, 17)} s (quadrature)")
# The rod angle's own acceleration has a part that does not multiply theta'':
alpha0 = sp.simplify(phi.diff(t, 2).subs(th.diff(t, 2), 0))
print(f"  rod alpha_0 = {alpha0}")

# --- rocking_disc_pendulum -------------------------------------------------------------
mb, L, A, W = sp.symbols("m L A W", positive=True)
th = sp.Function("theta")(t)
ang = th + A * sp.sin(W * t)                           # the bar's absolute angle
G = L / 2 * sp.Matrix([sp.sin(ang), -sp.cos(ang)])
T = (mb * v(G).dot(v(G)) + mb * L**2 / 12 * ang.diff(t) ** 2) / 2
V = mb * g * G[1]
eq = lagrange(T, V, th)
I_O = mb * L**2 / 3
hand = I_O * (th.diff(t, 2) - A * W**2 * sp.sin(W * t)) + mb * g * L / 2 * sp.sin(ang)
assert sp.simplify(eq - hand) == 0
E_abs = I_O * ang.diff(t) ** 2 / 2 - mb * g * L / 2 * sp.cos(ang)
dE = sp.simplify(E_abs.diff(t).subs(th.diff(t, 2), sp.solve(hand, th.diff(t, 2))[0]))
assert dE == 0
Lv, gv = 1.0, 9.81
K = mp.ellipk(mp.mpf(1) / 2)                           # K(k) with k^2 = 1/2
print("rocking_disc_pendulum (L = 1, g = 9.81):")
print(f"  K(1/sqrt 2)      = {mp.nstr(K, 17)}")
print(f"  period (amplitude pi/2) = {mp.nstr(4 * mp.sqrt(2 * Lv / (3 * gv)) * K, 17)} s")
