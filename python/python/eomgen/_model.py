"""Models, simulations and modal analyses: the Python face of the compiled library.

Every number comes from the Rust library (``eomgen._eomgen``); this module names the
arguments, documents shapes and units, and wraps the reports in small result objects.
"""

from __future__ import annotations

import functools
import html
import math
from typing import Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _eomgen
from .errors import IntegrationError

ArrayLike = Union[Sequence[float], np.ndarray]

#: The integration methods (``method=``), by name, from the library's method table (the one
#: ``eomgen simulate --help`` lists): fixed-step ones take ``dt``, adaptive ones
#: ``rtol``/``atol``; :data:`METHOD_SUMMARIES` says which is which.
METHODS = tuple(name for name, _ in _eomgen.methods())

#: One line on each method of :data:`METHODS`: its order, step, dense output and what it
#: suits.
METHOD_SUMMARIES = dict(_eomgen.methods())

#: ``simulate``'s defaults, those of ``eomgen simulate`` without options: end time (s),
#: method, tolerances, Baumgarte's gains (1/s).
DEFAULT_T_END, DEFAULT_METHOD, DEFAULT_RTOL, DEFAULT_ATOL, DEFAULT_BAUMGARTE = _eomgen.simulation_defaults()


def _finite(value: float, what: str) -> float:
    """``value`` as a float, or a ValueError naming ``what`` when it is not a finite number."""
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"{what} must be a finite number, got {x}")
    return x


def _gains(baumgarte) -> Tuple[float, float]:
    """Baumgarte's two gains ``(alpha, beta)`` (1/s), or a ValueError."""
    try:
        alpha, beta = baumgarte
    except (TypeError, ValueError):
        raise ValueError(f"baumgarte must be two gains (alpha, beta), got {baumgarte!r}") from None
    return float(alpha), float(beta)


def load(name_or_path: str) -> "Model":
    """Opens a model: a bundled model's name (``"double_pendulum"``, see
    :func:`bundled_models`) or the path of any model file (``"my/model.yaml"``), whose
    equations are derived and compiled to machine code now (milliseconds).

    Raises:
        ModelError: an unknown name, an unreadable file, or a file with mistakes (its
            ``diagnostics`` give file, line, column, message and help for each).
    """
    if not isinstance(name_or_path, (str, bytes)) and not hasattr(name_or_path, "__fspath__"):
        raise TypeError(f"load takes a model's name or a path, got {type(name_or_path).__name__}")
    import os

    return Model(_eomgen._Model.load(os.fsdecode(name_or_path)))


def bundled_models() -> List[str]:
    """The names of the bundled models (``eomgen list``)."""
    return list(_eomgen.bundled_models())


def expm_study(n: int = 10, seed: int = 32, t: float = 5.0, samples: int = 21, tol: float = 1e-13,
               matrix: Optional[ArrayLike] = None, z0: Optional[ArrayLike] = None,
               times: Optional[ArrayLike] = None) -> dict:
    """``ż = A z`` solved three ways — ``e^{At} z₀``, the superposition of the complex
    eigenvector solutions and DOP853 at ``tol`` — with the eigenvalues, the condition number
    of the eigenvector matrix and the largest differences between the routes against their
    bounds (``eomgen study expm``; HW32, lectures 30–33). ``A`` is random ``n × n`` with
    entries N(0, 1)/√n (SplitMix64 from ``seed``, the same numbers on every platform), or
    ``matrix`` (``(n, n)``); ``z₀`` the seed's unit vector, or ``z0``; times ``samples``
    evenly spaced on ``[0, t]`` (s), or ``times``. Returns the ``--json`` report with numeric
    lists as numpy arrays; ``differences``' ``passed`` flags say whether the routes agreed
    (the command line exits 1 otherwise).

    Raises:
        AnalysisError: a size out of 1 … 150, a matrix that is not square or not finite, a
            bad tolerance, end time or times, a zero solution.
        ValueError: a matrix that is not square (``z0`` or ``times`` given).
    """
    rows = None if matrix is None else [[float(v) for v in row] for row in np.atleast_2d(np.asarray(matrix, dtype=float))]
    return _eomgen.study_expm(int(n), int(seed), float(t), int(samples), float(tol), rows,
                              _floats(z0), _floats(times))


def reduce(model: Union[str, "Model"], keep: Union[str, Sequence[str]],
           branches: Optional[Mapping[str, str]] = None, initial: Optional[Mapping[str, Union[str, float]]] = None,
           name: Optional[str] = None) -> "Reduction":
    """A model with its holonomic constraints solved for the dependent coordinates and
    substituted, written as a model file in minimal coordinates (``eomgen reduce``; method
    II.2 of lectures 8–10, HW13).

    Args:
        model: a :class:`Model`, a bundled model's name, the path of a model file, or a model
            file's text (YAML, with a newline).
        keep: the coordinates to keep (one name or several); the others are eliminated, one
            per holonomic constraint.
        branches: the branch of a quadratic solution by eliminated coordinate
            (``{"y": "-"}``; default the one the initial state lies on).
        initial: new initial values of kept coordinates or rates (``{"x": "l/2"}``, numbers
            or expressions of the parameters).
        name: the reduced model's name (default ``<name>_in_<kept coordinates>``).

    Returns:
        a :class:`Reduction`: the reduced file's ``text``, the ``summary`` as
        ``eomgen reduce --json`` prints it, and :meth:`Reduction.load`.

    Raises:
        ModelError: a model that cannot be opened, or a text with mistakes.
        ValueError: an unknown coordinate to keep, the wrong number of them, an unused
            branch, a bad initial value.
        AnalysisError: a model that cannot be reduced (no holonomic constraints, a constraint
            that cannot be solved, a start where the reduction is singular).
    """
    if isinstance(model, Model):
        path, text = model.path, model.text
    elif isinstance(model, str) and "\n" in model:
        path, text = "<text>", model
    else:
        opened = load(model)
        path, text = opened.path, opened.text
    keep = [keep] if isinstance(keep, str) else [str(k) for k in keep]
    summary = _eomgen.reduce_model(
        path, text, keep, [(str(k), str(v)) for k, v in (branches or {}).items()],
        [(str(k), str(v)) for k, v in (initial or {}).items()], name)
    return Reduction(summary)


class Reduction:
    """A model file in minimal coordinates from :func:`reduce`.

    Attributes:
        text: the reduced model file's YAML text.
        kept: the coordinates kept.
        eliminations: one dict per eliminated coordinate (its solution, rate, constraint,
            degree and branch).
        notes: what of the original file was left out or changed.
        summary: the report as ``eomgen reduce --json`` prints it.
    """

    def __init__(self, summary: dict):
        self.summary = summary
        self.text = summary["text"]
        self.kept = list(summary["kept"])
        self.eliminations = summary["eliminations"]
        self.notes = summary["notes"]

    def load(self) -> "Model":
        """The reduced model, compiled (as :func:`eomgen.load` on its file)."""
        import re

        found = re.search(r"^name:\s*(\S+)", self.text, re.MULTILINE)
        return _restore(f"{found.group(1) if found else 'reduced'}.yaml", self.text, [])

    def save(self, path: str) -> None:
        """Writes the reduced model file to ``path`` (UTF-8)."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.text)

    def __str__(self) -> str:
        return self.text

    def __repr__(self) -> str:
        return f"eomgen.Reduction(keeping {', '.join(self.kept)}; {len(self.text)} characters)"


def _restore(argument: str, text: str, overrides: List[Tuple[str, float]]) -> "Model":
    """Rebuilds a pickled model from its file's text and parameter values."""
    return Model(_eomgen._Model.restore(argument, text, overrides))


class Model:
    """A model of a mechanism with its equations compiled, and parameter values of its own.

    Open one with :func:`eomgen.load`. A model is immutable: :meth:`with_parameters` returns
    a copy. It pickles by its file's text and its parameter values, so that
    ``concurrent.futures``, multiprocessing, Dask and Ray can send it to other processes
    (the file is compiled again there, once per process).

    Units are those of the model file (SI unless it says otherwise); angles are in rad,
    frequencies in rad/s unless the name ends in ``_hz``.
    """

    __slots__ = ("_core",)

    def __init__(self, core: "_eomgen._Model"):
        self._core = core

    # --- what the model is -----------------------------------------------------------

    @property
    def name(self) -> str:
        """The model's ``name``."""
        return self._core.name

    @property
    def path(self) -> str:
        """The model file as messages name it (``models/<file>`` for a bundled model)."""
        return self._core.path

    @property
    def text(self) -> str:
        """The model file's text."""
        return self._core.text

    @property
    def coordinates(self) -> List[str]:
        """The generalized coordinates' names ``q``, in the state's order (``n`` names)."""
        return list(self._core.coordinates)

    @property
    def speeds(self) -> List[str]:
        """The generalized speeds' names ``u`` (the file's ``speeds:``; ``n`` names), empty for a
        model in the coordinates' rates. With speeds the state is ``y = [q; u]``."""
        return list(self._core.speeds)

    @property
    def state_names(self) -> List[str]:
        """The names of the state's ``2n`` entries: the coordinates, then their rates
        (``x_dot``) or, with generalized speeds, the speeds."""
        return list(self._core.state_names)

    @property
    def parameters(self) -> Dict[str, float]:
        """Every parameter's value, by name, in the file's order (this model's values)."""
        return dict(self._core.parameters)

    @property
    def num_dofs(self) -> int:
        """The number of degrees of freedom ``n`` (coordinates)."""
        return self._core.num_dofs

    def description(self) -> dict:
        """The model's description: names, default parameters, points, constraints,
        equilibria, events, drawing and the equations as text."""
        return self._core.description()

    def with_parameters(self, values: Optional[Mapping[str, float]] = None, **kwargs: float) -> "Model":
        """A copy of this model with parameters set: ``m.with_parameters(g=9.81)`` or
        ``m.with_parameters({"g": 9.81})``.

        Raises:
            ParameterError: a name the model does not have, or a value that is not finite.
        """
        merged = dict(values or {})
        merged.update(kwargs)
        return Model(self._core.with_parameters([(str(k), float(v)) for k, v in merged.items()]))

    def initial_state(self, initial: Optional[Union[Mapping[str, float], ArrayLike]] = None) -> np.ndarray:
        """The state ``y0 = [q; q̇]`` (``2n``; ``[q; u]`` with generalized speeds) a simulation
        starts from: the file's ``initial:``, with ``initial`` applied — a dict of coordinates
        and rates (``{"theta1": 0.5, "theta1_dot": 0.0}``; the speeds by name with speeds) or a
        whole state of ``2n`` entries.

        Raises:
            ValueError: a name that is neither a coordinate nor a rate ``<coordinate>_dot``,
                a value that is not a finite number, or a state of the wrong length.
        """
        y0 = np.array(self._core.initial_state(), dtype=float)
        if initial is None:
            return y0
        if isinstance(initial, Mapping):
            names = self.coordinates
            states = self.state_names
            index = {c: i for i, c in enumerate(states)}
            for key, value in initial.items():
                if key not in index:
                    second = ", ".join(states[len(names):]) if self.speeds else "<coordinate>_dot"
                    raise ValueError(
                        f"`{key}` is not a coordinate or rate of `{self.name}` "
                        f"(coordinates: {', '.join(names)}; {'speeds' if self.speeds else 'rates'}: {second})"
                    )
                y0[index[key]] = _finite(value, f"initial `{key}`")
            return y0
        y = np.asarray(initial, dtype=float).reshape(-1)
        if y.shape != y0.shape:
            raise ValueError(f"the initial state must have {y0.size} entries ([q; q̇]), got {y.size}")
        bad = np.flatnonzero(~np.isfinite(y))
        if bad.size:
            raise ValueError(f"the initial state must be finite; entry {bad[0]} is {y[bad[0]]}")
        return y

    # --- simulation --------------------------------------------------------------------

    def simulate(
        self,
        t_end: float = DEFAULT_T_END,
        t_out: Optional[ArrayLike] = None,
        method: str = DEFAULT_METHOD,
        rtol: float = DEFAULT_RTOL,
        atol: float = DEFAULT_ATOL,
        dt: Optional[float] = None,
        initial: Optional[Union[Mapping[str, float], ArrayLike]] = None,
        stabilization: str = "none",
        baumgarte: Tuple[float, float] = DEFAULT_BAUMGARTE,
        stop_when: Iterable[str] = (),
        events: Iterable[str] = (),
    ) -> "Solution":
        """Integrates the model from its initial state to ``t_end`` (``eomgen simulate``).

        Args:
            t_end: end time (s).
            t_out: output times (s), ascending in ``[0, t_end]``; samples come from dense
                output at exactly these times. ``None``: every accepted step.
            method: one of :data:`METHODS` (default ``dp54``, Dormand–Prince 5(4)).
            rtol, atol: tolerances of the adaptive methods (defaults 1e-8, 1e-10).
            dt: the step of a fixed-step method (default ``t_end/1000``); the first step of
                an adaptive one (default automatic).
            initial: coordinates and rates to change (see :meth:`initial_state`), or a whole
                state ``[q; q̇]``. A constrained model's state is made consistent first.
            stabilization: drift control of a constrained model: ``none``, ``baumgarte``
                (gains ``baumgarte = (alpha, beta)``, 1/s) or ``projection``.
            stop_when: event functions that stop the run at their first zero: a model
                event's name or an expression ``"theta_dot = 0, falling"``.
            events: event functions located without stopping (same syntax).

        Returns:
            a :class:`Solution`: ``t`` (k,), ``q`` and ``qdot`` (k, n), ``energy`` (k,),
            ``stats``, ``events``.

        Raises:
            IntegrationError: the integration stopped early (``t``, ``reason``, and the
                samples before it in ``solution``).
            AnalysisError: no state consistent with the constraints.
            ValueError: an unknown method, a bad tolerance, end time or output times, an
                event expression that does not parse.
        """
        args = self._run_args(t_end, method, rtol, atol, dt, initial, stabilization, baumgarte, stop_when, events)
        result = self._core.simulate(args, t_out)
        solution = Solution(result, self.num_dofs)
        if solution._failure is not None:
            self._raise_failure(solution, f"the {len(solution.t)} samples computed before it were kept")
        return solution

    def _run_args(self, t_end, method, rtol, atol, dt, initial, stabilization, baumgarte, stop_when, events) -> dict:
        """One simulation's options as the library takes them (``simulate``, ``animate``)."""
        return {
            "t_end": float(t_end),
            "method": str(method),
            "rtol": float(rtol),
            "atol": float(atol),
            "dt": None if dt is None else float(dt),
            "initial_state": None if initial is None else self.initial_state(initial).tolist(),
            "stabilization": str(stabilization),
            "baumgarte": _gains(baumgarte),
            "stop_when": [str(s) for s in stop_when],
            "events": [str(s) for s in events],
        }

    def _raise_failure(self, solution: "Solution", kept: str, animation: Optional["Animation"] = None) -> None:
        """Raises the failure of `solution`'s run, if it stopped early: `IntegrationError`
        (`ValueError` for options refused before the first step)."""
        failure = solution._failure
        if failure is None:
            return
        t = failure.get("t")
        reason = failure["message"]
        if t is None:
            raise ValueError(reason)
        at = "" if "t = " in reason else f" at t = {t}"
        message = f"integration of `{self.name}` stopped: {reason}{at}; {kept}"
        if solution.cause is not None:
            message += f"\n{solution.cause}"
        raise IntegrationError(message, t, reason, solution, animation)

    def animate(
        self,
        t_end: float = DEFAULT_T_END,
        fps: Optional[float] = None,
        trace: Iterable[str] = (),
        method: str = DEFAULT_METHOD,
        rtol: float = DEFAULT_RTOL,
        atol: float = DEFAULT_ATOL,
        dt: Optional[float] = None,
        initial: Optional[Union[Mapping[str, float], ArrayLike]] = None,
        stabilization: str = "none",
        baumgarte: Tuple[float, float] = DEFAULT_BAUMGARTE,
        stop_when: Iterable[str] = (),
        events: Iterable[str] = (),
    ) -> "Animation":
        """Simulates the model and animates its ``draw:`` lines (``eomgen animate``): the
        same self-contained HTML page, frames at ``t = k / fps`` (default 30 frames per
        second of simulated time) from the integrator's dense
        output, the paths of the ``trace`` points (default: the file's ``draw: trace``), the
        energy drift over the frames. Shown inline in Jupyter; ``.save(path)`` writes the
        page. The other arguments are :meth:`simulate`'s.

        Raises:
            IntegrationError: the integration stopped early; its ``animation`` holds the
                frames computed before it.
            AnalysisError: a model with nothing to draw.
            ValueError: a bad ``fps``, an unknown trace point, options :meth:`simulate`
                refuses.
        """
        args = self._run_args(t_end, method, rtol, atol, dt, initial, stabilization, baumgarte, stop_when, events)
        page, result = _eomgen.animate_simulation(self._core, args, None if fps is None else float(fps),
                                                  [str(p) for p in trace])
        animation = None if page is None else Animation(page)
        solution = Solution(result, self.num_dofs)
        frames = "no frame was computed" if animation is None else "the frames computed before it are in the animation"
        self._raise_failure(solution, frames, animation)
        return animation

    def animate_modes(self, at: Optional[Union[str, Mapping[str, float], ArrayLike]] = None, t: float = 0.0) -> "Animation":
        """The normal modes at an equilibrium moving, ``q* + s ψₖ sin(ωₖ t)``, one clip per
        mode with a selector (``eomgen modes --animate``); ``at`` and ``t`` as in
        :meth:`modes`.

        Raises:
            AnalysisError: no equilibrium found, a steady motion, a model with nothing to draw.
        """
        at, label = self._operating_point(at)
        return Animation(_eomgen.animate_modes(self._core, at, label, float(t)))

    def simulate_many(
        self,
        initial_states: Optional[ArrayLike] = None,
        parameters: Optional[Union[Sequence[Mapping[str, float]], Mapping[str, ArrayLike]]] = None,
        t_end: float = DEFAULT_T_END,
        t_out: Optional[ArrayLike] = None,
        method: str = DEFAULT_METHOD,
        rtol: float = DEFAULT_RTOL,
        atol: float = DEFAULT_ATOL,
        dt: Optional[float] = None,
        stabilization: str = "none",
        baumgarte: Tuple[float, float] = DEFAULT_BAUMGARTE,
        threads: Optional[int] = None,
        errors: str = "raise",
    ) -> "Batch":
        """Runs a batch of simulations across the machine's cores and stacks the results:
        the building block of a sweep. Each run is the same computation as
        :meth:`simulate` on its own model instance, so the results equal the serial loop's
        bit for bit, whatever the number of threads.

        Args:
            initial_states: ``(b, 2n)`` states ``[q; q̇]``, one row per run (``None``: the
                file's initial state for every run).
            parameters: one dict of parameter values per run, or a dict of arrays
                (``{"l1": [1.0, 1.1, ...]}``), each of length ``b`` (``None``: this
                model's values).
            t_end, method, rtol, atol, dt, stabilization, baumgarte: as :meth:`simulate`.
            t_out: output times (default ``[t_end]``: the final state).
            threads: worker threads (default: one per core; ``1`` inside a Dask or
                multiprocessing worker that already has one process per core).
            errors: ``"raise"`` raises for the first run that failed
                (:class:`IntegrationError`, or :class:`AnalysisError` for an initial state
                the constraints cannot accept); ``"keep"`` returns the batch with
                ``ok[i] = False`` for those runs (``failures`` says where and why).

        A run ends at ``t_end``, at a terminal event of the model file (``stopped_by_event``
        says which and when; ``ok`` stays true), or at a failure. Samples after a run's end
        are NaN; ``t_final`` is the time each run reached.

        Returns:
            a :class:`Batch`: ``t`` (k,), ``y`` (b, k, 2n), ``q``, ``qdot`` (b, k, n),
            ``energy`` (b, k), ``ok``, ``t_final`` (b,), ``failures``, ``stopped_by_event``,
            ``stats``.

        Raises:
            ValueError: options every run shares that are refused (an unknown method, output
                times outside ``[0, t_end]``, a bad tolerance), ``initial_states`` of the
                wrong shape, parameter columns of different lengths, ``threads < 1``.
            ParameterError: a parameter the model does not have.
        """
        if errors not in ("raise", "keep"):
            raise ValueError(f"errors must be `raise` or `keep`, got `{errors}`")
        states = None
        if initial_states is not None:
            states = np.ascontiguousarray(np.atleast_2d(np.asarray(initial_states, dtype=float)))
            if states.ndim != 2:
                raise ValueError(f"initial_states must be a (b, 2n) array, got shape {states.shape}")
        sets = parameter_sets(parameters)
        if sets is not None:
            sets = [[(str(k), float(v)) for k, v in p.items()] for p in sets]
        times = [float(t_end)] if t_out is None else [float(t) for t in np.atleast_1d(t_out)]
        result = _eomgen.simulate_many(
            self._core,
            states,
            sets,
            float(t_end),
            times,
            str(method),
            float(rtol),
            float(atol),
            None if dt is None else float(dt),
            str(stabilization),
            _gains(baumgarte),
            None if threads is None else int(threads),
            errors == "keep",
        )
        batch = Batch(result, self.num_dofs)
        if errors == "raise" and batch.failures:
            index, t, reason = batch.failures[0]
            raise IntegrationError(
                f"integration of `{self.name}` stopped in run {index} of {len(batch.ok)}: {reason}"
                f" ({len(batch.failures)} run(s) failed; errors='keep' returns the batch)",
                None if math.isnan(t) else t,
                reason,
                batch,
            )
        return batch

    # --- linearisation and modes ----------------------------------------------------------

    def modes(self, at: Optional[Union[str, Mapping[str, float], ArrayLike]] = None, t: float = 0.0) -> Union["Modes", "SteadyMotion"]:
        """Normal modes about an operating point (``eomgen modes``): the equilibrium found
        by Newton's method, the exact linearisation ``M δq̈ + C δq̇ + K δq = 0`` there, the
        natural frequencies and mass-normalised mode shapes, the eigenvalues of the whole
        state matrix and the stability verdict from them.

        Args:
            at: where Newton starts: a name from the file's ``equilibria:`` (``"hanging"``,
                ``"upright"``), coordinates as a dict (others 0) or ``n`` values. Default:
                the file's first equilibrium, else ``q = 0``. A named steady motion (rates
                held, a bicycle at speed) or a non-holonomic model gives a
                :class:`SteadyMotion`.
            t: the time (s) of the equilibrium equations.

        Raises:
            AnalysisError: no equilibrium found, or a model whose equations change with
                ``t`` in ``M``, ``C`` or ``K``.
        """
        at, label = self._operating_point(at)
        kind, summary = self._core.modes(at, label, _finite(t, "t"))
        if kind == "steady":
            return SteadyMotion(summary)
        return Modes(summary)

    def state_space(self, inputs: Union[str, Sequence[str]], outputs: Sequence[str] = (),
                    at: Optional[Union[str, Mapping[str, float], ArrayLike]] = None) -> dict:
        """The linearisation about an equilibrium as a state-space model
        ``δẏ = A δy + B u``, ``z = C δy + D u`` (``y = [q; q̇]``), as ``eomgen modes --input
        … --output … --json`` gives it: a dict with ``states``, ``inputs``, ``outputs``,
        ``equilibrium`` and the NumPy arrays ``a`` (``2n × 2n``), ``b`` (``2n × r``), ``c``
        (``o × 2n``) and ``d`` (``o × r``, zero).

        Args:
            inputs: parameters that enter the forcing linearly (load amplitudes, read at
                ``t = 0``), or coordinates' names (a unit generalized force on each).
            outputs: coordinates, or rates ``NAME_dot`` (default: every coordinate).
            at: where Newton starts, as for :meth:`modes`; the equilibrium is found with
                the inputs at 0.

        Raises:
            AnalysisError: no equilibrium, a constrained model, an input that is not a
                load amplitude, an unknown output.
        """
        inputs = [inputs] if isinstance(inputs, str) else [str(i) for i in inputs]
        at, label = self._operating_point(at)
        result = self._core.state_space(at, label, inputs, [str(o) for o in outputs])
        for key in ("a", "b", "c", "d"):
            result[key] = np.array(result[key], dtype=float).reshape(len(result[key]), -1)
        return result

    def _operating_point(self, at):
        """`at` for the library: a name, or coordinates (a dict's, others 0) with a label."""
        if isinstance(at, Mapping):
            q = np.zeros(self.num_dofs)
            names = self.coordinates
            for key, value in at.items():
                if key not in names:
                    raise ValueError(f"`{key}` is not a coordinate of `{self.name}` (coordinates: {', '.join(names)})")
                q[names.index(key)] = _finite(value, f"`{key}`")
            return q.tolist(), ",".join(f"{k}={v}" for k, v in at.items())
        return _at(at), None

    # --- derivations --------------------------------------------------------------------

    def check(self, states: Optional[int] = None, timing: bool = False) -> dict:
        """Derives the model two ways (Lagrange and momentum balance, and the file's own
        balances) and compares ``q̈`` at ``states`` random states (default 200, as
        ``eomgen check``): the dict
        ``eomgen check --json`` prints (``passed``, ``checks``, ``power_balance``, …;
        with ``timing``, the derivation times too). Its ``passed`` is ``False`` when a check
        failed or nothing was compared.

        Raises:
            ModelError: a file that does not derive.
        """
        if states is None:
            _passed, summary = self._core.check(timing=bool(timing))
        else:
            _passed, summary = self._core.check(int(states), bool(timing))
        return summary

    def equations(self, latex: bool = False, method: str = "lagrange") -> "Equations":
        """The equations of motion ``M(q) q̈ = F(q, q̇, t)`` (with ``T``, ``V``, ``Q`` and
        each constraint), derived by ``method`` (``lagrange`` or ``momentum``), as text
        (``eomgen equations``) or, with ``latex``, as LaTeX. The string shows as LaTeX in
        Jupyter; ``.listing`` is the dict of ``eomgen equations --json``."""
        listing, text, latex_document = self._core.equations(str(method))
        return Equations(latex_document if latex else text, latex_document, listing)

    def kinematics(self, frames=None, points=None, partial: bool = False, reactions=None) -> dict:
        """The kinematics of the model's frames and points, as ``eomgen kinematics --json``
        gives it: for each frame ``F`` (default: every frame of the file's ``frames:``) its
        angular velocity ``^N ω^F`` in its own components (``"angular_velocity"``, rad/s,
        SymPy's ``F.ang_vel_in(N)``) and in the ground's (``"angular_velocity_ground"``) and
        its angular acceleration in its own components; for each point ``P`` (default: every
        point) its position, velocity ``^N v_P`` (``P.vel(N)``) and acceleration in the
        ground's components; with ``partial``, the partial velocities ``∂v/∂q̇ᵢ`` and
        ``∂ω/∂q̇ᵢ`` per coordinate. Each component is an expression string in the model
        file's syntax (``x_dot``, ``x_ddot``, ``^`` for powers), ``"latex"`` holds the same
        in LaTeX, and ``"text"`` the listing as the command line prints it.

        ``reactions`` lists ``(bodies, point)`` pairs (``bodies`` a name or a list of names) or
        ``"BODY@POINT"`` strings (``"a+b@O"`` for two bodies):
        for each, ``"reactions"`` gives the force ``R = Σ m a_G − Σ m g`` and the moment about
        the point that act on those bodies besides gravity and their own torques — the
        reaction of a pivot the model leaves implicit — as expressions of ``q``, ``q̇`` and
        ``q̈`` (``eomgen kinematics --reaction BODY@POINT``).

        Raises ``ValueError`` for a frame, point or body the file does not have, or a reaction
        of a model whose forces, springs or dampers act at points rather than on bodies."""
        pairs = []
        for r in reactions or []:
            if isinstance(r, str):
                bodies, sep, at = r.partition("@")
                if not sep or not bodies or not at:
                    raise ValueError(f"reaction {r!r}: write it as 'BODY@POINT' or ('BODY', 'POINT')")
                pairs.append((bodies.split("+"), at))
            else:
                bodies, at = r
                pairs.append(([bodies] if isinstance(bodies, str) else [str(x) for x in bodies], str(at)))
        listing, text, _ = self._core.kinematics(
            [str(f) for f in (frames or [])], [str(p) for p in (points or [])], bool(partial), pairs)
        listing["text"] = text
        return listing

    def export(self, language: str) -> str:
        """The equations as source code for another tool: ``language`` is ``"c"`` (C99),
        ``"matlab"`` (a MATLAB/Octave function file, saved as ``NAME.m``) or ``"python"``
        (a NumPy module), as ``eomgen equations --c`` (``--matlab``, ``--python``) prints
        them: ``M`` and ``F``, the right-hand side, the exact Jacobians, ``T``, ``V``, the
        points and the constraints as functions of ``(t, q, qd, p)``, with this model's
        parameter values (the file's, or those set by :meth:`with_parameters`) as the
        defaults. For example, ``namespace = {}; exec(m.export("python"),
        namespace); namespace["rhs"](0.0, namespace["initial_state"]())``."""
        return self._core.export(str(language))

    # --- evaluations for users' own solvers --------------------------------------------------

    def rhs(self, t: float, y: ArrayLike) -> np.ndarray:
        """The right-hand side ``ẏ = f(t, y)`` of the first-order form, ``y = [q; q̇]``
        (``2n`` in, ``2n`` out): ``q̈`` from ``M q̈ = F`` (with constraints, the KKT
        system). For SciPy's ``solve_ivp(m.rhs, ...)`` and other solvers."""
        return self._core.rhs(float(t), np.ascontiguousarray(y, dtype=float))

    def mass_matrix(self, q: ArrayLike, t: float = 0.0) -> np.ndarray:
        """The mass matrix ``M(q, t)`` (``n × n``, symmetric positive definite)."""
        q = np.ascontiguousarray(q, dtype=float)
        mass, _ = self._core.mass_matrix_and_forcing(q, np.zeros_like(q), float(t))
        return mass

    def forcing(self, q: ArrayLike, qdot: ArrayLike, t: float = 0.0) -> np.ndarray:
        """The forcing ``F(q, q̇, t)`` (``n``) of ``M q̈ = F``: generalized forces, gravity,
        springs, velocity-product terms."""
        _, forcing = self._core.mass_matrix_and_forcing(
            np.ascontiguousarray(q, dtype=float), np.ascontiguousarray(qdot, dtype=float), float(t)
        )
        return forcing

    def energy(self, y: ArrayLike, t: float = 0.0) -> Tuple[float, float]:
        """The kinetic and potential energies ``(T, V)`` (J) at the state ``y = [q; q̇]``."""
        return self._core.energies(float(t), np.ascontiguousarray(y, dtype=float))

    # --- studies -------------------------------------------------------------------------

    def work_precision(self, methods: Optional[Sequence[str]] = None, tolerances: Optional[Sequence[float]] = None,
                       steps: Optional[Sequence[int]] = None, t_end: Optional[float] = None,
                       samples: Optional[int] = None, target_error: Optional[float] = None,
                       reference_tol: Optional[float] = None, repeats: Optional[int] = None,
                       min_time_s: Optional[float] = None) -> dict:
        """Error against work of integration methods (``eomgen study work-precision``):
        every method at every tolerance (adaptive) or step count (fixed step), its error
        against a DOP853 reference at ``samples`` output times over ``[0, t_end]``, RHS
        evaluations and median wall time; ``None`` arguments take the study's defaults.
        Returns the ``--json`` report with numeric lists as numpy arrays."""
        return _eomgen.study_work_precision(
            self._core, None if methods is None else list(methods),
            None if tolerances is None else [float(x) for x in tolerances],
            None if steps is None else [int(x) for x in steps],
            t_end, samples, target_error, reference_tol, repeats, min_time_s)

    def parameter_sweep(self, parameter: str, values: ArrayLike,
                        at: Optional[Union[str, ArrayLike]] = None, refine: bool = True,
                        steps: int = 1) -> dict:
        """The eigenvalues of an equilibrium or steady motion against one parameter
        (``eomgen study parameter-sweep``), with every stability change located by
        bisection (``stability_changes``). ``values`` ascending. For a model with a change
        of support (a walker), its gait of ``steps`` landings per period followed over the
        parameter from the initial state, with the return map's eigenvalues and each change
        of stability named (``period_doubling``, ``fold``, ``neimark_sacker``; always
        bisected, ``refine`` and ``at`` do not apply). Returns the ``--json`` report with
        numeric lists as numpy arrays.

        Raises:
            ParameterError: an unknown parameter.
            AnalysisError: no value of the sweep could be analysed.
        """
        return _eomgen.study_parameter_sweep(
            self._core, str(parameter), [float(v) for v in np.atleast_1d(values)], _at(at), bool(refine),
            int(steps))

    def frf(self, input: str, outputs: Sequence[str] = (), frequency_range: Optional[Tuple[float, float]] = None,
            points: Optional[int] = None, frequencies: Sequence[float] = (), modal: bool = False,
            at: Optional[Union[str, ArrayLike]] = None) -> dict:
        """The frequency response ``H(ω)`` about an equilibrium (``eomgen frf``) to a
        harmonic ``input`` (a load parameter that enters the forcing linearly, or a
        coordinate's name for a unit generalized force on it), on ``points`` log-spaced
        frequencies (rad/s; default 400) in ``frequency_range`` (default: a decade around the
        natural frequencies), with the peaks, and at ``frequencies``. Returns the ``--json``
        report with numeric lists as numpy arrays."""
        return _eomgen.study_frf(
            self._core, str(input), [str(o) for o in outputs],
            None if frequency_range is None else (float(frequency_range[0]), float(frequency_range[1])),
            None if points is None else int(points), [float(f) for f in frequencies], bool(modal), _at(at))

    def floquet(self, period_parameter: Optional[str] = None, at: Optional[Union[str, ArrayLike]] = None,
                rtol: Optional[float] = None, atol: Optional[float] = None,
                stability_tolerance: Optional[float] = None) -> dict:
        """The Floquet analysis of a periodically forced model about its equilibrium
        (``eomgen study floquet``): the monodromy matrix over one period ``T = 2π/w`` of the
        forcing frequency parameter ``period_parameter`` (default ``w``), integrated with its
        variational equations by DOP853 at ``rtol``/``atol`` (default 1e-12), its multipliers
        ``μ`` and exponents, the spectral radius and the verdict (``|μ| ≤ 1`` within
        ``stability_tolerance``, default 1e-6). Returns the ``--json`` report with numeric
        lists as numpy arrays.

        Raises:
            AnalysisError: an unknown period parameter, a model that does not depend on
                ``t``, no equilibrium that stays one over the period.
        """
        return _eomgen.study_floquet(self._core, period_parameter, _at(at), rtol, atol, stability_tolerance)

    def free_response(self, at: Optional[Union[str, ArrayLike]] = None, dq0: Optional[ArrayLike] = None,
                      dqdot0: Optional[ArrayLike] = None, t_end: Optional[float] = None,
                      samples: Optional[int] = None, tol: Optional[float] = None) -> dict:
        """The free response about an equilibrium from a deviation ``(dq0, dqdot0)`` (default
        0.1 in every coordinate, at rest), four ways: superposed normal modes, ``e^{At}``,
        the linearised and the nonlinear equations integrated by DOP853 at ``tol`` (default
        1e-13), on ``samples`` times (default 401) over ``[0, t_end]`` (default: four
        periods of the slowest mode)
        (``eomgen study free-response``; HW28). Returns the ``--json`` report with numeric
        lists as numpy arrays."""
        return _eomgen.study_free_response(self._core, _at(at), _floats(dq0), _floats(dqdot0), t_end,
                                           samples, tol)

    def modal_damping(self, at: Optional[Union[str, ArrayLike]] = None,
                      rayleigh_modes: Optional[Tuple[int, int]] = None, dq0: Optional[ArrayLike] = None,
                      dqdot0: Optional[ArrayLike] = None, t_end: Optional[float] = None,
                      samples: Optional[int] = None, tol: Optional[float] = None) -> dict:
        """Modal damping against the exact damped response, and Rayleigh damping fitted to
        two modes (1-based ``rayleigh_modes``; default the slowest and fastest oscillatory
        ones), checked on ``samples`` times (default 801) by DOP853 at ``tol`` (default
        1e-12) (``eomgen study modal-damping``; HW34). Returns the ``--json`` report with
        numeric lists as numpy arrays."""
        modes = None if rayleigh_modes is None else (int(rayleigh_modes[0]), int(rayleigh_modes[1]))
        return _eomgen.study_modal_damping(self._core, _at(at), modes, _floats(dq0), _floats(dqdot0), t_end,
                                           samples, tol)

    def constraint_methods(self, t_end: Optional[float] = None, tol: Optional[float] = None,
                           stiffness: Optional[Sequence[float]] = None) -> dict:
        """Lectures 8–10's constraint methods compared on a model with holonomic
        constraints (``eomgen study constraint-methods``): the constraint replaced by a stiff
        spring of each ``stiffness`` (method I; default 1e2, 1e4, 1e6), the Lagrange
        multipliers with and without drift control, the constraints eliminated
        symbolically (method II.2, as :func:`eomgen.reduce`, where they can be) and the model
        file's ``minimal_twin:`` in minimal coordinates, each against a reference over
        ``[0, t_end]`` (default 10 s) at ``tol`` (default 1e-8). This model's parameter
        values are set on the twin too where it has them. Returns the ``--json`` report with
        numeric lists as numpy arrays.

        Raises:
            AnalysisError: a model without holonomic constraints, options the study refuses.
        """
        return _eomgen.study_constraint_methods(self._core, t_end, tol,
                                                None if stiffness is None else [float(k) for k in stiffness])

    def rayleigh(self, shape: Union[str, ArrayLike], at: Optional[Union[str, ArrayLike]] = None,
                 perturbations: Optional[ArrayLike] = None) -> dict:
        """The Rayleigh quotient ``R(v) = vᵀKv / vᵀMv`` of a trial shape ``v`` at an
        equilibrium (``eomgen study rayleigh``; lectures 35–37): ``√R`` against the exact
        lowest natural frequency ``ω₁`` (rad/s), the bound ``R ≥ ω₁²`` (``bound_holds``), the
        modal participation and the stationarity of ``R`` at ``ψ₁ + ε w`` for each
        ``perturbations`` ``ε`` (default 1e-1 … 1e-3). ``shape``: one number per coordinate
        (``n``, any scale), or the command line's text — entries comma separated
        (``"1,sqrt(2),1"``) or one expression of the 1-based index ``i`` and ``n``
        (``"sin(pi*i/(n+1))"``), with the parameters. Returns the ``--json`` report with
        numeric lists as numpy arrays.

        Raises:
            AnalysisError: no equilibrium, a shape of the wrong length, zero or not finite,
                a constrained or unstable model.
            ValueError: a shape text that does not parse or names something unknown.
        """
        if not isinstance(shape, str):
            shape = _floats(shape)
        return _eomgen.study_rayleigh(self._core, shape, _at(at), _floats(perturbations))

    def convolution(self, input: str, forcing: Union[str, Callable[[float], float]],
                    at: Optional[Union[str, ArrayLike]] = None, t_end: Optional[float] = None,
                    intervals: Optional[int] = None, rtol: Optional[float] = None,
                    label: Optional[str] = None) -> dict:
        """The response of the model linearised at an equilibrium to a forcing ``f(t)``
        through one ``input`` (a load parameter such as ``A`` in ``A*cos(w*t)``, or a
        coordinate's name for a unit generalized force on it), by Duhamel's integral over the
        impulse response, against DOP853 on the same linear equations at ``rtol`` (default
        1e-12) and, for one degree of freedom, the closed form (``eomgen study convolution``;
        lecture 21). ``forcing``: ``"impulse"`` (the response is ``h``), ``"step"``, an
        expression of ``t`` (s) and the parameters (``"sin(2*t)"``, ``"step(t - 1)"``), or a
        Python function of ``t`` (called with the interpreter held; ``label`` names it in the
        report, default its ``__name__``). On ``intervals`` (default 2000) grid intervals of
        ``[0, t_end]`` (default: ten periods of the lowest natural frequency). Returns the
        ``--json`` report with numeric lists as numpy arrays (``times`` (k,), ``convolution``
        and ``direct`` (k, n)).

        Raises:
            AnalysisError: an unknown input or one that is not a load, no equilibrium,
                options out of range, a forcing that is not finite.
            ValueError: a forcing text that does not parse or names something unknown.
            Exception: the first exception a forcing function raised.
        """
        if not isinstance(forcing, str) and not callable(forcing):
            raise TypeError("forcing must be `impulse`, `step`, an expression of t, or a function of t")
        return _eomgen.study_convolution(self._core, str(input), forcing, _at(at),
                                         None if t_end is None else float(t_end),
                                         None if intervals is None else int(intervals),
                                         None if rtol is None else float(rtol), label)

    def launch(self, speeds: Optional[ArrayLike] = None, angle_parameter: Optional[str] = None,
               speed_parameter: Optional[str] = None, event: Optional[str] = None,
               range_coordinate: Optional[str] = None, height_coordinate: Optional[str] = None,
               angles: Optional[int] = None, angle_tol: Optional[float] = None, rtol: Optional[float] = None,
               t_max: Optional[float] = None, path_samples: Optional[int] = None,
               shape_angle: Optional[Union[float, str]] = math.pi / 4) -> dict:
        """For each launch speed (m/s; default the model's value of ``speed_parameter``,
        ``v0``), the range against the launch angle ``angle_parameter`` (default ``theta0``)
        on ``angles`` (default 89) angles inside (0°, 90°), the best angle ``θ*`` by
        golden-section search to ``angle_tol`` (default 1e-7 rad), the best path's apex and
        landing angle, and the path at ``shape_angle`` (rad, a number or an expression such
        as ``"pi/3"``; default π/4, ``None`` for none) (``eomgen study launch``; lecture 2,
        HW2). Flights end at the model event ``event`` (default ``ground``), integrated by
        DOP853 at ``rtol`` (default 1e-12) for at most ``t_max`` s. Returns the ``--json``
        report with numeric lists as numpy arrays.

        Raises:
            ParameterError: no angle or speed parameter of that name.
            AnalysisError: an unknown event or coordinate, a speed that is not positive, a
                flight that does not land.
        """
        if isinstance(shape_angle, (int, float)):
            shape_angle = float(shape_angle)
        return _eomgen.study_launch(
            self._core, [] if speeds is None else _floats(speeds), angle_parameter, speed_parameter, event,
            range_coordinate, height_coordinate, None if angles is None else int(angles),
            angle_tol, rtol, t_max, None if path_samples is None else int(path_samples), shape_angle)

    def periodic_orbit(self, guess: Optional[Union[Mapping[str, float], ArrayLike]] = None,
                       period: Optional[Union[float, str]] = None, fix_period: bool = False,
                       energy: Optional[Union[float, str]] = None, tol: Optional[float] = None,
                       max_iterations: Optional[int] = None, integration_tol: Optional[float] = None,
                       samples: Optional[int] = None,
                       unit_multiplier_tolerance: Optional[float] = None, steps: int = 1) -> dict:
        """A periodic orbit found by shooting (``eomgen study periodic-orbit``; HW5, HW7,
        HW39): Gauss–Newton on the flow map and its monodromy matrix with a phase condition
        and, with the period free in a conservative model, the energy fixed. Returns its
        period, initial state, residual, Newton iterations and Floquet multipliers, the
        ``--json`` report with numeric lists as numpy arrays.

        Args:
            guess: Newton's start: the model's initial state with these coordinates and rates
                changed (``{"x1": -0.971, "x3_dot": 0.933}``, see :meth:`initial_state`), or a
                whole state ``[q; q̇]``; default the initial state.
            period: the period (s) — the guess, or the period itself with ``fix_period`` — a
                number or an expression of the parameters; default the model file's
                ``checks:`` (``period:``, else the time of ``final_state:``).
            fix_period: keep the period fixed and solve for the start only.
            energy: the energy ``T + V`` (J) of the orbit sought with the period free: a
                number, an expression, or ``"start"`` for the guess's; default the energy of
                the model's initial state, so that ``guess`` moves Newton's start, not the
                orbit sought.
            tol: Newton's tolerance ``‖φ_T(y₀) − y₀‖ ≤ tol (1 + ‖y₀‖)`` (default 1e-10).
            max_iterations: most Newton iterations (default 30).
            integration_tol: DOP853's tolerance (default 1e-12).
            samples: samples of the orbit over one period (default 400).
            unit_multiplier_tolerance: ``|μ − 1|`` below which a multiplier is trivial
                (default 1e-3).
            steps: for a model with a change of support (a walker, a rimless wheel), the
                landings in one period of its gait (default 1). Such a model's gait is the
                fixed point of its return map from the state just after a landing, with the
                map's Jacobian from the variational equations and a saltation matrix at each
                landing, its ``eigenvalues``, ``floquet_multipliers`` and ``stability``;
                ``period``, ``fix_period``, ``energy``, ``integration_tol``, ``samples`` and
                ``unit_multiplier_tolerance`` do not apply (a ValueError).

        Raises:
            AnalysisError: Newton did not converge, a constrained model, a time-dependent
                model with the period free, options out of range.
            ValueError: no period given or in the file, a bad guess or expression.
        """
        start = None if guess is None else self.initial_state(guess).tolist()
        return _eomgen.study_periodic_orbit(
            self._core, start, period, bool(fix_period), energy, tol,
            None if max_iterations is None else int(max_iterations), integration_tol,
            None if samples is None else int(samples), unit_multiplier_tolerance, int(steps))

    def rolling_contact(self, after_lift_off: bool = False, flight: Optional[Union[str, "Model"]] = None,
                        mu: Optional[ArrayLike] = None, ground: Optional[str] = None,
                        normal: Optional[str] = None, angle: Optional[str] = None,
                        lift_off: Optional[str] = None, landing: Optional[str] = None,
                        samples: Optional[int] = None, t_end: Optional[float] = None,
                        rtol: Optional[float] = None) -> dict:
        """The friction coefficient ``μ(t) = |F_t|/N`` a body rolling on the ground needs, from
        its constraint forces up to the lift-off (event ``lift_off``), checked against
        Newton–Euler, with the first time ``μ(t)`` exceeds each of ``mu`` (default 0.2, 0.5,
        1) (``eomgen study rolling-contact``; HW36). With ``after_lift_off``, the free flight
        that follows, on the ``flight`` model (a :class:`Model` or a name; default this
        model's name with ``_flight``, with this model's parameter values where it has them),
        to its event ``landing``, checked against its closed forms. ``ground``, ``normal``,
        ``angle``: the coordinates (default ``x``, ``y``, ``theta``); ``samples`` per phase
        (default 2001), ``t_end`` the longest phase (s, default 10), DOP853 at ``rtol``
        (default 1e-12). Returns the ``--json`` report with numeric lists as numpy arrays;
        its checks' ``passed`` flags say whether they held (the command line exits 1
        otherwise).

        Raises:
            AnalysisError: an unknown coordinate or event, a model without constraints,
                options out of range, a failed integration.
            ModelError: no flight model of that name.
            ValueError: a ``flight`` without ``after_lift_off``.
        """
        flight_core = None
        if after_lift_off:
            if not isinstance(flight, Model):
                # As `--flight NAME --set …`: this model's values where the flight has them.
                flight = load(f"{self.name}_flight" if flight is None else flight)
                own = flight.parameters
                values = {k: v for k, v in self._core.overrides if k in own}
                if values:
                    flight = flight.with_parameters(values)
            flight_core = flight._core
        elif flight is not None:
            raise ValueError("flight is used with after_lift_off=True only")
        return _eomgen.study_rolling_contact(
            self._core, flight_core, _floats(mu), ground, normal, angle, lift_off, landing,
            None if samples is None else int(samples), t_end, rtol)

    # --- Python protocols --------------------------------------------------------------

    def __reduce__(self):
        argument, text, overrides = self._core.state()
        return (_restore, (argument, text, list(overrides)))

    def __repr__(self) -> str:
        changed = dict(self._core.overrides)
        extra = f", {changed}" if changed else ""
        return f"eomgen.Model({self.name!r} from {self.path!r}, {self.num_dofs} dof{extra})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Model):
            return NotImplemented
        return self._core.state() == other._core.state()

    def __hash__(self) -> int:
        argument, text, overrides = self._core.state()
        return hash((argument, text, tuple(overrides)))


def _html_table(headers: Sequence[str], rows: Iterable[Sequence[object]]) -> str:
    """An HTML table (cells escaped) for the rich displays of Jupyter."""
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in headers)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>"
                   for row in rows)
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _verdict(stability: Optional[dict]) -> str:
    """The stability verdict in words (``marginally stable``), or ``-``."""
    if not stability or "verdict" not in stability:
        return "-"
    return str(stability["verdict"]).replace("_", " ")


def _pyplot(what: str):
    """``matplotlib.pyplot``, or an ImportError that says how to get it."""
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError(f"{what} needs matplotlib: pip install matplotlib") from e
    return plt


class Solution:
    """The samples of one simulation, with its energy, work and events.

    Attributes:
        t: times (s), shape ``(k,)``.
        y: states ``[q; q̇]``, shape ``(k, 2n)``.
        q, qdot: coordinates and rates, ``(k, n)`` each (views of ``y``).
        energy: ``T + V`` (J) at every sample, ``(k,)``.
        stats: the integrator's work: ``steps``, ``rejected``, ``rhs_evals``,
            ``jacobian_evals``, ``lu_decompositions``, ``event_evals``, ``wall_time_s``.
        events: the located events, each ``{"name", "t", "direction", "terminal", "q",
            "qdot"}``.
        transitions: a model with contacts: each impact, closing, lift-off, stick or
            slip, in time order, ``{"t", "contact", "kind", "mode", "qdot", "normal_velocity",
            "normal_impulse", "tangential_impulse", "energy_lost", "sample"}``.
        contact_stop: why the run stopped at a contact before its end time, or ``None``.
        lagrange_multipliers: a constrained model's ``λ`` at every sample, ``(k, m)``
            (NaN rows where the constrained system is singular; ``None`` without
            constraints).
        constraint_drift: ``max |Φ|`` and ``max |Φ̇|`` at every sample, ``(k, 2)``.
        summary: the whole report as ``eomgen simulate --json`` prints it (built on first
            use).
    """

    def __init__(self, result: dict, num_dofs: int):
        # The summary's dicts are made at its first use (`summary_header`); the failure at once.
        self._header = None
        self._deferred_header = result["summary"]
        self._failure = result.get("error")
        self.t = result["t"]
        self.y = result["y"]
        self._num_dofs = num_dofs
        self.energy = result["energy"]
        self.lagrange_multipliers = result.get("lagrange_multipliers")
        self._solved = result.get("multipliers_solved")
        self.constraint_drift = result.get("constraint_drift")
        #: The wall time (s) of the library's simulation call alone (instance, integration,
        #: energy and drift measures), without the binding's conversions.
        self.library_time_s = result.get("library_time_s")
        #: What the model shows where a failed integration stopped (a mass matrix that is
        #: not positive definite, a forcing out of its domain), or ``None``.
        self.cause = result.get("cause")
        self._summary = None

    def __getstate__(self) -> dict:
        """Pickled with the summary's dicts (the deferred report is not picklable) and
        without the views of ``y``, which unpickling makes again."""
        state = dict(self.__dict__)
        state["_header"] = self.summary_header
        state["_deferred_header"] = None
        state.pop("q", None)
        state.pop("qdot", None)
        return state

    def __setstate__(self, state: dict) -> None:
        """Unpickles this version's state, or an earlier one's (its summary as
        ``summary_header``, ``q`` and ``qdot`` kept as arrays)."""
        if "_deferred_header" not in state:
            header = state.pop("summary_header")
            num_dofs = state["q"].shape[1]
            state = {k: v for k, v in state.items() if k not in ("q", "qdot")}
            state.update(_header=header, _deferred_header=None, _failure=header.get("error"),
                         _num_dofs=num_dofs)
        self.__dict__.update(state)

    @functools.cached_property
    def q(self) -> np.ndarray:
        """The coordinates, ``(k, n)`` (a view of ``y``)."""
        return self.y[:, :self._num_dofs]

    @functools.cached_property
    def qdot(self) -> np.ndarray:
        """The rates, ``(k, n)`` (a view of ``y``)."""
        return self.y[:, self._num_dofs:]

    @property
    def summary_header(self) -> dict:
        """The report as ``eomgen simulate --json`` prints it, without the samples."""
        if self._header is None:
            self._header = self._deferred_header()
        return self._header

    @property
    def stats(self) -> dict:
        """The integrator's work (see the class's attributes)."""
        return self.summary_header["stats"]

    @property
    def events(self) -> List[dict]:
        """The located events, in time order."""
        return self.summary_header.get("events") or []

    @property
    def transitions(self) -> List[dict]:
        """The transitions at the model's contacts (impacts, closings, lift-offs, sticks
        and slips), in time order; ``qdot`` is ``[before, after]``, ``sample`` the index of the first sample
        after it (the one before has the same time)."""
        return self.summary_header.get("transitions") or []

    @property
    def contact_stop(self) -> Optional[dict]:
        """Why the run stopped at a contact before its end time (``{"kind", …,
        "message"}``), or ``None``."""
        return self.summary_header.get("contact_stop")

    @property
    def energy_drift(self) -> Optional[float]:
        """``max |E − E(0)|`` over the samples, relative to ``max(T + |V|)``."""
        return self.summary_header["energy_drift"]

    @property
    def warnings(self) -> List[dict]:
        """Warnings about the settings or the result (a step past the stability limit, an
        energy that drifted on a conservative model)."""
        return self.summary_header.get("warnings", [])

    @property
    def summary(self) -> dict:
        """The report as ``eomgen simulate --json`` prints it, samples included."""
        if self._summary is None:
            summary = dict(self.summary_header)
            samples = []
            constrained = self.lagrange_multipliers is not None
            for k in range(len(self.t)):
                sample = {
                    "t": float(self.t[k]),
                    "q": self.q[k].tolist(),
                    "qdot": self.qdot[k].tolist(),
                    "energy": _json_number(self.energy[k]),
                }
                if constrained:
                    sample["constraint_forces"] = self.lagrange_multipliers[k].tolist() if self._solved[k] else None
                    sample["constraint_drift"] = {
                        "position": float(self.constraint_drift[k, 0]),
                        "velocity": float(self.constraint_drift[k, 1]),
                    }
                samples.append(sample)
            summary["samples"] = samples
            self._summary = summary
        return self._summary

    def __len__(self) -> int:
        return len(self.t)

    def _repr_html_(self) -> str:
        """The run's summary and its last state, for Jupyter."""
        h, stats = self.summary_header, self.stats
        k = len(self.t)
        lines = [
            f"<b>eomgen.Solution</b> of <code>{html.escape(str(h['model']))}</code> by "
            f"{html.escape(str(h.get('method', '-')))} (rtol {h.get('rtol', '-')}, atol {h.get('atol', '-')})",
            f"{k} samples, t = {self.t[0]:.6g} … {self.t[-1]:.6g} s" if k else "no samples",
            f"{stats.get('steps', 0)} steps ({stats.get('rejected', 0)} rejected), "
            f"{stats.get('rhs_evals', 0)} RHS evaluations, {stats.get('wall_time_s', 0) * 1e3:.3g} ms",
        ]
        if self.energy_drift is not None:
            lines.append(f"energy drift {self.energy_drift:.3e} (relative)")
        for w in self.warnings:
            lines.append(f"warning: {html.escape(str(w.get('message', w)))}")
        if self._failure:
            lines.append(f"<b>failed</b>: {html.escape(str(self._failure))}")
        table = ""
        if k:
            names = list(h.get("coordinates", [f"q{i}" for i in range(self._num_dofs)]))
            table = _html_table(["coordinate", f"q(t = {self.t[-1]:.6g})", "u" if h.get("speeds") else "q̇"],
                                ((c, f"{self.q[-1, i]:.10g}", f"{self.qdot[-1, i]:.10g}")
                                 for i, c in enumerate(names)))
        return "<br>".join(lines) + table

    def plot(self, coordinates: Optional[Sequence[str]] = None, rates: bool = False):
        """One panel per coordinate against ``t`` (and its rate with ``rates``), so that a
        large spin does not flatten a small nutation; needs matplotlib. Returns the
        figure.

        Args:
            coordinates: the coordinates to draw, by name (default: all).
            rates: also draw each coordinate's rate, in a second column.

        Raises:
            ValueError: a name that is not a coordinate. ImportError: no matplotlib.
        """
        plt = _pyplot("Solution.plot")
        names = list(self.summary_header["coordinates"])
        chosen = names if coordinates is None else [str(c) for c in coordinates]
        for c in chosen:
            if c not in names:
                raise ValueError(f"`{c}` is not a coordinate (coordinates: {', '.join(names)})")
        columns = 2 if rates else 1
        fig, axes = plt.subplots(len(chosen), columns, sharex=True, squeeze=False,
                                 figsize=(6.4 * columns, 1.8 * len(chosen) + 0.8))
        for row, c in enumerate(chosen):
            i = names.index(c)
            axes[row, 0].plot(self.t, self.q[:, i])
            axes[row, 0].set_ylabel(c)
            if rates:
                axes[row, 1].plot(self.t, self.qdot[:, i])
                speeds = self.summary_header.get("speeds")
                axes[row, 1].set_ylabel(speeds[i] if speeds else f"{c}_dot")
        for col in range(columns):
            axes[-1, col].set_xlabel("t (s)")
        fig.suptitle(str(self.summary_header["model"]))
        fig.tight_layout()
        return fig

    def __repr__(self) -> str:
        return (f"eomgen.Solution({self.summary_header['model']!r}, {len(self.t)} samples, "
                f"t = {self.t[0] if len(self.t) else '-'} … {self.t[-1] if len(self.t) else '-'}, "
                f"{self.stats['steps']} steps)")


def parameter_sets(parameters) -> Optional[List[Dict[str, float]]]:
    """Parameters of a batch as one dict per run: a sequence of dicts as given, or a dict
    of columns (``{"l1": [1.0, 1.1, …]}``, every column of the same length) cut into rows.

    Raises:
        ValueError: columns of different lengths.
    """
    if parameters is None:
        return None
    if isinstance(parameters, Mapping):
        columns = {k: np.atleast_1d(np.asarray(v, dtype=float)) for k, v in parameters.items()}
        lengths = {len(v) for v in columns.values()}
        if len(lengths) != 1:
            raise ValueError("every parameter's values must have the same length")
        (count,) = lengths
        return [{k: float(v[i]) for k, v in columns.items()} for i in range(count)]
    return [dict(p) for p in parameters]


def _at(at):
    """An operating point argument for the library: ``None``, a name, or ``n`` values."""
    if at is None or isinstance(at, str):
        return at
    return [float(v) for v in np.asarray(at, dtype=float).reshape(-1)]


def _floats(values):
    """``None`` or a list of floats."""
    return None if values is None else [float(v) for v in np.asarray(values, dtype=float).reshape(-1)]


def _json_number(x: float) -> Optional[float]:
    """A float as the command line's JSON gives it: non-finite numbers are ``null``."""
    x = float(x)
    return x if math.isfinite(x) else None


class Batch:
    """The stacked results of :meth:`Model.simulate_many` (``b`` runs, ``k`` output times).

    Attributes:
        t: output times (s), ``(k,)``.
        y: states, ``(b, k, 2n)``; ``q``, ``qdot``: ``(b, k, n)``. Samples after a run's
            end (a failure or a terminal event) are NaN.
        energy: ``(b, k)``.
        ok: ``(b,)`` booleans: the run ended without a failure (at ``t_end``, or at a
            terminal event of the model file).
        t_final: ``(b,)``: the time (s) each run reached (NaN for a run that did not start).
        failures: ``[(index, t, reason)]`` of the runs that failed (``t`` NaN for one that
            did not start).
        stopped_by_event: ``[(index, t, event)]`` of the runs a terminal event ended.
        stats: ``steps``, ``rejected``, ``rhs_evals``, each ``(b,)``.
    """

    def __init__(self, result: dict, num_dofs: int):
        self.t = result["t"]
        self.y = result["y"]
        self.q = self.y[:, :, :num_dofs]
        self.qdot = self.y[:, :, num_dofs:]
        self.energy = result["energy"]
        self.ok = result["ok"]
        self.t_final = result["t_final"]
        self.failures = [tuple(f) for f in result["failures"]]
        self.stopped_by_event = [tuple(s) for s in result["stopped_by_event"]]
        self.stats = {k: result[k] for k in ("steps", "rejected", "rhs_evals")}

    def __len__(self) -> int:
        return len(self.ok)

    def __repr__(self) -> str:
        return f"eomgen.Batch({len(self.ok)} runs × {len(self.t)} output times, {len(self.failures)} failed)"


class Modes:
    """The modal analysis about an equilibrium (``eomgen modes``), ``n`` coordinates,
    ``r`` minimal coordinates (``r = n`` without constraints).

    Attributes:
        natural_frequencies: ``ωₖ`` (rad/s), ascending, ``(r,)``.
        frequencies_hz: ``ωₖ/2π`` (Hz).
        mode_shapes: ``(n, r)``: column ``k`` is mode ``k`` in the model's coordinates
            (``δq = N ψ`` for a constrained model), mass-normalised:
            ``ΨᵀM(q*)Ψ = I`` with ``M(q*) = model.mass_matrix(modes.equilibrium)``.
        mass_matrix, stiffness_matrix, damping_matrix: ``M``, ``K``, ``C`` in the ``r``
            minimal coordinates (``NᵀMN`` … for a constrained model; the model's own
            without constraints).
        damping_ratios: ``ζ`` of each damped mode.
        eigenvalues: ``ωₖ²`` (1/s², negative for an unstable mode).
        equilibrium: ``q*`` (``n``).
        stability: the verdict from the eigenvalues of the whole state matrix (damping and
            gyroscopic terms included), with ``C`` split into damping and gyroscopic parts.
        summary: the report as ``eomgen modes --json`` prints it.
    """

    def __init__(self, summary: dict):
        self.summary = summary
        self.natural_frequencies = np.array(summary["natural_frequencies"], dtype=float)
        self.frequencies_hz = np.array(summary["frequencies_hz"], dtype=float)
        self.eigenvalues = np.array(summary["eigenvalues"], dtype=float)
        n = len(summary["coordinates"])
        shapes = np.array(summary["mode_shapes"], dtype=float).reshape(-1, n)
        self.mode_shapes = shapes.T
        r = len(summary["minimal_coordinates"])
        self.mass_matrix = np.array(summary["mass_matrix"], dtype=float).reshape(r, r)
        self.stiffness_matrix = np.array(summary["stiffness_matrix"], dtype=float).reshape(r, r)
        self.damping_matrix = np.array(summary["damping_matrix"], dtype=float).reshape(r, r)
        self.damping_ratios = np.array(summary["damping_ratios"], dtype=float)
        self.equilibrium = np.array(summary["operating_point"]["q"] if isinstance(summary["operating_point"]["q"], list)
                                    else [summary["operating_point"]["q"][c] for c in summary["coordinates"]], dtype=float)
        self.stability = summary["stability"]
        self.kinds = summary["kinds"]
        self.coordinates = summary["coordinates"]

    @property
    def damped_eigenvalues(self) -> np.ndarray:
        """The eigenvalues ``s`` of the state matrix with ``Im s ≥ 0`` (complex)."""
        return np.array([complex(d["re"], d["im"]) for d in self.summary["damped_modes"]])

    @property
    def state_eigenvalues(self) -> np.ndarray:
        """Every eigenvalue ``s`` of the state matrix ``A = [0 I; −M⁻¹K −M⁻¹C]`` (complex,
        ``2r``), each complex one with its conjugate: what the stability verdict reads."""
        return np.array([complex(re, im) for re, im in self.stability["eigenvalues"]])

    def _repr_html_(self) -> str:
        """The modes as a table (ω, f, ζ, kind) and the verdict, for Jupyter."""
        point = self.summary["operating_point"]
        q = ", ".join(f"{c} = {v:.6g}" for c, v in zip(self.coordinates, self.equilibrium))
        rows = []
        for k, w in enumerate(self.natural_frequencies):
            zeta = self.damping_ratios[k] if k < len(self.damping_ratios) else float("nan")
            kind = self.kinds[k].get("kind", "-") if k < len(self.kinds) else "-"
            rows.append((k + 1, f"{w:.8g}", f"{self.frequencies_hz[k]:.6g}", f"{zeta:.4g}", kind))
        return (f"<b>eomgen.Modes</b> of <code>{html.escape(self.summary['model'])}</code> at "
                f"{html.escape(str(point['name']))}: {html.escape(q)}"
                + _html_table(["mode", "ω (rad/s, undamped)", "f (Hz)", "ζ", "kind"], rows)
                + f"stability: <b>{html.escape(_verdict(self.stability))}</b>")

    def plot(self):
        """The mass-normalised mode shapes, one line per mode over the coordinates; needs
        matplotlib. Returns the figure."""
        plt = _pyplot("Modes.plot")
        fig, ax = plt.subplots(figsize=(6.4, 3.6))
        x = np.arange(len(self.coordinates))
        for k, w in enumerate(self.natural_frequencies):
            ax.plot(x, self.mode_shapes[:, k], marker="o", label=f"mode {k + 1}: ω = {w:.4g} rad/s")
        ax.axhline(0.0, color="0.6", linewidth=0.8)
        ax.set_xticks(x, self.coordinates)
        ax.set_ylabel("ψ (mass-normalised)")
        ax.set_title(f"{self.summary['model']} at {self.summary['operating_point']['name']}")
        ax.legend(fontsize="small")
        fig.tight_layout()
        return fig

    def __repr__(self) -> str:
        freqs = ", ".join(f"{w:.6g}" for w in self.natural_frequencies)
        return f"eomgen.Modes({self.summary['model']!r} at {self.summary['operating_point']['name']!r}: ω = [{freqs}] rad/s)"


class SteadyMotion:
    """The linearisation about a steady motion (rates held, or a non-holonomic model):
    the reduced state, its eigenvalues and the stability verdict (``eomgen modes`` at a
    steady motion).

    Attributes:
        eigenvalues: every eigenvalue ``s`` of the reduced state matrix (complex), each
            complex one followed by its conjugate.
        damped_eigenvalues: those with ``Im s ≥ 0``: each complex pair once, each real
            eigenvalue once, as the report lists them (with ``damping_ratios``).
        damping_ratios: ``ζ`` of each of ``damped_eigenvalues``.
        turning: for a steady turn (an entry with ``turning:``), the frame in which the
            plane's rates are held and the linearisation is taken: ``{"angle", "plane",
            "rate", "radius"}`` (``rate`` Ω in rad/s, ``radius`` ``|v|/|Ω|``, absent when
            Ω = 0); ``None`` otherwise.
        found_rates: the rates the search found (``{ guess: … }`` in the entry) rather than
            held.
        held_coordinates: the coordinates held at their value (``{ held: … }``) rather than
            found.
        summary: the report as ``eomgen modes --json`` prints it.
    """

    def __init__(self, summary: dict):
        self.summary = summary
        point = summary["operating_point"]
        self.turning = point.get("turning")
        self.found_rates = list(point.get("found_rates", []))
        self.held_coordinates = list(point.get("held_coordinates", []))
        modes = summary["damped_modes"]
        self.damped_eigenvalues = np.array([complex(d["re"], d["im"]) for d in modes])
        self.damping_ratios = np.array([d["damping_ratio"] for d in modes], dtype=float)
        full = []
        for s in self.damped_eigenvalues:
            full.append(s)
            if s.imag != 0.0:
                full.append(s.conjugate())
        self.eigenvalues = np.array(full)
        self.stability = summary.get("stability")

    def _repr_html_(self) -> str:
        """The steady motion, its eigenvalues (Re s, Im s, ζ) and the verdict, for Jupyter."""
        point = self.summary["operating_point"]
        rates = point.get("qdot", {}).items()
        held = ", ".join(f"{c} = {v:.6g}" for c, v in rates if c not in self.found_rates)
        found = ", ".join(f"{c} = {v:.6g}" for c, v in rates if c in self.found_rates)
        rows = [(k + 1, f"{s.real:.8g}", f"{s.imag:.8g}", f"{z:.4g}")
                for k, (s, z) in enumerate(zip(self.damped_eigenvalues, self.damping_ratios))]
        turn = ""
        if self.turning:
            a, b = self.turning["plane"]
            radius = self.turning.get("radius")
            radius = "infinite (straight)" if radius is None else f"{radius:.6g}"
            turn = (f"<br>{html.escape(a)}_dot, {html.escape(b)}_dot constant in the frame turned by "
                    f"{html.escape(self.turning['angle'])}: Ω = {self.turning['rate']:.6g} rad/s, "
                    f"radius {radius}; linearised in that frame")
        return (f"<b>eomgen.SteadyMotion</b> of <code>{html.escape(self.summary['model'])}</code> at "
                f"{html.escape(str(point.get('name', '-')))}" + (f"; rates held {html.escape(held)}" if held else "")
                + (f"; rates found {html.escape(found)}" if found else "") + turn
                + _html_table(["eigenvalue", "Re s (1/s)", "Im s (rad/s, ≥ 0)", "ζ"], rows)
                + f"stability: <b>{html.escape(_verdict(self.stability))}</b>")

    def __repr__(self) -> str:
        return f"eomgen.SteadyMotion({self.summary['model']!r}: {len(self.eigenvalues)} eigenvalues)"


class Animation:
    """A self-contained HTML page (no network needed) with the mechanism moving: the page
    ``eomgen animate`` and ``eomgen modes --animate`` write, to the byte.

    Attributes:
        html: the page.
    """

    def __init__(self, html: str):
        self.html = html

    def save(self, path: str) -> None:
        """Writes the page to ``path`` (UTF-8)."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.html)

    def _repr_html_(self) -> str:
        # In its own frame: the page's script and element ids cannot meet another output's.
        import html as _html

        return (f'<iframe srcdoc="{_html.escape(self.html, quote=True)}" style="width: 100%; height: 640px; '
                'border: 0" sandbox="allow-scripts"></iframe>')

    def __repr__(self) -> str:
        return f"eomgen.Animation({len(self.html)} bytes of HTML)"


class Equations(str):
    """The equations of motion as text (or LaTeX); shown as LaTeX in Jupyter.

    Attributes:
        latex: the LaTeX listing (amsmath).
        listing: ``{"model", "method", "equations", "latex"}`` as
            ``eomgen equations --json`` prints it.
    """

    latex: str
    listing: dict

    def __new__(cls, text: str, latex: str, listing: dict):
        self = super().__new__(cls, text)
        self.latex = latex
        self.listing = listing
        return self

    def _repr_latex_(self) -> str:
        # Jupyter typesets text/latex with MathJax, which needs math delimiters; the listing's
        # lines are separated by `\\`, as inside `gathered`.
        return "$$\\begin{gathered}\n" + self.latex.strip() + "\n\\end{gathered}$$"

    def __reduce__(self):
        return (Equations, (str(self), self.latex, self.listing))
