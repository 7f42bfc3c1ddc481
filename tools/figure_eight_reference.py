"""Independent cross-check of the HW7 figure eight (models/figure_eight.yaml; not used by the product).

Three equal masses m = 1, G = 1, hand-written inverse-square pairwise attraction
  r_i'' = sum_{j != i} G m (r_j - r_i) / |r_j - r_i|^3,
from the HW7 initial conditions, integrated with SciPy's DOP853 at rtol = atol = 1e-13.
Prints the initial energy, linear and angular momentum, and the period found as the time of
least distance |y(t) - y(0)| near the literature value 6.32591398 (minimised by Brent's method
on the dense output), to compare with tests/long_runs.rs.

Run: python3 tools/figure_eight_reference.py
"""
import json
import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

G = m = 1.0
x1, y1 = -0.97000436, 0.24308753
vx3, vy3 = 0.93240737, 0.86473146
y0 = np.array([x1, y1, -x1, -y1, 0.0, 0.0,
               -vx3 / 2, -vy3 / 2, -vx3 / 2, -vy3 / 2, vx3, vy3])


def rhs(t, y):
    r = y[:6].reshape(3, 2)
    a = np.zeros((3, 2))
    for i in range(3):
        for j in range(3):
            if i != j:
                d = r[j] - r[i]
                a[i] += G * m * d / np.linalg.norm(d) ** 3
    return np.concatenate([y[6:], a.ravel()])


def energy(y):
    r = y[:6].reshape(3, 2)
    v = y[6:].reshape(3, 2)
    kinetic = 0.5 * m * np.sum(v * v)
    potential = -G * m * m * sum(1.0 / np.linalg.norm(r[i] - r[j])
                                 for i in range(3) for j in range(i + 1, 3))
    return kinetic + potential


def angular_momentum(y):
    r = y[:6].reshape(3, 2)
    v = y[6:].reshape(3, 2)
    return float(np.sum(m * (r[:, 0] * v[:, 1] - r[:, 1] * v[:, 0])))


sol = solve_ivp(rhs, (0.0, 6.5), y0, method="DOP853", rtol=1e-13, atol=1e-13,
                dense_output=True)
found = minimize_scalar(lambda t: float(np.linalg.norm(sol.sol(t) - y0)),
                        bracket=(6.30, 6.3259, 6.35), tol=1e-12)
y_end = sol.sol(found.x)
print(json.dumps({
    "energy": energy(y0),
    "linear_momentum": (m * y0[6:].reshape(3, 2).sum(axis=0)).tolist(),
    "angular_momentum": angular_momentum(y0),
    "period": found.x,
    "distance_at_period": found.fun,
    "energy_error_at_period": energy(y_end) - energy(y0),
    "rhs_evals": int(sol.nfev),
}, indent=1))
