"""The exceptions of eomgen.

Each keeps its attributes through ``pickle`` (a Dask worker's exception reaches the client
whole): every constructor argument is passed on to ``Exception.__init__``, so that ``args``
rebuilds the instance.
"""

from __future__ import annotations

from typing import Any, List, Optional


class EomgenError(Exception):
    """Base class of every exception raised by eomgen."""


class ModelError(EomgenError):
    """A model that cannot be opened: an unknown name, an unreadable file, or a file with
    mistakes.

    Attributes:
        message: the whole message, with every diagnostic rendered on its source line.
        diagnostics: one dict per located mistake, ``{"file", "line", "column", "message",
            "help"}`` (1-based line and column; ``help`` says what would be right, or is
            ``None``) — the objects of ``eomgen ... --json``'s error. Empty for an unknown
            name or an unreadable file.
    """

    def __init__(self, message: str, diagnostics: Optional[List[dict]] = None):
        super().__init__(message, diagnostics)
        self.message = message
        self.diagnostics = list(diagnostics or [])

    def __str__(self) -> str:
        return self.message


class ParameterError(EomgenError, ValueError):
    """A parameter the model does not have, or a value that is not a finite number."""


class AnalysisError(EomgenError):
    """An analysis that could not be done: no equilibrium found, constraints that cannot be
    satisfied, a failed eigenproblem, options the study refuses."""


class IntegrationError(EomgenError):
    """An integration that stopped before its end time.

    Attributes:
        message: what the command line prints: the model, the reason and the time.
        t: the time (s) at which it stopped (``None`` when it stopped before the first step).
        reason: the integrator's own message (step size too small, a non-finite state, …).
        solution: the samples computed before the failure: a :class:`eomgen.Solution`
            (a :class:`eomgen.Batch` for a batch).
        animation: for :meth:`eomgen.Model.animate`, the :class:`eomgen.Animation` of the
            frames computed before the failure (``None`` when there was none).
    """

    def __init__(self, message: str, t: Optional[float], reason: str, solution: Any = None,
                 animation: Any = None):
        super().__init__(message, t, reason, solution, animation)
        self.message = message
        self.t = t
        self.reason = reason
        self.solution = solution
        self.animation = animation

    def __str__(self) -> str:
        return self.message
