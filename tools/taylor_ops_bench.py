"""The Taylor method's cost per operation, eomgen against heyoka, on the same expression.
Not used by the product.

Each case is one oscillator, x'' = -x + g(x, x'), with `g` one operation applied to simple
arguments (a product, a square, a quotient, a square root, a real power, exp, ln, a sine, a sine
times a cosine); the baseline is g = 0. Both codes integrate it from x = 0.5, x' = 0 to
t = 20 with their adaptive Taylor methods at rtol = atol = tol, and take the same steps at the
same orders (checked), so the time per step compares their recurrences and step loops on that
expression, and the time per step above the baseline's is the operation's own cost:

- eomgen: the model file `coordinates: [x]`, `kinetic: x_dot^2/2`, `generalized_forces: {x:
  -x + g}`, loaded and compiled at run time (benches/work_precision_peers.rs `--from-file
  on`: the command line's path), `--methods taylor`, every step recorded;
- heyoka: `taylor_adaptive([(x, v), (v, -x + g)], tol=tol)`, `propagate_until(20)` (the
  expression converted from the same text by SymPy, as tools/heyoka_peer.py converts a
  model's); its integrator built once per case and tolerance, not timed.

Times are medians over `--rounds` rounds (the two codes alternated) of the medians of `--reps`
runs. Usage (from the repository root, with heyoka, sympy and the eomgen package installed):

    cargo build --release -p eomgen-benches --features work-precision --example work_precision_peers
    python tools/taylor_ops_bench.py [--tols 1e-6,1e-9,1e-12] [--rounds 5] [--reps 21] [--out ops.md]
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import heyoka as hy
import sympy

sys.path.insert(0, str(Path(__file__).resolve().parent))
import heyoka_peer  # noqa: E402  (its SymPy -> heyoka conversion)

ROOT = Path(__file__).resolve().parent.parent
T_END = 20.0
X0 = 0.5

# (name, g(x, x_dot) in the model files' syntax); arguments kept in 2 ± 0.5 where an
# operation has a branch point.
CASES = [
    ("baseline (g = 0)", "0"),
    ("product x·ẋ", "0.1*x*x_dot"),
    ("square x²", "0.1*x^2"),
    ("quotient 1/(2 + ẋ)", "0.1/(2 + x_dot)"),
    ("square root √(2 + x)", "0.1*sqrt(2 + x)"),
    ("real power (2 + x)^-1.5", "0.1*(2 + x)^(-1.5)"),
    ("exp(x)", "0.1*exp(x)"),
    ("ln(2 + x)", "0.1*ln(2 + x)"),
    ("sin(x)", "0.1*sin(x)"),
    ("sin(x)·cos(ẋ)", "0.1*sin(x)*cos(x_dot)"),
]


def model_text(g):
    return (f"name: oscillator\ncoordinates: [x]\nkinetic: x_dot^2/2\n"
            f"generalized_forces:\n  x: -x + {g}\ninitial: {{ x: {X0} }}\n")


def eomgen_run(binary, path, tols, reps):
    """{tol: (time_s, steps)} of eomgen's Taylor method on the model file at `path`."""
    cmd = [binary, "run", "--from-file", "on", "--model", str(path), "--t-end", repr(T_END),
           "--methods", "taylor", "--tols", ",".join(map(repr, tols)), "--reps", str(reps)]
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: {out.stderr}")
    results = [json.loads(line) for line in out.stdout.splitlines() if line.strip()]
    for r in results:
        if "failed" in r:
            raise RuntimeError(f"{path}: {r['failed']}")
    return {r["tol"]: (r["time_s"], r["steps"]) for r in results}


def heyoka_integrator(g, tol):
    """heyoka's integrator of x'' = -x + g, built from the same text."""
    x, v = hy.make_vars("x", "x_dot")
    text = f"-x + {g}".replace("^", "**")
    names = {"x": sympy.Symbol("x"), "x_dot": sympy.Symbol("x_dot"), "ln": sympy.log}
    expr = sympy.sympify(text, locals=names)
    rhs = heyoka_peer.to_heyoka(sympy.nsimplify(expr, rational=True), {"x": x, "x_dot": v},
                                heyoka_peer.make_number(None))
    return hy.taylor_adaptive([(x, v), (v, rhs)], [X0, 0.0], tol=tol)


def heyoka_run(ta, reps):
    """(median time, steps, order) of `reps` runs of `ta` from the start to T_END."""
    times, steps = [], None
    for _ in range(reps + 1):
        ta.time = 0.0
        ta.state[:] = [X0, 0.0]
        start = time.perf_counter()
        outcome = ta.propagate_until(T_END)
        times.append(time.perf_counter() - start)
        if outcome[0] != hy.taylor_outcome.time_limit:
            raise RuntimeError(f"heyoka stopped: {outcome}")
        steps = outcome[3]
    return statistics.median(times[1:]), steps, ta.order


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    target = os.environ.get("CARGO_TARGET_DIR", str(ROOT / "target"))
    parser.add_argument("--binary", default=str(Path(target) / "release/examples/work_precision_peers"))
    parser.add_argument("--tols", default="1e-6,1e-9,1e-12")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--reps", type=int, default=21)
    parser.add_argument("--out")
    args = parser.parse_args()
    tols = [float(t) for t in args.tols.split(",")]
    work = Path(tempfile.mkdtemp(prefix="taylor-ops-"))
    files = {}
    for i, (name, g) in enumerate(CASES):
        files[name] = work / f"case{i}.yaml"
        files[name].write_text(model_text(g))
    integrators = {(name, tol): heyoka_integrator(g, tol) for name, g in CASES for tol in tols}
    ours = {name: [] for name, _ in CASES}
    theirs = {(name, tol): [] for name, _ in CASES for tol in tols}
    for r in range(args.rounds):
        for name, _ in CASES:
            sides = ["eomgen", "heyoka"] if r % 2 == 0 else ["heyoka", "eomgen"]
            for side in sides:
                if side == "eomgen":
                    ours[name].append(eomgen_run(args.binary, files[name], tols, args.reps))
                else:
                    for tol in tols:
                        theirs[(name, tol)].append(heyoka_run(integrators[(name, tol)], args.reps))
        print(f"round {r + 1}/{args.rounds}", file=sys.stderr)
    lines = [f"Taylor per step, x'' = -x + g from x = {X0} to t = {T_END}, same steps and orders; "
             f"median of {args.rounds} alternating rounds of {args.reps} runs "
             f"({time.strftime('%Y-%m-%d', time.gmtime())}, {os.cpu_count()} cores, heyoka "
             f"{hy.__version__}). ns per step: eomgen / heyoka (eomgen ÷ heyoka); the operation's "
             "own cost above the baseline's in brackets.", ""]
    head = ["g"] + [f"tol {t:.0e} (order {theirs[(CASES[0][0], t)][0][2]})" for t in tols]
    lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    base = {}
    for name, _ in CASES:
        row = [name]
        for tol in tols:
            e_time = statistics.median(run[tol][0] for run in ours[name])
            e_steps = ours[name][0][tol][1]
            h_time = statistics.median(x[0] for x in theirs[(name, tol)])
            h_steps = theirs[(name, tol)][0][1]
            e_ns, h_ns = 1e9 * e_time / e_steps, 1e9 * h_time / h_steps
            if name == CASES[0][0]:
                base[tol] = (e_ns, h_ns)
                own = ""
            else:
                own = f" [{e_ns - base[tol][0]:.0f} / {h_ns - base[tol][1]:.0f}]"
            steps = "" if e_steps == h_steps else f", steps {e_steps}/{h_steps}"
            row.append(f"{e_ns:.0f} / {h_ns:.0f} ({e_ns / h_ns:.2f}){own}{steps}")
        lines.append("| " + " | ".join(row) + " |")
    text = "\n".join(lines) + "\n"
    if args.out:
        Path(args.out).write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
