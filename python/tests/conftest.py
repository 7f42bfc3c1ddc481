"""Shared fixtures: the command-line program (for comparisons with its `--json`), model files
written to a temporary directory.

With EOMGEN_CI=1 (as `.ci/run` sets it) nothing may be skipped: the command-line program must
be found, and a test skipped for any other reason (Dask or SciPy missing) fails the run.
"""

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
    it is not built, and fail instead when EOMGEN_CI=1 (CI builds it first)."""
    path = cli_path()
    if path is None:
        if os.environ.get("EOMGEN_CI") == "1":
            pytest.fail("EOMGEN_CI=1 but no eomgen program was found (set EOMGEN_CLI)")
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


def pytest_sessionfinish(session, exitstatus):
    """With EOMGEN_CI=1, a run that skipped a test is a failed run."""
    if os.environ.get("EOMGEN_CI") != "1":
        return
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    skipped = reporter.stats.get("skipped", []) if reporter is not None else []
    if skipped:
        reporter.write_line(f"EOMGEN_CI=1: {len(skipped)} test(s) skipped; every test must run in CI", red=True)
        session.exitstatus = 1
