#!/usr/bin/env python3
"""Record what the CLI prints and writes for a fixed set of runs, and compare two records.

A restructuring that must change nothing a user sees (text, JSON, charts, CSV, HTML, exit
statuses) is checked by recording before and after it and comparing:

    python3 tools/golden.py record /tmp/before      # with the old binary built
    python3 tools/golden.py record /tmp/after       # with the new one
    python3 tools/golden.py compare /tmp/before /tmp/after

`record` runs `target/release/eomgen` (or `$EOMGEN`) once per case, in an empty directory, and
keeps its exit status, stdout, stderr and every file it wrote. Wall-clock figures are masked
(the JSON keys that hold times, the text columns of timings), because they are the only
outputs that may differ between two identical runs. `compare` prints each case whose record
differs and exits 1 if any does.
"""

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

MODELS = [
    "double_pendulum",
    "simple_pendulum_cartesian",
    "three_masses_damped",
    "chaplygin_sleigh",
    "slider_crank",
    "bead_spinning_rod",
    "four_bar",
    "spring_pair_3d",
]

CASES = [["list"], ["list", "--json"]]
for m in MODELS:
    CASES += [
        ["simulate", m, "--t-end", "2", "--json"],
        ["simulate", m, "--t-end", "1", "--csv", "out.csv", "--plot", "out.svg"],
        ["check", m, "--states", "20", "--json"],
        ["equations", m],
        ["equations", m, "--latex"],
        ["equations", m, "--json"],
        ["equations", m, "--rust"],
        ["modes", m, "--json"],
        ["modes", m],
    ]
CASES += [
    ["simulate", "double_pendulum", "--method", "radau5", "--t-end", "1", "--json"],
    ["simulate", "double_pendulum", "--method", "stormer-verlet", "--dt", "0.01", "--t-end", "1"],
    ["simulate", "simple_pendulum_cartesian", "--stabilization", "baumgarte", "--t-end", "2"],
    ["animate", "double_pendulum", "--t-end", "1", "-o", "a.html"],
    ["modes", "three_masses", "--plot", "m", "--json"],
    ["frf", "three_masses_forced", "--input", "A", "--json"],
    ["frf", "three_masses_forced", "--input", "A", "--modal", "--simulate", "2", "--plot", "frf.svg"],
    ["study", "free-response", "three_masses", "--json"],
    ["study", "modal-damping", "three_masses_damped", "--json"],
    ["study", "floquet", "mathieu_pendulum", "--json"],
    ["study", "constraint-methods", "two_masses_rod", "--json"],
    ["study", "euler-roundoff", "--json"],
    ["report", "--models", "double_pendulum,three_masses", "-o", "rep"],
    ["new", "n-link-pendulum", "4"],
    ["check", "nope_model"],
    ["simulate", "double_pendulum", "--set", "l1=0", "--t-end", "1"],
    # Text outputs, PNG charts and the other studies (the chart writer and the shared helpers
    # of every command).
    ["check", "double_pendulum"],
    ["simulate", "slider_crank", "--t-end", "1", "--plot", "s.png", "--plot-phase", "p.svg",
     "--plot-energy", "e.png", "--csv", "s.csv", "--event", "theta = 1"],
    ["simulate", "double_pendulum", "--t-end", "1", "--stop-when", "theta1 = 0", "--json"],
    ["simulate", "double_pendulum", "--t-end", "1", "--json", "--timing"],
    ["check", "double_pendulum", "--json", "--timing"],
    ["animate", "double_pendulum", "--t-end", "0.5", "--fps", "10", "-o", "a.html",
     "--gif", "a.gif"],
    ["modes", "double_pendulum", "--plot", "m.png", "--animate", "m.html"],
    ["modes", "three_masses_damped", "--json", "--at", "x1=0.1"],
    ["frf", "three_masses_forced", "--input", "A", "--plot", "frf.png"],
    ["frf", "three_masses_forced", "--input", "A", "--modal"],
    ["study", "free-response", "three_masses", "--plot", "fr.svg"],
    ["study", "free-response", "three_masses", "--plot", "fr.png", "--json"],
    ["study", "modal-damping", "three_masses_damped", "--plot", "md.svg"],
    ["study", "floquet", "mathieu_pendulum", "--plot", "fl.svg"],
    ["study", "floquet", "mathieu_pendulum", "--sweep", "a=0..0.2:3,w=40..60:3", "--json",
     "--plot", "sw.png"],
    ["study", "constraint-methods", "two_masses_rod", "--t-end", "1", "--plot", "cm.svg"],
    ["study", "euler-roundoff", "--max-n", "4", "--plot", "er.png"],
    ["study", "euler-roundoff", "--max-n", "4"],
    ["study", "stability", "--steps", "200", "--periods", "20", "--plot", "st.svg"],
    ["study", "stability", "--steps", "200", "--periods", "20", "--json"],
    ["study", "work-precision", "double_pendulum", "--t-end", "1", "--tols", "1e-3..1e-6",
     "--steps", "64..256", "--methods", "dp54,rk4", "--repeats", "1", "--min-time-ms", "0",
     "--json", "--plot", "wp"],
    ["study", "work-precision", "double_pendulum", "--t-end", "1", "--tols", "1e-3..1e-5",
     "--steps", "64..128", "--methods", "dp54,rk4", "--repeats", "1", "--min-time-ms", "0"],
]
# Every command's help: the defaults shown must not change.
for c in [["simulate"], ["animate"], ["check"], ["equations"], ["modes"], ["frf"], ["new"],
          ["report"], ["list"], ["study"], ["study", "work-precision"], ["study", "stability"],
          ["study", "euler-roundoff"], ["study", "constraint-methods"],
          ["study", "free-response"], ["study", "modal-damping"], ["study", "floquet"]]:
    CASES.append(c + ["--help"])
CASES.append(["--help"])
# JSON of rarer shapes (added last, so that the earlier cases keep their numbers): a failed
# run with warnings, an added event that never fires, the modal sums and simulated points of
# `frf`, unbounded peaks, failed cells of a sweep, a given Rayleigh fit.
CASES += [
    ["simulate", "double_pendulum", "--method", "euler", "--dt", "0.5", "--t-end", "2000",
     "--json"],
    ["simulate", "double_pendulum", "--t-end", "0.5", "--event", "theta1 = 100", "--json"],
    ["frf", "three_masses_forced", "--input", "A", "--modal", "--simulate", "2",
     "--frequency", "3", "--json"],
    ["frf", "forced_oscillator", "--input", "A", "--set", "c=0", "--modal", "--frequency", "1",
     "--json"],
    ["study", "floquet", "mathieu_pendulum", "--sweep", "a=0..0.2:2,w=0..60:3", "--json"],
    ["study", "modal-damping", "three_masses_damped", "--rayleigh-modes", "1,2", "--json"],
    # A fixed-step method without `--dt`: the library's default number of steps.
    ["simulate", "double_pendulum", "--method", "rk4", "--t-end", "1", "--json"],
]

# Cases whose text has unlabelled wall-time columns (milliseconds with three decimals) and
# whose `-time` charts plot wall time: those columns and charts are masked.
TIMED = ("constraint-methods", "work-precision")

TIME_KEYS = re.compile(r"(^|_)(time|times|seconds|elapsed|ms|wall|time_s|wall_s|ns)(_|$)")


def mask_json(value):
    if isinstance(value, dict):
        return {k: ("<time>" if TIME_KEYS.search(k) else mask_json(v)) for k, v in value.items()}
    if isinstance(value, list):
        return [mask_json(v) for v in value]
    return value


def mask_text(text, timed=False):
    try:
        # Key order kept: it is part of what a user sees.
        return json.dumps(mask_json(json.loads(text)), indent=1)
    except ValueError:
        if timed:
            text = re.sub(r"\b\d+\.\d{3}\b", "<ms>", text)
        # Durations printed in tables and summaries.
        return re.sub(r"\b\d+(\.\d+)?(e-?\d+)? ?(ms|µs|us|ns|s)\b", "<dur>", text)


def record(out):
    binary = os.path.abspath(os.environ.get("EOMGEN", "target/release/eomgen"))
    os.makedirs(out, exist_ok=True)
    for i, case in enumerate(CASES):
        timed = any(word in TIMED for word in case) and "--help" not in case
        with tempfile.TemporaryDirectory() as cwd:
            p = subprocess.run([binary] + case, cwd=cwd, capture_output=True, text=True)
            files = {}
            for root, _, names in os.walk(cwd):
                for n in sorted(names):
                    path = os.path.join(root, n)
                    with open(path, "rb") as f:
                        data = f.read()
                    rel = os.path.relpath(path, cwd)
                    if timed and "-time." in n:
                        files[rel] = "<wall-time chart>"
                        continue
                    try:
                        files[rel] = mask_text(data.decode())
                    except UnicodeDecodeError:
                        files[rel] = data.hex()
            rec = {
                "case": case,
                "status": p.returncode,
                "stdout": mask_text(p.stdout, timed),
                "stderr": mask_text(p.stderr),
                "files": files,
            }
        with open(os.path.join(out, f"{i:03}.json"), "w") as f:
            json.dump(rec, f, indent=1, sort_keys=True)
    print(f"recorded {len(CASES)} cases in {out}")


def compare(a, b):
    names = sorted(set(os.listdir(a)) | set(os.listdir(b)))
    bad = 0
    for n in names:
        pa, pb = os.path.join(a, n), os.path.join(b, n)
        if not (os.path.exists(pa) and os.path.exists(pb)):
            print(f"{n}: only in one record")
            bad += 1
            continue
        ra, rb = json.load(open(pa)), json.load(open(pb))
        if ra != rb:
            bad += 1
            keys = [k for k in ra if ra.get(k) != rb.get(k)]
            print(f"{n}: {' '.join(ra['case'])}: differs in {', '.join(keys)}")
    print(f"{len(names) - bad} of {len(names)} cases identical")
    return 1 if bad else 0


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "record":
        record(sys.argv[2])
    elif len(sys.argv) == 4 and sys.argv[1] == "compare":
        sys.exit(compare(sys.argv[2], sys.argv[3]))
    else:
        print(__doc__)
        sys.exit(2)
