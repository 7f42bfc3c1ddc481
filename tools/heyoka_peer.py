"""heyoka's Taylor integrator on eomgen's models, for the work-precision comparison with peers.

heyoka (https://bluescarni.github.io/heyoka.py/, PyPI `heyoka`, tested with 7.13.2) is an
adaptive Taylor-series integrator that compiles the ODE's Taylor recurrences with LLVM.
The models are those of the panel, tools/peer_panel.py, by their `name`: its `t_end`, and
its initial state `eomgen.load(model_argument(e)).initial_state(e["set"])` (eomgen's own
doubles, bit for bit). Entries with `heyoka: None` (the bicycle: constraints) are not
heyoka's: asking for them raises a ValueError. Each entry's `heyoka` says how the ODE is built:

"hand": written out here, as before the panel existed:
- `double_pendulum` (models/double_pendulum.yaml, HW19): two uniform bars, absolute angles
  from +x, M(q) q'' = F(q, q') with the hand-derived M, F of
  tools/double_pendulum_reference.py (the same mathematics as eomgen's momentum balances),
  solved for q'' by Cramer's rule. Both rows are multiplied by 6 first, so that every
  coefficient is an integer combination of the parameters (exact in binary: the
  multiprecision reference below then solves exactly the model's ODE, not one with 1/3 and 1/2
  rounded to double):
      6 M = [[2 m1 l1^2 + 6 m2 l1^2, 3 m2 l1 l2 cos(t1 - t2)], [3 m2 l1 l2 cos(t1 - t2), 2 m2 l2^2]]
      6 F = [-3 m2 l1 l2 sin(t1 - t2) w2^2 - (3 m1 + 6 m2) g l1 cos t1,
              3 m2 l1 l2 sin(t1 - t2) w1^2 - 3 m2 g l2 cos t2]
      t1'' = (A22 b1 - A12 b2) / det,  t2'' = (A11 b2 - A12 b1) / det,  det = A11 A22 - A12^2.
- `figure_eight` (models/figure_eight.yaml, HW7): three equal masses, pairwise gravity, the
  model's `checks.equations_of_motion`: r_i'' = sum_j G m (r_j - r_i) / |r_j - r_i|^3.

"lagrangian" (`heavy_top`, `kepler_e09`, `five_link_chain`): heyoka's own
`lagrangian(L, qs, qdots)`, as a heyoka user would write the model, of L = T - V with T and V
eomgen's kinetic and potential energies as text (`Model.equations().listing`, the text of
`eomgen equations --json`). The text is parsed by SymPy (`^` is a power), the parameters'
exact values substituted (below), T simplified (`simplified_kinetic`: a polynomial in the
rates, each coefficient by SymPy's trigsimp; eomgen writes T as the bodies' sum of
m (vx^2 + vy^2 + vz^2) / 2, with sin^2 + cos^2 and sin a sin b + cos a cos b left in, which a
heyoka user would not write), and the result converted to heyoka expressions by `to_heyoka`
(sums, products with the negative integral powers as one division, `x^(1/2)` as `sqrt`,
other powers as `pow`, sin, cos ...); names `q` and `q_dot` are heyoka's variables, and the
state is eomgen's [q1..qn, q1_dot..qn_dot]. heyoka forms the Euler-Lagrange equations and
solves M(q) q'' = F symbolically (its own elimination; the dense 5 x 5 chain works: a Taylor
decomposition of 375 terms, compiled in ~0.7 s (tol 1e-6) to ~2 s (1e-9) in double precision,
~0.6 s at 170 bits in compact mode; SymPy's simplification takes 0.3 s). A model with
generalized forces, constraints or time in T - V is refused. Form "lagrangian-raw" is the
same with eomgen's T as written: a 6.5-7x slower step for the heavy top (decomposition 311
terms against 53), 1.4-1.6x for the chain, none for the Kepler orbit.

Fairness (`fairness`, heyoka 7.13.2, tol 1e-9, same 580 / 801 steps of order 12): the
hand-written double pendulum takes 0.32 us a step, "lagrangian" 0.47 (1.5x; 1.2x at 1e-6),
"lagrangian-raw" 1.1 (3.4x); the figure eight 0.29 us by hand, 0.30 by `lagrangian`. (An r^(-1/2)
written 1 / sqrt(r) made the lagrangian figure eight's step 2x slower: see `_product`.)
`--form lagrangian` (run, serve) builds every model by `lagrangian`.

Parameters: the model file's `parameters:` text (YAML, every value read as a string) parsed
exactly by SymPy: decimals as exact fractions (9.81 = 981/100), expressions (`pi/6`) exactly.
Every constant of an ODE (a rational of them, simplified exactly by SymPy) is rounded once:
to double, or at `prec` bits to an mp real, so that the multiprecision reference solves
exactly the model's ODE.

heyoka's tolerance: `taylor_adaptive(..., tol=tol)` is one number used as both the relative
and the absolute tolerance (rtol = atol = tol). The Taylor order is p = ceil(-ln(tol)/2 + 1)
and the step is chosen a priori from the last two Taylor coefficients so that the estimated
local truncation error is <= tol * max(1, ||x||_inf) (infinity norm over the whole state; Biscani
and Izzo, MNRAS 504 (2021) 2614, doi:10.1093/mnras/staa3867, section 3). eomgen and
ode_solvers instead weigh each component by atol + rtol |y_i| and estimate the error a
posteriori by an embedded pair, so equal `tol` does not mean equal error: compare at equal
error.

A degenerate first step: when the Taylor coefficients of orders p - 1 and p of the whole
state are all exactly zero, heyoka's step is infinite and the integration fails
(err_nf_state). The 5-link chain released at rest with every bar horizontal is such a start:
its series holds only the powers t^(4k+2) (q) and t^(4k+1) (q'), so every order p = 0 mod 4
fails (tol 1e-6, 1e-9, ... and 210 bits at tol 1e-58). `first_step` detects it when the
integrator is built, and then one step of at most h0 is taken before `propagate_until`, h0
being heyoka's own formula, rho / e^2 * exp(-0.7 / (p - 1)), with rho from the last two
non-zero orders (the series' next term is then ~e^(-2 (p + 2)) relative: below tol). That step
is counted in `steps` and timed.

Timing: for each (model, tol) the integrator is constructed (and JIT-compiled) once and
cached; its construction time is reported as `construct_s` and is not in `time_s`. Each
timed repetition resets the time to 0 and the state to y0 and times `propagate_until(t_end)`
alone (time.perf_counter; no continuous output, no callback). heyoka also keeps compiled code
in an on-disk cache ($XDG_CACHE_HOME/heyoka): a construction found there takes ~0.003-0.04 s
instead of ~0.02-2 s; `time_s` is the median of
`reps` repetitions (the first, untimed, gives the state and the step count).

Reference: `reference` integrates every heyoka model of the panel (or `--models`) with heyoka
in multiple precision (fp_type=heyoka.real, 170 bits, tol 1e-48), from the same double initial
states converted exactly, and checks the result against a second run at 210 bits, tol 1e-58;
the final states are written with 45 significant digits; the two runs agree to 2e-45 or
better on every model. The whole panel takes ~35 s on one core, the 5-link chain 22 s of it
(~470 steps of order 57 at ~20 ms). (The Taylor method in arbitrary precision is
a different computation from the double-precision runs being measured; the equations are
checked against eomgen's by `check`.)

Usage (from the repository root; P = the Rust program of benches/work_precision_peers.rs;
a Python with heyoka, numpy, sympy, pyyaml, mpmath and the eomgen package):
    python tools/heyoka_peer.py reference --out /tmp/peers-out/reference.json [--models a,b]
    python tools/heyoka_peer.py check [--models a,b] [--states 20] [--binary $P]
        # heyoka's RHS against eomgen's (Python package) at random states, every model in
        # each form (hand, lagrangian, lagrangian-raw); with --binary, y0 and the RHS of the
        # hand models against the Rust program's too
    python tools/heyoka_peer.py run --jobs double_pendulum:1e-8,five_link_chain:1e-9 \
        --reps 5 [--reference /tmp/peers-out/reference.json] [--high-accuracy] \
        [--form lagrangian|lagrangian-raw]
    python tools/heyoka_peer.py serve [--reference FILE] [--high-accuracy]  # a job list per line
    python tools/heyoka_peer.py fairness [--models double_pendulum,heavy_top] [--tol 1e-9]
        # steps and time per step of each model in each form
(`--high-accuracy`: heyoka's mode of that name, method "heyoka-taylor-high-accuracy".)
As a module: `HeyokaPeer(reference, high_accuracy).run([(model, tol), ...], reps)` returns the
result dicts
(the driver, tools/work_precision_peers.py, uses this and keeps the integrators between rounds).

Output: one JSON line per job: {"side": "heyoka", "method": "heyoka-taylor", "model", "tol",
"t_end", "time_s", "times_s", "call_overhead_s" (median time of a propagate_until that takes
no step: the Python call's own cost, included in time_s), "construct_s", "order", "steps", "rhs_evals": null,
"final_state", "error" (max |y_i(t_end) - y_ref_i| over the state, null without a
reference), "energy_drift" (|E(t_end) - E(0)| / |E(0)|, double precision; when E(0) = 0, as
for the 5-link chain, / (T + |V|)(t_end))}.
"""
import argparse
import functools
import json
import math
import random
import subprocess
import sys
import time
from fractions import Fraction
from pathlib import Path

import eomgen
import heyoka as hy
import numpy as np
import sympy
import yaml
from sympy.parsing.sympy_parser import (convert_xor, parse_expr, rationalize,
                                        standard_transformations)

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))
import peer_panel  # noqa: E402  (the panel: tools/peer_panel.py)

# The panel's models heyoka can express, and how ("hand" or "lagrangian").
FORMS = {e["name"]: e["heyoka"] for e in peer_panel.PANEL if e["heyoka"]}
HEYOKA_MODELS = list(FORMS)
# End times, from the panel (10 s for the double pendulum; 10 periods, Simo's T = 6.32591398,
# of the figure eight ...). The same doubles are passed to the Rust program.
T_END = {e["name"]: e["t_end"] for e in peer_panel.PANEL if e["heyoka"]}

METHOD = "heyoka-taylor"
METHOD_HIGH_ACCURACY = "heyoka-taylor-high-accuracy"

# (bits, tol) of the reference run and of the run it is checked against.
REFERENCE_RUN = (170, "1e-48")
CHECK_RUN = (210, "1e-58")

# eomgen's text: `^` is a power, decimals are exact.
TRANSFORMATIONS = standard_transformations + (convert_xor, rationalize)


def heyoka_entry(name):
    """The panel entry `name`, or a ValueError when heyoka cannot express its model."""
    e = peer_panel.entry(name)
    if e["heyoka"] is None:
        raise ValueError(f"`{name}` is not heyoka's: heyoka cannot express its model "
                         f"({e['why']}); heyoka's models: {', '.join(HEYOKA_MODELS)}")
    return e


@functools.lru_cache(maxsize=None)
def eomgen_model(name):
    """eomgen's compiled model of panel entry `name`."""
    return eomgen.load(peer_panel.model_argument(heyoka_entry(name)))


@functools.lru_cache(maxsize=None)
def _initial_state(name):
    e = heyoka_entry(name)
    return tuple(float(x) for x in eomgen_model(name).initial_state(e["set"]))


def initial_state(name):
    """y(0) as eomgen computes it: the file's `initial:` with the panel entry's `set`."""
    return list(_initial_state(name))


@functools.lru_cache(maxsize=None)
def exact_parameters(name):
    """{parameter: exact SymPy number} of the model file's `parameters:` text (decimals as
    fractions; expressions of constants and earlier parameters evaluated exactly)."""
    text = yaml.load(eomgen_model(name).text, Loader=yaml.BaseLoader)
    symbols = {k: sympy.Symbol(k) for k in text.get("parameters", {})}
    values = {}
    for k, v in text.get("parameters", {}).items():
        value = parse_expr(str(v), local_dict=symbols, transformations=TRANSFORMATIONS)
        values[k] = value.subs({symbols[j]: values[j] for j in values})
        if values[k].free_symbols:
            raise ValueError(f"{name}: parameter `{k}` = {v} is not a number")
    return values


def parameters(model):
    """The rational parameters of the model file, as exact Fractions of their decimal text."""
    return {k: Fraction(int(v.p), int(v.q)) for k, v in exact_parameters(model).items()
            if v.is_Rational}


def make_constant(prec):
    """Converts a Fraction into an expression constant: a double, or at `prec` bits an mp real
    (numerator and denominator exact, one rounding)."""
    if prec is None:
        return lambda fr: hy.expression(float(fr))

    def constant(fr):
        fr = Fraction(fr)
        return hy.expression(hy.real(fr.numerator, prec) / hy.real(fr.denominator, prec))
    return constant


def make_number(prec):
    """Converts an exact SymPy number into an expression constant, rounded once (a rational
    by `make_constant`, another number evaluated by SymPy with guard digits)."""
    constant = make_constant(prec)
    digits = 30 if prec is None else int(prec * math.log10(2)) + 20

    def number(x):
        if x.is_Rational:
            return constant(Fraction(int(x.p), int(x.q)))
        value = sympy.N(x, digits)
        if not value.is_real:
            raise ValueError(f"{x} is not a real number")
        if prec is None:
            return hy.expression(float(value))
        return hy.expression(hy.real(str(value), prec))
    return number


def double_pendulum_system(c, p):
    """The hand-written double pendulum (see the module's docstring)."""
    t1, t2, w1, w2 = hy.make_vars("theta1", "theta2", "theta1_dot", "theta2_dot")
    m1, m2, l1, l2, g = p["m1"], p["m2"], p["l1"], p["l2"], p["g"]
    cd, sd = hy.cos(t1 - t2), hy.sin(t1 - t2)
    a11 = c(2 * m1 * l1**2 + 6 * m2 * l1**2)
    a12 = c(3 * m2 * l1 * l2) * cd
    a22 = c(2 * m2 * l2**2)
    b1 = -c(3 * m2 * l1 * l2) * sd * w2**2 - c((3 * m1 + 6 * m2) * g * l1) * hy.cos(t1)
    b2 = c(3 * m2 * l1 * l2) * sd * w1**2 - c(3 * m2 * g * l2) * hy.cos(t2)
    det = a11 * a22 - a12 * a12
    acc1 = (a22 * b1 - a12 * b2) / det
    acc2 = (a11 * b2 - a12 * b1) / det
    return [t1, t2, w1, w2], [(t1, w1), (t2, w2), (w1, acc1), (w2, acc2)]


def figure_eight_system(c, p):
    """The hand-written three bodies of the figure eight (see the module's docstring)."""
    names = ["x1", "y1", "x2", "y2", "x3", "y3"]
    q = hy.make_vars(*names)
    v = hy.make_vars(*[n + "_dot" for n in names])
    gm = c(p["G"] * p["m"])
    acc = [[None, None] for _ in range(3)]
    pulls = {}
    for i in range(3):
        for j in range(i + 1, 3):
            dx, dy = q[2 * j] - q[2 * i], q[2 * j + 1] - q[2 * i + 1]
            k = gm * (dx**2 + dy**2) ** c(Fraction(-3, 2))
            pulls[(i, j)] = (k * dx, k * dy)
            pulls[(j, i)] = (-(k * dx), -(k * dy))
    for i in range(3):
        others = [j for j in range(3) if j != i]
        acc[i] = [pulls[(i, others[0])][0] + pulls[(i, others[1])][0],
                  pulls[(i, others[0])][1] + pulls[(i, others[1])][1]]
    rhs = [(q[k], v[k]) for k in range(6)]
    rhs += [(v[2 * i + d], acc[i][d]) for i in range(3) for d in range(2)]
    return list(q) + list(v), rhs


HAND_SYSTEMS = {"double_pendulum": double_pendulum_system, "figure_eight": figure_eight_system}

# SymPy's functions of one argument and heyoka's.
FUNCTIONS = {sympy.sin: hy.sin, sympy.cos: hy.cos, sympy.tan: hy.tan, sympy.exp: hy.exp,
             sympy.log: hy.log, sympy.sinh: hy.sinh, sympy.cosh: hy.cosh,
             sympy.tanh: hy.tanh, sympy.asin: hy.asin, sympy.acos: hy.acos,
             sympy.atan: hy.atan}


def to_heyoka(e, variables, number):
    """The SymPy expression `e` as a heyoka expression: symbols by name from `variables`,
    numbers by `number` (see make_number)."""
    if e.is_Symbol:
        return variables[e.name]
    if not e.free_symbols:
        return number(e)
    if e.is_Add:
        return hy.sum([to_heyoka(a, variables, number) for a in e.args])
    if e.is_Mul:
        return _product(e, variables, number)
    if e.is_Pow:
        return _power(e, variables, number)
    if e.func in FUNCTIONS and len(e.args) == 1:
        return FUNCTIONS[e.func](to_heyoka(e.args[0], variables, number))
    if e.func == sympy.atan2:
        return hy.atan2(*(to_heyoka(a, variables, number) for a in e.args))
    raise ValueError(f"no heyoka function for `{e.func}` in {e}")


def _product(e, variables, number):
    """A product: -(...) for a coefficient -1, the factors with negative integral powers
    divided by as one product. (A negative fractional power stays a power, as SymPy has it:
    heyoka differentiates r^(-1/2) into r^(-3/2), the hand-written form, but 1 / sqrt(r) into
    sqrt(r)^(-2) / sqrt(r), which makes the figure eight's steps twice as slow.)"""
    coefficient, rest = e.as_coeff_Mul()
    if coefficient == -1:
        return -to_heyoka(rest, variables, number)
    numerator, denominator = [], []
    for f in sympy.Mul.make_args(e):
        if f.is_Pow and f.exp.is_Integer and f.exp < 0:
            denominator.append(to_heyoka(f.base ** -f.exp, variables, number))
        else:
            numerator.append(to_heyoka(f, variables, number))
    top = numerator[0] if len(numerator) == 1 else (
        hy.prod(numerator) if numerator else number(sympy.Integer(1)))
    if not denominator:
        return top
    return top / (denominator[0] if len(denominator) == 1 else hy.prod(denominator))


def _power(e, variables, number):
    """base^exponent: sqrt for 1/2, a division for a negative integer, heyoka's pow
    otherwise (an integral exponent as an integer)."""
    base, exponent = e.base, e.exp
    if not exponent.is_Number:
        return to_heyoka(base, variables, number) ** to_heyoka(exponent, variables, number)
    if exponent.is_Integer and exponent < 0:
        return number(sympy.Integer(1)) / to_heyoka(base ** -exponent, variables, number)
    x = to_heyoka(base, variables, number)
    if exponent == sympy.Rational(1, 2):
        return hy.sqrt(x)
    if exponent.is_Integer:
        return x ** int(exponent)
    return x ** number(exponent)


def simplified_kinetic(kinetic, rates):
    """T as a polynomial in the rates with each coefficient simplified by SymPy's trigsimp
    (sin^2 + cos^2 = 1, sin a sin b + cos a cos b = cos(a - b) ...): eomgen's T is the sum of
    the bodies' (1/2) m v^2 with v in components, which a heyoka user would not write; it is
    kept if that is not shorter (count_ops)."""
    expanded = sympy.expand(kinetic)
    if not expanded.is_polynomial(*rates):
        return kinetic
    terms = sympy.Poly(expanded, *rates).terms()
    simplified = sympy.Add(*[sympy.trigsimp(c) * sympy.Mul(*[r**k for r, k in zip(rates, m)])
                             for m, c in terms])
    return simplified if sympy.count_ops(simplified) < sympy.count_ops(kinetic) else kinetic


@functools.lru_cache(maxsize=None)
def lagrangian_of(name, simplify=True):
    """(coordinates, L = T - V) of eomgen's model `name`: SymPy, parameters substituted;
    with `simplify`, T by `simplified_kinetic`."""
    model = eomgen_model(name)
    eq = model.equations().listing["equations"]
    if eq["generalized_forces"] or eq["constraints"]:
        raise ValueError(f"{name}: generalized forces or constraints are not in T - V")
    qs = model.coordinates
    params = exact_parameters(name)
    symbols = {n: sympy.Symbol(n) for n in qs + [q + "_dot" for q in qs] + list(params)}
    values = {symbols[k]: v for k, v in params.items()}

    def parse(text):
        return parse_expr(text, local_dict=symbols, transformations=TRANSFORMATIONS).subs(values)
    kinetic, potential = parse(eq["kinetic_energy"]), parse(eq["potential_energy"])
    if simplify:
        kinetic = simplified_kinetic(kinetic, [symbols[q + "_dot"] for q in qs])
    lagrangian = kinetic - potential
    stray = {s.name for s in lagrangian.free_symbols} - set(symbols)
    if stray:
        raise ValueError(f"{name}: T - V depends on {', '.join(sorted(stray))} "
                         "(heyoka's lagrangian takes L(q, q_dot) only)")
    return tuple(qs), lagrangian


def lagrangian_system(name, prec=None, simplify=True):
    """(state variables, [(var, rhs)]) of heyoka's `lagrangian(L, qs, qdots)` of eomgen's
    T - V, in eomgen's order [q; q_dot]."""
    qs, lagrangian = lagrangian_of(name, simplify)
    names = list(qs) + [q + "_dot" for q in qs]
    variables = hy.make_vars(*names)
    variables = variables if isinstance(variables, list) else [variables]
    ell = to_heyoka(lagrangian, dict(zip(names, variables)), make_number(prec))
    equations = hy.lagrangian(ell, variables[:len(qs)], variables[len(qs):])
    by_name = {str(var): rhs for var, rhs in equations}
    return variables, [(var, by_name[n]) for var, n in zip(variables, names)]


def system(model, prec=None, form=None):
    """(state variables, [(var, rhs)]) of the model's first-order ODE, in eomgen's state
    order; `form` "hand", "lagrangian" or "lagrangian-raw" (T not simplified; default: the
    panel's)."""
    form = form or heyoka_entry(model)["heyoka"]
    if form in ("lagrangian", "lagrangian-raw"):
        return lagrangian_system(model, prec, simplify=form == "lagrangian")
    if form == "hand" and model in HAND_SYSTEMS:
        return HAND_SYSTEMS[model](make_constant(prec), parameters(model))
    raise ValueError(f"no {form!r} heyoka system of {model!r} (hand-written: "
                     f"{', '.join(HAND_SYSTEMS)}; lagrangian: any of {', '.join(HEYOKA_MODELS)})")


def energy(model, y):
    """Total energy T + V (double precision) of the state y: the hand models' formulas (as
    eomgen's ModelInfo::energy), eomgen's `Model.energy` for the others."""
    if model not in HAND_SYSTEMS:
        kinetic, potential = eomgen_model(model).energy(np.asarray(y, dtype=float))
        return kinetic + potential
    p = {k: float(v) for k, v in parameters(model).items()}
    if model == "double_pendulum":
        t1, t2, w1, w2 = y
        m1, m2, l1, l2, g = p["m1"], p["m2"], p["l1"], p["l2"], p["g"]
        c = 0.5 * m2 * l1 * l2 * math.cos(t1 - t2)
        kinetic = 0.5 * ((m1 * l1**2 / 3 + m2 * l1**2) * w1**2 + 2 * c * w1 * w2
                         + m2 * l2**2 / 3 * w2**2)
        potential = g * (m1 * l1 / 2 * math.sin(t1) + m2 * (l1 * math.sin(t1)
                                                              + l2 / 2 * math.sin(t2)))
        return kinetic + potential
    gm, m = p["G"] * p["m"] ** 2, p["m"]
    r = np.asarray(y[:6]).reshape(3, 2)
    v = np.asarray(y[6:]).reshape(3, 2)
    potential = -gm * sum(1.0 / np.linalg.norm(r[i] - r[j])
                          for i in range(3) for j in range(i + 1, 3))
    return 0.5 * m * float(np.sum(v * v)) + potential


def energy_drift(model, y0, y1):
    """|E(y1) - E(y0)| / |E(y0)|, or, when E(y0) = 0 (the 5-link chain released from
    horizontal), / (T + |V|)(y1), T and V by eomgen."""
    e0, e1 = energy(model, y0), energy(model, y1)
    if e0 != 0:
        return abs((e1 - e0) / e0)
    kinetic, potential = eomgen_model(model).energy(np.asarray(y1, dtype=float))
    return abs(e1 - e0) / (kinetic + abs(potential))


def first_step(ta):
    """The largest first step h0 when heyoka's own would be infinite (the Taylor
    coefficients of orders p - 1 and p all zero: see the module's docstring), else None.
    The integrator's state and time are left as they were."""
    y0, t0 = ta.state.copy(), ta.time
    mp = isinstance(t0, hy.real)
    ta.step(max_delta_t=hy.real(1e-300, ta.prec) if mp else 1e-300, write_tc=True)
    norms = [max(abs(float(x)) for x in column) for column in ta.tc.T]
    ta.state[:] = y0
    ta.time = t0
    p = ta.order
    if norms[p] > 0 or norms[p - 1] > 0:
        return None
    orders = [k for k in range(1, p + 1) if norms[k] > 0][-2:]
    scale = max(1.0, max(abs(float(x)) for x in y0))
    rho = min((scale / norms[k]) ** (1.0 / k) for k in orders)
    h0 = rho * math.exp(-2.0 - 0.7 / (p - 1))
    return hy.real(h0, ta.prec) if mp else h0


def propagate(ta, t_end, h0=None):
    """propagate_until(t_end), after one step of at most h0 if h0 is given:
    (outcome, steps)."""
    steps = 0
    if h0 is not None:
        outcome, _ = ta.step(max_delta_t=h0)
        if outcome not in (hy.taylor_outcome.success, hy.taylor_outcome.time_limit):
            return outcome, 1
        steps = 1
    result = ta.propagate_until(t_end)
    return result[0], steps + int(result[3])


def load_reference(path):
    """{model: (t_end, [float state])} from a reference JSON file."""
    data = json.loads(Path(path).read_text())
    return {k: (v["t_end"], [float(s) for s in v["state"]]) for k, v in data.items()}


class HeyokaPeer:
    """Cached heyoka integrators, one per (model, tol), and the timed runs."""

    def __init__(self, reference=None, high_accuracy=False, form=None):
        """`high_accuracy`: heyoka's mode of that name (the terms of each step's Taylor
        polynomial summed with compensation, the error not carried to the next step, unlike
        eomgen's Taylor method); its results are then labelled `METHOD_HIGH_ACCURACY`.
        `form`: "lagrangian" ("lagrangian-raw") builds every model by heyoka's `lagrangian`
        of T - V with T simplified (as eomgen writes it), default: each model's panel form."""
        self.reference = reference or {}
        self.integrators = {}
        self.high_accuracy = high_accuracy
        self.form = form
        self.method = METHOD_HIGH_ACCURACY if high_accuracy else METHOD

    def integrator(self, model, tol):
        """(taylor_adaptive, construction time in s, first step or None), built on first
        use."""
        key = (model, tol)
        if key not in self.integrators:
            _, sys_ = system(model, form=self.form)
            start = time.perf_counter()
            ta = hy.taylor_adaptive(sys_, initial_state(model), tol=tol,
                                    high_accuracy=self.high_accuracy)
            construct_s = time.perf_counter() - start
            self.integrators[key] = (ta, construct_s, first_step(ta))
        return self.integrators[key]

    def run_one(self, model, tol, reps=5, t_end=None):
        """One job: the result dict described in the module's docstring."""
        heyoka_entry(model)
        t_end = T_END[model] if t_end is None else t_end
        ta, construct_s, h0 = self.integrator(model, tol)
        y0 = np.array(initial_state(model))
        times, steps, final = [], None, None
        for rep in range(reps + 1):
            ta.time = 0.0
            ta.state[:] = y0
            start = time.perf_counter()
            outcome, n = propagate(ta, t_end, h0)
            elapsed = time.perf_counter() - start
            if outcome != hy.taylor_outcome.time_limit or ta.time != t_end:
                return {"side": "heyoka", "method": self.method, "model": model, "tol": tol,
                        "failed": f"propagate_until stopped: {outcome} at t = {ta.time}"}
            if rep == 0:
                steps, final = n, ta.state.tolist()
            else:
                times.append(elapsed)
        # The cost of the call itself (argument conversion, the returned tuple): a
        # propagation to the current time, which takes no step.
        overheads = []
        for _ in range(max(reps, 1)):
            start = time.perf_counter()
            ta.propagate_until(t_end)
            overheads.append(time.perf_counter() - start)
        error = None
        if model in self.reference:
            t_ref, y_ref = self.reference[model]
            if t_ref == t_end:
                error = max(abs(a - b) for a, b in zip(final, y_ref))
        return {"side": "heyoka", "method": self.method, "model": model, "tol": tol,
                "t_end": t_end, "time_s": float(np.median(times)) if times else None,
                "times_s": times, "call_overhead_s": float(np.median(overheads)),
                "construct_s": construct_s, "order": ta.order,
                "steps": steps, "rhs_evals": None, "final_state": final, "error": error,
                "energy_drift": energy_drift(model, y0, final)}

    def run(self, jobs, reps=5):
        """The result dicts of the jobs [(model, tol)] or [(model, tol, t_end)], in order."""
        return [self.run_one(*job[:2], reps=reps, t_end=job[2] if len(job) > 2 else None)
                for job in jobs]


def reference_state(model, prec, tol):
    """(y(t_end) at `prec` bits with heyoka's Taylor method at `tol` (mp reals), steps,
    order, construction time in s)."""
    _, sys_ = system(model, prec)
    y0 = [hy.real(x, prec) for x in initial_state(model)]
    start = time.perf_counter()
    ta = hy.taylor_adaptive(sys_, y0, fp_type=hy.real, tol=hy.real(tol, prec))
    construct_s = time.perf_counter() - start
    outcome, steps = propagate(ta, hy.real(T_END[model], prec), first_step(ta))
    if outcome != hy.taylor_outcome.time_limit:
        raise RuntimeError(f"{model}: reference integration stopped: {outcome}")
    return list(ta.state), steps, ta.order, construct_s


def parse_models(models):
    """A list of panel names from a comma-separated string or a list (None: every model
    heyoka can express); each checked to be heyoka's."""
    if not models:
        return list(HEYOKA_MODELS)
    names = [n for n in models.split(",") if n] if isinstance(models, str) else list(models)
    for name in names:
        heyoka_entry(name)
    return names


def command_reference(args):
    """The reference file (see the module's docstring); `args.out`, `args.models`."""
    out = {}
    for model in parse_models(getattr(args, "models", None)):
        start = time.perf_counter()
        y, steps, order, _ = reference_state(model, REFERENCE_RUN[0], REFERENCE_RUN[1])
        y_check, steps_check, _, _ = reference_state(model, *CHECK_RUN)
        diff = max(abs(float(a - b)) for a, b in zip(y, y_check))
        out[model] = {
            "t_end": T_END[model],
            "state": [mp_digits(x, 45) for x in y],
            "initial_state": [repr(x) for x in initial_state(model)],
            "method": (f"heyoka taylor_adaptive, fp_type=real, {REFERENCE_RUN[0]} bits, "
                       f"tol {REFERENCE_RUN[1]}, {FORMS[model]} equations"),
            "steps": steps, "order": order,
            f"difference_from_{CHECK_RUN[0]}_bits_tol_{CHECK_RUN[1]}": diff,
            "seconds": time.perf_counter() - start,
        }
        print(f"{model}: {steps} steps of order {order} ({steps_check} at {CHECK_RUN[0]} "
              f"bits); differs from the {CHECK_RUN[0]}-bit run by {diff:.1e}; "
              f"{out[model]['seconds']:.1f} s", file=sys.stderr)
    text = json.dumps(out, indent=1)
    if getattr(args, "out", None):
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(text + "\n")
    else:
        print(text)


def mp_digits(x, digits):
    """The mp real x with `digits` significant decimal digits, in scientific notation."""
    import mpmath
    mpmath.mp.dps = digits + 10
    return mpmath.nstr(mpmath.mpf(str(x)), digits, min_fixed=1, max_fixed=0)


def random_state(y0, rng):
    """y0 with each component moved by up to 0.3 max(1, |y0_i|) (the heavy top's nutation
    stays between 0.22 and 0.83 rad, away from its Euler angles' singularity at 0)."""
    return [x + rng.uniform(-0.3, 0.3) * max(1.0, abs(x)) for x in y0]


def check_rhs(name, form, states, rng):
    """The largest relative difference max_i |f_i - g_i| / max_i |g_i| between heyoka's
    right-hand side (a compiled cfunc of the `form` system, double precision) and eomgen's
    `Model.rhs` at `states` random states; a summary line is printed."""
    variables, sys_ = system(name, form=form)
    start = time.perf_counter()
    cf = hy.cfunc([rhs for _, rhs in sys_], variables)
    compile_s = time.perf_counter() - start
    model = eomgen_model(name)
    worst = 0.0
    for _ in range(states):
        y = np.array(random_state(initial_state(name), rng))
        ours, theirs = cf(y), model.rhs(0.0, y)
        worst = max(worst, float(np.max(np.abs(ours - theirs)) / np.max(np.abs(theirs))))
    print(json.dumps({"model": name, "form": form, "against": "eomgen.Model.rhs",
                      "states": states, "max_relative_difference": worst,
                      "cfunc_compile_s": compile_s}))
    return worst


def check_binary(name, binary, states, rng):
    """The hand model `name` against the Rust program: y(0) bit for bit, and the RHS at
    random states (the double pendulum's also against tools/double_pendulum_reference.py)."""
    initial = json.loads(subprocess.run([binary, "initial", "--model", name],
                                        capture_output=True, text=True, check=True).stdout)
    same = initial["initial_state"] == initial_state(name)
    print(json.dumps({"model": name, "initial_state_bitwise_equal": same}))
    worst = 0.0 if same else 1.0
    variables, sys_ = system(name, form="hand")
    cf = hy.cfunc([rhs for _, rhs in sys_], variables)
    for _ in range(states):
        if name == "double_pendulum":
            y = [rng.uniform(-math.pi, math.pi) for _ in range(2)] + \
                [rng.uniform(-5, 5) for _ in range(2)]
        else:
            y = [x + rng.uniform(-0.3, 0.3) for x in initial_state(name)]
        eomgen_rhs = json.loads(subprocess.run(
            [binary, "rhs", "--model", name, "--state", ",".join(map(repr, y))],
            capture_output=True, text=True, check=True).stdout)["rhs"]
        ours = cf(np.array(y)).tolist()
        rel = max(abs(a - b) for a, b in zip(ours, eomgen_rhs)) / max(map(abs, eomgen_rhs))
        line = {"model": name, "state": y, "heyoka_rhs": ours, "eomgen_rhs": eomgen_rhs,
                "max_relative_difference": rel}
        if name == "double_pendulum":
            line["reference_script_rhs"] = reference_script_rhs(y)
            rel2 = max(abs(a - b) for a, b in zip(ours, line["reference_script_rhs"]))
            line["max_relative_difference_reference_script"] = rel2 / max(map(abs, ours))
            rel = max(rel, line["max_relative_difference_reference_script"])
        worst = max(worst, rel)
        print(json.dumps(line))
    return worst


def command_check(args):
    """heyoka's right-hand side against eomgen's (the Python package) at random states,
    every model in each of its forms (`forms_of`); with
    `--binary`, the hand models' y(0) and RHS against the Rust program's too."""
    rng = random.Random(20261125)
    worst = 0.0
    for name in parse_models(args.models):
        for form in forms_of(name):
            worst = max(worst, check_rhs(name, form, args.states, rng))
        if FORMS[name] == "hand" and args.binary:
            worst = max(worst, check_binary(name, args.binary, args.states, rng))
    print(json.dumps({"worst_relative_difference": worst}))
    # The generated and heyoka's equations differ in rounding only.
    return 0 if worst < 1e-13 else 1


def reference_script_rhs(y):
    """The right-hand side of tools/double_pendulum_reference.py (its `rhs`, copied: that
    script integrates when imported)."""
    m1 = m2 = l1 = l2 = 1.0
    g = 10.0
    t1, t2, w1, w2 = y
    c = 0.5 * m2 * l1 * l2
    M = np.array([[m1 * l1**2 / 3 + m2 * l1**2, c * math.cos(t1 - t2)],
                  [c * math.cos(t1 - t2), m2 * l2**2 / 3]])
    F = np.array([-c * math.sin(t1 - t2) * w2**2 - (0.5 * m1 + m2) * g * l1 * math.cos(t1),
                  c * math.sin(t1 - t2) * w1**2 - 0.5 * m2 * g * l2 * math.cos(t2)])
    a = np.linalg.solve(M, F)
    return [w1, w2, float(a[0]), float(a[1])]


def forms_of(name):
    """The forms the model can be built in: "hand" (if written out), "lagrangian",
    "lagrangian-raw"."""
    return (["hand"] if name in HAND_SYSTEMS else []) + ["lagrangian", "lagrangian-raw"]


def command_fairness(args):
    """Each model's ODE in each of its forms (`forms_of`) at one tolerance: steps, order,
    time per step (median of `reps`), construction time, Taylor decomposition size, and the
    time per step and the final state relative to the first form; one JSON line per model."""
    for name in parse_models(args.models):
        rows = {}
        forms = forms_of(name)
        for form in forms:
            peer = HeyokaPeer(form=form)
            result = peer.run_one(name, args.tol, reps=args.reps)
            ta = peer.integrators[(name, args.tol)][0]
            rows[form] = {"steps": result["steps"], "order": result["order"],
                          "time_s": result["time_s"],
                          "time_per_step_us": 1e6 * result["time_s"] / result["steps"],
                          "construct_s": result["construct_s"],
                          "decomposition_size": len(ta.decomposition),
                          "final_state": result["final_state"]}
        first = rows[forms[0]]
        for row in rows.values():
            row["time_per_step_ratio"] = row["time_per_step_us"] / first["time_per_step_us"]
            row["final_state_difference"] = max(
                abs(a - b) for a, b in zip(row["final_state"], first["final_state"]))
        print(json.dumps({"model": name, "tol": args.tol, "relative_to": forms[0], **rows}))
    return 0


def parse_jobs(text):
    """`model:tol,model:tol` -> [(model, tol)]."""
    jobs = []
    for item in text.split(","):
        model, tol = item.split(":")
        jobs.append((model, float(tol)))
    return jobs


def arguments():
    """The command line's arguments."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    models = "comma-separated panel names (default: every model heyoka can express)"
    p = sub.add_parser("reference", help="multiprecision reference states")
    p.add_argument("--out")
    p.add_argument("--models", help=models)
    p = sub.add_parser("check", help="compare the RHS (and y0 with --binary) with eomgen's")
    p.add_argument("--binary", help="the Rust program (checks the hand models against it)")
    p.add_argument("--states", type=int, default=20)
    p.add_argument("--models", help=models)
    p = sub.add_parser("fairness", help="steps and time per step of each model in each form")
    p.add_argument("--models", help=models)
    p.add_argument("--tol", type=float, default=1e-9)
    p.add_argument("--reps", type=int, default=21)
    for name, text in (("run", "run jobs model:tol,..."),
                       ("serve", "read one JSON job list per line on stdin")):
        p = sub.add_parser(name, help=text)
        if name == "run":
            p.add_argument("--jobs", required=True)
        p.add_argument("--reps", type=int, default=5)
        p.add_argument("--reference")
        p.add_argument("--high-accuracy", action="store_true",
                       help="heyoka's high_accuracy mode (method label " + METHOD_HIGH_ACCURACY + ")")
        p.add_argument("--form", choices=["lagrangian", "lagrangian-raw"],
                       help="build every model by heyoka's lagrangian of T - V, T simplified "
                            "(-raw: as eomgen writes it); default: the panel's form")
    return parser.parse_args()


def main():
    args = arguments()
    if args.command == "reference":
        command_reference(args)
        return 0
    if args.command == "check":
        return command_check(args)
    if args.command == "fairness":
        return command_fairness(args)
    peer = HeyokaPeer(load_reference(args.reference) if args.reference else None,
                      high_accuracy=args.high_accuracy, form=args.form)
    if args.command == "run":
        for result in peer.run(parse_jobs(args.jobs), args.reps):
            print(json.dumps(result), flush=True)
        return 0
    for line in sys.stdin:
        if line.strip():
            for result in peer.run([tuple(job) for job in json.loads(line)], args.reps):
                print(json.dumps(result), flush=True)
            print(json.dumps({"done": True}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
