"""Independent reference for the HW19 double pendulum (not used by the product).

Equations derived by hand for two uniform bars (m, l, absolute angles from +x, gravity -y):
  M11 = m1 l1^2/3 + m2 l1^2,  M12 = m2 l1 l2/2 cos(t1 - t2),  M22 = m2 l2^2/3
  F1 = -m2 l1 l2/2 sin(t1 - t2) w2^2 - (m1/2 + m2) g l1 cos t1
  F2 =  m2 l1 l2/2 sin(t1 - t2) w1^2 - m2 g l2/2 cos t2
integrated with SciPy's DOP853 at rtol = atol = 1e-13 from t1 = 0, t2 = pi/2 at rest.

Run: python3 tools/double_pendulum_reference.py
Compare: cargo run --release -- simulate double_pendulum --t-out 1,2,5,10 --rtol 1e-12 --atol 1e-12 --json
"""
import json
import math

import numpy as np
from scipy.integrate import solve_ivp

m1 = m2 = l1 = l2 = 1.0
g = 10.0


def rhs(t, y):
    t1, t2, w1, w2 = y
    c = 0.5 * m2 * l1 * l2
    M = np.array([[m1 * l1**2 / 3 + m2 * l1**2, c * math.cos(t1 - t2)],
                  [c * math.cos(t1 - t2), m2 * l2**2 / 3]])
    F = np.array([-c * math.sin(t1 - t2) * w2**2 - (0.5 * m1 + m2) * g * l1 * math.cos(t1),
                  c * math.sin(t1 - t2) * w1**2 - 0.5 * m2 * g * l2 * math.cos(t2)])
    a = np.linalg.solve(M, F)
    return [w1, w2, a[0], a[1]]


times = [1.0, 2.0, 5.0, 10.0]
sol = solve_ivp(rhs, (0.0, 10.0), [0.0, math.pi / 2, 0.0, 0.0], method="DOP853",
                rtol=1e-13, atol=1e-13, t_eval=times)
print(json.dumps({"t": times, "y": sol.y.T.tolist()}, indent=1))
