"""Shared fixtures: the command-line program (for comparisons with its `--json`), model files
written to a temporary directory."""

import os
import pathlib
import shutil

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


def cli_path():
    """The `eomgen` program: $EOMGEN_CLI, else the workspace's release or debug build."""
    explicit = os.environ.get("EOMGEN_CLI")
    if explicit:
        return explicit
    for profile in ("release", "debug"):
        candidate = REPO / "target" / profile / "eomgen"
        if candidate.is_file():
            return str(candidate)
    return shutil.which("eomgen")


@pytest.fixture(scope="session")
def cli():
    """The path of the `eomgen` program; the tests that compare with it are skipped where
    it is not built, and fail instead when EOMGEN_REQUIRE_CLI=1 (CI builds it first)."""
    path = cli_path()
    if path is None:
        if os.environ.get("EOMGEN_REQUIRE_CLI") == "1":
            pytest.fail("EOMGEN_REQUIRE_CLI=1 but no eomgen program was found (set EOMGEN_CLI)")
        pytest.skip("the eomgen program is not built (cargo build); set EOMGEN_CLI to compare with it")
    return path


@pytest.fixture()
def model_file(tmp_path):
    """A copy of a bundled model file under a temporary directory, by model name."""

    def write(name, text=None):
        import eomgen

        source = text if text is not None else eomgen.load(name).text
        path = tmp_path / f"{name}.yaml"
        path.write_text(source)
        return str(path)

    return write
