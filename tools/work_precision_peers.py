"""Work-precision of eomgen's methods against ode_solvers and heyoka, measured in one run.

Codes compared, on the same model, initial state and reference:
- eomgen's adaptive methods, by their `Method` names (`--methods dp54,dop853`; methods added
  later are included by name), and ode_solvers 0.6.2's Dop853 (`--peers
  ode_solvers-dop853`, optionally `ode_solvers-dopri5`), both measured by the Rust program of
  examples/work_precision_peers.rs on the model compiled by `model!` (with `--from-file`,
  on the model loaded from its file and compiled at run time, the command line's path: build
  the example with `--features jit`);
- heyoka's `taylor_adaptive` (tools/heyoka_peer.py, imported: its integrators are built and
  compiled once per tolerance and reused, so compile time is not in the timings; it is
  reported separately: by default heyoka's on-disk cache of compiled code, $XDG_CACHE_HOME/heyoka,
  is pointed at an empty temporary directory so that these are first compilations;
  `--warm-cache` keeps the user's cache).

Problems: the HW19 double pendulum (models/double_pendulum.yaml) from its initial state to
t = 10 s at tolerances rtol = atol = tol = 1e-2 ... 1e-15 (`--per-decade` values per decade),
error = max |y_i(10) - y_ref_i| over [theta1, theta2, theta1_dot, theta2_dot] (rad, rad/s;
the norm of benches/peers.rs); and the figure-eight three-body orbit
(models/figure_eight.yaml) over 10 periods (t = 63.2591398) at tol = 1e-14: time, relative
energy drift |E(T) - E(0)| / |E(0)| and final-state error (with the fastest single run
beside the median: on a shared machine a run that loses its core to another process shows as
a second mode of the times). The reference final states are
computed in multiple precision (tools/heyoka_peer.py reference: 170 bits, checked against 210
bits; 45 digits written) from the same double initial states, once, into --reference.

Timing: `--rounds` rounds alternate the two batches (Rust program, heyoka; the order reversed
on odd rounds), so a drift of the shared machine's speed falls on every code alike; each batch
times every configuration `--reps` times and reports the median; the table uses the median of
the rounds' medians. Errors and step counts are deterministic and checked equal between
rounds.

Equal error (the rule of docs/performance.md): for a target error E, a method's cost is its
time at the loosest tolerance from which every tighter tolerance of the sweep gives an error
<= E (no interpolation; "-" if there is none). The ratios heyoka / eomgen-best and
ode_solvers / eomgen-best (> 1: eomgen cheaper) are taken at targets 1e-2 ... 1e-10, where
eomgen-best is the cheapest of eomgen's methods at that target.

Usage (from the repository root):
    CARGO_TARGET_DIR=... cargo build --release --no-default-features --example work_precision_peers
    python tools/work_precision_peers.py --binary $CARGO_TARGET_DIR/release/examples/work_precision_peers \
        [--methods dp54,dop853] [--peers ode_solvers-dop853] [--rounds 7] [--reps 5] \
        [--per-decade 2] [--reference /tmp/peers-out/reference.json] \
        [--out /tmp/peers-out/work_precision_peers.md] [--svg /tmp/peers-out/work_precision_peers.svg] \
        [--raw /tmp/peers-out/raw.jsonl] [--warm-cache] [--heyoka-high-accuracy] [--from-file]
Without --out the markdown is printed. The chart (log-log, error against median time, one
line per method) is drawn with matplotlib.
"""
import argparse
import atexit
import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
# Imported in main(), after the choice of heyoka's cache directory.
heyoka_peer = None
# heyoka's method label: heyoka_peer.METHOD, or METHOD_HIGH_ACCURACY with --heyoka-high-accuracy.
HEYOKA_METHOD = None

ROOT = Path(__file__).resolve().parent.parent
DP, FE = "double_pendulum", "figure_eight"
FE_TOL = 1e-14
TARGETS = [10.0 ** -k for k in range(2, 11)]


def tolerances(per_decade):
    """1e-2 ... 1e-15 with `per_decade` values per decade, loosest first."""
    return [10.0 ** (-k / per_decade) for k in range(2 * per_decade, 15 * per_decade + 1)]


def rust_batch(binary, methods, tols, reps, reference, from_file=False):
    """The Rust program's results for the double-pendulum sweep and the figure eight
    (`from_file`: the models loaded from their files and compiled at run time)."""
    results = []
    for model, model_tols in ((DP, tols), (FE, [FE_TOL])):
        cmd = [binary, "run", "--model", model, "--t-end", repr(heyoka_peer.T_END[model]),
               "--methods", ",".join(methods), "--tols", ",".join(map(repr, model_tols)),
               "--reps", str(reps), "--reference", str(reference)]
        if from_file:
            cmd += ["--from-file", "on"]
        out = subprocess.run(cmd, capture_output=True, text=True)
        if out.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)} failed: {out.stderr}")
        results += [json.loads(line) for line in out.stdout.splitlines() if line.strip()]
    return results


def heyoka_batch(peer, tols, reps):
    """heyoka's results for the same jobs."""
    return peer.run([(DP, tol) for tol in tols] + [(FE, FE_TOL)], reps)


def key(result):
    return (result["method"], result["model"], result["tol"])


def merge(rounds):
    """One result per (method, model, tol): the first round's, with `time_s` the median of the
    rounds' medians and `round_times_s` all of them; a changed error or step count between
    rounds is an error."""
    merged = {}
    for batch in rounds:
        for r in batch:
            k = key(r)
            if k not in merged:
                merged[k] = dict(r, round_times_s=[])
            m = merged[k]
            if "failed" in r or "failed" in m:
                continue
            if r["final_state"] != m["final_state"] or r["steps"] != m["steps"]:
                raise RuntimeError(f"{k}: a deterministic run changed between rounds")
            m["round_times_s"].append(r["time_s"])
            m["min_s"] = min([m.get("min_s", math.inf)] + r["times_s"])
    for m in merged.values():
        if m["round_times_s"]:
            m["time_s"] = statistics.median(m["round_times_s"])
    return merged


def cost_at(sweep, target):
    """The docs' rule: the run at the loosest tolerance from which every tighter one gives an
    error <= target, or None. `sweep` is sorted loosest first."""
    ok = [("failed" not in r) and r["error"] is not None and r["error"] <= target
          for r in sweep]
    for i in range(len(sweep)):
        if all(ok[i:]):
            return sweep[i]
    return None


def fmt_time(s):
    return "-" if s is None else (f"{s * 1e6:.1f} µs" if s < 1e-3 else f"{s * 1e3:.3f} ms")


def fmt_ratio(a, b):
    return "-" if a is None or b is None else f"{a / b:.2f}"


def report(merged, methods, peers, tols, args, meta):
    """The markdown text: equal-error table, the sweep, the figure eight."""
    all_methods = methods + peers + [HEYOKA_METHOD]
    sweeps = {m: sorted([merged[(m, DP, t)] for t in tols if (m, DP, t) in merged],
                        key=lambda r: -r["tol"]) for m in all_methods}
    lines = []
    w = lines.append
    w(f"Work-precision, double pendulum (HW19 defaults) 0 -> 10 s; error = max|y(10) - y_ref| "
      f"(rad, rad/s) against a 45-digit reference; time = median over {args.rounds} "
      f"alternating rounds of the median of {args.reps} runs. {meta}")
    w("")
    w("Cost at equal error: the time at the loosest tolerance from which every tighter one "
      "meets the target (tolerance in parentheses); ratios > 1: eomgen cheaper.")
    w("")
    head = ["target error"] + [f"eomgen {m}" for m in methods] + \
        [p for p in peers] + [label(HEYOKA_METHOD), "eomgen best"] + \
        [f"{p} / eomgen best" for p in peers] + ["heyoka / eomgen best"]
    w("| " + " | ".join(head) + " |")
    w("|" + "---|" * len(head))
    for target in TARGETS:
        costs = {m: cost_at(sweeps[m], target) for m in all_methods}
        cell = {m: "-" if costs[m] is None else
                f"{fmt_time(costs[m]['time_s'])} ({costs[m]['tol']:.0e})" for m in all_methods}
        eomgen = [(costs[m]["time_s"], m) for m in methods if costs[m] is not None]
        best = min(eomgen) if eomgen else None
        row = [f"{target:.0e}"] + [cell[m] for m in methods] + [cell[p] for p in peers] + \
            [cell[HEYOKA_METHOD], "-" if best is None else best[1]]
        best_t = best[0] if best else None
        row += [fmt_ratio(costs[p]["time_s"] if costs[p] else None, best_t) for p in peers]
        hy_cost = costs[HEYOKA_METHOD]
        row += [fmt_ratio(hy_cost["time_s"] if hy_cost else None, best_t)]
        w("| " + " | ".join(row) + " |")
    w("")
    w("The sweep (error, median time, RHS evaluations or Taylor steps × order):")
    w("")
    head = ["tol"] + all_methods
    w("| " + " | ".join(head) + " |")
    w("|" + "---|" * len(head))
    for tol in tols:
        row = [f"{tol:.1e}"]
        for m in all_methods:
            r = merged.get((m, DP, tol))
            if r is None:
                row.append("")
            elif "failed" in r:
                row.append("failed")
            elif r["rhs_evals"] is not None:
                row.append(f"{r['error']:.1e}, {fmt_time(r['time_s'])}, {r['rhs_evals']} RHS")
            else:
                row.append(f"{r['error']:.1e}, {fmt_time(r['time_s'])}, "
                           f"{r['steps']} × {r['order']}")
        w("| " + " | ".join(row) + " |")
    w("")
    w(f"Figure eight (HW7), 10 periods (t = {heyoka_peer.T_END[FE]}), tol = {FE_TOL:.0e}:")
    w("")
    w("| method | time (median) | fastest run | RHS evaluations / steps | relative energy drift "
      "| final-state error |")
    w("|---|---|---|---|---|---|")
    for m in all_methods:
        r = merged.get((m, FE, FE_TOL))
        if r is None:
            continue
        if "failed" in r:
            w(f"| {m} | failed: {r['failed']} | | | | |")
            continue
        work = f"{r['rhs_evals']} RHS, {r['steps']} steps" if r["rhs_evals"] is not None \
            else f"{r['steps']} steps of order {r['order']}"
        w(f"| {m} | {fmt_time(r['time_s'])} | {fmt_time(r.get('min_s'))} | {work} | {r['energy_drift']:.1e} | "
          f"{r['error']:.1e} |")
    w("")
    builds = [(r["tol"], r["model"], r["construct_s"]) for r in merged.values()
              if r.get("construct_s") is not None]
    if builds:
        dp_builds = [b for _, model, b in builds if model == DP]
        orders = [r["order"] for r in sweeps[HEYOKA_METHOD] if "order" in r]
        cache = "from heyoka's on-disk cache" if args.warm_cache else \
            "first compilation, empty cache"
        w(f"heyoka construction (Taylor decomposition + LLVM compilation, {cache}) per "
          f"tolerance, not in the times above: double pendulum {min(dp_builds):.2f}–{max(dp_builds):.2f} s "
          f"(Taylor orders {min(orders)}–{max(orders)}); figure "
          f"eight {[b for _, model, b in builds if model == FE][0]:.2f} s.")
    overheads = [r["call_overhead_s"] for r in merged.values() if "call_overhead_s" in r]
    if overheads:
        w(f"The Python call of heyoka's propagate_until costs {fmt_time(min(overheads))}–"
          f"{fmt_time(max(overheads))} (a call that takes no step), included in its times.")
    return "\n".join(lines) + "\n", sweeps


def label(method):
    """The chart's name of a method: the code and its method."""
    if method.startswith("ode_solvers-"):
        return "ode_solvers " + method.split("-", 1)[1].capitalize()
    if method == HEYOKA_METHOD:
        return "heyoka taylor_adaptive" + (
            " (high_accuracy)" if method == heyoka_peer.METHOD_HIGH_ACCURACY else "")
    return "eomgen " + method


def chart(sweeps, path, title):
    """A log-log SVG: error against median time, one line per method."""
    import matplotlib
    matplotlib.use("svg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 5))
    markers = "os^Dv<>ph*"
    for i, (method, sweep) in enumerate(sweeps.items()):
        pts = [(r["error"], r["time_s"]) for r in sweep
               if "failed" not in r and r["error"] and r["error"] > 0]
        if pts:
            ax.loglog([p[0] for p in pts], [p[1] * 1e3 for p in pts],
                      marker=markers[i % len(markers)], markersize=4, label=label(method))
    ax.set_xlabel("error at t = 10 s, max |y - y_ref| (rad, rad/s)")
    ax.set_ylabel("time (ms)")
    ax.set_title(title, fontsize=10)
    ax.invert_xaxis()
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, metadata={"Date": None})
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    target = os.environ.get("CARGO_TARGET_DIR", str(ROOT / "target"))
    parser.add_argument("--binary",
                        default=str(Path(target) / "release/examples/work_precision_peers"))
    parser.add_argument("--methods", default="dp54,dop853")
    parser.add_argument("--peers", default="ode_solvers-dop853")
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--per-decade", type=int, default=2)
    parser.add_argument("--reference", default="/tmp/peers-out/reference.json")
    parser.add_argument("--out")
    parser.add_argument("--svg")
    parser.add_argument("--raw")
    parser.add_argument("--heyoka-high-accuracy", action="store_true",
                        help="run heyoka with high_accuracy=True (each step's polynomial "
                             "summed with compensation)")
    parser.add_argument("--from-file", action="store_true",
                        help="eomgen's models loaded from their files and compiled at run "
                             "time (the command line's path; build the example with "
                             "--features jit)")
    parser.add_argument("--warm-cache", action="store_true",
                        help="let heyoka use its on-disk cache of compiled integrators")
    args = parser.parse_args()
    if not args.warm_cache:
        # heyoka keeps compiled code in $XDG_CACHE_HOME/heyoka; an empty one makes the
        # reported construction times those of a first compilation.
        os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp(prefix="heyoka-cache-")
        atexit.register(shutil.rmtree, os.environ["XDG_CACHE_HOME"], ignore_errors=True)
    global heyoka_peer, HEYOKA_METHOD
    import heyoka_peer as module
    heyoka_peer = module
    methods = [m for m in args.methods.split(",") if m]
    peers = [p for p in args.peers.split(",") if p]
    tols = tolerances(args.per_decade)
    if not Path(args.reference).exists():
        heyoka_peer.command_reference(argparse.Namespace(out=args.reference))
    peer = heyoka_peer.HeyokaPeer(heyoka_peer.load_reference(args.reference),
                                  high_accuracy=args.heyoka_high_accuracy)
    HEYOKA_METHOD = peer.method
    start = time.perf_counter()
    heyoka_batch(peer, tols, 1)  # builds and compiles every integrator once
    print(f"heyoka integrators built in {time.perf_counter() - start:.1f} s", file=sys.stderr)
    rounds = []
    for r in range(args.rounds):
        batches = [lambda: rust_batch(args.binary, methods + peers, tols, args.reps,
                                      args.reference, args.from_file),
                   lambda: heyoka_batch(peer, tols, args.reps)]
        if r % 2:
            batches.reverse()
        for batch in batches:
            rounds.append(batch())
        print(f"round {r + 1}/{args.rounds} done", file=sys.stderr)
    merged = merge(rounds)
    if args.raw:
        Path(args.raw).write_text("".join(json.dumps(m) + "\n" for m in merged.values()))
    load = os.getloadavg()
    meta = (f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {platform.machine()}, "
            f"{os.cpu_count()} cores, load average {load[0]:.1f} at the end; heyoka "
            f"{heyoka_peer.hy.__version__}; eomgen's models "
            f"{'loaded from their files' if args.from_file else 'compiled by model!'}.")
    text, sweeps = report(merged, methods, peers, tols, args, meta)
    if args.out:
        Path(args.out).write_text(text)
    else:
        print(text)
    if args.svg:
        chart(sweeps, args.svg, "Double pendulum 0–10 s: work–precision (median times)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
