"""Work-precision of eomgen's methods against ode_solvers and heyoka, measured in one run.

Codes compared, on the same model, initial state and reference:
- eomgen's adaptive methods, by their `Method` names (`--methods dp54,dop853`; methods added
  later are included by name), and ode_solvers 0.6.2's Dop853 (`--peers
  ode_solvers-dop853`, optionally `ode_solvers-dopri5`), both measured by the Rust program of
  benches/work_precision_peers.rs on the model loaded from its file and compiled at run
  time, the command line's path, or with
  `--compiled` on the copy `model!` compiled into the program (the double pendulum and the
  figure eight only);
- heyoka's `taylor_adaptive` (tools/heyoka_peer.py, imported: its integrators are built and
  compiled once per tolerance and reused, so compile time is not in the timings; it is
  reported separately: by default heyoka's on-disk cache of compiled code, $XDG_CACHE_HOME/heyoka,
  is pointed at an empty temporary directory so that these are first compilations;
  `--warm-cache` keeps the user's cache).

Problems: the panel of tools/peer_panel.py (double pendulum, figure eight, heavy top off
its steady precession, a Kepler orbit at e = 0.9 from a file, a 5-link chain, the benchmark
bicycle), or the `--models` named, each from its initial state (with the panel's changes) to
its end time, every one swept over the same tolerances rtol = atol = tol (`--per-decade` values
per decade from `--loosest` to `--tightest`); error = max |y_i(t_end) - y_ref_i| over the whole
state [q; q'] (the norm of benches/peers.rs). The reference final states are computed in
multiple precision by heyoka (tools/heyoka_peer.py reference: 170 bits, checked against 210
bits; 45 digits written) from the same double initial states, once, into --reference; for a
model heyoka cannot express (the bicycle's constraints) by eomgen itself, Vern9 at
rtol = atol = 1e-15, with its disagreement with DOP853 and Vern9 at 1e-14 as its uncertainty
(targets below ten times that are not reported).

Timing: `--rounds` rounds alternate the two batches (Rust program, heyoka; the order reversed
on odd rounds), so a drift of the shared machine's speed falls on every code alike; each batch
times every configuration `--reps` times and reports the median; the table uses the median of
the rounds' medians. Errors and step counts are deterministic and checked equal between
rounds.

Equal error (the rule of docs/performance.md): for a target error E, a method's cost is its
time at the loosest tolerance from which every tighter tolerance of the sweep gives an error
<= E (no interpolation; "-" if there is none). The ratios heyoka / eomgen-best and
ode_solvers / eomgen-best (> 1: eomgen cheaper) are taken at targets 1e-2 ... 1e-10, where
eomgen-best is the cheapest of eomgen's methods at that target. The panel's goals (issue
"ahead of heyoka on models nobody tuned for"): heyoka / eomgen-best >= 1.0 at every target
1e-4 ... 1e-10 on every model heyoka can express, >= 1.3 at 1e-8 and tighter; the report's
first table gives that ratio per model and target, and a verdict.

Usage (from the repository root; the driver and heyoka_peer need a Python with heyoka, sympy,
pyyaml, matplotlib and the eomgen package):
    cargo build --release -p eomgen-benches --features work-precision --example work_precision_peers
    python tools/work_precision_peers.py --binary target/release/examples/work_precision_peers \
        [--models double_pendulum,kepler_e09] [--compiled] [--methods dp54,dop853,vern9,taylor] \
        [--peers ode_solvers-dop853] [--rounds 5] [--reps 3] [--per-decade 2] \
        [--reference /tmp/peers-out/reference.json] [--out table.md] [--svg panel.svg] \
        [--raw raw.jsonl] [--warm-cache] [--heyoka-high-accuracy]
Without --out the markdown is printed. The chart (log-log, error against median time, one
panel per model, one line per method) is drawn with matplotlib.
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
import peer_panel  # noqa: E402  (the panel: tools/peer_panel.py)

TARGETS = [10.0 ** -k for k in range(2, 11)]
# The panel's goals: heyoka / eomgen-best at these targets.
GOAL_TARGETS = [10.0 ** -k for k in range(4, 11)]
GOAL_ALL, GOAL_TIGHT, TIGHT_FROM = 1.0, 1.3, 1e-8


def tolerances(per_decade, loosest=2, tightest=15):
    """1e-`loosest` ... 1e-`tightest` with `per_decade` values per decade, loosest first."""
    return [10.0 ** (-k / per_decade)
            for k in range(loosest * per_decade, tightest * per_decade + 1)]


def rust_command(binary, e, command, from_file):
    """The Rust program's command line for panel entry `e` (without the subcommand's own
    options)."""
    cmd = [binary, command, "--model", peer_panel.model_argument(e) if from_file else e["model"],
           "--name", e["name"]]
    if from_file:
        cmd += ["--from-file", "on"]
    changes = peer_panel.set_argument(e)
    if changes:
        cmd += ["--set", changes]
    return cmd


def run_rust(cmd):
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed: {out.stderr}")
    return [json.loads(line) for line in out.stdout.splitlines() if line.strip()]


def rust_batch(binary, entries, methods, tols, reps, reference, from_file):
    """The Rust program's results: every entry, method and tolerance."""
    results = []
    for e in entries:
        cmd = rust_command(binary, e, "run", from_file) + [
            "--t-end", repr(e["t_end"]), "--methods", ",".join(methods),
            "--tols", ",".join(map(repr, tols)), "--reps", str(reps), "--reference", str(reference)]
        results += run_rust(cmd)
    return results


def heyoka_batch(peer, entries, tols, reps):
    """heyoka's results for the entries it can express."""
    return peer.run([(e["name"], tol) for e in entries if e["heyoka"] for tol in tols], reps)


def eomgen_reference(binary, e, from_file):
    """(state, uncertainty) at t_end of a model heyoka cannot express: eomgen's Vern9 at
    rtol = atol = 1e-15, and its largest difference from Vern9 at 1e-14 and DOP853 at 1e-15."""
    cmd = rust_command(binary, e, "run", from_file) + [
        "--t-end", repr(e["t_end"]), "--methods", "vern9,dop853", "--tols", "1e-14,1e-15",
        "--reps", "1"]
    runs = {(r["method"], r["tol"]): r for r in run_rust(cmd)}
    best = runs[("vern9", 1e-15)]["final_state"]
    others = [runs[("vern9", 1e-14)]["final_state"], runs[("dop853", 1e-15)]["final_state"]]
    spread = max(abs(a - b) for o in others for a, b in zip(o, best))
    return best, spread


def initial_state(binary, e, from_file):
    """Entry `e`'s initial state as the Rust program starts from it."""
    return run_rust(rust_command(binary, e, "initial", from_file))[0]["initial_state"]


def references(args, entries):
    """The reference file (its entries written when missing, or when the panel's end time or
    initial state is no longer theirs) and the targets each model can be judged at:
    {name: smallest target}."""
    path = Path(args.reference)
    data = json.loads(path.read_text()) if path.exists() else {}

    def current(e):
        r = data.get(e["name"])
        return (r is not None and r["t_end"] == e["t_end"]
                and [float(x) for x in r.get("initial_state", [])]
                == initial_state(args.binary, e, args.from_file))
    missing = [e for e in entries if not current(e)]
    mp = [e["name"] for e in missing if e["heyoka"]]
    if mp:
        tmp = path.with_suffix(".heyoka.json")
        heyoka_peer.command_reference(argparse.Namespace(out=str(tmp), models=mp))
        data.update(json.loads(tmp.read_text()))
    for e in missing:
        if not e["heyoka"]:
            state, spread = eomgen_reference(args.binary, e, args.from_file)
            data[e["name"]] = {
                "t_end": e["t_end"], "state": [repr(x) for x in state],
                "initial_state": [repr(x) for x in initial_state(args.binary, e, args.from_file)],
                "uncertainty": spread, "by": "eomgen vern9 1e-15"}
    if missing:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(data, indent=1) + "\n")
        stale = [e["name"] for e in missing if not current(e)]
        if stale:
            raise RuntimeError(f"the references of {', '.join(stale)} start from another "
                               "state than the Rust program's (heyoka_peer's initial state "
                               "and the program's --set disagree)")
    return {e["name"]: 10 * data[e["name"]].get("uncertainty", 0.0) for e in entries}


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


def costs_of(merged, name, methods, tols, target):
    """{method: the run that meets `target` at equal error (or None)} on model `name`."""
    out = {}
    for m in methods:
        sweep = sorted([merged[(m, name, t)] for t in tols if (m, name, t) in merged],
                       key=lambda r: -r["tol"])
        out[m] = cost_at(sweep, target) if sweep else None
    return out


def best_of(costs, methods):
    """(time, method) of the cheapest of eomgen's `methods` in `costs`, or None."""
    found = [(costs[m]["time_s"], m) for m in methods if costs.get(m) is not None]
    return min(found) if found else None


def panel_table(merged, entries, methods, peer_name, tols, floors, goals=True):
    """Rows of `peer_name` / eomgen-best per model and target, and (`goals`) the goals'
    verdict."""
    w = []
    head = ["model"] + [f"{t:.0e}" for t in TARGETS] + (["goals"] if goals else [])
    w.append("| " + " | ".join(head) + " |")
    w.append("|" + "---|" * len(head))
    verdicts = {}
    for e in entries:
        if peer_name == HEYOKA_METHOD and not e["heyoka"]:
            continue
        row, states = [e["name"]], []
        peer_failed = any("failed" in r for (m, model, _), r in merged.items()
                          if m == peer_name and model == e["name"])
        for target in TARGETS:
            goal = any(abs(target - g) <= 1e-6 * g for g in GOAL_TARGETS)
            if target < floors[e["name"]]:
                row.append("(ref.)")
                states.append("below the reference" if goal else None)
                continue
            costs = costs_of(merged, e["name"], methods + [peer_name], tols, target)
            best = best_of(costs, methods)
            peer = costs[peer_name]
            if best is None:
                # eomgen reaches no run that meets the target: a goal missed.
                row.append("-")
                state = "fail"
            elif peer is None:
                # The peer meets it at no tolerance of the sweep: eomgen ahead, unless a run
                # of the peer failed (then its column is not to be read as a loss).
                row.append(f"∞ ({best[1]})" if not peer_failed else f"? ({best[1]})")
                state = "incomplete" if peer_failed else "pass"
            else:
                ratio = peer["time_s"] / best[0]
                row.append(f"{ratio:.2f} ({best[1]})")
                need = GOAL_TIGHT if target <= TIGHT_FROM * (1 + 1e-6) else GOAL_ALL
                state = "pass" if ratio >= need else "fail"
            states.append(state if goal else None)
        judged = [x for x in states if x is not None]
        if "fail" in judged:
            verdict = "not met"
        elif "incomplete" in judged:
            verdict = "incomplete (a run of the peer failed)"
        elif "below the reference" in judged:
            verdict = "met above the reference's floor"
        else:
            verdict = "met"
        verdicts[e["name"]] = verdict
        if goals:
            row.append(verdict)
        w.append("| " + " | ".join(row) + " |")
    return w, verdicts


def model_details(merged, e, methods, peers, tols, floors):
    """The cost at equal error of every code on model `e`, one row per target."""
    codes = methods + peers + ([HEYOKA_METHOD] if e["heyoka"] else [])
    w = [f"**{e['name']}** ({e['why']}; 0 → {e['t_end']:.6g} s"
         + (f", initial {e['set']}" if e["set"] else "") + ")", ""]
    head = ["target"] + [label(m) for m in codes]
    w.append("| " + " | ".join(head) + " |")
    w.append("|" + "---|" * len(head))
    for target in TARGETS:
        if target < floors[e["name"]]:
            continue
        costs = costs_of(merged, e["name"], codes, tols, target)
        cells = ["-" if costs[m] is None else
                 f"{fmt_time(costs[m]['time_s'])} ({costs[m]['tol']:.0e})" for m in codes]
        w.append("| " + " | ".join([f"{target:.0e}"] + cells) + " |")
    w.append("")
    return w


def report(merged, entries, methods, peers, tols, floors, args, meta):
    """The markdown text: the panel's ratios and verdicts, then each model's costs."""
    w = [f"Work-precision panel. {meta}", "",
         "heyoka / eomgen-best at equal error (> 1: eomgen cheaper; the cheapest eomgen method "
         "in parentheses). Goals: ≥ 1.0 at every target 1e-4 … 1e-10, ≥ 1.3 at 1e-8 and "
         "tighter. \"(ref.)\": below ten times the reference's uncertainty; \"∞\": the peer "
         "meets the target at no tolerance of the sweep; \"-\": eomgen does not.", ""]
    rows, verdicts = panel_table(merged, entries, methods, HEYOKA_METHOD, tols, floors)
    w += rows + [""]
    spreads = []
    for e in entries:
        ratios = [max(r["round_times_s"]) / min(r["round_times_s"]) for r in merged.values()
                  if r["model"] == e["name"] and len(r.get("round_times_s", [])) > 1]
        if ratios:
            spreads.append(f"{e['name']} {statistics.median(ratios):.2f} "
                           f"(largest {max(ratios):.2f})")
    w += ["Spread of the rounds (largest over smallest of the rounds' medians, the median over "
          "every code and tolerance of a model): " + "; ".join(spreads) + ".", ""]
    for p in peers:
        w += [f"{label(p)} / eomgen-best at equal error:", ""]
        w += panel_table(merged, entries, methods, p, tols, floors, goals=False)[0] + [""]
    w += ["Cost at equal error of each code (median time; the loosest tolerance from which "
          "every tighter one meets the target, in parentheses):", ""]
    for e in entries:
        w += model_details(merged, e, methods, peers, tols, floors)
    builds = {}
    for r in merged.values():
        if r.get("construct_s") is not None:
            builds.setdefault(r["model"], []).append(r["construct_s"])
    if builds:
        cache = "from heyoka's on-disk cache" if args.warm_cache else "first compilation, empty cache"
        w.append(f"heyoka construction (Taylor decomposition + LLVM compilation, {cache}) per "
                 "tolerance, not in the times above: " + "; ".join(
                     f"{k} {min(v):.2f}–{max(v):.2f} s" for k, v in builds.items()) + ".")
    overheads = [r["call_overhead_s"] for r in merged.values() if "call_overhead_s" in r]
    if overheads:
        w.append(f"The Python call of heyoka's propagate_until costs {fmt_time(min(overheads))}–"
                 f"{fmt_time(max(overheads))} (a call that takes no step), included in its times.")
    return "\n".join(w) + "\n", verdicts


def label(method):
    """The chart's name of a method: the code and its method."""
    if method.startswith("ode_solvers-"):
        return "ode_solvers " + method.split("-", 1)[1].capitalize()
    if method == HEYOKA_METHOD:
        return "heyoka" + (" (high_accuracy)" if method == heyoka_peer.METHOD_HIGH_ACCURACY else "")
    return "eomgen " + method


def chart(merged, entries, codes, tols, path):
    """A log-log SVG, one panel per model: error against median time, one line per code."""
    import matplotlib
    matplotlib.use("svg")
    import matplotlib.pyplot as plt
    matplotlib.rcParams["svg.fonttype"] = "none"  # text as text: a smaller file
    cols = 3
    rows = (len(entries) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.4 * rows), squeeze=False)
    markers = "os^Dv<>ph*"
    for ax, e in zip(axes.flat, entries):
        for i, m in enumerate(codes):
            pts = sorted((r["error"], r["time_s"]) for t in tols
                         for r in [merged.get((m, e["name"], t))]
                         if r and "failed" not in r and r["error"] and r["error"] > 0)
            if pts:
                ax.loglog([p[0] for p in pts], [p[1] * 1e3 for p in pts],
                          marker=markers[i % len(markers)], markersize=3, label=label(m))
        ax.set_title(e["name"], fontsize=9)
        ax.set_xlabel("error at t_end", fontsize=8)
        ax.set_ylabel("time (ms)", fontsize=8)
        ax.invert_xaxis()
        ax.grid(True, which="both", alpha=0.3)
    for ax in list(axes.flat)[len(entries):]:
        ax.axis("off")
    axes.flat[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, metadata={"Date": None})
    plt.close(fig)


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    target = os.environ.get("CARGO_TARGET_DIR", str(ROOT / "target"))
    parser.add_argument("--binary",
                        default=str(Path(target) / "release/examples/work_precision_peers"))
    parser.add_argument("--models", default=",".join(e["name"] for e in peer_panel.PANEL),
                        help="panel entries (tools/peer_panel.py), comma-separated")
    parser.add_argument("--methods", default="dp54,dop853,vern9,taylor")
    parser.add_argument("--peers", default="ode_solvers-dop853")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--reps", type=int, default=3)
    parser.add_argument("--per-decade", type=int, default=2)
    parser.add_argument("--loosest", type=int, default=3, help="loosest tolerance 1e-K")
    parser.add_argument("--tightest", type=int, default=14, help="tightest tolerance 1e-K")
    parser.add_argument("--reference", default="/tmp/peers-out/reference.json")
    parser.add_argument("--out")
    parser.add_argument("--svg")
    parser.add_argument("--raw")
    parser.add_argument("--heyoka-high-accuracy", action="store_true",
                        help="run heyoka with high_accuracy=True (each step's polynomial "
                             "summed with compensation)")
    parser.add_argument("--compiled", dest="from_file", action="store_false",
                        help="eomgen's models as compiled into the Rust program by model! "
                             "(double_pendulum and figure_eight only) instead of loaded from "
                             "their files and compiled at run time, the command line's path "
                             "(the default)")
    parser.add_argument("--warm-cache", action="store_true",
                        help="let heyoka use its on-disk cache of compiled integrators")
    return parser.parse_args()


def main():
    args = parse_args()
    if not args.warm_cache:
        # heyoka keeps compiled code in $XDG_CACHE_HOME/heyoka; an empty one makes the
        # reported construction times those of a first compilation.
        os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp(prefix="heyoka-cache-")
        atexit.register(shutil.rmtree, os.environ["XDG_CACHE_HOME"], ignore_errors=True)
    global heyoka_peer, HEYOKA_METHOD
    import heyoka_peer as module
    heyoka_peer = module
    entries = [peer_panel.entry(n) for n in args.models.split(",") if n]
    methods = [m for m in args.methods.split(",") if m]
    peers = [p for p in args.peers.split(",") if p]
    tols = tolerances(args.per_decade, args.loosest, args.tightest)
    floors = references(args, entries)
    peer = heyoka_peer.HeyokaPeer(heyoka_peer.load_reference(args.reference),
                                  high_accuracy=args.heyoka_high_accuracy)
    HEYOKA_METHOD = peer.method
    start = time.perf_counter()
    heyoka_batch(peer, entries, tols, 1)  # builds and compiles every integrator once
    print(f"heyoka integrators built in {time.perf_counter() - start:.1f} s", file=sys.stderr)
    rounds = []
    for r in range(args.rounds):
        batches = [lambda: rust_batch(args.binary, entries, methods + peers, tols, args.reps,
                                      args.reference, args.from_file),
                   lambda: heyoka_batch(peer, entries, tols, args.reps)]
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
            f"{heyoka_peer.hy.__version__}; tolerances 1e-{args.loosest} … 1e-{args.tightest}, "
            f"{args.per_decade} per decade; {args.rounds} alternating rounds of {args.reps} runs; "
            f"eomgen's models {'loaded from their files' if args.from_file else 'compiled by model!'}.")
    text, verdicts = report(merged, entries, methods, peers, tols, floors, args, meta)
    if args.out:
        Path(args.out).write_text(text)
    else:
        print(text)
    if args.svg:
        chart(merged, entries, methods + peers + [HEYOKA_METHOD], tols, args.svg)
    print("goals: " + ", ".join(f"{k} {v}" for k, v in verdicts.items()), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
