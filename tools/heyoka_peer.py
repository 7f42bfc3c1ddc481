"""heyoka's Taylor integrator on eomgen's models, for the work-precision comparison with peers.

heyoka (https://bluescarni.github.io/heyoka.py/, PyPI `heyoka`, tested with 7.13.2) is an
adaptive Taylor-series integrator that compiles the ODE's Taylor recurrences with LLVM.
This script builds, from the model files' equations, the first-order ODEs of

- `double_pendulum` (models/double_pendulum.yaml, HW19): two uniform bars, absolute angles
  from +x, M(q) q'' = F(q, q') with the hand-derived M, F of
  tools/double_pendulum_reference.py (the same mathematics as eomgen's momentum balances),
  solved for q'' by Cramer's rule. Both rows are multiplied by 6 first, so that every
  coefficient is an integer combination of the parameters (exact in binary: the
  multiprecision reference below then solves exactly the model's ODE, not one with 1/3 and 1/2
  rounded to double):
      6 M = [[2 m1 l1^2 + 6 m2 l1^2, 3 m2 l1 l2 cos(t1 - t2)], [3 m2 l1 l2 cos(t1 - t2), 2 m2 l2^2]]
      6 F = [-3 m2 l1 l2 sin(t1 - t2) w2^2 - (3 m1 + 6 m2) g l1 cos t1,
              3 m2 l1 l2 sin(t1 - t2) w1^2 - 3 m2 g l2 cos t2]
      t1'' = (A22 b1 - A12 b2) / det,  t2'' = (A11 b2 - A12 b1) / det,  det = A11 A22 - A12^2.
- `figure_eight` (models/figure_eight.yaml, HW7): three equal masses, pairwise gravity, the
  model's `checks.equations_of_motion`: r_i'' = sum_j G m (r_j - r_i) / |r_j - r_i|^3.

Parameters are read from the model file (`parameters:`); the initial states are the model
files' `initial:` evaluated in double precision exactly as eomgen does (pi/2 rounded to double,
-0.93240737/2*sqrt(G m) ...), and `check` verifies them bit for bit against the Rust program.

heyoka's tolerance: `taylor_adaptive(..., tol=tol)` is one number used as both the relative
and the absolute tolerance (rtol = atol = tol). The Taylor order is p = ceil(-ln(tol)/2 + 1)
and the step is chosen a priori from the last two Taylor coefficients so that the estimated
local truncation error is <= tol * max(1, ||x||_inf) (infinity norm over the whole state; Biscani
and Izzo, MNRAS 504 (2021) 2614, doi:10.1093/mnras/staa3867, section 3). eomgen and
ode_solvers instead weigh each component by atol + rtol |y_i| and estimate the error a
posteriori by an embedded pair, so equal `tol` does not mean equal error: compare at equal
error.

Timing: for each (model, tol) the integrator is constructed (and JIT-compiled) once and
cached; its construction time is reported as `construct_s` and is not in `time_s`. Each
timed repetition resets the time to 0 and the state to y0 and times `propagate_until(t_end)`
alone (time.perf_counter; no continuous output, no callback). heyoka also keeps compiled code
in an on-disk cache ($XDG_CACHE_HOME/heyoka): a construction found there takes ~0.01-0.1 s
instead of ~0.4-1.2 s; `time_s` is the median of
`reps` repetitions (the first, untimed, gives the state and the step count).

Reference: `reference` integrates both models with heyoka in multiple precision
(fp_type=heyoka.real, 170 bits, tol 1e-48), from the same double initial states converted
exactly, and checks the result against a second run at 210 bits, tol 1e-58; the final states
are written with 45 significant digits. (The Taylor method in arbitrary precision is a
different computation from the double-precision runs being measured; the equations are checked
against eomgen's by `check`.)

Usage (from the repository root; P = the Rust program of examples/work_precision_peers.rs):
    python tools/heyoka_peer.py reference --out /tmp/peers-out/reference.json
    python tools/heyoka_peer.py check --binary $P          # RHS and y0 against eomgen's
    python tools/heyoka_peer.py run --jobs double_pendulum:1e-8,figure_eight:1e-14 \
        --reps 5 [--reference /tmp/peers-out/reference.json] [--high-accuracy]
    python tools/heyoka_peer.py serve [--reference FILE] [--high-accuracy]  # a job list per line
(`--high-accuracy`: heyoka's mode of that name, method "heyoka-taylor-high-accuracy".)
As a module: `HeyokaPeer(reference, high_accuracy).run([(model, tol), ...], reps)` returns the
result dicts
(the driver, tools/work_precision_peers.py, uses this and keeps the integrators between rounds).

Output: one JSON line per job: {"side": "heyoka", "method": "heyoka-taylor", "model", "tol",
"t_end", "time_s", "times_s", "call_overhead_s" (median time of a propagate_until that takes
no step: the Python call's own cost, included in time_s), "construct_s", "order", "steps", "rhs_evals": null,
"final_state", "error" (max |y_i(t_end) - y_ref_i| over the state, null without a
reference), "energy_drift" (|E(t_end) - E(0)| / |E(0)|, double precision)}.
"""
import argparse
import json
import math
import random
import subprocess
import sys
import time
from fractions import Fraction
from pathlib import Path

import heyoka as hy
import numpy as np
import yaml

ROOT = Path(__file__).resolve().parent.parent

# End times: 10 s for the double pendulum; 10 periods (Simo's T = 6.32591398) of the figure
# eight. The same doubles are passed to the Rust program.
T_END = {"double_pendulum": 10.0, "figure_eight": 63.2591398}

METHOD = "heyoka-taylor"
METHOD_HIGH_ACCURACY = "heyoka-taylor-high-accuracy"


def parameters(model):
    """The model file's default parameters, as exact Fractions of their decimal text."""
    text = (ROOT / "models" / f"{model}.yaml").read_text()
    params = yaml.safe_load(text)["parameters"]
    return {k: Fraction(str(v)) for k, v in params.items()}


def initial_state(model):
    """y(0) as eomgen computes it from the model file's `initial:` (double precision)."""
    if model == "double_pendulum":
        return [0.0, math.pi / 2, 0.0, 0.0]
    p = parameters("figure_eight")
    s = math.sqrt(float(p["G"]) * float(p["m"]))
    x1, y1, vx3, vy3 = -0.97000436, 0.24308753, 0.93240737, 0.86473146
    return [x1, y1, 0.97000436, -0.24308753, 0.0, 0.0,
            -vx3 / 2 * s, -vy3 / 2 * s, -vx3 / 2 * s, -vy3 / 2 * s, vx3 * s, vy3 * s]


def make_constant(prec):
    """Converts a Fraction into an expression constant: a double, or at `prec` bits an mp real
    (numerator and denominator exact, one rounding)."""
    if prec is None:
        return lambda fr: hy.expression(float(fr))

    def constant(fr):
        fr = Fraction(fr)
        return hy.expression(hy.real(fr.numerator, prec) / hy.real(fr.denominator, prec))
    return constant


def system(model, prec=None):
    """(state variables, [(var, rhs)]) of the model's first-order ODE."""
    c = make_constant(prec)
    p = parameters(model)
    if model == "double_pendulum":
        t1, t2, w1, w2 = hy.make_vars("theta1", "theta2", "theta1_dot", "theta2_dot")
        m1, m2, l1, l2, g = p["m1"], p["m2"], p["l1"], p["l2"], p["g"]
        cd, sd = hy.cos(t1 - t2), hy.sin(t1 - t2)
        a11 = c(2 * m1 * l1**2 + 6 * m2 * l1**2)
        a12 = c(3 * m2 * l1 * l2) * cd
        a22 = c(2 * m2 * l2**2)
        b1 = -c(3 * m2 * l1 * l2) * sd * w2**2 - c((3 * m1 + 6 * m2) * g * l1) * hy.cos(t1)
        b2 = c(3 * m2 * l1 * l2) * sd * w1**2 - c(3 * m2 * g * l2) * hy.cos(t2)
        det = a11 * a22 - a12 * a12
        acc1 = (a22 * b1 - a12 * b2) / det
        acc2 = (a11 * b2 - a12 * b1) / det
        return [t1, t2, w1, w2], [(t1, w1), (t2, w2), (w1, acc1), (w2, acc2)]
    if model == "figure_eight":
        names = ["x1", "y1", "x2", "y2", "x3", "y3"]
        q = hy.make_vars(*names)
        v = hy.make_vars(*[n + "_dot" for n in names])
        gm = c(p["G"] * p["m"])
        acc = [[None, None] for _ in range(3)]
        pulls = {}
        for i in range(3):
            for j in range(i + 1, 3):
                dx, dy = q[2 * j] - q[2 * i], q[2 * j + 1] - q[2 * i + 1]
                k = gm * (dx**2 + dy**2) ** c(Fraction(-3, 2))
                pulls[(i, j)] = (k * dx, k * dy)
                pulls[(j, i)] = (-(k * dx), -(k * dy))
        for i in range(3):
            others = [j for j in range(3) if j != i]
            acc[i] = [pulls[(i, others[0])][0] + pulls[(i, others[1])][0],
                      pulls[(i, others[0])][1] + pulls[(i, others[1])][1]]
        rhs = [(q[k], v[k]) for k in range(6)]
        rhs += [(v[2 * i + d], acc[i][d]) for i in range(3) for d in range(2)]
        return list(q) + list(v), rhs
    raise ValueError(f"unknown model {model!r} (valid: double_pendulum, figure_eight)")


def energy(model, y):
    """Total energy T + V (double precision) of the state y, as eomgen's ModelInfo::energy."""
    p = {k: float(v) for k, v in parameters(model).items()}
    if model == "double_pendulum":
        t1, t2, w1, w2 = y
        m1, m2, l1, l2, g = p["m1"], p["m2"], p["l1"], p["l2"], p["g"]
        c = 0.5 * m2 * l1 * l2 * math.cos(t1 - t2)
        kinetic = 0.5 * ((m1 * l1**2 / 3 + m2 * l1**2) * w1**2 + 2 * c * w1 * w2
                         + m2 * l2**2 / 3 * w2**2)
        potential = g * (m1 * l1 / 2 * math.sin(t1) + m2 * (l1 * math.sin(t1)
                                                              + l2 / 2 * math.sin(t2)))
        return kinetic + potential
    gm, m = p["G"] * p["m"] ** 2, p["m"]
    r = np.asarray(y[:6]).reshape(3, 2)
    v = np.asarray(y[6:]).reshape(3, 2)
    potential = -gm * sum(1.0 / np.linalg.norm(r[i] - r[j])
                          for i in range(3) for j in range(i + 1, 3))
    return 0.5 * m * float(np.sum(v * v)) + potential


def load_reference(path):
    """{model: (t_end, [float state])} from a reference JSON file."""
    data = json.loads(Path(path).read_text())
    return {k: (v["t_end"], [float(s) for s in v["state"]]) for k, v in data.items()}


class HeyokaPeer:
    """Cached heyoka integrators, one per (model, tol), and the timed runs."""

    def __init__(self, reference=None, high_accuracy=False):
        """`high_accuracy`: heyoka's mode of that name (the terms of each step's Taylor
        polynomial summed with compensation, the error not carried to the next step, unlike
        eomgen's Taylor method); its results are then labelled `METHOD_HIGH_ACCURACY`."""
        self.reference = reference or {}
        self.integrators = {}
        self.high_accuracy = high_accuracy
        self.method = METHOD_HIGH_ACCURACY if high_accuracy else METHOD

    def integrator(self, model, tol):
        """(taylor_adaptive, construction time in s), built on first use."""
        key = (model, tol)
        if key not in self.integrators:
            _, sys_ = system(model)
            start = time.perf_counter()
            ta = hy.taylor_adaptive(sys_, initial_state(model), tol=tol,
                                    high_accuracy=self.high_accuracy)
            self.integrators[key] = (ta, time.perf_counter() - start)
        return self.integrators[key]

    def run_one(self, model, tol, reps=5, t_end=None):
        """One job: the result dict described in the module's docstring."""
        t_end = T_END[model] if t_end is None else t_end
        ta, construct_s = self.integrator(model, tol)
        y0 = np.array(initial_state(model))
        times, steps, final = [], None, None
        for rep in range(reps + 1):
            ta.time = 0.0
            ta.state[:] = y0
            start = time.perf_counter()
            outcome = ta.propagate_until(t_end)
            elapsed = time.perf_counter() - start
            if outcome[0] != hy.taylor_outcome.time_limit or ta.time != t_end:
                return {"side": "heyoka", "method": self.method, "model": model, "tol": tol,
                        "failed": f"propagate_until stopped: {outcome[0]} at t = {ta.time}"}
            if rep == 0:
                steps, final = int(outcome[3]), ta.state.tolist()
            else:
                times.append(elapsed)
        # The cost of the call itself (argument conversion, the returned tuple): a
        # propagation to the current time, which takes no step.
        overheads = []
        for _ in range(max(reps, 1)):
            start = time.perf_counter()
            ta.propagate_until(t_end)
            overheads.append(time.perf_counter() - start)
        error = None
        if model in self.reference:
            t_ref, y_ref = self.reference[model]
            if t_ref == t_end:
                error = max(abs(a - b) for a, b in zip(final, y_ref))
        e0 = energy(model, y0)
        return {"side": "heyoka", "method": self.method, "model": model, "tol": tol,
                "t_end": t_end, "time_s": float(np.median(times)) if times else None,
                "times_s": times, "call_overhead_s": float(np.median(overheads)),
                "construct_s": construct_s, "order": ta.order,
                "steps": steps, "rhs_evals": None, "final_state": final, "error": error,
                "energy_drift": abs((energy(model, final) - e0) / e0)}

    def run(self, jobs, reps=5):
        """The result dicts of the jobs [(model, tol)] or [(model, tol, t_end)], in order."""
        return [self.run_one(*job[:2], reps=reps, t_end=job[2] if len(job) > 2 else None)
                for job in jobs]


def reference_state(model, prec, tol):
    """y(t_end) at `prec` bits with heyoka's Taylor method at `tol` (mp reals)."""
    _, sys_ = system(model, prec)
    y0 = [hy.real(x, prec) for x in initial_state(model)]
    ta = hy.taylor_adaptive(sys_, y0, fp_type=hy.real, tol=hy.real(tol, prec))
    outcome = ta.propagate_until(hy.real(T_END[model], prec))
    if outcome[0] != hy.taylor_outcome.time_limit:
        raise RuntimeError(f"{model}: reference integration stopped: {outcome[0]}")
    return list(ta.state), int(outcome[3]), ta.order


def command_reference(args):
    out = {}
    for model in ("double_pendulum", "figure_eight"):
        start = time.perf_counter()
        y, steps, order = reference_state(model, 170, "1e-48")
        y_check, _, _ = reference_state(model, 210, "1e-58")
        diff = max(abs(float(a - b)) for a, b in zip(y, y_check))
        out[model] = {
            "t_end": T_END[model],
            "state": [mp_digits(x, 45) for x in y],
            "initial_state": [repr(x) for x in initial_state(model)],
            "method": "heyoka taylor_adaptive, fp_type=real, 170 bits, tol 1e-48",
            "steps": steps, "order": order,
            "difference_from_210_bits_tol_1e-58": diff,
            "seconds": time.perf_counter() - start,
        }
        print(f"{model}: {steps} steps of order {order}; differs from the 210-bit run by "
              f"{diff:.1e}", file=sys.stderr)
    text = json.dumps(out, indent=1)
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(text + "\n")
    else:
        print(text)


def mp_digits(x, digits):
    """The mp real x with `digits` significant decimal digits, in scientific notation."""
    import mpmath
    mpmath.mp.dps = digits + 10
    return mpmath.nstr(mpmath.mpf(str(x)), digits, min_fixed=1, max_fixed=0)


def command_check(args):
    """Compares y(0) and the right-hand side at random states with eomgen's (`rhs` of the Rust
    program), and for the double pendulum with the numpy formula of
    tools/double_pendulum_reference.py."""
    rng = random.Random(20261125)
    worst = 0.0
    for model in ("double_pendulum", "figure_eight"):
        initial = json.loads(subprocess.run([args.binary, "initial", "--model", model],
                                            capture_output=True, text=True, check=True).stdout)
        same = initial["initial_state"] == initial_state(model)
        print(json.dumps({"model": model, "initial_state_bitwise_equal": same}))
        worst = max(worst, 0.0 if same else 1.0)
        variables, sys_ = system(model)
        cf = hy.cfunc([rhs for _, rhs in sys_], variables)
        for _ in range(args.states):
            if model == "double_pendulum":
                y = [rng.uniform(-math.pi, math.pi) for _ in range(2)] + \
                    [rng.uniform(-5, 5) for _ in range(2)]
            else:
                y = [x + rng.uniform(-0.3, 0.3) for x in initial_state(model)]
            eomgen = json.loads(subprocess.run(
                [args.binary, "rhs", "--model", model, "--state", ",".join(map(repr, y))],
                capture_output=True, text=True, check=True).stdout)["rhs"]
            ours = cf(np.array(y)).tolist()
            rel = max(abs(a - b) for a, b in zip(ours, eomgen)) / max(map(abs, eomgen))
            line = {"model": model, "state": y, "heyoka_rhs": ours, "eomgen_rhs": eomgen,
                    "max_relative_difference": rel}
            if model == "double_pendulum":
                line["reference_script_rhs"] = reference_script_rhs(y)
                rel2 = max(abs(a - b) for a, b in zip(ours, line["reference_script_rhs"]))
                line["max_relative_difference_reference_script"] = rel2 / max(map(abs, ours))
                rel = max(rel, line["max_relative_difference_reference_script"])
            worst = max(worst, rel)
            print(json.dumps(line))
    print(json.dumps({"worst_relative_difference": worst}))
    # The generated and the hand-derived equations differ in rounding only.
    return 0 if worst < 1e-13 else 1


def reference_script_rhs(y):
    """The right-hand side of tools/double_pendulum_reference.py (its `rhs`, copied: that
    script integrates when imported)."""
    m1 = m2 = l1 = l2 = 1.0
    g = 10.0
    t1, t2, w1, w2 = y
    c = 0.5 * m2 * l1 * l2
    M = np.array([[m1 * l1**2 / 3 + m2 * l1**2, c * math.cos(t1 - t2)],
                  [c * math.cos(t1 - t2), m2 * l2**2 / 3]])
    F = np.array([-c * math.sin(t1 - t2) * w2**2 - (0.5 * m1 + m2) * g * l1 * math.cos(t1),
                  c * math.sin(t1 - t2) * w1**2 - 0.5 * m2 * g * l2 * math.cos(t2)])
    a = np.linalg.solve(M, F)
    return [w1, w2, float(a[0]), float(a[1])]


def parse_jobs(text):
    """`model:tol,model:tol` -> [(model, tol)]."""
    jobs = []
    for item in text.split(","):
        model, tol = item.split(":")
        jobs.append((model, float(tol)))
    return jobs


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("reference", help="multiprecision reference states")
    p.add_argument("--out")
    p = sub.add_parser("check", help="compare y0 and the RHS with eomgen's")
    p.add_argument("--binary", required=True)
    p.add_argument("--states", type=int, default=5)
    for name, text in (("run", "run jobs model:tol,..."),
                       ("serve", "read one JSON job list per line on stdin")):
        p = sub.add_parser(name, help=text)
        if name == "run":
            p.add_argument("--jobs", required=True)
        p.add_argument("--reps", type=int, default=5)
        p.add_argument("--reference")
        p.add_argument("--high-accuracy", action="store_true",
                       help="heyoka's high_accuracy mode (method label " + METHOD_HIGH_ACCURACY + ")")
    args = parser.parse_args()
    if args.command == "reference":
        command_reference(args)
        return 0
    if args.command == "check":
        return command_check(args)
    peer = HeyokaPeer(load_reference(args.reference) if args.reference else None,
                      high_accuracy=args.high_accuracy)
    if args.command == "run":
        for result in peer.run(parse_jobs(args.jobs), args.reps):
            print(json.dumps(result), flush=True)
        return 0
    for line in sys.stdin:
        if line.strip():
            for result in peer.run([tuple(job) for job in json.loads(line)], args.reps):
                print(json.dumps(result), flush=True)
            print(json.dumps({"done": True}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
