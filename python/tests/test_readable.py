"""The printed equations are no longer than SymPy's ``trigsimp`` of the same (issue 53, item 4).

Every entry of ``Model.equations().listing`` (the JSON of ``eomgen equations --json``: T, V,
the generalized forces, M, F, and each constraint's equation, Jacobian row and gamma) of the
bundled 3-D models is parsed by SymPy, simplified by ``trigsimp`` and printed; eomgen's text
must not be longer, spaces aside and ``**`` counted as ``^``. The value of each readable entry
against the derived one is tested in Rust (``symbolic/tests/derivations.rs``); this test is
about the form. ``tools/readable_vs_trigsimp.py`` runs the same comparison on more models."""

import re

import pytest

import eomgen

sp = pytest.importorskip("sympy")

FUNCTIONS = {"sin", "cos", "tan", "asin", "acos", "atan", "sqrt", "exp"}


def _entries(listing):
    e = listing["equations"]
    yield "T", e["kinetic_energy"]
    yield "V", e["potential_energy"]
    for q in e["generalized_forces"]:
        yield f"Q[{q['coordinate']}]", q["expression"]
    for i, row in enumerate(e["mass_matrix"]):
        for j, x in enumerate(row[i:], start=i):
            yield f"M[{i},{j}]", x
    for i, x in enumerate(e["forcing"]):
        yield f"F[{i}]", x
    for c in e["constraints"]:
        yield c["name"], c["equation"]
        for j, x in enumerate(c["jacobian"]):
            yield f"J[{c['name']},{j}]", x
        yield f"gamma[{c['name']}]", c["gamma"]


def _length(text):
    return len(text.replace(" ", "").replace("**", "^"))


@pytest.mark.parametrize("name", ["free_rigid_body", "heavy_top", "rolling_disc", "furuta_pendulum"])
def test_printed_equations_are_no_longer_than_trigsimp(name):
    listing = eomgen.load(name).equations().listing
    longer = []
    for entry, text in _entries(listing):
        names = {n: sp.Symbol(n) for n in re.findall(r"[A-Za-z_][A-Za-z_0-9]*", text)
                 if n not in FUNCTIONS}
        expr = sp.parse_expr(text.replace("^", "**"), local_dict=names)
        theirs = sp.sstr(sp.trigsimp(expr))
        if _length(text) > _length(theirs):
            longer.append(f"{entry}: {text} against {theirs}")
    assert not longer, "\n".join(longer)
