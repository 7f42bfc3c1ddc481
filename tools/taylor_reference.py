#!/usr/bin/env python3
"""High-precision reference Taylor coefficients of every bundled model's motion.

For each model file `models/*.yaml` this computes the Taylor coefficients
`y_i^[k] = y_i^(k)(t0)/k!`, k = 0..12, of the solution of `M(q, t) q'' = F(q, q', t)` through a
fixed state `(t0, y)`, `y = [q; q']`, at 50 significant digits (with constraints, of the
index-1 system `[M J^T; J 0][q''; lambda] = [F; gamma]`), and writes them to
`tests/data/taylor_coefficients.json`, which `tests/taylor_coefficients.rs` compares with
`OdeSystem::taylor_coefficients` of the model compiled at run time from its file and of the
same file compiled by `eomgen::model!` (the models of `tests/compiled_models.rs`) or
interpreted.

Nothing here shares code with eomgen: the equations are read as text from the CLI
(`eomgen equations models/<file>.yaml --json`, the fields `equations.mass_matrix`,
`equations.forcing`, `equations.constraints`), parsed with SymPy, and evaluated on truncated
power series of mpmath numbers:

* `+ - *` by the Cauchy product, `/` by series long division, integer powers by repeated
  multiplication, constant real powers and `sqrt`, `exp`, `ln`, `sin`, `cos`, `sinh`, `cosh`
  by composition with the function's Taylor expansion at the series' constant term
  (`f(x0 + h) = sum_j f^(j)(x0)/j! h^j`, closed-form derivatives), `tan`, `tanh` as quotients,
  `asin`, `acos`, `atan`, `atan2` by integrating their derivative along the series
  (`f(x(tau)) = f(x0) + int f'(x) x' dtau`);
* `M(tau) a(tau) = F(tau)` solved order by order with mpmath's LU solver (with constraints,
  `[M J^T; J 0](tau) [a; lambda](tau) = [F; gamma](tau)`, the constraints' rows and gamma read
  from `equations.constraints`), and `q^[k+1] = q'^[k]/(k+1)`, `q'^[k+1] = a^[k]/(k+1)`.

Each model's coefficients are cross-checked against a second, unrelated route: mpmath's own
ODE Taylor method (`mpmath.calculus.odes.ode_taylor`: Euler steps of size 2^-130 at
thousands of bits and finite differences, with `q''` from an mpmath LU solve of the
equations lambdified by SymPy), which agrees to ~1e-35 relative; the script fails if any
coefficient differs by more than 1e-28 (1 + |c|). `--self-test` also checks each series
function against `mpmath.taylor` of the composed function.

State: `t0 = 0.3`; `q` = the file's `initial:` values (0 where absent) plus a seeded uniform
perturbation in [-0.1, 0.1], `q'` = the file's initial rates plus one in [-0.5, 0.5] (seed:
CRC-32 of the model's name), each rounded to an IEEE double; parameters are the file's
defaults rounded to doubles, as the model holds them. Constants in the equations text are
taken as SymPy reads them (integers and fractions exact, decimals as doubles).

The state of a constrained model is off its constraints (the perturbation): the index-1
system is an ODE there too, and its series is what the Taylor method follows.

Skipped (recorded with a reason): models whose equations use a function without a Taylor
recurrence (`abs`, `sign`, `step`) or a power with a non-constant exponent, and models
whose listing leaves an expression out as too long to print (the Whipple bicycle).

Regenerate (from the repository root; about a minute):

    cargo build --release
    python3 tools/taylor_reference.py --eomgen target/release/eomgen

(`--self-test` runs the function checks only; `--models a,b` limits the run and prints
without writing.) Requires Python 3 with sympy, mpmath and PyYAML.
"""

import argparse
import json
import math
import os
import random
import re
import subprocess
import sys
import zlib
from decimal import Decimal

import mpmath
import sympy
import yaml
from mpmath import mp, mpf

ORDER = 12
T0 = 0.3
DIGITS = 50
OUTPUT_DIGITS = 30
CROSS_CHECK_TOLERANCE = mpf("1e-28")
FUNCTIONS = {
    "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "exp",
    "ln", "sqrt", "abs", "sign", "step",
}
NO_RECURRENCE = ("abs", "sign", "step")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


# --- truncated power series ------------------------------------------------------------------


class Series:
    """`sum_k c[k] tau^k`, k < len(c), with mpmath coefficients."""

    __slots__ = ("c",)

    def __init__(self, c):
        self.c = list(c)

    def __len__(self):
        return len(self.c)

    @staticmethod
    def constant(v, n):
        return Series([mpf(v)] + [mpf(0)] * (n - 1))

    def _lift(self, other):
        if isinstance(other, Series):
            return other
        return Series.constant(other, len(self.c))

    def __add__(self, o):
        if not isinstance(o, Series):
            return Series([self.c[0] + o] + self.c[1:])
        return Series([a + b for a, b in zip(self.c, o.c)])

    __radd__ = __add__

    def __neg__(self):
        return Series([-a for a in self.c])

    def __sub__(self, o):
        return self + (-o)

    def __rsub__(self, o):
        return (-self) + o

    def __mul__(self, o):
        if not isinstance(o, Series):
            return Series([a * o for a in self.c])
        n = len(self.c)
        a, b = self.c, o.c
        return Series([mpmath.fsum(a[j] * b[k - j] for j in range(k + 1)) for k in range(n)])

    __rmul__ = __mul__

    def __truediv__(self, o):
        if not isinstance(o, Series):
            return Series([a / o for a in self.c])
        # Long division: a = b q, q_k = (a_k - sum_{j>=1} b_j q_{k-j}) / b_0.
        a, b = self.c, o.c
        if b[0] == 0:
            raise ZeroDivisionError("series division by a series with zero constant term")
        q = []
        for k in range(len(a)):
            q.append((a[k] - mpmath.fsum(b[j] * q[k - j] for j in range(1, k + 1))) / b[0])
        return Series(q)

    def __rtruediv__(self, o):
        return Series.constant(o, len(self.c)) / self

    def derivative(self):
        """d/dtau, one coefficient shorter (padded with an unknown-free 0 at the end is wrong,
        so the caller integrates back to the full length)."""
        return Series([k * self.c[k] for k in range(1, len(self.c))])

    def integral(self, c0):
        """`c0 + int_0^tau s`, one coefficient longer."""
        return Series([mpf(c0)] + [self.c[k] / (k + 1) for k in range(len(self.c))])


def powi(x, n):
    """`x^n` for an integer n by repeated multiplication (binary powering)."""
    if n < 0:
        return 1 / powi(x, -n)
    result = Series.constant(1, len(x)) if isinstance(x, Series) else mpf(1)
    base = x
    while n:
        if n & 1:
            result = result * base
        n >>= 1
        if n:
            base = base * base
    return result


def compose(x, derivatives_over_factorial):
    """`sum_j d[j] h^j` with `h = x - x0` (zero constant term), truncated to len(x)."""
    n = len(x)
    h = Series([mpf(0)] + x.c[1:])
    out = Series.constant(derivatives_over_factorial[0], n)
    power = Series.constant(1, n)
    for j in range(1, n):
        power = power * h
        out = out + power * derivatives_over_factorial[j]
    return out


def s_exp(x):
    e = mpmath.exp(x.c[0])
    return compose(x, [e / mpmath.factorial(j) for j in range(len(x))])


def s_sin(x):
    return compose(x, [mpmath.sin(x.c[0] + j * mpmath.pi / 2) / mpmath.factorial(j)
                       for j in range(len(x))])


def s_cos(x):
    return compose(x, [mpmath.cos(x.c[0] + j * mpmath.pi / 2) / mpmath.factorial(j)
                       for j in range(len(x))])


def s_sinh(x):
    s, c = mpmath.sinh(x.c[0]), mpmath.cosh(x.c[0])
    return compose(x, [(s if j % 2 == 0 else c) / mpmath.factorial(j) for j in range(len(x))])


def s_cosh(x):
    s, c = mpmath.sinh(x.c[0]), mpmath.cosh(x.c[0])
    return compose(x, [(c if j % 2 == 0 else s) / mpmath.factorial(j) for j in range(len(x))])


def s_ln(x):
    x0 = x.c[0]
    if x0 <= 0:
        raise ValueError("ln of a series with a non-positive constant term")
    d = [mpmath.log(x0)] + [(-1) ** (j + 1) / (j * x0 ** j) for j in range(1, len(x))]
    return compose(x, d)


def s_pow_real(x, alpha):
    """`x^alpha` for a constant real alpha: binomial series at x0 > 0."""
    x0 = x.c[0]
    if x0 <= 0:
        raise ValueError("non-integer power of a series with a non-positive constant term")
    return compose(x, [mpmath.binomial(alpha, j) * x0 ** (alpha - j) for j in range(len(x))])


def s_sqrt(x):
    return s_pow_real(x, mpf(1) / 2)


def s_tan(x):
    return s_sin(x) / s_cos(x)


def s_tanh(x):
    return s_sinh(x) / s_cosh(x)


def _by_integral(value0, integrand):
    """`f(x(tau)) = f(x0) + int f'(x) x' dtau`, integrand = f'(x) x' to one order less."""
    return integrand.integral(value0)


def _shorter(x):
    return Series(x.c[:-1])


def s_atan(x):
    if len(x) == 1:
        return Series([mpmath.atan(x.c[0])])
    xs = _shorter(x)
    return _by_integral(mpmath.atan(x.c[0]), x.derivative() / (1 + xs * xs))


def s_asin(x):
    if len(x) == 1:
        return Series([mpmath.asin(x.c[0])])
    xs = _shorter(x)
    return _by_integral(mpmath.asin(x.c[0]), x.derivative() / s_sqrt(1 - xs * xs))


def s_acos(x):
    if len(x) == 1:
        return Series([mpmath.acos(x.c[0])])
    xs = _shorter(x)
    return _by_integral(mpmath.acos(x.c[0]), -(x.derivative() / s_sqrt(1 - xs * xs)))


def s_atan2(y, x):
    theta0 = mpmath.atan2(y.c[0], x.c[0])
    if len(x) == 1:
        return Series([theta0])
    xs, ys = _shorter(x), _shorter(y)
    return _by_integral(theta0, (xs * y.derivative() - ys * x.derivative()) / (xs * xs + ys * ys))


SERIES_FUNCTIONS = {
    "sin": s_sin, "cos": s_cos, "tan": s_tan, "asin": s_asin, "acos": s_acos, "atan": s_atan,
    "sinh": s_sinh, "cosh": s_cosh, "tanh": s_tanh, "exp": s_exp, "log": s_ln, "sqrt": s_sqrt,
}
SCALAR_FUNCTIONS = {
    "sin": mpmath.sin, "cos": mpmath.cos, "tan": mpmath.tan, "asin": mpmath.asin,
    "acos": mpmath.acos, "atan": mpmath.atan, "sinh": mpmath.sinh, "cosh": mpmath.cosh,
    "tanh": mpmath.tanh, "exp": mpmath.exp, "log": mpmath.log, "sqrt": mpmath.sqrt,
}


# --- the equations as SymPy expressions ------------------------------------------------------

TOKEN = re.compile(r"(\d+\.?\d*(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?)|([A-Za-z_]\w*)")
SYMPY_FUNCTIONS = {
    "sin": sympy.sin, "cos": sympy.cos, "tan": sympy.tan, "asin": sympy.asin,
    "acos": sympy.acos, "atan": sympy.atan, "atan2": sympy.atan2, "sinh": sympy.sinh,
    "cosh": sympy.cosh, "tanh": sympy.tanh, "exp": sympy.exp, "ln": sympy.log,
    "sqrt": sympy.sqrt, "abs": sympy.Abs, "sign": sympy.sign,
    "step": sympy.Function("step"),
}


def parse(text, symbols):
    """Parses eomgen's expression text: every identifier that is not a function becomes the
    symbol of that name (so `I`, `E`, `lambda` are parameters, not SymPy's), `^` is power."""
    local = {}

    def rename(m):
        if m.group(1):
            return m.group(1)
        name = m.group(2)
        if name in SYMPY_FUNCTIONS:
            key = "F_" + name
            local[key] = SYMPY_FUNCTIONS[name]
            return key
        if name == "pi" and name not in symbols:
            local["C_pi"] = sympy.pi
            return "C_pi"
        if name not in symbols:
            raise ValueError(f"unknown name `{name}` in `{text}`")
        key = "S_" + name
        local[key] = symbols[name]
        return key

    code = TOKEN.sub(rename, text).replace("^", "**")
    return sympy.parse_expr(code, local_dict=local, evaluate=False)


def functions_used(text):
    return [f for f in dict.fromkeys(re.findall(r"([A-Za-z_]\w*)\s*\(", text))]


class VariableExponent(ValueError):
    """A power whose exponent depends on the state or on time (no recurrence)."""


class Evaluator:
    """Evaluates SymPy trees on series (or scalars), with every symbol bound, memoised per
    subexpression."""

    def __init__(self, bindings):
        self.bindings = bindings
        self.memo = {}

    def __call__(self, e):
        if e in self.memo:
            return self.memo[e]
        v = self._eval(e)
        self.memo[e] = v
        return v

    def _eval(self, e):
        if e.is_Symbol:
            return self.bindings[e]
        if e.is_Integer:
            return mpf(int(e))
        if e.is_Rational:
            return mpf(int(e.p)) / int(e.q)
        if e.is_Float:
            return mpf(e._mpf_)
        if e is sympy.pi:
            return +mpmath.pi
        if e.is_Add:
            acc = mpf(0)
            for a in e.args:
                acc = self(a) + acc if isinstance(self(a), Series) else acc + self(a)
            return acc
        if e.is_Mul:
            acc = mpf(1)
            for a in e.args:
                v = self(a)
                acc = v * acc if isinstance(v, Series) else acc * v
            return acc
        if e.is_Pow:
            base, exponent = e.args
            b = self(base)
            alpha = self(exponent)
            if isinstance(alpha, Series):
                raise VariableExponent(f"power with a variable exponent: {e}")
            if alpha == int(alpha) and abs(alpha) <= 64:
                return powi(b, int(alpha))
            if isinstance(b, Series):
                return s_pow_real(b, alpha)
            return b ** alpha
        if isinstance(e, sympy.atan2):
            y, x = self(e.args[0]), self(e.args[1])
            if isinstance(x, Series) or isinstance(y, Series):
                n = len(x) if isinstance(x, Series) else len(y)
                x = x if isinstance(x, Series) else Series.constant(x, n)
                y = y if isinstance(y, Series) else Series.constant(y, n)
                return s_atan2(y, x)
            return mpmath.atan2(y, x)
        if isinstance(e, sympy.Function):
            name = e.func.__name__
            if name not in SERIES_FUNCTIONS:
                raise ValueError(f"no series for `{name}`")
            a = self(e.args[0])
            if isinstance(a, Series):
                return SERIES_FUNCTIONS[name](a)
            return SCALAR_FUNCTIONS[name](a)
        raise ValueError(f"cannot evaluate {e!r} ({type(e).__name__})")


# --- the model -------------------------------------------------------------------------------


def double(v):
    """The IEEE double nearest `v` (a SymPy number), as an exact mpf."""
    return mpf(float(sympy.N(v, 40)))


class Model:
    def __init__(self, path, eomgen):
        self.path = path
        self.file = os.path.relpath(path, ROOT)
        text = subprocess.run(
            [eomgen, "equations", path, "--json"], check=True, capture_output=True, text=True
        ).stdout
        doc = json.loads(text)
        self.name = doc["model"]
        eq = doc["equations"]
        self.coordinates = eq["coordinates"]
        self.n = len(self.coordinates)
        self.mass_text = eq["mass_matrix"]
        self.forcing_text = eq["forcing"]
        self.constraints = eq["constraints"]
        source = yaml.safe_load(open(path))
        self.parameter_names = list((source.get("parameters") or {}).keys())
        self.source = source

    def constraint_texts(self):
        return [t for c in self.constraints for t in c["jacobian"] + [c["gamma"]]]

    def skip_reason(self):
        text = " ".join(sum(self.mass_text, []) + self.forcing_text + self.constraint_texts())
        if "[not printed" in text:
            return "an expression of its listing is too long to print", None
        missing = [f for f in functions_used(text) if f in NO_RECURRENCE]
        if missing:
            return "functions without a Taylor recurrence: " + ", ".join(missing), missing
        return None, None

    def setup(self):
        n = self.n
        self.sym_q = [sympy.Symbol(c) for c in self.coordinates]
        self.sym_v = [sympy.Symbol(c + "_dot") for c in self.coordinates]
        self.sym_t = sympy.Symbol("t")
        self.sym_p = [sympy.Symbol(p) for p in self.parameter_names]
        symbols = {s.name: s for s in self.sym_q + self.sym_v + self.sym_p + [self.sym_t]}
        self.M = [[parse(self.mass_text[i][j], symbols) for j in range(n)] for i in range(n)]
        self.F = [parse(self.forcing_text[i], symbols) for i in range(n)]
        self.m = len(self.constraints)
        self.J = [[parse(c["jacobian"][j], symbols) for j in range(n)] for c in self.constraints]
        self.gamma = [parse(c["gamma"], symbols) for c in self.constraints]
        # Parameters: the file's defaults, in order (a default may use earlier ones).
        exact = {}
        for name, value in (self.source.get("parameters") or {}).items():
            expr = parse(str(value), {**symbols}) if isinstance(value, str) else sympy.sympify(value)
            exact[symbols[name]] = expr.subs(exact)
        self.parameters = {s: double(exact[s]) for s in self.sym_p}
        self.exact_parameters = exact
        # Initial state from the file, perturbed.
        initial = self.source.get("initial") or {}

        def value(key):
            v = initial.get(key, 0)
            if isinstance(v, dict):
                v = v.get("guess", 0)
            expr = parse(str(v), symbols) if isinstance(v, str) else sympy.sympify(v)
            return float(sympy.N(expr.subs(exact), 30))

        rng = random.Random(zlib.crc32(self.name.encode()))
        q = [value(c) + rng.uniform(-0.1, 0.1) for c in self.coordinates]
        v = [value(c + "_dot") + rng.uniform(-0.5, 0.5) for c in self.coordinates]
        self.y = [float(x) for x in q + v]

    # Series route.
    def series_coefficients(self, t0, y, order):
        n, dim = self.n, 2 * self.n
        q = [[mpf(y[i])] for i in range(n)]
        v = [[mpf(y[n + i])] for i in range(n)]
        acc = []  # acc[k] = a^[k] (list of n)
        for k in range(order):
            length = k + 1
            bindings = dict(self.parameters)
            for i in range(n):
                bindings[self.sym_q[i]] = Series(q[i])
                bindings[self.sym_v[i]] = Series(v[i])
            bindings[self.sym_t] = Series(([mpf(t0), mpf(1)] + [mpf(0)] * length)[:length])
            ev = Evaluator(bindings)

            def coeff(x, j):
                return x.c[j] if isinstance(x, Series) else (x if j == 0 else mpf(0))

            # [M J^T; J 0] and [F; gamma] as series, then the Cauchy product solved for
            # order k of [a; lambda].
            m = self.m
            size = n + m
            Js = [[ev(self.J[r][j]) for j in range(n)] for r in range(m)]
            As = [[None] * size for _ in range(size)]
            for i in range(size):
                for j in range(size):
                    if i < n and j < n:
                        As[i][j] = ev(self.M[i][j])
                    elif i >= n and j < n:
                        As[i][j] = Js[i - n][j]
                    elif i < n:
                        As[i][j] = Js[j - n][i]
                    else:
                        As[i][j] = mpf(0)
            bs = [ev(self.F[i]) for i in range(n)] + [ev(g) for g in self.gamma]
            A0 = mpmath.matrix(size, size)
            for i in range(size):
                for j in range(size):
                    A0[i, j] = coeff(As[i][j], 0)
            rhs = mpmath.matrix(size, 1)
            for i in range(size):
                s = coeff(bs[i], k)
                for l in range(size):
                    for j in range(1, k + 1):
                        s -= coeff(As[i][l], j) * acc[k - j][l]
                rhs[i] = s
            a = mpmath.lu_solve(A0, rhs)
            acc.append([a[i] for i in range(size)])
            for i in range(n):
                q[i].append(v[i][k] / (k + 1))
                v[i].append(a[i] / (k + 1))
        return [(q[i] if i < n else v[i - n])[k] for k in range(order + 1) for i in range(dim)]

    # Second route: mpmath's ODE Taylor method on y' = [q'; a], a from M a = F (with
    # constraints, [M J^T; J 0][a; lambda] = [F; gamma]) solved at each evaluation.
    def ode_taylor_coefficients(self, t0, y, order):
        n, m = self.n, self.m
        args = self.sym_p + self.sym_q + self.sym_v + [self.sym_t]
        blocks = sympy.Matrix(self.M)
        right = sympy.Matrix(self.F)
        if m:
            jac = sympy.Matrix(self.J)
            blocks = sympy.Matrix(sympy.BlockMatrix([[blocks, jac.T],
                                                     [jac, sympy.zeros(m, m)]]))
            right = right.col_join(sympy.Matrix(self.gamma))
        Mf = sympy.lambdify(args, blocks, modules="mpmath")
        Ff = sympy.lambdify(args, right, modules="mpmath")
        pvals = [self.parameters[s] for s in self.sym_p]

        def derivs(t, yy):
            a_args = pvals + list(yy[:n]) + list(yy[n:]) + [t]
            Mm = mpmath.matrix(Mf(*a_args).tolist())
            Fm = mpmath.matrix(Ff(*a_args).tolist())
            a = mpmath.lu_solve(Mm, Fm)
            return list(yy[n:]) + [a[i] for i in range(n)]

        ser, _ = mpmath.calculus.odes.ode_taylor(
            mp, derivs, mpf(t0), [mpf(v) for v in y], 130, order)
        return [ser[i][k] for k in range(order + 1) for i in range(2 * n)]


def decimal(v, digits):
    return mpmath.nstr(v, digits, min_fixed=-4, max_fixed=6, strip_zeros=False)


def double_text(x):
    s = format(Decimal(x), ".24e")
    assert float(s) == x, (s, x)
    return s


# --- self-test -------------------------------------------------------------------------------


def self_test():
    """Every series function against `mpmath.taylor` of the composed scalar function."""
    n = ORDER + 1
    x = Series([mpf("0.3"), mpf("0.7"), mpf("-0.2"), mpf("0.05")] + [mpf(0)] * (n - 4))
    y = Series([mpf("-0.4"), mpf("0.1"), mpf("0.3")] + [mpf(0)] * (n - 3))

    def xs(tau):
        return mpf("0.3") + mpf("0.7") * tau - mpf("0.2") * tau ** 2 + mpf("0.05") * tau ** 3

    def ys(tau):
        return mpf("-0.4") + mpf("0.1") * tau + mpf("0.3") * tau ** 2

    cases = [(name, f, lambda tau, g=SCALAR_FUNCTIONS[name]: g(xs(tau)))
             for name, f in SERIES_FUNCTIONS.items()]
    cases += [
        ("x^-3", lambda s: powi(s, -3), lambda tau: xs(tau) ** -3),
        ("x^(3/2)", lambda s: s_pow_real(s, mpf(3) / 2), lambda tau: xs(tau) ** (mpf(3) / 2)),
        ("x/y", lambda s: s / y, lambda tau: xs(tau) / ys(tau)),
        ("atan2(y,x)", lambda s: s_atan2(y, s), lambda tau: mpmath.atan2(ys(tau), xs(tau))),
        ("atan2(y,-x)", lambda s: s_atan2(y, -s), lambda tau: mpmath.atan2(ys(tau), -xs(tau))),
    ]
    worst = mpf(0)
    for name, f, g in cases:
        got = f(x).c
        with mp.workdps(DIGITS + 30):
            want = mpmath.taylor(g, 0, n - 1)
        for k in range(n):
            err = abs(got[k] - want[k]) / (1 + abs(want[k]))
            worst = max(worst, err)
            if err > mpf("1e-40"):
                raise AssertionError(f"{name}: order {k}: {got[k]} vs {want[k]}")
    print(f"self-test: {len(cases)} series functions agree with mpmath.taylor to "
          f"{mpmath.nstr(worst, 3)} relative", file=sys.stderr)


# --- main ------------------------------------------------------------------------------------


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--eomgen", default=os.path.join(ROOT, "target/release/eomgen"))
    parser.add_argument("--models", help="comma-separated file stems; print, do not write")
    parser.add_argument("--self-test", action="store_true")
    parser.add_argument("--output", default=os.path.join(ROOT, "tests/data/taylor_coefficients.json"))
    args = parser.parse_args()
    mp.dps = DIGITS
    self_test()
    if args.self_test:
        return
    files = sorted(f for f in os.listdir(os.path.join(ROOT, "models")) if f.endswith(".yaml"))
    if args.models:
        wanted = set(args.models.split(","))
        files = [f for f in files if f[:-5] in wanted]
    entries = []
    worst_cross = mpf(0)
    for f in files:
        model = Model(os.path.join(ROOT, "models", f), args.eomgen)
        entry = {"name": model.name, "file": model.file}
        reason, missing = model.skip_reason()
        if reason:
            entry["skip"] = reason
            entry["constraints"] = len(model.constraints)
            if missing:
                entry["functions"] = missing
            print(f"{model.name}: skipped: {reason}", file=sys.stderr)
            entries.append(entry)
            continue
        model.setup()
        try:
            c = model.series_coefficients(T0, model.y, ORDER)
        except VariableExponent as error:
            entry["skip"] = str(error)
            entry["constraints"] = len(model.constraints)
            print(f"{model.name}: skipped: {error}", file=sys.stderr)
            entries.append(entry)
            continue
        d = model.ode_taylor_coefficients(T0, model.y, ORDER)
        cross = max(abs(a - b) / (1 + abs(a)) for a, b in zip(c, d))
        worst_cross = max(worst_cross, cross)
        if cross > CROSS_CHECK_TOLERANCE:
            dim = 2 * model.n
            bad = max(range(len(c)), key=lambda j: abs(c[j] - d[j]) / (1 + abs(c[j])))
            raise AssertionError(
                f"{model.name}: the two routes disagree: order {bad // dim}, component "
                f"{bad % dim}: {c[bad]} vs {d[bad]}")
        biggest = max(abs(v) for v in c)
        print(f"{model.name}: dim {2 * model.n}, routes agree to {mpmath.nstr(cross, 3)}, "
              f"largest |c| {mpmath.nstr(biggest, 3)}", file=sys.stderr)
        entry.update({
            "constraints": model.m,
            "dim": 2 * model.n,
            "t": double_text(T0),
            "y": [double_text(v) for v in model.y],
            "order": ORDER,
            "coefficients": [decimal(v, OUTPUT_DIGITS) for v in c],
        })
        entries.append(entry)
    doc = {
        "description": "Taylor coefficients y_i^[k] = y_i^(k)(t)/k! of each bundled model's "
                       "motion, coefficients[k*dim + i], from tools/taylor_reference.py "
                       "(series arithmetic in mpmath at 50 digits, cross-checked with "
                       "mpmath's ODE Taylor method).",
        "digits": DIGITS,
        "cross_check_worst_relative_difference": mpmath.nstr(worst_cross, 3),
        "models": entries,
    }
    if args.models:
        print(json.dumps(doc, indent=1))
        return
    os.makedirs(os.path.dirname(args.output), exist_ok=True)
    with open(args.output, "w") as out:
        json.dump(doc, out, indent=1)
        out.write("\n")
    print(f"wrote {args.output}", file=sys.stderr)


if __name__ == "__main__":
    main()
