"""eomgen: declarative models of mechanisms compiled into equations of motion, simulated and
analysed — from Python.

>>> import eomgen
>>> m = eomgen.load("double_pendulum")            # a bundled name or a path to a .yaml file
>>> sol = m.simulate(t_end=10.0, t_out=[1.0, 2.0, 5.0], method="dop853", rtol=1e-12, atol=1e-12)
>>> sol.q.shape
(3, 2)

Every computation runs in the compiled Rust library with the interpreter released; the
results are numpy arrays and dicts equal to the command line's ``--json`` output. See
docs/python.md.
"""

from ._eomgen import __version__
from . import sweep
from ._model import (
    METHODS,
    METHOD_SUMMARIES,
    Animation,
    Batch,
    Equations,
    Model,
    Modes,
    Reduction,
    Solution,
    SteadyMotion,
    bundled_models,
    expm_study,
    load,
    reduce,
)
from .errors import AnalysisError, EomgenError, IntegrationError, ModelError, ParameterError

__all__ = [
    "METHODS",
    "METHOD_SUMMARIES",
    "AnalysisError",
    "Animation",
    "Batch",
    "EomgenError",
    "Equations",
    "IntegrationError",
    "Model",
    "ModelError",
    "Modes",
    "ParameterError",
    "Reduction",
    "Solution",
    "SteadyMotion",
    "__version__",
    "bundled_models",
    "expm_study",
    "load",
    "reduce",
    "sweep",
]
