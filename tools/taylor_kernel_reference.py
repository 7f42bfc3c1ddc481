#!/usr/bin/env python3
"""High-precision reference series for the Taylor-recurrence kernels of `eomgen::taylor`.

`runtime/src/taylor/kernels.rs` computes the Taylor coefficients `f^[k]` (the coefficient of tau^k,
i.e. f^(k)(0)/k!) of `f(a(tau))` order by order from those of its operands, by the recurrences
of Jorba & Zou (2005, section 2) and heyoka's `doc/ad_notes.rst` (one kernel per `SeriesOp`).
This script writes `tests/data/taylor_kernels.json`, which `tests/taylor_kernels.rs` reads to
check, for each kernel the bundled models rarely exercise (`mul`, `div`, `constant_div`, `exp`,
`ln`, `sqrt`, `pow_constant`, `sin_cos`, `sinh_cosh`, `tan_or_tanh` as tan and as tanh, `asin`
as asin and as acos, `atan`, `atan2`), that orders 1..16 of every slot the kernel writes
(including hidden partners: `cos` of `sin_cos`, `square` of tan/tanh/atan, `root` of asin/acos,
`norm` of atan2) match these values.

How the reference is computed (nothing shared with the recurrences):

* each operand is a polynomial `a(tau) = sum_{i=0}^{16} a_i tau^i`; `a_0` is chosen inside the
  function's domain (e.g. ln at 1.7, asin at 0.3, acos at -0.45, atan2 in the first, second
  and third quadrants), the `a_i`, i >= 1, are seeded uniform values in [-1, 1] times 0.6^i;
  every input (and the constants: the exponent of `pow_constant`, the numerator of
  `constant_div`) is an IEEE double, written with 17 significant digits so that Rust reads
  back exactly the same double, and the reference is computed from those exact doubles;
* route 1: `mpmath.taylor(F, 0, 16)` of the composed function `F(tau) = f(a(tau))` evaluated
  with mpmath's own elementary functions at 50 significant digits (numerical differentiation
  at raised working precision; `atan2` by `mpmath.atan2`, tan as `mpmath.tan`, ...);
* route 2: the same coefficients by Cauchy's integral formula (`method='quad'`, a circle of
  radius 1/4 in the complex tau plane, on which every composed function is analytic; atan2
  there as `atan(y/x)` plus the quadrant's constant, since `mpmath.atan2` is real only);
* the script fails unless the two routes agree to 1e-35 relative to the largest coefficient
  of the series (they agree to ~1e-45), then writes route 1's values with 25 significant
  digits.

Hidden partners are references of their own definition: `square = tan(a)^2` (tanh^2),
`a^2` for atan, `root = sqrt(1 - a^2)`, `norm = x^2 + y^2`.

Run from the repository root (a few tens of seconds; needs mpmath, installed in /work/venv):

    /work/venv/bin/python tools/taylor_kernel_reference.py

then `cargo test --release --test suite taylor_kernels::`.  `--check` recomputes and compares with
the existing file instead of writing it.
"""

import argparse
import json
import os
import random
import sys

import mpmath as mp

ORDER = 16
DIGITS = 50
SEED = 20250405
RATIO = 0.6
RADIUS = mp.mpf(1) / 4
OUT_DIGITS = 25

HERE = os.path.dirname(os.path.abspath(__file__))
OUTPUT = os.path.join(HERE, "..", "tests", "data", "taylor_kernels.json")


def series(rng, a0):
    """An operand: `a0` (a double) then ORDER seeded doubles in [-1, 1] * RATIO^i."""
    return [float(a0)] + [rng.uniform(-1.0, 1.0) * RATIO**i for i in range(1, ORDER + 1)]


def poly(coefficients):
    """The polynomial with those (double) coefficients, as a function of tau (mpmath, exact
    inputs)."""
    cs = [mp.mpf(c) for c in coefficients]

    def p(tau):
        v = cs[-1]
        for c in reversed(cs[:-1]):
            v = v * tau + c
        return v

    return p


def atan2_complex(y0, x0):
    """`atan2(y, x)` continued analytically near `(y0, x0)` (x0 != 0): `atan(y/x)` plus the
    quadrant's constant."""
    if x0 > 0:
        shift = mp.mpf(0)
    elif y0 >= 0:
        shift = +mp.pi
    else:
        shift = -mp.pi
    return lambda y, x: mp.atan(y / x) + shift


def make_cases():
    """Every case: name, kernel, op, operands (double lists), constants (doubles), and the
    outputs as (real function, complex function) of the operands' values."""
    rng = random.Random(SEED)
    cases = []

    def case(name, kernel, op, operands, constants, outputs):
        cases.append(
            dict(name=name, kernel=kernel, op=op, operands=operands, constants=constants,
                 outputs=outputs)
        )

    one = lambda f: (f, f)  # noqa: E731  (the same function serves both routes)

    a, b = series(rng, 0.8), series(rng, -1.25)
    case("mul", "mul", "Mul", {"a": a, "b": b}, {}, {"out": one(lambda a, b: a * b)})
    a, b = series(rng, -0.35), series(rng, 1.3)
    case("div", "div", "Div", {"a": a, "b": b}, {}, {"out": one(lambda a, b: a / b)})
    a, b = series(rng, 0.9), series(rng, -1.6)
    case("div_negative_denominator", "div", "Div", {"a": a, "b": b}, {},
         {"out": one(lambda a, b: a / b)})
    b = series(rng, 1.45)
    c = 2.5
    case("constant_div", "constant_div", "ConstantDiv", {"b": b}, {"constant": c},
         {"out": one(lambda b, c=c: mp.mpf(c) / b)})
    b = series(rng, -0.95)
    c = -0.7
    case("constant_div_negative", "constant_div", "ConstantDiv", {"b": b}, {"constant": c},
         {"out": one(lambda b, c=c: mp.mpf(c) / b)})
    a = series(rng, 0.4)
    case("exp", "exp", "Exp", {"a": a}, {}, {"out": one(mp.exp)})
    a = series(rng, -1.1)
    case("exp_negative", "exp", "Exp", {"a": a}, {}, {"out": one(mp.exp)})
    a = series(rng, 1.7)
    case("ln", "ln", "Ln", {"a": a}, {}, {"out": one(mp.log)})
    a = series(rng, 0.55)
    case("ln_below_one", "ln", "Ln", {"a": a}, {}, {"out": one(mp.log)})
    a = series(rng, 2.3)
    case("sqrt", "sqrt", "Sqrt", {"a": a}, {}, {"out": one(mp.sqrt)})
    a = series(rng, 1.4)
    e = 2.5
    case("pow_constant", "pow_constant", "PowConstant", {"a": a}, {"exponent": e},
         {"out": one(lambda a, e=e: mp.power(a, mp.mpf(e)))})
    a = series(rng, 1.9)
    e = -1.0 / 3.0
    case("pow_constant_negative_exponent", "pow_constant", "PowConstant", {"a": a},
         {"exponent": e}, {"out": one(lambda a, e=e: mp.power(a, mp.mpf(e)))})
    a = series(rng, -0.8)
    e = 3.0
    case("pow_constant_negative_base", "pow_constant", "PowConstant", {"a": a},
         {"exponent": e}, {"out": one(lambda a: a * a * a)})
    a = series(rng, 0.9)
    case("sin_cos", "sin_cos", "SinCos", {"a": a}, {},
         {"sin": one(mp.sin), "cos": one(mp.cos)})
    a = series(rng, -2.2)
    case("sin_cos_large", "sin_cos", "SinCos", {"a": a}, {},
         {"sin": one(mp.sin), "cos": one(mp.cos)})
    a = series(rng, -0.6)
    case("sinh_cosh", "sinh_cosh", "SinhCosh", {"a": a}, {},
         {"sinh": one(mp.sinh), "cosh": one(mp.cosh)})
    a = series(rng, 0.5)
    case("tan", "tan_or_tanh", "Tan", {"a": a}, {},
         {"out": one(mp.tan), "square": one(lambda a: mp.tan(a) ** 2)})
    a = series(rng, -1.0)
    case("tan_steep", "tan_or_tanh", "Tan", {"a": a}, {},
         {"out": one(mp.tan), "square": one(lambda a: mp.tan(a) ** 2)})
    a = series(rng, 0.8)
    case("tanh", "tan_or_tanh", "Tanh", {"a": a}, {},
         {"out": one(mp.tanh), "square": one(lambda a: mp.tanh(a) ** 2)})
    a = series(rng, 0.3)
    case("asin", "asin", "Asin", {"a": a}, {},
         {"out": one(mp.asin), "root": one(lambda a: mp.sqrt(1 - a * a))})
    a = series(rng, -0.45)
    case("acos", "asin", "Acos", {"a": a}, {},
         {"out": one(mp.acos), "root": one(lambda a: mp.sqrt(1 - a * a))})
    a = series(rng, 0.7)
    case("atan", "atan", "Atan", {"a": a}, {},
         {"out": one(mp.atan), "square": one(lambda a: a * a)})
    a = series(rng, -2.0)
    case("atan_large", "atan", "Atan", {"a": a}, {},
         {"out": one(mp.atan), "square": one(lambda a: a * a)})
    for name, y0, x0 in [
        ("atan2_first_quadrant", 0.6, 0.9),
        ("atan2_second_quadrant", 0.4, -1.1),
        ("atan2_third_quadrant", -0.3, -0.8),
    ]:
        y, x = series(rng, y0), series(rng, x0)
        case(name, "atan2", "Atan2", {"y": y, "x": x}, {},
             {"out": (mp.atan2, atan2_complex(y0, x0)),
              "norm": one(lambda y, x: x * x + y * y)})
    return cases


def reference(case, agreement):
    """The expected coefficients of every output of `case`, by the two routes, checked
    against each other (each output's relative difference appended to `agreement`)."""
    polys = [poly(c) for c in case["operands"].values()]
    expected = {}
    for name, (real, complex_) in case["outputs"].items():
        step = mp.taylor(lambda t: real(*[p(t) for p in polys]), 0, ORDER)
        quad = mp.taylor(lambda t: complex_(*[p(t) for p in polys]), 0, ORDER,
                         method="quad", radius=RADIUS)
        scale = max(abs(v) for v in step)
        worst = max(abs(s - q) for s, q in zip(step, quad)) / scale
        if not worst < mp.mpf("1e-35"):
            sys.exit(f"{case['name']}.{name}: the two routes differ by {mp.nstr(worst, 3)}")
        expected[name] = step
        agreement.append(worst)
    return expected


def decimal(v, digits):
    """`v` with `digits` significant digits, in exponent notation."""
    return mp.nstr(mp.mpf(v), digits, min_fixed=0, max_fixed=0)


def double(v):
    """A double with 17 significant digits: read back exactly."""
    s = "%.17g" % v
    assert float(s) == v
    return s


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--check", action="store_true",
                        help="compare with the existing file instead of writing it")
    args = parser.parse_args()
    mp.mp.dps = DIGITS
    out = []
    agreement = []
    for case in make_cases():
        expected = reference(case, agreement)
        out.append({
            "name": case["name"],
            "kernel": case["kernel"],
            "op": case["op"],
            "operands": {k: [double(v) for v in vs] for k, vs in case["operands"].items()},
            "constants": {k: double(v) for k, v in case["constants"].items()},
            "expected": {k: [decimal(v, OUT_DIGITS) for v in vs] for k, vs in expected.items()},
        })
        print(f"{case['name']}: {', '.join(expected)}", file=sys.stderr)
    document = {
        "generator": "tools/taylor_kernel_reference.py",
        "digits": DIGITS,
        "order": ORDER,
        "note": "Taylor coefficients (of tau^k) of each kernel's outputs for polynomial "
                "operands; operands and constants are doubles (17 digits), expected values "
                "are mpmath at 50 digits rounded to 25.",
        "cases": out,
    }
    print(f"largest difference between the two routes: {mp.nstr(max(agreement), 3)} of the "
          "largest coefficient", file=sys.stderr)
    text = json.dumps(document, indent=1) + "\n"
    if args.check:
        with open(OUTPUT) as f:
            if f.read() != text:
                sys.exit(f"{OUTPUT} differs from a fresh computation")
        print("up to date", file=sys.stderr)
    else:
        with open(OUTPUT, "w") as f:
            f.write(text)
        print(f"wrote {len(out)} cases to {os.path.normpath(OUTPUT)}", file=sys.stderr)


if __name__ == "__main__":
    main()
