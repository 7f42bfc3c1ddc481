#!/usr/bin/env python3
"""Where the figure eight's Taylor step loses to heyoka: the same recurrences as straight-line
code with every coefficient a value of its own (SSA), compiled by LLVM (rustc) and by
Cranelift, against the workspace-in-memory code eomgen runs. Not used by the product.

Writes a standalone Cargo project into DIR with two binaries and runs both:

* `llvm`: the series of the figure eight (three unit masses, G = 1) to order 12 as one Rust
  function of `let` bindings, one per coefficient, emitted by this script;
* `cranelift PROGRAM`: an op list built with Cranelift's `FunctionBuilder` (the version
  eomgen's run-time compiler uses) and timed, its machine code written to `PROGRAM.disasm`:
  `program.txt`, the same operations as `llvm`'s, one value each; and `paired.txt`, the same
  arithmetic with each body's x and y components as the two lanes of one vector (positions,
  velocities, differences, squares' sums, pulls; the powers' recurrences scalar), which is
  what LLVM's SLP vectoriser does to the first.

Each prints the time of one series (orders 0 … 12 of the 12-component state) and its 12
order-12 coefficients (the recurrences are eomgen's: serial sums, squares as half sums, the
power's weights α(k − j) − j; order 0's r⁻³ as 1/(r²√r²) in both; no mass solve and no
G m² scaling, unit masses: a few operations fewer than eomgen's program). The state is the
one of models/figure_eight.yaml mirrored through the origin (the same motion turned by π).

    python3 tools/taylor_ssa_probe.py /tmp/probe        # builds and runs both (offline)

Needs cargo, with the cranelift 0.135.8 crates in its cache (eomgen's run-time compiler's
version: `cargo build` of the workspace puts them there), and Python's standard library.
For the other rows of docs/performance.md's table, build `llvm` again with
`RUSTFLAGS="-C llvm-args=-vectorize-slp=false"`, with `-C target-cpu=native` added, and with
`-C llvm-args=-fp-contract=fast` added to that (FMA: other bits).

What it showed (2026-11-27, 2-core AMD EPYC with AVX-512): LLVM 225 ns a series, Cranelift
494 ns (its code: 2,172 16-byte spill moves among 5,037 instructions), Cranelift with x and
y paired 203 ns, all three with the same order-12 coefficients; eomgen's per-order
compiled code about 600 ns (the orders' share of its step in `perf`), heyoka's whole step
290 ns (tools/work_precision_peers.py, the figure eight at tol 1e-9). LLVM's code pairs the x and y
components into two-lane vectors (mulpd/addpd: its SLP vectoriser); without that pairing
(`RUSTFLAGS="-C llvm-args=-vectorize-slp=false"`) it takes 610 ns, and 278 ns when it may
use the host's 32 registers (`-C target-cpu=native`). See docs/performance.md, the panel.
"""

import os
import subprocess
import sys

P = 12
ALPHA = -1.5
PAIRS = [(0, 1), (0, 2), (1, 2)]
STATE = [0.97000436, -0.24308753, -0.97000436, 0.24308753, 0.0, 0.0, 0.466203685, 0.43236573,
         0.466203685, 0.43236573, -0.93240737, -0.86473146]


def power(op, const, v, at, zero):
    """Order `k` of pair `n`'s `p = r^α` (`v["p{n}_{j}"]` of `r = v["r{n}_{j}"]`), scalar in
    both programs: order 0 as `1/(r √r)`, then eomgen's recurrence with the weights
    α(k − j) − j and one division by `k r⁰`."""
    n, k = at
    if k == 0:
        r = v[f"r{n}_0"]
        return op("/", const(1.0), op("*", r, op("s", r)))
    s = zero
    for jj in range(k):
        w = ALPHA * (k - jj) - jj
        s = op("+", s, op("*", op("*", const(w), v[f"r{n}_{k - jj}"]), v[f"p{n}_{jj}"]))
    return op("/", s, op("*", const(float(k)), v[f"r{n}_0"]))


def program():
    """The series as an op list: one value a line (`in i`, `c x`, `+ a b`, `- a b`, `* a b`,
    `/ a b`, `s a` for √, `n a` for −a, `out i a`), values numbered by line."""
    ops, v = [], {}

    def emit(line):
        ops.append(line)
        return len(ops) - 1

    def op(o, a, b=None):
        return emit(f"{o} {a}" + (f" {b}" if b is not None else ""))

    def const(x):
        return emit(f"c {x!r}")

    for c in range(6):
        v[f"q{c}_0"] = emit(f"in {c}")
        v[f"v{c}_0"] = emit(f"in {6 + c}")
    zero = const(0.0)
    for k in range(P):
        for n, (i, j) in enumerate(PAIRS):
            v[f"dx{n}_{k}"] = op("-", v[f"q{2 * j}_{k}"], v[f"q{2 * i}_{k}"])
            v[f"dy{n}_{k}"] = op("-", v[f"q{2 * j + 1}_{k}"], v[f"q{2 * i + 1}_{k}"])
            squares = {}
            for d in ("dx", "dy"):
                s = zero
                for m in range((k + 1) // 2):
                    s = op("+", s, op("*", v[f"{d}{n}_{m}"], v[f"{d}{n}_{k - m}"]))
                if (k + 1) // 2:
                    s = op("*", const(2.0), s)
                if k % 2 == 0:
                    h = v[f"{d}{n}_{k // 2}"]
                    s = op("+", s, op("*", h, h))
                squares[d] = s
            v[f"r{n}_{k}"] = op("+", squares["dx"], squares["dy"])
            v[f"p{n}_{k}"] = power(op, const, v, (n, k), zero)
            for d, f in (("dx", "fx"), ("dy", "fy")):
                s = zero
                for jj in range(k + 1):
                    s = op("+", s, op("*", v[f"{d}{n}_{jj}"], v[f"p{n}_{k - jj}"]))
                v[f"{f}{n}_{k}"] = s
        inverse = const(1.0 / (k + 1))
        g = lambda name: v[f"{name}_{k}"]  # noqa: E731
        acc = [op("+", g("fx0"), g("fx1")), op("+", g("fy0"), g("fy1")),
               op("-", g("fx2"), g("fx0")), op("-", g("fy2"), g("fy0")),
               op("-", op("n", g("fx1")), g("fx2")), op("-", op("n", g("fy1")), g("fy2"))]
        for c in range(6):
            v[f"q{c}_{k + 1}"] = op("*", v[f"v{c}_{k}"], inverse)
            v[f"v{c}_{k + 1}"] = op("*", acc[c], inverse)
    for k in range(P + 1):
        for c in range(6):
            emit(f"out {k * 12 + c} {v[f'q{c}_{k}']}")
            emit(f"out {k * 12 + 6 + c} {v[f'v{c}_{k}']}")
    return ops


def paired_program():
    """`program()` with x and y in the lanes of one two-lane vector (`Vin i` loads `y[i]` and
    `y[i + 1]`, `V+ V- V* Vn` lane by lane, `Vsplat a` both lanes `a`, `lane0 a`, `lane1 a`,
    `Vout i a`): each lane runs its scalar operations in the same order."""
    ops, v = [], {}

    def emit(line):
        ops.append(line)
        return len(ops) - 1

    def op(o, *args):
        return emit(" ".join([o] + [str(a) for a in args]))

    def const(x):
        return emit(f"c {x!r}")

    for c in range(3):
        v[f"Q{c}_0"] = op("Vin", 2 * c)
        v[f"W{c}_0"] = op("Vin", 6 + 2 * c)
    zero = const(0.0)
    vzero = op("Vsplat", zero)
    for k in range(P):
        for n, (i, j) in enumerate(PAIRS):
            v[f"D{n}_{k}"] = op("V-", v[f"Q{j}_{k}"], v[f"Q{i}_{k}"])
            s = vzero
            for m in range((k + 1) // 2):
                s = op("V+", s, op("V*", v[f"D{n}_{m}"], v[f"D{n}_{k - m}"]))
            if (k + 1) // 2:
                s = op("V*", op("Vsplat", const(2.0)), s)
            if k % 2 == 0:
                h = v[f"D{n}_{k // 2}"]
                s = op("V+", s, op("V*", h, h))
            v[f"r{n}_{k}"] = op("+", op("lane0", s), op("lane1", s))
            v[f"p{n}_{k}"] = power(op, const, v, (n, k), zero)
            v[f"P{n}_{k}"] = op("Vsplat", v[f"p{n}_{k}"])
            s = vzero
            for jj in range(k + 1):
                s = op("V+", s, op("V*", v[f"D{n}_{jj}"], v[f"P{n}_{k - jj}"]))
            v[f"F{n}_{k}"] = s
        inverse = op("Vsplat", const(1.0 / (k + 1)))
        g = lambda name: v[f"{name}_{k}"]  # noqa: E731
        acc = [op("V+", g("F0"), g("F1")), op("V-", g("F2"), g("F0")),
               op("V-", op("Vn", g("F1")), g("F2"))]
        for c in range(3):
            v[f"Q{c}_{k + 1}"] = op("V*", v[f"W{c}_{k}"], inverse)
            v[f"W{c}_{k + 1}"] = op("V*", acc[c], inverse)
    for k in range(P + 1):
        for c in range(3):
            op("Vout", k * 12 + 2 * c, v[f"Q{c}_{k}"])
            op("Vout", k * 12 + 6 + 2 * c, v[f"W{c}_{k}"])
    return ops


def rust_body(ops):
    """The op list as `let` bindings."""
    lines = []
    for n, line in enumerate(ops):
        p = line.split(" ")
        x = lambda i: f"v{p[i]}"  # noqa: E731
        expr = {
            "in": lambda: f"y[{p[1]}]",
            "c": lambda: f"{float(p[1])!r}f64",
            "+": lambda: f"{x(1)} + {x(2)}",
            "-": lambda: f"{x(1)} - {x(2)}",
            "*": lambda: f"{x(1)} * {x(2)}",
            "/": lambda: f"{x(1)} / {x(2)}",
            "s": lambda: f"{x(1)}.sqrt()",
            "n": lambda: f"-{x(1)}",
        }
        if p[0] == "out":
            lines.append(f"    out[{p[1]}] = v{p[2]};")
        else:
            lines.append(f"    let v{n} = {expr[p[0]]()};")
    return "\n".join(lines)


TIMING = """
fn time(mut series: impl FnMut(&[f64; 12], &mut [f64; 156])) {
    let y = STATE;
    let mut out = [0.0f64; 156];
    let n = 2_000_000;
    for _ in 0..3 {
        let t = std::time::Instant::now();
        for _ in 0..n {
            series(std::hint::black_box(&y), &mut out);
            std::hint::black_box(&out);
        }
        println!("{:.1} ns per series", t.elapsed().as_nanos() as f64 / n as f64);
    }
    println!("order 12: {:?}", &out[144..156]);
}
"""

CRANELIFT = r"""
use cranelift_codegen::ir::{types, AbiParam, InstBuilder, MemFlagsData};
use cranelift_codegen::settings::{self, Configurable};
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{Linkage, Module};

fn main() {
    let path = std::env::args().nth(1).expect("an op list");
    let text = std::fs::read_to_string(&path).expect("the op list reads");
    let mut flags = settings::builder();
    flags.set("opt_level", "speed").unwrap();
    let isa = cranelift_native::builder().unwrap().finish(settings::Flags::new(flags)).unwrap();
    let mut module =
        JITModule::new(JITBuilder::with_isa(isa, cranelift_module::default_libcall_names()));
    let mut ctx = module.make_context();
    let pointer = module.target_config().pointer_type();
    ctx.func.signature.params.push(AbiParam::new(pointer));
    ctx.func.signature.params.push(AbiParam::new(pointer));
    let target = module.target_config();
    let mut builder_context = FunctionBuilderContext::new();
    {
        let mut b = FunctionBuilder::new(&mut ctx.func, &mut builder_context);
        let block = b.create_block();
        b.append_block_params_for_function_params(block);
        b.switch_to_block(block);
        b.seal_block(block);
        let (y, out) = (b.block_params(block)[0], b.block_params(block)[1]);
        let flags = MemFlagsData::trusted();
        let mut v = Vec::new();
        for line in text.lines() {
            let p: Vec<&str> = line.split(' ').collect();
            let a = |i: usize| -> usize { p[i].parse().unwrap() };
            let value = match p[0] {
                "in" => b.ins().load(types::F64, flags, y, (a(1) * 8) as i32),
                "c" => b.ins().f64const(p[1].parse::<f64>().unwrap()),
                "+" => { let (x, z) = (v[a(1)], v[a(2)]); b.ins().fadd(x, z) }
                "-" => { let (x, z) = (v[a(1)], v[a(2)]); b.ins().fsub(x, z) }
                "*" => { let (x, z) = (v[a(1)], v[a(2)]); b.ins().fmul(x, z) }
                "/" => { let (x, z) = (v[a(1)], v[a(2)]); b.ins().fdiv(x, z) }
                "s" => { let x = v[a(1)]; b.ins().sqrt(x) }
                "n" => { let x = v[a(1)]; b.ins().fneg(x) }
                "out" => { let x = v[a(2)]; b.ins().store(flags, x, out, (a(1) * 8) as i32); x }
                "Vin" => b.ins().load(types::F64X2, flags, y, (a(1) * 8) as i32),
                "Vout" => { let x = v[a(2)]; b.ins().store(flags, x, out, (a(1) * 8) as i32); x }
                "V+" => { let (x, z) = (v[a(1)], v[a(2)]); b.ins().fadd(x, z) }
                "V-" => { let (x, z) = (v[a(1)], v[a(2)]); b.ins().fsub(x, z) }
                "V*" => { let (x, z) = (v[a(1)], v[a(2)]); b.ins().fmul(x, z) }
                "Vn" => { let x = v[a(1)]; b.ins().fneg(x) }
                "Vsplat" => { let x = v[a(1)]; b.ins().splat(types::F64X2, x) }
                "lane0" => { let x = v[a(1)]; b.ins().extractlane(x, 0) }
                "lane1" => { let x = v[a(1)]; b.ins().extractlane(x, 1) }
                other => panic!("unknown op {other}"),
            };
            v.push(value);
        }
        b.ins().return_(&[]);
        b.finalize(target);
    }
    ctx.set_disasm(true);
    let id = module.declare_function("series", Linkage::Local, &ctx.func.signature).unwrap();
    module.define_function(id, &mut ctx).unwrap();
    if let Some(code) = ctx.compiled_code() {
        std::fs::write(format!("{path}.disasm"), code.vcode.clone().unwrap_or_default()).unwrap();
    }
    module.clear_context(&mut ctx);
    module.finalize_definitions().unwrap();
    let f: extern "C" fn(*const f64, *mut f64) =
        unsafe { std::mem::transmute(module.get_finalized_function(id)) };
    time(|y, out| f(y.as_ptr(), out.as_mut_ptr()));
}
"""

CARGO = """[package]
name = "taylor-ssa-probe"
version = "0.1.0"
edition = "2021"

[[bin]]
name = "llvm"
path = "llvm.rs"

[[bin]]
name = "cranelift"
path = "cranelift.rs"

[dependencies]
cranelift-codegen = "=0.135.8"
cranelift-frontend = "=0.135.8"
cranelift-jit = "=0.135.8"
cranelift-module = "=0.135.8"
cranelift-native = "=0.135.8"

[profile.release]
opt-level = 3

[workspace]
"""


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    ops = program()
    state = "const STATE: [f64; 12] = [" + ", ".join(repr(x) for x in STATE) + "];\n"
    with open(os.path.join(out, "program.txt"), "w") as f:
        f.write("\n".join(ops) + "\n")
    with open(os.path.join(out, "paired.txt"), "w") as f:
        f.write("\n".join(paired_program()) + "\n")
    with open(os.path.join(out, "llvm.rs"), "w") as f:
        f.write(state + TIMING + "\n#[inline(never)]\n#[allow(clippy::all)]\n"
                "fn series(y: &[f64; 12], out: &mut [f64; 156]) {\n" + rust_body(ops) + "\n}\n"
                "fn main() { time(series); }\n")
    with open(os.path.join(out, "cranelift.rs"), "w") as f:
        f.write(state + TIMING + CRANELIFT)
    with open(os.path.join(out, "Cargo.toml"), "w") as f:
        f.write(CARGO)
    print(f"{len(ops)} operations", flush=True)
    subprocess.run(["cargo", "build", "--release", "--offline", "-q", "--target-dir", "target"],
                   cwd=out, check=True)
    for name, args in (("llvm", []), ("cranelift", ["program.txt"]), ("cranelift", ["paired.txt"])):
        print(f"== {name} {' '.join(args)}", flush=True)
        subprocess.run([os.path.join("target", "release", name)] + args, cwd=out, check=True)


if __name__ == "__main__":
    main()
