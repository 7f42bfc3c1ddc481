"""Benchmarks of the Python package `eomgen`, whose figures go into docs/python.md.
Not used by the product.

It measures, in one run, on the machine it runs on:

1. `overhead`: the cost of the binding. The double pendulum integrated for 10 s (dp54,
   rtol = atol = 1e-10), once with every step as output and once with `t_out=[10]`, and
   for 0.01 s (3 steps) the same two ways: the median Python wall time of
   `m.simulate(...)` against the median `library_time_s` (the Rust library call alone) and
   `stats["wall_time_s"]` (the integrator alone). The goal is 10 µs per call.
2. `pydy`: against SymPy mechanics + PyDy + SciPy on the n-link pendulum of
   `eomgen new n-link-pendulum N`:
   a) model to first step: `eomgen.load(file)` + `m.rhs(0, y0)` (and load + a 1 ms
      simulation) against `KanesMethod.kanes_equations` + `pydy.codegen.ode_function_generators
      .generate_ode_function(generator="lambdify")` + one RHS evaluation; plus the cold
      import of each stack in a fresh interpreter;
   b) simulation at equal error: the final-state error and time of eomgen dop853 and dp54
      and of `scipy.integrate.solve_ivp(method="DOP853")` on the PyDy RHS over a grid of
      tolerances, against an eomgen dop853 reference at 1e-13 (checked against eomgen at
      1e-14 and SciPy at 1e-13); at each target error, the time each needs by the rule of
      docs/performance.md: the loosest tolerance from which every tighter one meets it.
3. `dask`: a 1,000-run Monte Carlo over theta1 of the double pendulum: the serial Python
   loop of `m.simulate`, `m.simulate_many(threads=1)`, `m.simulate_many()` and
   `eomgen.sweep.run` on a `distributed.LocalCluster` of 1, 2, 4 worker processes; every
   result is checked equal to the serial loop's bit for bit.

Alternatives compared with each other run interleaved (A B A B ...) after a warm-up, and
the tables give medians over the repetitions. Progress goes to stderr, the report (machine
facts and markdown tables) to stdout.

Run (from the repository, with the package installed in the virtual environment):

    /work/venv/bin/python tools/python_bench.py                  # everything, ~3 min on 2 cores
    /work/venv/bin/python tools/python_bench.py --only overhead
    /work/venv/bin/python tools/python_bench.py --only pydy --sizes 2 5
    /work/venv/bin/python tools/python_bench.py --only dask --workers 1 2

The n-link model files come from the command-line program (`target/release/eomgen`, or
`--cli PATH`).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import eomgen

REPO = Path(__file__).resolve().parents[1]

# --- small helpers ------------------------------------------------------------------------


def log(message: str) -> None:
    """Progress, on stderr so that stdout is the report alone."""
    print(message, file=sys.stderr, flush=True)


def median(values):
    return statistics.median(values) if values else float("nan")


def fmt_time(seconds: float) -> str:
    """A duration with a unit that keeps 3-4 significant digits readable."""
    if seconds != seconds:
        return "–"
    if seconds < 1e-3:
        return f"{seconds * 1e6:.1f} µs"
    if seconds < 1.0:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds:.3g} s"


def fmt_err(x: float) -> str:
    return "–" if x != x else f"{x:.1e}"


def table(headers, rows) -> str:
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def machine_facts() -> dict:
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        nproc = subprocess.run(["nproc"], capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        nproc = str(os.cpu_count())
    versions = {"python": platform.python_version(), "numpy": np.__version__, "eomgen": eomgen.__version__}
    # The heavy packages are imported for their version only; the sections import them again.
    for name in ("scipy", "sympy", "pydy", "dask", "distributed"):
        try:
            versions[name] = __import__(name).__version__
        except ImportError:
            versions[name] = "not installed"
    try:
        import Cython  # noqa: F401  (decides which PyDy generator could be used)
        versions["Cython"] = Cython.__version__
    except ImportError:
        versions["Cython"] = "not installed"
    try:
        commit = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"],
                                capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        commit = "unknown"
    # The package is installed editable: say which build was measured.
    binary = Path(eomgen._eomgen.__file__)
    built = time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime(binary.stat().st_mtime))
    versions["eomgen"] += f" ({binary.name} built {built} UTC)"
    return {"nproc": nproc, "cpu": cpu, "platform": platform.platform(),
            "loadavg": os.getloadavg(), "commit": commit, "versions": versions}


# --- 1. call overhead ---------------------------------------------------------------------


def bench_overhead(args) -> dict:
    m = eomgen.load("double_pendulum")
    variants = [
        ("every step", dict(t_end=10.0, rtol=1e-10, atol=1e-10)),
        ("t_out=[10]", dict(t_end=10.0, t_out=[10.0], rtol=1e-10, atol=1e-10)),
        # A run of 3 steps: the library call is ~2 µs, so the binding's share is what shows.
        ("0.01 s, every step", dict(t_end=0.01)),
        ("0.01 s, t_out=0.01", dict(t_end=0.01, t_out=0.01)),
    ]
    for _ in range(10):
        for _, kw in variants:
            m.simulate(**kw)
    records = {name: {"wall": [], "library": [], "integrator": []} for name, _ in variants}
    shape = {}
    for _ in range(args.overhead_reps):
        for name, kw in variants:
            start = time.perf_counter()
            s = m.simulate(**kw)
            wall = time.perf_counter() - start
            records[name]["wall"].append(wall)
            records[name]["library"].append(s.library_time_s)
            records[name]["integrator"].append(s.stats["wall_time_s"])
            shape[name] = (len(s.t), s.stats["steps"], s.stats["rhs_evals"])
    rows = []
    for name, _ in variants:
        r = records[name]
        wall, lib = np.array(r["wall"]), np.array(r["library"])
        per_call = wall - lib
        k, steps, evals = shape[name]
        rows.append([
            name, k, steps, evals,
            fmt_time(median(r["integrator"])), fmt_time(median(r["library"])), fmt_time(median(r["wall"])),
            f"{(median(r['wall']) - median(r['library'])) * 1e6:.1f} µs",
            f"{np.median(per_call) * 1e6:.1f} µs (p90 {np.percentile(per_call, 90) * 1e6:.1f})",
            f"{median(r['wall']) / median(r['library']):.3f}",
            "yes" if np.median(per_call) <= 10e-6 else "no",
        ])
    headers = ["output", "samples", "steps", "RHS evals", "integrator (stats wall_time_s)",
               "library_time_s", "Python wall time", "wall − library (of medians)",
               "wall − library (median per call)", "wall / library", "≤ 10 µs"]
    text = (f"### Call overhead: double pendulum, dp54 (10 s at rtol = atol = 1e-10, 0.01 s at the defaults) "
            f"(medians of {args.overhead_reps} interleaved calls after 10 warm-up pairs)\n\n"
            + table(headers, rows))
    return {"text": text, "raw": records}


# --- 2. SymPy mechanics + PyDy ------------------------------------------------------------


def cli_path(args) -> str:
    if args.cli:
        return args.cli
    built = REPO / "target" / "release" / "eomgen"
    if built.exists():
        return str(built)
    found = shutil.which("eomgen")
    if found is None:
        sys.exit("no eomgen command-line program: build it (cargo build --release) or pass --cli")
    return found


def chain(n):
    """The n-link chain of `eomgen new n-link-pendulum N` in SymPy mechanics, as
    tools/sympy_n_link.py builds it (per-bar symbols m1..mN, l1..lN and g, absolute angles
    q_i from N.x: the file's theta_i), with its constants in the order of the PyDy call."""
    import sympy as sm

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from sympy_n_link import chain as sympy_chain

    frame, _origin, q, u, bodies, loads = sympy_chain(n, "per-bar")
    constants = [*sm.symbols(f"m1:{n + 1}"), *sm.symbols(f"l1:{n + 1}"), sm.symbols("g")]
    return frame, q, u, bodies, loads, constants


def pydy_build(n):
    """Equations by Kane's method, then PyDy's numerical RHS f(x, t, p) (x = [q; u]).
    SymPy's cache is cleared first: without it a second build of the same chain reuses the
    first one's results and is not what a fresh session pays. Returns the RHS, the
    constants (in the RHS's order) and the two phases' times."""
    import sympy as sm
    import sympy.physics.mechanics as me
    from sympy.core.cache import clear_cache
    from pydy.codegen.ode_function_generators import generate_ode_function

    clear_cache()
    start = time.perf_counter()
    frame, q, u, bodies, loads, constants = chain(n)
    kane = me.KanesMethod(frame, q_ind=q, u_ind=u, kd_eqs=[qi.diff() - ui for qi, ui in zip(q, u)])
    kane.kanes_equations(bodies, loads)
    derived = time.perf_counter()
    # Form [3] of generate_ode_function: M(q) u' = F(q, u), q' = u. Cython is not
    # installed here, so the generator is "lambdify" (PyDy's default) with NumPy's solve.
    rhs = generate_ode_function(kane.forcing, q, u, constants, mass_matrix=kane.mass_matrix,
                                coordinate_derivatives=sm.Matrix(u), generator="lambdify",
                                constants_arg_type="array", specifieds_arg_type="array")
    generated = time.perf_counter()
    return rhs, constants, (derived - start, generated - derived)


def check_same_model(m, f, p, n, rng):
    """The two right-hand sides at the initial state and random states must agree to
    rounding: the same model, parameters, state order and angle convention. Exits if not."""
    worst = 0.0
    states = [m.initial_state()] + [rng.uniform(-np.pi, np.pi, 2 * n) for _ in range(3)]
    for y in states:
        a = m.rhs(0.0, y)
        b = f(y, 0.0, p)
        diff = float(np.max(np.abs(a - b)))
        scale = max(1.0, float(np.max(np.abs(a))))
        worst = max(worst, diff / scale)
        if diff > 1e-12 * scale:
            sys.exit(f"n = {n}: eomgen and PyDy right-hand sides differ by {diff:.3e} at y = {y} "
                     f"(|dy| = {scale:.3g}): not the same model; nothing timed")
    return worst


def make_copies(text, n, count, directory):
    """`count` copies of the model file under distinct paths: the binding caches compiled
    files by (path, text), and each timed load must compile."""
    paths = []
    for k in range(count):
        path = Path(directory) / f"n_link_{n}_copy{k}.yaml"
        path.write_text(text)
        paths.append(str(path))
    return paths


def cold_imports(reps):
    """The import of each stack in a fresh interpreter (what a new session pays before the
    first model), interleaved, median of `reps`."""
    snippets = {
        "eomgen": "import eomgen",
        "SymPy mechanics + PyDy + SciPy": ("import sympy.physics.mechanics, scipy.integrate; "
                                           "import pydy.codegen.ode_function_generators"),
    }
    times = {k: [] for k in snippets}
    for _ in range(reps):
        for name, code in snippets.items():
            probe = f"import time; t = time.perf_counter(); {code}; print(time.perf_counter() - t)"
            out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
            times[name].append(float(out.stdout.strip()))
    return {k: median(v) for k, v in times.items()}


def bench_first_step(args, files, tmp):
    """Table 2a: from a model file to the first RHS value."""
    from pydy.codegen.ode_function_generators import generate_ode_function  # noqa: F401 (import outside the timing)

    log("pydy: warm-up (eomgen load, PyDy build of n = 2)")
    warm = eomgen.load(make_copies(next(iter(files.values())), 0, 1, tmp)[0])
    warm.rhs(0.0, warm.initial_state())
    pydy_build(2)

    rows, raw, built = [], {}, {}
    for n in args.sizes:
        text = files[n]
        reps = args.reps
        pydy_reps = args.reps if n < args.large else args.large_build_reps
        rhs_paths = make_copies(text, n, reps, Path(tmp) / "rhs")
        sim_paths = make_copies(text, n, reps, Path(tmp) / "sim")
        rec = {"load+rhs": [], "load+simulate": [], "cached load+rhs": [], "pydy": [], "kane": [], "codegen": []}
        # Parameter values and initial state for PyDy, from a copy no timed load uses.
        probe = eomgen.load(make_copies(text, n, 1, Path(tmp) / "probe")[0])
        parameters, y0 = probe.parameters, probe.initial_state()

        def eomgen_rhs(r):
            start = time.perf_counter()
            m = eomgen.load(rhs_paths[r])
            m.rhs(0.0, m.initial_state())
            rec["load+rhs"].append(time.perf_counter() - start)
            # The same path again: the compiled file comes from the binding's cache.
            start = time.perf_counter()
            m = eomgen.load(rhs_paths[r])
            m.rhs(0.0, m.initial_state())
            rec["cached load+rhs"].append(time.perf_counter() - start)

        def eomgen_simulate(r):
            start = time.perf_counter()
            m = eomgen.load(sim_paths[r])
            m.simulate(t_end=1e-3)
            rec["load+simulate"].append(time.perf_counter() - start)

        def pydy(r):
            if r >= pydy_reps:
                return
            start = time.perf_counter()
            f, constants, (kane_s, codegen_s) = pydy_build(n)
            p = np.array([parameters[str(c)] for c in constants])
            f(y0, 0.0, p)
            rec["pydy"].append(time.perf_counter() - start)
            rec["kane"].append(kane_s)
            rec["codegen"].append(codegen_s)
            built[n] = (f, constants)

        tasks = [eomgen_rhs, eomgen_simulate, pydy]
        for r in range(reps):
            log(f"pydy: first step n = {n}, repetition {r + 1}/{reps}")
            # Rotated each repetition, so that no alternative always follows PyDy's build.
            for task in tasks[r % 3:] + tasks[:r % 3]:
                task(r)
        raw[n] = rec
        rows.append([
            n, fmt_time(median(rec["load+rhs"])), fmt_time(median(rec["load+simulate"])),
            fmt_time(median(rec["cached load+rhs"])),
            fmt_time(median(rec["pydy"])), fmt_time(median(rec["kane"])), fmt_time(median(rec["codegen"])),
            f"{median(rec['pydy']) / median(rec['load+rhs']):.0f}×", f"{reps} / {pydy_reps}",
        ])
    log("pydy: cold imports")
    imports = cold_imports(args.reps)
    headers = ["n", "eomgen load + rhs", "eomgen load + simulate(1 ms)", "eomgen, cached file",
               "PyDy total (Kane + codegen + rhs)", "KanesMethod", "generate_ode_function",
               "PyDy / eomgen", "repetitions eomgen / PyDy"]
    text = ("### Model to first step: n-link pendulum, from the file on disk (eomgen) or the "
            "SymPy chain (PyDy, generator=\"lambdify\", SymPy cache cleared before each build) "
            "to the first RHS value (medians)\n\n" + table(headers, rows)
            + "\n\nCold import in a fresh interpreter (median of "
            + f"{args.reps}): " + "; ".join(f"{k}: {fmt_time(v)}" for k, v in imports.items()))
    return {"text": text, "raw": {"first_step": raw, "imports": imports}}, built


def t_end_for(args, n):
    """The simulation length of the equal-error comparison (see --t-end)."""
    if args.t_end is not None:
        return args.t_end
    # The chain is chaotic: from n = 5 on, 10 s loses every digit the targets need (the
    # dop853 reference at 1e-13 and at 1e-14 differ by 1e-5…1e-3), so those run 5 s.
    return 10.0 if n <= 2 else 5.0


def loosest_meeting(errors, target):
    """Index (into tolerances ordered loose → tight) of the loosest tolerance from which on
    every tighter one gives an error ≤ target; None when the tightest one misses it."""
    chosen = None
    for i in range(len(errors) - 1, -1, -1):
        if errors[i] <= target:
            chosen = i
        else:
            break
    return chosen


def reference_spread(files, sizes, tmp):
    """How well 10 s and 5 s are determined: |eomgen dop853 at 1e-13 − at 1e-14| (cheap, for
    the choice of t_end)."""
    rows = []
    for n in sizes:
        m = eomgen.load(make_copies(files[n], n, 1, Path(tmp) / "spread")[0])
        cells = [n]
        for t_end in (10.0, 5.0):
            a = m.simulate(t_end=t_end, t_out=[t_end], method="dop853", rtol=1e-13, atol=1e-13).y[-1]
            b = m.simulate(t_end=t_end, t_out=[t_end], method="dop853", rtol=1e-14, atol=1e-14).y[-1]
            cells.append(fmt_err(float(np.max(np.abs(a - b)))))
        rows.append(cells)
    return ("Final-state spread of the eomgen reference, max |dop853(1e-13) − dop853(1e-14)| "
            "over the state:\n\n" + table(["n", "t_end = 10 s", "t_end = 5 s"], rows))


def bench_equal_error(args, files, built, tmp):
    """Table 2b: the time at equal error."""
    from scipy.integrate import solve_ivp

    rng = np.random.default_rng(20240601)
    tols = sorted(args.tols, reverse=True)
    targets = args.targets
    summary_rows, detail_texts, raw = [], [], {}
    for n in args.sizes:
        t_end = t_end_for(args, n)
        m = eomgen.load(make_copies(files[n], n, 1, Path(tmp) / "equal")[0])
        if n in built:
            f, constants = built[n]
        else:
            log(f"pydy: building the PyDy model for n = {n}")
            f, constants, _ = pydy_build(n)
        values = m.parameters
        if sorted(str(c) for c in constants) != sorted(values):
            sys.exit(f"n = {n}: PyDy constants {constants} are not the file's parameters {list(values)}")
        p = np.array([values[str(c)] for c in constants])
        mismatch = check_same_model(m, f, p, n, rng)
        y0 = m.initial_state()

        def fun(t, y):
            # PyDy's generated function returns the same output array on every call; SciPy
            # keeps the stages' derivatives, so without a copy each call overwrites the
            # previous stages (at tol 1e-12 on the double pendulum: 6.8x the RHS evaluations
            # and 3,500x the error).
            return f(y, t, p).copy()

        log(f"pydy: n = {n}, t_end = {t_end}: references")
        ref = m.simulate(t_end=t_end, t_out=[t_end], method="dop853", rtol=1e-13, atol=1e-13).y[-1]
        ref14 = m.simulate(t_end=t_end, t_out=[t_end], method="dop853", rtol=1e-14, atol=1e-14).y[-1]
        start = time.perf_counter()
        sci = solve_ivp(fun, (0.0, t_end), y0, method="DOP853", rtol=1e-13, atol=1e-13, t_eval=[t_end])
        sci_ref_s = time.perf_counter() - start
        if not sci.success:
            sys.exit(f"n = {n}: SciPy's reference failed: {sci.message}")
        spread14 = float(np.max(np.abs(ref - ref14)))
        spread_sci = float(np.max(np.abs(ref - sci.y[:, -1])))
        # Targets below ten times the reference's own uncertainty are not reported.
        floor = 10 * max(spread14, spread_sci)

        solvers = ["eomgen dop853", "eomgen dp54", "SciPy DOP853 + PyDy"]
        times = {s: {tol: [] for tol in tols} for s in solvers}
        errors = {s: {} for s in solvers}
        evals = {s: {} for s in solvers}
        failures = {}  # SciPy's runs that stopped early, by tolerance

        def run(solver, tol):
            start = time.perf_counter()
            if solver == "SciPy DOP853 + PyDy":
                # Trial steps of a loose tolerance can overflow in the lambdified RHS; the
                # warnings say nothing the result does not.
                with np.errstate(over="ignore", invalid="ignore"):
                    sol = solve_ivp(fun, (0.0, t_end), y0, method="DOP853", rtol=tol, atol=tol, t_eval=[t_end])
                elapsed = time.perf_counter() - start
                if not sol.success:
                    # At loose tolerances SciPy can stop early ("Required step size is less
                    # than spacing between numbers"): a run that misses every target.
                    failures[tol] = sol.message
                    return elapsed, np.full(2 * n, np.inf), sol.nfev
                return elapsed, sol.y[:, -1], sol.nfev
            method = "dop853" if solver == "eomgen dop853" else "dp54"
            s = m.simulate(t_end=t_end, t_out=[t_end], method=method, rtol=tol, atol=tol)
            elapsed = time.perf_counter() - start
            return elapsed, s.y[-1], s.stats["rhs_evals"]

        for solver in solvers:  # warm-up
            run(solver, tols[0])
        eomgen_reps = args.reps
        scipy_reps = args.reps if n < args.large else args.large_reps
        for r in range(eomgen_reps):
            log(f"pydy: n = {n}, equal error, repetition {r + 1}/{eomgen_reps}"
                + ("" if r < scipy_reps else " (eomgen only)"))
            for tol in tols:
                for solver in solvers:
                    if solver.startswith("SciPy") and r >= scipy_reps:
                        continue
                    elapsed, y, count = run(solver, tol)
                    times[solver][tol].append(elapsed)
                    err = float(np.max(np.abs(y - ref)))
                    if tol in errors[solver] and err != errors[solver][tol] and np.isfinite(err):
                        sys.exit(f"n = {n}: {solver} at {tol} is not deterministic")
                    errors[solver][tol] = err
                    evals[solver][tol] = count

        detail_rows = []
        for tol in tols:
            cells = [f"{tol:.0e}"]
            for solver in solvers:
                failed = solver.startswith("SciPy") and tol in failures
                cells += ["failed" if failed else fmt_err(errors[solver][tol]),
                          fmt_time(median(times[solver][tol])), evals[solver][tol]]
            detail_rows.append(cells)
        headers = ["tol"]
        for solver in solvers:
            headers += [f"{solver} error", "time", "RHS evals"]
        detail_texts.append(
            f"n = {n}, t_end = {t_end:g} s (repetitions: eomgen {eomgen_reps}, SciPy {scipy_reps}; "
            f"RHS check eomgen vs PyDy: max relative difference {mismatch:.1e}; reference "
            f"dop853(1e-13) vs dop853(1e-14): {spread14:.1e}, vs SciPy DOP853(1e-13) + PyDy: "
            f"{spread_sci:.1e} in {fmt_time(sci_ref_s)}):\n\n" + table(headers, detail_rows)
            + "".join(f"\n\nSciPy at tol {tol:.0e} failed: {message} (time and RHS evals up to the failure)"
                      for tol, message in failures.items()))

        for target in targets:
            cells = [n, f"{t_end:g} s", f"{target:.0e}"]
            if target < floor:
                summary_rows.append(cells + [f"reference uncertain ({floor / 10:.0e})"] + ["–"] * 4)
                continue
            picked = {}
            for solver in solvers:
                i = loosest_meeting([errors[solver][tol] for tol in tols], target)
                picked[solver] = None if i is None else (tols[i], median(times[solver][tols[i]]))
            for solver in solvers:
                pick = picked[solver]
                cells.append("not reached" if pick is None else f"{fmt_time(pick[1])} ({pick[0]:.0e})")
            sci_pick = picked["SciPy DOP853 + PyDy"]
            for solver in ("eomgen dop853", "eomgen dp54"):
                pick = picked[solver]
                cells.append("–" if pick is None or sci_pick is None else f"{sci_pick[1] / pick[1]:.0f}×")
            summary_rows.append(cells)
        raw[n] = {"t_end": t_end, "tols": tols, "errors": errors, "evals": evals,
                  "times": {s: {str(k): v for k, v in t.items()} for s, t in times.items()},
                  "spread14": spread14, "spread_scipy": spread_sci, "rhs_mismatch": mismatch,
                  "scipy_failures": {str(k): v for k, v in failures.items()}}

    headers = ["n", "t_end", "target error", "eomgen dop853 (tol)", "eomgen dp54 (tol)",
               "SciPy DOP853 + PyDy (tol)", "SciPy+PyDy / eomgen dop853", "SciPy+PyDy / eomgen dp54"]
    text = ("### Simulation at equal error: n-link pendulum from the file's initial state (all bars "
            "along +x, at rest), error = max |y(t_end) − reference| over the state; time = median wall "
            "time of the call at the loosest tolerance from which every tighter one meets the target; "
            "a target below ten times the reference's uncertainty (its distance to dop853 at 1e-14 or "
            "to SciPy at 1e-13, whichever is larger) is not reported\n\n"
            + table(headers, summary_rows)
            + "\n\n" + reference_spread(files, args.sizes, tmp)
            + "\n\n#### Every tolerance\n\n" + "\n\n".join(detail_texts))
    return {"text": text, "raw": raw}


def bench_pydy(args) -> dict:
    cli = cli_path(args)
    files = {}
    for n in args.sizes:
        files[n] = subprocess.run([cli, "new", "n-link-pendulum", str(n)], capture_output=True,
                                  text=True, check=True).stdout
    with tempfile.TemporaryDirectory(prefix="eomgen-bench-") as tmp:
        for sub in ("rhs", "sim", "probe", "equal", "spread"):
            (Path(tmp) / sub).mkdir()
        first, built = bench_first_step(args, files, tmp)
        equal = bench_equal_error(args, files, built, tmp)
    return {"text": first["text"] + "\n\n" + equal["text"], "raw": {"first": first["raw"], "equal": equal["raw"]}}


# --- 3. Dask sweep ------------------------------------------------------------------------


def bench_dask(args) -> dict:
    from distributed import Client, LocalCluster

    import eomgen.sweep

    m = eomgen.load("double_pendulum")
    y0 = m.initial_state()
    states = np.tile(y0, (args.points, 1))
    states[:, m.coordinates.index("theta1")] += np.linspace(-0.1, 0.1, args.points)
    options = dict(t_end=10.0, t_out=[10.0], rtol=1e-10, atol=1e-10)

    def serial():
        return np.stack([m.simulate(initial=s, **options).y for s in states])

    local = {
        "serial loop of m.simulate": serial,
        "m.simulate_many(threads=1)": lambda: m.simulate_many(initial_states=states, threads=1, **options).y,
        f"m.simulate_many() ({os.cpu_count()} threads)": lambda: m.simulate_many(initial_states=states, **options).y,
    }
    log("dask: warm-up")
    expected = serial()
    for fn in local.values():
        fn()
    times = {k: [] for k in local}
    equal = {k: True for k in local}
    for r in range(args.reps):
        log(f"dask: local, repetition {r + 1}/{args.reps}")
        for name, fn in local.items():
            start = time.perf_counter()
            y = fn()
            times[name].append(time.perf_counter() - start)
            equal[name] &= bool(np.array_equal(y, expected))
    serial_s = median(times["serial loop of m.simulate"])
    rows = [[name, "–", fmt_time(median(t)), f"{args.points / median(t):,.0f}", f"{serial_s / median(t):.2f}×",
             "–", "–", equal[name]] for name, t in times.items()]

    cores = os.cpu_count() or 1
    raw = {"local": times, "dask": {}}
    for workers in args.workers:
        log(f"dask: LocalCluster with {workers} worker(s)")
        start = time.perf_counter()
        cluster = LocalCluster(host="127.0.0.1", n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
        client.wait_for_workers(workers)
        startup = time.perf_counter() - start
        try:
            # The first sweep also unpickles and compiles the model once in each worker.
            start = time.perf_counter()
            y = eomgen.sweep.run(client, m, initial_states=states, **options).y
            first = time.perf_counter() - start
            same = bool(np.array_equal(y, expected))
            sweep_times, baseline = [], []
            for r in range(args.reps):
                log(f"dask: {workers} worker(s), repetition {r + 1}/{args.reps}")
                start = time.perf_counter()
                y = eomgen.sweep.run(client, m, initial_states=states, **options).y
                sweep_times.append(time.perf_counter() - start)
                same &= bool(np.array_equal(y, expected))
                # simulate_many on all cores, interleaved, with the cluster idle beside it.
                start = time.perf_counter()
                m.simulate_many(initial_states=states, **options)
                baseline.append(time.perf_counter() - start)
        finally:
            client.close()
            cluster.close()
        t = median(sweep_times)
        label = f"eomgen.sweep.run, LocalCluster {workers} worker(s), {10 * workers} chunks"
        if workers > cores:
            label += f" (oversubscribed: {cores} cores)"
        rows.append([label, fmt_time(startup), fmt_time(t), f"{args.points / t:,.0f}", f"{serial_s / t:.2f}×",
                     fmt_time(first), f"{t / median(baseline):.2f}", same])
        raw["dask"][workers] = {"startup": startup, "first": first, "times": sweep_times, "baseline": baseline}

    headers = ["runner", "cluster start-up (not in time)", "time (median)", "runs/s", "speed-up vs serial loop",
               "first sweep (cold workers)", "time / simulate_many() interleaved", "equal to serial loop bit for bit"]
    text = (f"### Sweep: {args.points:,}-run Monte Carlo over theta1 ± 0.1 rad of the double pendulum, "
            f"10 s, dp54, rtol = atol = 1e-10, t_out = [10] (medians of {args.reps}; {cores} cores)\n\n"
            + table(headers, rows))
    return {"text": text, "raw": raw}


# --- main ---------------------------------------------------------------------------------


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", nargs="+", choices=["overhead", "pydy", "dask"],
                        default=["overhead", "pydy", "dask"], help="sections to run (default: all)")
    parser.add_argument("--sizes", nargs="+", type=int, default=[2, 5, 10, 20], help="chain lengths n")
    parser.add_argument("--reps", type=int, default=5, help="repetitions after the warm-up (default 5)")
    parser.add_argument("--overhead-reps", type=int, default=1001, help="calls of each overhead variant")
    parser.add_argument("--large", type=int, default=20,
                        help="from this n on, the PyDy/SciPy side runs fewer repetitions (default 20)")
    parser.add_argument("--large-build-reps", type=int, default=2, help="PyDy builds at n ≥ --large (default 2)")
    parser.add_argument("--large-reps", type=int, default=3, help="SciPy runs at n ≥ --large (default 3)")
    parser.add_argument("--tols", nargs="+", type=float, default=[10.0**-k for k in range(4, 13)],
                        help="tolerances of the equal-error comparison (default 1e-4 … 1e-12)")
    parser.add_argument("--targets", nargs="+", type=float, default=[1e-4, 1e-6, 1e-8, 1e-10])
    parser.add_argument("--t-end", type=float, default=None,
                        help="simulated time of the equal-error comparison (default 10 s for n ≤ 2, 5 s above)")
    parser.add_argument("--points", type=int, default=1000, help="runs of the Monte Carlo sweep")
    parser.add_argument("--workers", nargs="+", type=int, default=[1, 2, 4], help="Dask worker processes")
    parser.add_argument("--cli", help="the eomgen command-line program (default target/release/eomgen)")
    parser.add_argument("--json", help="also write the raw figures to this file")
    return parser.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    facts = machine_facts()
    report = ["## eomgen Python benchmarks", "",
              f"- CPU: {facts['cpu']}, nproc = {facts['nproc']}; {facts['platform']}; "
              f"load average at start {facts['loadavg'][0]:.2f}",
              "- " + ", ".join(f"{k} {v}" for k, v in facts["versions"].items()),
              f"- repository commit {facts['commit']}; command: {' '.join([Path(sys.executable).name] + sys.argv)}"]
    print("\n".join(report), flush=True)
    results = {"facts": facts}
    started = time.perf_counter()
    sections = {"overhead": bench_overhead, "pydy": bench_pydy, "dask": bench_dask}
    for name in ("overhead", "pydy", "dask"):
        if name in args.only:
            section_start = time.perf_counter()
            results[name] = sections[name](args)
            log(f"{name}: {time.perf_counter() - section_start:.1f} s")
            print("\n" + results[name]["text"], flush=True)
    print(f"\n(total {time.perf_counter() - started:.0f} s; load average at the end {os.getloadavg()[0]:.2f})")
    if args.json:
        raw = {k: (v["raw"] if isinstance(v, dict) and "raw" in v else v) for k, v in results.items()}
        Path(args.json).write_text(json.dumps(raw, indent=1, default=str))


if __name__ == "__main__":
    main()
