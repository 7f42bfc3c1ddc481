"""The equations exported as a NumPy module (``Model.export("python")``, ``eomgen equations
--python``) against the model's own values, for every bundled model at three seeded states
near its initial state: ``rhs`` (with constraints, through the index-1 system), ``M``, ``F``,
``T`` and ``V``. Both evaluate the same operations, with NumPy's ``sin``, ``sqrt``, … against
the ``libm`` crate's, so they agree to an ulp or so per operation: the tolerance is 1e-13
relative to the output's largest entry (at least 1). The exported C and MATLAB, and the
Jacobians, points and constraints, are compared by ``tests/export.rs``.
"""
import numpy as np
import pytest

import eomgen

TOLERANCE = 1e-13


def _module(model):
    namespace = {}
    exec(compile(model.export("python"), f"<{model.name}>", "exec"), namespace)
    return namespace


def _close(exported, reference):
    exported, reference = np.asarray(exported, dtype=float), np.asarray(reference, dtype=float)
    assert exported.shape == reference.shape
    scale = max(1.0, float(np.max(np.abs(reference), initial=0.0)))
    return float(np.max(np.abs(exported - reference), initial=0.0)) / scale


_FIXTURES = __import__("pathlib").Path(__file__).resolve().parents[2] / "tests" / "fixtures"


# Every bundled model, and four in generalized speeds (their ``qd`` is ``u``; ``rhs`` takes the
# rates from ``coordinate_rates``; the rolling disc and the Euler parameters hold their
# auxiliary speeds at 0).
@pytest.mark.parametrize("name", eomgen.bundled_models() + [
    str(_FIXTURES / "free_rigid_body_speeds.yaml"),
    str(_FIXTURES / "heavy_top_speeds.yaml"),
    str(_FIXTURES / "rolling_disc_speeds.yaml"),
    str(_FIXTURES / "free_rigid_body_quaternion_speeds.yaml"),
])
def test_exported_python_computes_what_eomgen_computes(name):
    model = eomgen.load(name)
    code = _module(model)
    n = model.num_dofs
    rng = np.random.default_rng(7)
    y0 = model.initial_state()
    np.testing.assert_array_equal(code["initial_state"]().shape, (2 * n,))
    assert list(code["COORDINATES"]) == model.coordinates
    assert dict(zip(code["PARAMETER_NAMES"], code["PARAMETERS"])) == model.parameters
    for _ in range(3):
        t = float(rng.uniform(0.0, 1.0))
        y = y0 + np.concatenate((0.1 * rng.uniform(-1, 1, n), 0.5 * rng.uniform(-1, 1, n)))
        q, qd = y[:n], y[n:]
        mass, forcing = code["mass_matrix_and_forcing"](t, q, qd)
        assert _close(mass, model.mass_matrix(q, t)) <= TOLERANCE
        assert _close(forcing, model.forcing(q, qd, t)) <= TOLERANCE
        assert _close(code["rhs"](t, y), model.rhs(t, y)) <= TOLERANCE
        kinetic, potential = model.energy(y, t)
        assert abs(code["kinetic_energy"](t, q, qd) - kinetic) <= TOLERANCE * max(1.0, abs(kinetic))
        assert abs(code["potential_energy"](t, q) - potential) <= TOLERANCE * max(1.0, abs(potential))


def test_export_names_the_languages():
    model = eomgen.load("double_pendulum")
    assert model.export("c").startswith("/*")
    assert model.export("matlab").startswith("function model = double_pendulum()")
    with pytest.raises(ValueError, match="language must be"):
        model.export("fortran")



def test_export_carries_the_parameters_set_on_the_model():
    """``with_parameters(...).export(...)``: the exported defaults are the model's values."""
    model = eomgen.load("double_pendulum").with_parameters(l1=1.5, g=9.81)
    code = _module(model)
    assert dict(zip(code["PARAMETER_NAMES"], code["PARAMETERS"])) == model.parameters
    y = model.initial_state() + 0.1
    assert _close(code["rhs"](0.3, y), model.rhs(0.3, y)) <= TOLERANCE
