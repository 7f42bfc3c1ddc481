"""SymPy mechanics on the n-link pendulum of `eomgen new n-link-pendulum N`, for a side-by-side
derivation-time and operation-count comparison (issue 4). Not used by the product.

Same model as `symbolic/src/model/templates.rs`: a chain of uniform bars, absolute angles
q_i from +x, bar i hinged at the end of bar i - 1, centre of mass at its middle, centroidal
inertia m_i l_i^2/12, gravity g along -y. Two parameterisations:

- `per-bar` (default, like for like with the template): symbols m1..mN, l1..lN and g;
- `shared`: one m, one l and g for every bar (what this script measured before issue 4; fewer
  distinct symbols, so SymPy's CSE finds more to share).

For each N it reports, separately:

- the wall time of `KanesMethod.kanes_equations` (M and F; u_i = q_i' as generalized speeds),
  and with `--lagrange` of `LagrangesMethod.form_lagranges_equations` too;
- the wall time of the Jacobians dF/dq and dF/du (`Matrix.jacobian`), what `eomgen::model!`
  also derives (`Jacobians::of`);
- the operations of M and F after `sympy.cse`, counted two ways:
  `count_ops`, SymPy's own visual count (a - b, a/b and -a are one operation each), and
  `eomgen`, the rule of `ExprArena::tree_operation_count` / `CsePlan::operation_count`
  (see `eomgen_ops` below).

Run: python3 tools/sympy_n_link.py [--params per-bar|shared] [--lagrange] [--jacobians] 2 5 10
"""
import argparse
import sys
import time

import sympy as sm
import sympy.physics.mechanics as me
from sympy.core.function import AppliedUndef


def chain(n, params):
    """Bodies, loads, coordinates and speeds of the n-link chain (KanesMethod and
    LagrangesMethod take the same bodies and loads)."""
    q = me.dynamicsymbols(f"q1:{n + 1}")
    u = me.dynamicsymbols(f"u1:{n + 1}")
    g = sm.symbols("g")
    if params == "shared":
        m_all, l_all = sm.symbols("m l")
        masses, lengths = [m_all] * n, [l_all] * n
    else:
        masses = sm.symbols(f"m1:{n + 1}")
        lengths = sm.symbols(f"l1:{n + 1}")
    frame = me.ReferenceFrame("N")
    origin = me.Point("O")
    origin.set_vel(frame, 0)
    bodies, loads = [], []
    joint = origin
    for i in range(n):
        m, l = masses[i], lengths[i]
        bar = me.ReferenceFrame(f"A{i}")
        bar.orient_axis(frame, frame.z, q[i])
        centre = joint.locatenew(f"G{i}", l / 2 * bar.x)
        centre.v2pt_theory(joint, frame, bar)
        end = joint.locatenew(f"P{i}", l * bar.x)
        end.v2pt_theory(joint, frame, bar)
        inertia = me.inertia(bar, 0, 0, m * l**2 / 12)
        bodies.append(me.RigidBody(f"B{i}", centre, bar, m, (inertia, centre)))
        loads.append((centre, -m * g * frame.y))
        joint = end
    return frame, origin, q, u, bodies, loads


def eomgen_ops(exprs):
    """Operations to evaluate `exprs` the way eomgen counts them (`node_operation_count` in
    symbolic/src/expr/mod.rs, summed over the DAG as `CsePlan::operation_count` does):

    - a sum or product of k operands costs k - 1 (a numeric coefficient is an operand, so
      -a = (-1)*a and a/2 = (1/2)*a cost 1; a - b = a + (-1)*b costs 2);
    - a power costs 1 whatever its exponent (a/b = a*b**-1 costs 2), a function call 1;
    - numbers, symbols, the coordinates q_i(t), u_i(t) and the rates q_i'(t) cost 0;
    - every distinct subexpression is counted once (eomgen's plan evaluates each DAG node
      once), and sin(x) with cos(x) of the same x costs 1 (eomgen emits one `sin_cos`).
    """
    seen = set()
    ops = 0
    trig_args = {sm.sin: set(), sm.cos: set()}
    stack = list(exprs)
    while stack:
        e = stack.pop()
        if e in seen:
            continue
        seen.add(e)
        if is_leaf(e):
            continue
        if e.is_Add or e.is_Mul:
            ops += len(e.args) - 1
        elif e.is_Pow or e.is_Function:
            ops += 1
            if e.func in trig_args:
                trig_args[e.func].add(e.args[0])
        else:
            raise ValueError(f"no eomgen cost for {e.func}")
        stack.extend(e.args)
    return ops - len(trig_args[sm.sin] & trig_args[sm.cos])


def eomgen_tree_ops(exprs):
    """Operations of `exprs` evaluated as trees (no sharing at all), eomgen's
    `tree_operation_count` rule (see `eomgen_ops`; no sin/cos pairing)."""
    def tree(e):
        if is_leaf(e):
            return 0
        own = len(e.args) - 1 if (e.is_Add or e.is_Mul) else 1
        return own + sum(tree(a) for a in e.args)
    return sum(tree(e) for e in exprs)


def is_leaf(e):
    """A number, a symbol, a coordinate q_i(t) or a rate q_i'(t) (LagrangesMethod's)."""
    return e.is_Atom or isinstance(e, (AppliedUndef, sm.Derivative))


def after_cse(matrices):
    """`sympy.cse` of `matrices` and the operations left (count_ops, eomgen rule), with the
    wall time of the CSE itself."""
    start = time.perf_counter()
    replacements, reduced = sm.cse(matrices)
    cse_s = time.perf_counter() - start
    exprs = [rhs for _, rhs in replacements] + [x for m in reduced for x in m]
    return cse_s, sum(sm.count_ops(e) for e in exprs), eomgen_ops(exprs)


def run(n, params, lagrange, jacobians):
    frame, _, q, u, bodies, loads = chain(n, params)
    kd = [qi.diff() - ui for qi, ui in zip(q, u)]
    start = time.perf_counter()
    kane = me.KanesMethod(frame, q_ind=q, u_ind=u, kd_eqs=kd)
    kane.kanes_equations(bodies, loads)
    kane_s = time.perf_counter() - start
    mass, forcing = kane.mass_matrix, kane.forcing
    trees = eomgen_tree_ops(list(mass) + list(forcing))
    cse_s, count_ops, ours = after_cse([mass, forcing])
    line = (f"n={n} params={params}: KanesMethod M,F {kane_s:.3f} s; M,F {trees} ops as trees "
            f"(eomgen rule); after cse ({cse_s:.3f} s): {count_ops} count_ops, {ours} eomgen rule")
    if jacobians:
        start = time.perf_counter()
        forcing.jacobian(q)
        forcing.jacobian(u)
        line += f"; Jacobians dF/dq, dF/du {time.perf_counter() - start:.3f} s"
    if lagrange:
        frame, origin, q, _, bodies, loads = chain(n, params)
        start = time.perf_counter()
        for body, (_, force) in zip(bodies, loads):
            body.potential_energy = -force.dot(body.masscenter.pos_from(origin))
        lagrangian = me.Lagrangian(frame, *bodies)
        method = me.LagrangesMethod(lagrangian, q)
        method.form_lagranges_equations()
        lagrange_s = time.perf_counter() - start
        _, _, ours_l = after_cse([method.mass_matrix, method.forcing])
        line += f"; LagrangesMethod M,F {lagrange_s:.3f} s, {ours_l} eomgen-rule ops after cse"
    print(line)
    sys.stdout.flush()


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sizes", type=int, nargs="+", help="chain lengths N")
    parser.add_argument("--params", choices=["per-bar", "shared"], default="per-bar")
    parser.add_argument("--lagrange", action="store_true", help="also time LagrangesMethod")
    parser.add_argument("--jacobians", action="store_true", help="also time dF/dq, dF/du")
    args = parser.parse_args()
    for n in args.sizes:
        run(n, args.params, args.lagrange, args.jacobians)


if __name__ == "__main__":
    main()
