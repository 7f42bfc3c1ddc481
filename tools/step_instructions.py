"""Instructions per step of an integration, counted by callgrind: a measure of a step's cost
that the machine's pace does not move. Not used by the product.

On a shared machine the time of one run moves by up to 2x from one run to the next (the same
binary against itself: ratios from 0.5 to 2.1 in single pairs, 2026-11-29), so a change of a
few per cent in the cost of a step shows in time only over many rounds, if at all. The count of
instructions executed does not depend on the pace: it moves by about +-70 in 8,000 from one count
to the next. It does not weigh them (a division against an addition, a cache miss), so a change
that moves the count is still checked in time (docs/performance.md, "Fewer instructions per
step").

For each model and tolerance, `work_precision_peers run --from-file on` (the command line's path:
the model loaded from its file and compiled at run time, its Taylor orders at the first series;
with `--from-file off`, the copy `model!` compiled into the program, `--model double_pendulum`
or `figure_eight` by name)
runs under `valgrind --tool=callgrind --smc-check=all` twice, with `--reps 5` and `--reps 25`; the
difference over 20 times the run's steps is the count per step, without the load, the compile and
the first runs. Usage (from the repository root, valgrind installed):

    cargo build --release -p eomgen-benches --features work-precision --example work_precision_peers
    python3 tools/step_instructions.py --model models/figure_eight.yaml --t-end 63.2591398 \\
        --tols 1e-6,1e-9 [--methods taylor] [--set theta_dot=5.0] [--binary OTHER] [--binary B2]

With two or more `--binary`, each model and tolerance is counted with each, for a before and
after. The end state is printed beside each count, to see whether the bits changed.
"""
import argparse
import json
import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FEW, MANY = 5, 25


def count(binary, args, tol, reps):
    """(instructions, steps, first component of the final state) of one run under callgrind."""
    cmd = ["valgrind", "--tool=callgrind", "--smc-check=all", "--callgrind-out-file=/dev/null",
           binary, "run", "--from-file", args.from_file, "--model", args.model, "--t-end", args.t_end,
           "--methods", args.methods, "--tols", tol, "--reps", str(reps)]
    if args.set:
        cmd += ["--set", args.set]
    done = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    found = re.search(r"Collected : (\d+)", done.stderr)
    if done.returncode != 0 or not found or not done.stdout.strip():
        sys.exit(f"error: {' '.join(cmd)} failed:\n{done.stderr[-2000:]}")
    result = json.loads(done.stdout.splitlines()[0])
    if result.get("error"):
        sys.exit(f"error: the run failed: {result['error']}")
    return int(found.group(1)), result["steps"], result["final_state"][0]


def main():
    target = os.environ.get("CARGO_TARGET_DIR", str(ROOT / "target"))
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--binary", action="append",
                        help="the work-precision program (default: the release build's); "
                             "repeat to compare")
    parser.add_argument("--model", required=True,
                        help="a model file's path (with --from-file off, a model the program "
                             "compiles in, by name)")
    parser.add_argument("--t-end", required=True)
    parser.add_argument("--tols", default="1e-9")
    parser.add_argument("--methods", default="taylor", help="one method")
    parser.add_argument("--set", help="changes to the initial state, name=value,...")
    parser.add_argument("--from-file", default="on", choices=["on", "off"],
                        help="off: the copy `model!` compiled into the program (a model it "
                             "bundles, by name)")
    args = parser.parse_args()
    binaries = args.binary or [str(Path(target) / "release/examples/work_precision_peers")]
    for tol in args.tols.split(","):
        for binary in binaries:
            few, steps, _ = count(binary, args, tol, FEW)
            many, _, end = count(binary, args, tol, MANY)
            per_step = (many - few) / ((MANY - FEW) * steps)
            print(f"{args.model} {args.methods} {tol}: {steps} steps, {per_step:,.0f} "
                  f"instructions a step; x(t_end)[0] = {end!r}  ({binary})", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
