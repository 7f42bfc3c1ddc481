"""The simplest walker's gait from the paper's own limit equations (m/M -> 0), independently
of eomgen: Garcia, Chatterjee, Ruina & Coleman, J. Biomech. Eng. 120 (1998), eqs. 2-4.

    theta'' = sin(theta - gamma)
    phi''   = theta'' + theta'^2 sin(phi) - cos(theta - gamma) sin(phi)

heel strike where phi - 2 theta rises through 0 with theta < 0 (scuffing near mid-stance
ignored), then theta+ = -theta, phi+ = -2 theta, theta'+ = cos(2 theta) theta',
phi'+ = cos(2 theta) (1 - cos(2 theta)) theta'.

The fixed point of the map on the state just after a heel strike (theta, theta', phi') (phi =
2 theta there) is found by Newton with a Jacobian by central differences, the integration by
SciPy's DOP853 at rtol = atol = 1e-13; the eigenvalues are those of that 3 x 3 Jacobian (the
map's fourth direction, phi - 2 theta, is fixed at 0 by the heel strike). Prints JSON for
gamma = 0.009, and the slope of the period doubling (an eigenvalue at -1, by bisection):
the values tests/gaits.rs compares against.

Run: python3 tools/simplest_walker_reference.py   (needs numpy, scipy)
"""

import json

import numpy as np
from scipy.integrate import solve_ivp


def flow(gamma):
    def f(_t, y):
        th, ph, thd, phd = y
        thdd = np.sin(th - gamma)
        phdd = thdd + thd**2 * np.sin(ph) - np.cos(th - gamma) * np.sin(ph)
        return [thd, phd, thdd, phdd]

    return f


def step(x, gamma):
    """The map: (theta, theta', phi') just after a heel strike -> the same after the next."""
    th, thd, phd = x
    y0 = [th, 2 * th, thd, phd]

    def strike(_t, y):
        return y[1] - 2 * y[0] if y[0] < 0 else -1.0

    strike.terminal = True
    strike.direction = 1
    sol = solve_ivp(flow(gamma), [0, 20], y0, method="DOP853", rtol=1e-13, atol=1e-13,
                    events=strike)
    t = sol.t_events[0][0]
    th, ph, thd, phd = sol.y_events[0][0]
    c = np.cos(2 * th)
    return np.array([-th, c * thd, c * (1 - c) * thd]), t


def jacobian(x, gamma, h=1e-6):
    j = np.zeros((3, 3))
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        j[:, k] = (step(x + e, gamma)[0] - step(x - e, gamma)[0]) / (2 * h)
    return j


def gait(gamma, x):
    for _ in range(20):
        r = step(x, gamma)[0] - x
        if np.max(np.abs(r)) < 1e-13:
            break
        x = x - np.linalg.solve(jacobian(x, gamma) - np.eye(3), r)
    return x


def period_doubling(lo, hi, x):
    """The slope where the gait's most negative eigenvalue reaches -1, by bisection (the
    gait followed from `x`)."""
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        x = gait(mid, x)
        if min(np.linalg.eigvals(jacobian(x, mid)).real) > -1:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def main():
    gamma = 0.009
    x = gait(gamma, np.array([0.2003, -0.1998, -0.0158]))
    end, period = step(x, gamma)
    eig = np.linalg.eigvals(jacobian(x, gamma))
    eig = sorted(eig, key=lambda z: (-abs(z), -z.imag))
    x15 = x
    for g in np.linspace(0.009, 0.015, 7):
        x15 = gait(g, x15)
    print(json.dumps({
        "period_doubling_gamma": period_doubling(0.015, 0.016, x15),
        "gamma": gamma,
        "theta": x[0], "theta_dot": x[1], "phi": 2 * x[0], "phi_dot": x[2],
        "period": period,
        "residual": float(np.max(np.abs(end - x))),
        "eigenvalues": [[z.real, z.imag] for z in eig],
    }, indent=2))


def bench():
    """SciPy's times for what benches/gait.rs times in eomgen, on the limit's equations (the
    same gait): one step of the map with its Jacobian by central differences (7 steps), the
    gait from the same rough guess, and the gait followed over 100 slopes (each from the
    last); medians of 5 runs, in one process."""
    import statistics
    import time

    def median(f, runs=5):
        times = []
        for _ in range(runs):
            t0 = time.perf_counter()
            f()
            times.append(time.perf_counter() - t0)
        return statistics.median(times)

    x = np.array([0.2003109005442575, -0.1998324730049286, -0.015822999948309113])
    rough = np.array([0.198, -0.1998, -0.0142])
    one = median(lambda: step(x, 0.009))
    with_jacobian = median(lambda: (step(x, 0.009), jacobian(x, 0.009)))
    fixed = median(lambda: gait(0.009, rough))

    def sweep():
        y = x
        for g in np.linspace(0.001, 0.0149, 100):
            y = gait(g, y)

    swept = median(sweep, runs=1)
    print(json.dumps({
        "one_step_s": one, "one_step_with_jacobian_s": with_jacobian,
        "gait_from_rough_guess_s": fixed, "sweep_100_slopes_s": swept,
    }, indent=2))


if __name__ == "__main__":
    import sys
    bench() if "--bench" in sys.argv else main()
