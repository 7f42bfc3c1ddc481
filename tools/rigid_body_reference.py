"""Independent reference values for the 3-D rigid-body models (not used by the product).

- free_rigid_body: the period of w1 for a torque-free body with I = (1, 2, 3) started from
  w = (0.3, 0.2, 1), from the exact solution of Euler's equations in Jacobi's elliptic
  functions (Landau & Lifshitz, Mechanics, §37): with 2T = sum I_i w_i^2, H^2 = sum (I_i w_i)^2
  and H^2 > 2 T I2, w1 ~ cn(tau, k), tau = t sqrt((I3 - I2)(H^2 - 2 T I1)/(I1 I2 I3)),
  k^2 = (I2 - I1)(2 T I3 - H^2)/((I3 - I2)(H^2 - 2 T I1)); the period of cn is 4 K(k).
  Cross-checked by integrating Euler's equations with mpmath's Taylor integrator.
- heavy_top: the slow and fast steady-precession rates of a symmetric top, the roots of
  I1 cos(theta0) phi'^2 - I3 w3 phi' + m g l = 0 (Goldstein, Classical Mechanics, §5.7),
  and the body-axis form of the top's Lagrange equations checked symbolically against the
  Euler-angle Lagrangian with SymPy.

Run: python3 tools/rigid_body_reference.py
Compare: cargo run --release -- report --models free_rigid_body,heavy_top
"""
import mpmath as mp
import sympy as sp

mp.mp.dps = 40

# --- free_rigid_body -------------------------------------------------------------------
I1, I2, I3 = mp.mpf(1), mp.mpf(2), mp.mpf(3)
w0 = [mp.mpf("0.3"), mp.mpf("0.2"), mp.mpf(1)]
T2 = I1 * w0[0] ** 2 + I2 * w0[1] ** 2 + I3 * w0[2] ** 2
H2 = (I1 * w0[0]) ** 2 + (I2 * w0[1]) ** 2 + (I3 * w0[2]) ** 2
assert H2 > T2 * I2
k2 = (I2 - I1) * (T2 * I3 - H2) / ((I3 - I2) * (H2 - T2 * I1))
rate = mp.sqrt((I3 - I2) * (H2 - T2 * I1) / (I1 * I2 * I3))
period = 4 * mp.ellipk(k2) / rate
print(f"free_rigid_body: period of w1 = {mp.nstr(period, 17)} s (k^2 = {mp.nstr(k2, 17)})")


def euler(t, w):
    return [(I2 - I3) * w[1] * w[2] / I1, (I3 - I1) * w[2] * w[0] / I2,
            (I1 - I2) * w[0] * w[1] / I3]


# Zeros of w1 going up, by the Taylor integrator and bisection on its dense solution.
sol = mp.odefun(euler, 0, w0)
ups = []
step = mp.mpf("0.05")
t = mp.mpf(0)
prev = sol(t)[0]
while len(ups) < 3:
    t2 = t + step
    cur = sol(t2)[0]
    if prev < 0 <= cur:
        ups.append(mp.findroot(lambda s: sol(s)[0], (t, t2), solver="bisect"))
    t, prev = t2, cur
print(f"  by integration: {mp.nstr(ups[2] - ups[1], 17)} s between rising zeros of w1")
assert abs(ups[2] - ups[1] - period) < mp.mpf("1e-15")

# --- heavy_top -------------------------------------------------------------------------
m, g, l, J1, J3, th0, w3 = 1, mp.mpf("9.81"), mp.mpf("0.1"), mp.mpf("0.02"), mp.mpf("0.01"), mp.pi / 6, 100
a, b, c = J1 * mp.cos(th0), -J3 * w3, m * g * l
slow = (-b - mp.sqrt(b * b - 4 * a * c)) / (2 * a)
fast = (-b + mp.sqrt(b * b - 4 * a * c)) / (2 * a)
print(f"heavy_top: steady precession at 30 degrees, w3 = 100: slow {mp.nstr(slow, 16)}, fast {mp.nstr(fast, 16)} rad/s")
# Nutation about the slow steady precession: Routh's reduction by the conserved momenta
# p_phi, p_psi leaves I1 theta'' = -U'(theta) with
# U = (p_phi - p_psi cos theta)^2/(2 I1 sin^2 theta) + m g l cos theta; U'(theta0) = 0 and the
# linearised frequency is sqrt(U''(theta0)/I1).
p_psi = J3 * w3
p_phi = J1 * slow * mp.sin(th0) ** 2 + p_psi * mp.cos(th0)


def routh(th):
    return (p_phi - p_psi * mp.cos(th)) ** 2 / (2 * J1 * mp.sin(th) ** 2) + m * g * l * mp.cos(th)


assert abs(mp.diff(routh, th0)) < mp.mpf("1e-30")
nutation = mp.sqrt(mp.diff(routh, th0, 2) / J1)
print(f"  nutation about the slow precession: {mp.nstr(nutation, 16)} rad/s")
# The sleeping top (tests/fixtures/sleeping_top.yaml): stable for w3 > 2 sqrt(I1 m g l)/I3,
# I1 = A + m l^2 about O (A = 0.01, l = 0.1, m = 1: I1 = 0.02).
print(f"sleeping_top: critical spin {mp.nstr(2 * mp.sqrt(J1 * m * g * l) / J3, 16)} rad/s")

t = sp.symbols("t")
phi, theta, psi = (sp.Function(n)(t) for n in ("phi", "theta", "psi"))
A1, A3, M, G, L = sp.symbols("I1 I3 m g l", positive=True)
Lag = A1 * (theta.diff(t) ** 2 + phi.diff(t) ** 2 * sp.sin(theta) ** 2) / 2 \
    + A3 * (psi.diff(t) + phi.diff(t) * sp.cos(theta)) ** 2 / 2 - M * G * L * sp.cos(theta)
eqs = [sp.diff(sp.diff(Lag, q.diff(t)), t) - sp.diff(Lag, q) for q in (phi, theta, psi)]
# The model file's hand-written equations, as residuals lhs - rhs.
pd, td, sd = phi.diff(t), theta.diff(t), psi.diff(t)
pdd, tdd, sdd = phi.diff(t, 2), theta.diff(t, 2), psi.diff(t, 2)
hand = [
    A1 * pdd * sp.sin(theta) ** 2 + 2 * A1 * pd * td * sp.sin(theta) * sp.cos(theta)
    + A3 * (sdd + pdd * sp.cos(theta) - pd * td * sp.sin(theta)) * sp.cos(theta)
    - A3 * (sd + pd * sp.cos(theta)) * td * sp.sin(theta),
    A1 * tdd - A1 * pd ** 2 * sp.sin(theta) * sp.cos(theta)
    + A3 * (sd + pd * sp.cos(theta)) * pd * sp.sin(theta) - M * G * L * sp.sin(theta),
    A3 * (sdd + pdd * sp.cos(theta) - pd * td * sp.sin(theta)),
]
for e, h in zip(eqs, hand):
    assert sp.simplify(sp.expand(e - h)) == 0
print("  the model file's equations_of_motion equal Lagrange's on the Euler-angle Lagrangian")
