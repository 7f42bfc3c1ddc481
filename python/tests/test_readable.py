"""The printed equations are no longer than SymPy's ``trigsimp`` of the same (issue 53, item 4).

Every entry of ``Model.equations().listing`` (the JSON of ``eomgen equations --json``: T, V,
the generalized forces, M, F, and each constraint's equation, Jacobian row and gamma) of the
bundled 3-D models is parsed by SymPy, simplified by ``trigsimp`` and printed; eomgen's text
must not be longer, spaces aside and ``**`` counted as ``^``. The entries and the comparison
are those of ``tools/readable_vs_trigsimp.py``, which runs it on more models. The value of
each readable entry against the derived one is tested in Rust
(``symbolic/tests/derivations.rs``); this test is about the form."""

import importlib.util
from pathlib import Path

import pytest

import eomgen

pytest.importorskip("sympy")

_TOOL = Path(__file__).resolve().parents[2] / "tools" / "readable_vs_trigsimp.py"
_spec = importlib.util.spec_from_file_location("readable_vs_trigsimp", _TOOL)
tool = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(tool)


@pytest.mark.parametrize("name", ["free_rigid_body", "heavy_top", "rolling_disc", "furuta_pendulum"])
def test_printed_equations_are_no_longer_than_trigsimp(name):
    listing = eomgen.load(name).equations().listing
    longer = []
    for entry, text in tool.entries(listing):
        theirs = tool.trigsimp_text(text)
        if len(tool.normal(text)) > len(theirs):
            longer.append(f"{entry}: {text} against {theirs}")
    assert not longer, "\n".join(longer)
