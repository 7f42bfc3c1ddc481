"""How long eomgen's printed equations are against SymPy's `trigsimp` of the same.

For each model named (default: the bundled 3-D models and a few planar ones), every entry
of `eomgen equations MODEL --json` (T, V, Q, M, F, each constraint's equation, Jacobian row
and gamma) is parsed by SymPy, simplified by `trigsimp`, and printed; lengths are compared
with spaces removed and `**` written `^` (the model file's syntax). Entries longer than
`--most` characters are skipped (trigsimp takes minutes on them), and so are entries where
trigsimp runs past `--seconds`.

    python3 tools/readable_vs_trigsimp.py [--eomgen target/release/eomgen] [MODEL ...]
"""

import argparse
import json
import multiprocessing
import re
import subprocess

import sympy as sp

DEFAULT = ["heavy_top", "free_rigid_body", "furuta_pendulum", "rolling_disc", "double_pendulum",
           "triple_pendulum", "cart_pendulum", "four_bar", "slider_crank", "spring_pair_3d",
           "chaplygin_sleigh", "turntable_slot_spring", "bead_spinning_rod"]


def entries(listing):
    e = listing["equations"]
    yield "T", e["kinetic_energy"]
    yield "V", e["potential_energy"]
    for q in e["generalized_forces"]:
        yield f"Q[{q['coordinate']}]", q["expression"]
    for i, row in enumerate(e["mass_matrix"]):
        for j, x in enumerate(row):
            if j >= i:
                yield f"M[{i},{j}]", x
    for i, x in enumerate(e["forcing"]):
        yield f"F[{i}]", x
    for c in e["constraints"]:
        yield f"{c['name']}", c["equation"]
        for j, x in enumerate(c["jacobian"]):
            yield f"J[{c['name']},{j}]", x
        yield f"gamma[{c['name']}]", c["gamma"]


def normal(text):
    return text.replace(" ", "").replace("**", "^")


FUNCTIONS = {"sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh",
             "exp", "ln", "sqrt", "abs", "sign", "pi"}


def trigsimp_text(text):
    """SymPy's `trigsimp` of an entry printed by eomgen, printed as `normal` writes it."""
    # Every name a symbol (a parameter `I` is not the imaginary unit), `ln` the logarithm.
    names = {n: sp.Symbol(n) for n in re.findall(r"[A-Za-z_][A-Za-z_0-9]*", text)
             if n not in FUNCTIONS}
    names["ln"] = sp.log
    expr = sp.parse_expr(text.replace("^", "**"), local_dict=names)
    return normal(sp.sstr(sp.trigsimp(expr)))


def simplify(text, out):
    out.put(trigsimp_text(text))


def trigsimp_length(text, seconds):
    out = multiprocessing.Queue()
    worker = multiprocessing.Process(target=simplify, args=(text, out))
    worker.start()
    worker.join(seconds)
    if worker.is_alive():
        worker.terminate()
        return f"trigsimp past {seconds} s"
    return len(out.get()) if not out.empty() else "SymPy failed on it"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("models", nargs="*", default=DEFAULT)
    parser.add_argument("--eomgen", default="target/release/eomgen")
    parser.add_argument("--most", type=int, default=1500)
    parser.add_argument("--seconds", type=float, default=20.0)
    args = parser.parse_args()
    total = longer = skipped = 0
    ours_sum = theirs_sum = 0
    for model in args.models:
        listing = json.loads(subprocess.check_output([args.eomgen, "equations", model, "--json"]))
        for name, text in entries(listing):
            ours = len(normal(text))
            if ours > args.most:
                skipped += 1
                print(f"{model} {name}: skipped, {ours} characters (--most {args.most})")
                continue
            theirs = trigsimp_length(text, args.seconds)
            if isinstance(theirs, str):
                skipped += 1
                print(f"{model} {name}: skipped, {theirs}")
                continue
            total += 1
            ours_sum += ours
            theirs_sum += theirs
            if ours > theirs:
                longer += 1
                print(f"{model} {name}: eomgen {ours} > trigsimp {theirs}: {text}")
    print(f"{total} entries compared ({skipped} skipped): eomgen longer in {longer}; "
          f"characters eomgen {ours_sum}, trigsimp {theirs_sum}")


if __name__ == "__main__":
    main()
