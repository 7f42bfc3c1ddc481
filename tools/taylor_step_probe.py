#!/usr/bin/env python3
"""How fast can a Taylor step on the Kepler orbit be? The whole step (the series, Jorba & Zou's
step rule, the polynomial with its compensated sum) written as one Rust function and compiled
by rustc (LLVM), timed beside heyoka and eomgen in one interleaved run. Not used by the
product.

The orbit is the panel's (tools/panel/kepler_e09.yaml: e = 0.9, mu = 1, 10 periods, from
x = 0.1, y_dot = sqrt(19)), at tol 1e-6 (order 8) and 1e-9 (order 12). Every code takes the
same 702 and 715 steps, and ends within 1e-14 of eomgen's x, both of which the probe checks.
The probe writes a standalone Cargo project into DIR. It has one binary, with the step in
three forms of the same motion:

* eomgen's: its program for this model (squares of x and y, their sum, the power r2^-1.5 by
  the recurrence with weights alpha (k - j) - j, the products x r^-3 and y r^-3, negated);
* heyoka's (`taylor_adaptive(...).decomposition`): the sum of squares as one convolution,
  r2^1.5 by the same recurrence, and -x / r^3 and -y / r^3 by the quotient's recurrence;
* quotient: eomgen's squares, heyoka's r2^1.5 and quotients.

The probe is a straightforward implementation, not a bound: its order 0 takes r2 sqrt(r2)
where heyoka calls `pow`, it has no finiteness or branch checks and no driver, and it adds the
compensated sum heyoka does not make; its sums are serial chains.

It is built three times: for any x86-64 (SSE2, 16 registers), for this host
(`-C target-cpu=native`: AVX-512's 32 registers here; rustc neither contracts nor
reassociates, so the arithmetic is the same), and for this host with products and sums
contracted into fused multiply-adds where the compiler chooses (`-C llvm-args=-fp-contract=fast`,
as heyoka's LLVM code is: other bits than eomgen's, which contracts nothing).

Each round runs, in turn, heyoka twice (`propagate_until`, median of 31: the system written by
hand, `-x / (x^2 + y^2)^1.5`, and the panel's, heyoka's `lagrangian` of the model file's
T - V from tools/heyoka_peer.py), eomgen (`work_precision_peers run --from-file on`, the
command line's path, median of 31) and the nine probes (median of 31), the order reversed
every other round. It prints ns per step (the median over the rounds), each code's time over
the hand-written heyoka's in the same round (the median of those ratios) and their spread
(the largest over the smallest). Usage (from the repository root, with heyoka installed and
the crates in cargo's cache; offline):

    cargo build --release -p eomgen-benches --features work-precision --example work_precision_peers
    python3 tools/taylor_step_probe.py DIR [ROUNDS]

What it showed is in docs/performance.md ("How fast a Kepler step can be").
"""

import json
import math
import os
import re
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
T_END = 20.0 * math.pi

CARGO = """[package]
name = "taylor-step-probe"
version = "0.1.0"
edition = "2021"

[profile.release]
codegen-units = 1

[workspace]
"""

SOURCE = r'''//! The Kepler orbit's Taylor step as one function: written by tools/taylor_step_probe.py.
use std::hint::black_box;
use std::time::Instant;

/// Coefficients kept per series (orders 0 ... P, P <= 12).
const W: usize = 16;

/// The motion's form: eomgen's program, or heyoka's decomposition.
#[derive(Clone, Copy, PartialEq)]
enum Form {
    Eomgen,
    Heyoka,
    Quotient,
}

/// Orders 0 ... P of the state (x, y, vx, vy) from its order 0 in `s`.
#[inline(always)]
fn series<const P: usize>(form: Form, s: &mut [[f64; W]; 4], reciprocals: &[f64; W]) {
    let (mut r2, mut f, mut ax, mut ay) = ([0.0; W], [0.0; W], [0.0; W], [0.0; W]);
    // eomgen: f = r2^-1.5; heyoka and quotient: f = r2^1.5.
    let alpha = if form == Form::Eomgen { -1.5 } else { 1.5 };
    // The two squares apart (eomgen, quotient) or as one sum (heyoka).
    let apart = form != Form::Heyoka;
    for k in 0..P {
        let (x, y) = (&s[0], &s[1]);
        // Squares as half sums: 2 sum_{j < k/2} a^j a^(k-j) + (a^(k/2))^2 for even k.
        let (mut a, mut b) = (0.0, 0.0);
        for j in 0..(k + 1) / 2 {
            if apart {
                a += x[j] * x[k - j];
                b += y[j] * y[k - j];
            } else {
                a += x[j] * x[k - j] + y[j] * y[k - j];
            }
        }
        a *= 2.0;
        b *= 2.0;
        if k % 2 == 0 {
            if apart {
                a += x[k / 2] * x[k / 2];
                b += y[k / 2] * y[k / 2];
            } else {
                a += x[k / 2] * x[k / 2] + y[k / 2] * y[k / 2];
            }
        }
        r2[k] = a + b;
        f[k] = if k == 0 {
            let root = r2[0].sqrt();
            if form == Form::Eomgen { 1.0 / (r2[0] * root) } else { r2[0] * root }
        } else {
            let mut sum = 0.0;
            for j in 0..k {
                sum += (alpha * (k - j) as f64 - j as f64) * r2[k - j] * f[j];
            }
            sum * (1.0 / (k as f64 * r2[0]))
        };
        if form == Form::Eomgen {
            // -(x f), -(y f): products.
            let (mut a, mut b) = (0.0, 0.0);
            for j in 0..=k {
                a += x[j] * f[k - j];
                b += y[j] * f[k - j];
            }
            ax[k] = -a;
            ay[k] = -b;
        } else {
            // -x / f, -y / f: quotients.
            let (mut a, mut b) = (-x[k], -y[k]);
            for j in 1..=k {
                a -= f[j] * ax[k - j];
                b -= f[j] * ay[k - j];
            }
            let inverse = 1.0 / f[0];
            ax[k] = a * inverse;
            ay[k] = b * inverse;
        }
        let r = reciprocals[k];
        s[0][k + 1] = s[2][k] * r;
        s[1][k + 1] = s[3][k] * r;
        s[2][k + 1] = ax[k] * r;
        s[3][k + 1] = ay[k] * r;
    }
}

/// One step from (t, y): the series, the step rule of Jorba & Zou (eomgen's and heyoka's:
/// the last two orders, rtol = atol = tol), y + (delta + carry) by Horner's rule with the
/// carry of Knuth's two-sum. True at t_end.
#[inline(always)]
fn step<const P: usize>(
    form: Form,
    y: &mut [f64; 4],
    carry: &mut [f64; 4],
    t: &mut f64,
    (t_end, factor): (f64, f64),
    reciprocals: &[f64; W],
) -> bool {
    let mut s = [[0.0; W]; 4];
    for i in 0..4 {
        s[i][0] = y[i];
    }
    series::<P>(form, &mut s, reciprocals);
    let norm = |k: usize| s[0][k].abs().max(s[1][k].abs()).max(s[2][k].abs()).max(s[3][k].abs());
    // Relative mode when the state's norm is above 1 (rtol = atol).
    let n = norm(0).max(1.0);
    let ln_n = if n == 1.0 { 0.0 } else { n.ln() };
    let rho = ((ln_n - norm(P - 1).ln()) / (P - 1) as f64).min((ln_n - norm(P).ln()) / P as f64);
    let mut h = rho.exp() * factor;
    let last = *t + h >= t_end;
    if last {
        h = t_end - *t;
    }
    for i in 0..4 {
        let mut p = s[i][P];
        for k in (1..P).rev() {
            p = p * h + s[i][k];
        }
        let u = p * h + carry[i];
        let sum = y[i] + u;
        let u_part = sum - y[i];
        let y_part = sum - u_part;
        carry[i] = (y[i] - y_part) + (u - u_part);
        y[i] = sum;
    }
    *t = if last { t_end } else { *t + h };
    last
}

fn run<const P: usize>(form: Form, t_end: f64) -> (usize, f64) {
    let mut reciprocals = [0.0; W];
    for (k, r) in reciprocals.iter_mut().enumerate() {
        *r = 1.0 / (k + 1) as f64;
    }
    let factor = (-0.7 / (P - 1) as f64).exp() / std::f64::consts::E.powi(2);
    let (mut y, mut carry, mut t, mut steps) = ([0.1, 0.0, 0.0, 19f64.sqrt()], [0.0; 4], 0.0, 0);
    loop {
        steps += 1;
        if step::<P>(form, &mut y, &mut carry, &mut t, (t_end, factor), &reciprocals) {
            return (steps, y[0]);
        }
    }
}

fn main() {
    let form = match std::env::args().nth(1).as_deref() {
        Some("heyoka") => Form::Heyoka,
        Some("quotient") => Form::Quotient,
        _ => Form::Eomgen,
    };
    let t_end = 20.0 * std::f64::consts::PI;
    for p in [8usize, 12] {
        let mut times = Vec::new();
        let mut out = (0, 0.0);
        for _ in 0..31 {
            let start = Instant::now();
            out = match p {
                8 => run::<8>(black_box(form), black_box(t_end)),
                _ => run::<12>(black_box(form), black_box(t_end)),
            };
            times.push(start.elapsed().as_secs_f64());
        }
        times.sort_by(f64::total_cmp);
        let median = times[times.len() / 2];
        println!("{} {} {:?}", out.0, median * 1e9 / out.0 as f64, out.1);
    }
}
'''

HEYOKA = """
import math, statistics, sys, time
import heyoka as hy
sys.path.insert(0, sys.argv[2])
if sys.argv[1] == "hand":
    x, y, vx, vy = hy.make_vars("x", "y", "vx", "vy")
    r3 = (x**2 + y**2)**1.5
    equations = [(x, vx), (y, vy), (vx, -x / r3), (vy, -y / r3)]
else:
    import heyoka_peer
    equations = heyoka_peer.system("kepler_e09", form="lagrangian")[1]
y0 = [0.1, 0.0, 0.0, math.sqrt(19)]
for tol in (1e-6, 1e-9):
    ta = hy.taylor_adaptive(equations, y0, tol=tol)
    times = []
    for _ in range(31):
        ta.state[:] = y0
        ta.time = 0.0
        start = time.perf_counter()
        outcome = ta.propagate_until(20 * math.pi)
        times.append(time.perf_counter() - start)
    print(outcome[3], statistics.median(times) * 1e9 / outcome[3], ta.state[0])
"""

BUILDS = {
    "any x86-64": "",
    "this host": "-C target-cpu=native",
    "this host, fused multiply-adds": "-C target-cpu=native -C llvm-args=-fp-contract=fast",
}


def lines(cmd, **kw):
    """(steps, ns per step, x) per tolerance from a probe's or heyoka's output."""
    out = subprocess.run(cmd, capture_output=True, text=True, check=True, **kw).stdout
    return [(int(a), float(b), float(c)) for a, b, c in (l.split() for l in out.splitlines())]


def eomgen(binary):
    out = subprocess.run([binary, "run", "--from-file", "on", "--model",
                          "tools/panel/kepler_e09.yaml", "--t-end", repr(T_END), "--methods",
                          "taylor", "--tols", "1e-6,1e-9", "--reps", "31"],
                         capture_output=True, text=True, check=True, cwd=ROOT).stdout
    rows = [json.loads(l) for l in out.splitlines()]
    return [(r["steps"], r["time_s"] * 1e9 / r["steps"], r["final_state"][0]) for r in rows]


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    work = Path(sys.argv[1]).resolve()
    rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 6
    (work / "src").mkdir(parents=True, exist_ok=True)
    (work / "Cargo.toml").write_text(CARGO)
    (work / "src" / "main.rs").write_text(SOURCE)
    binaries = {}
    for i, (name, flags) in enumerate(BUILDS.items()):
        target = work / f"target{i}"
        env = dict(os.environ, RUSTFLAGS=flags, CARGO_TARGET_DIR=str(target))
        subprocess.run(["cargo", "build", "--release", "--offline", "--quiet"], cwd=work,
                       env=env, check=True)
        binaries[name] = target / "release" / "taylor-step-probe"
    peers = os.environ.get("EOMGEN_PEERS_BINARY",
                           str(ROOT / "target/release/examples/work_precision_peers"))
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    tools = str(ROOT / "tools")
    codes = {"heyoka": lambda: lines([sys.executable, "-c", HEYOKA, "hand", tools], env=env),
             "heyoka, the panel's lagrangian": lambda: lines(
                 [sys.executable, "-c", HEYOKA, "lagrangian", tools], env=env, cwd=ROOT),
             "eomgen": lambda: eomgen(peers)}
    for name, binary in binaries.items():
        for form in ("eomgen", "quotient", "heyoka"):
            codes[f"one function, {form}'s form, {name}"] = (
                lambda b=binary, f=form: lines([str(b), f]))
    results = {name: [] for name in codes}
    for r in range(rounds):
        order = list(codes.items()) if r % 2 == 0 else list(codes.items())[::-1]
        for name, run in order:
            results[name].append(run())
        print(f"round {r + 1}/{rounds}", file=sys.stderr)
    steps = {tuple(x[0] for x in row) for rows in results.values() for row in rows}
    if len(steps) != 1:
        sys.exit(f"error: the codes took different steps: {steps}")
    reference = results["eomgen"][0]
    for name, rows in results.items():
        for row in rows:
            for (_, _, x), (_, _, x_ref) in zip(row, reference):
                if abs(x - x_ref) > 1e-14:
                    sys.exit(f"error: {name} ends at x = {x!r}, eomgen at {x_ref!r}")
    print(f"Kepler orbit e = 0.9, 10 periods, {steps.pop()} steps at tol 1e-6 and 1e-9; "
          f"{rounds} interleaved rounds, medians")
    print("| code | ns a step, 1e-6 | 1e-9 | over heyoka's time, 1e-6 | 1e-9 | spread |")
    print("|---|---|---|---|---|---|")
    for name, rows in results.items():
        ns = [statistics.median(r[i][1] for r in rows) for i in range(2)]
        ratios = [[r[i][1] / h[i][1] for r, h in zip(rows, results["heyoka"])] for i in range(2)]
        ratio = [statistics.median(x) for x in ratios]
        spread = max(max(x) / min(x) for x in ratios)
        print(f"| {name} | {ns[0]:.0f} | {ns[1]:.0f} | {ratio[0]:.2f} | {ratio[1]:.2f} "
              f"| {spread:.2f} |")
    for name, rows in results.items():
        print(f"{name}: x(t_end) = {rows[0][0][2]!r}, {rows[0][1][2]!r}", file=sys.stderr)


if __name__ == "__main__":
    main()
