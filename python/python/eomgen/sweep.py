"""Sweeps spread over processes or machines: Dask, ``concurrent.futures``, multiprocessing.

A sweep (a Monte Carlo over initial conditions, a design sweep over parameters) is cut into
chunks; each chunk is one :meth:`eomgen.Model.simulate_many` call on a worker (the model
travels pickled, by its file's text and parameters), and the chunks' results are stacked in
order. Each run is computed exactly as :meth:`eomgen.Model.simulate` computes it, so the
result equals the serial loop's bit for bit, whatever the number of workers.

>>> from distributed import Client, LocalCluster                     # doctest: +SKIP
>>> with LocalCluster(host="127.0.0.1", n_workers=2, threads_per_worker=1,
...                   dashboard_address=None) as cluster, Client(cluster) as client:
...     batch = eomgen.sweep.run(client, m, initial_states=y0s, t_end=10.0)
>>> # the same on a cluster: Client("tcp://scheduler:8786") instead of the LocalCluster

Tasks of a few milliseconds are dominated by the scheduler's cost per task (about 1 ms on
Dask): chunks default to ten per worker.
"""

from __future__ import annotations

from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np

from ._model import Batch, Model, parameter_sets


def run_chunk(model: Model, initial_states: Optional[np.ndarray], parameters: Optional[List[Mapping[str, float]]],
              options: Dict[str, Any]) -> Dict[str, Any]:
    """One chunk of a sweep on a worker: :meth:`Model.simulate_many` on one thread (the
    worker process is the unit of parallelism), failures kept. Returns the batch's arrays
    as a dict (what travels back to the client)."""
    batch = model.simulate_many(initial_states=initial_states, parameters=parameters, threads=1,
                                errors="keep", **options)
    return {
        "t": batch.t,
        "y": batch.y,
        "energy": batch.energy,
        "ok": batch.ok,
        "t_final": batch.t_final,
        "failures": batch.failures,
        "stopped_by_event": batch.stopped_by_event,
        "steps": batch.stats["steps"],
        "rejected": batch.stats["rejected"],
        "rhs_evals": batch.stats["rhs_evals"],
    }


def run(executor: Any, model: Model, initial_states: Optional[Any] = None,
        parameters: Optional[Union[Sequence[Mapping[str, float]], Mapping[str, Any]]] = None,
        chunks: Optional[int] = None, errors: str = "raise", **options: Any) -> Batch:
    """Runs :meth:`Model.simulate_many`'s batch in chunks on ``executor`` and stacks the
    results in order.

    Args:
        executor: a ``distributed.Client`` (a ``LocalCluster``'s or a remote scheduler's),
            or any ``concurrent.futures.Executor`` (``ProcessPoolExecutor``, Ray's
            executors).
        model: the model (pickled to the workers).
        initial_states, parameters: as :meth:`Model.simulate_many` (``b`` runs).
        chunks: how many tasks (default: ten per worker, read from the Dask scheduler or
            the executor's ``max_workers``).
        errors: ``raise`` (the first failed run raises :class:`eomgen.IntegrationError`) or
            ``keep``.
        options: ``t_end``, ``t_out``, ``method``, ``rtol``, ``atol``, ``dt``,
            ``stabilization``, ``baumgarte``, as :meth:`Model.simulate_many`.

    Returns:
        a :class:`eomgen.Batch` equal to ``model.simulate_many(...)`` on one machine.
    """
    from .errors import IntegrationError

    if errors not in ("raise", "keep"):
        raise ValueError(f"errors must be `raise` or `keep`, got `{errors}`")
    reserved = {"threads", "errors", "initial_states", "parameters"} & set(options)
    if reserved:
        raise TypeError(f"sweep.run sets {', '.join(sorted(reserved))} itself")
    states = None if initial_states is None else np.atleast_2d(np.asarray(initial_states, dtype=float))
    sets = parameter_sets(parameters)
    count = len(states) if states is not None else (len(sets) if sets is not None else 0)
    if states is not None and sets is not None and len(states) != len(sets):
        raise ValueError(f"initial_states has {len(states)} rows and parameters {len(sets)} entries")
    if count == 0:
        raise ValueError("the sweep is empty: give initial_states or parameters with at least one run")
    if chunks is None:
        chunks = 10 * _workers(executor)
    bounds = np.linspace(0, count, min(max(int(chunks), 1), count) + 1).astype(int)
    pieces = [(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:]) if b > a]
    args = [
        (model,
         None if states is None else states[a:b],
         None if sets is None else sets[a:b],
         dict(options))
        for a, b in pieces
    ]
    if hasattr(executor, "gather") and hasattr(executor, "map"):
        # A Dask client: `pure=False`, every chunk runs (equal chunks are not merged).
        futures = executor.map(run_chunk, *zip(*args), pure=False)
        parts = executor.gather(futures)
    else:
        futures = [executor.submit(run_chunk, *a) for a in args]
        parts = [f.result() for f in futures]
    failures, stopped = [], []
    for (a, _), part in zip(pieces, parts):
        failures.extend((a + i, t, reason) for i, t, reason in part["failures"])
        stopped.extend((a + i, t, event) for i, t, event in part["stopped_by_event"])
    n = model.num_dofs
    result = {
        "t": parts[0]["t"],
        "y": np.concatenate([p["y"] for p in parts]),
        "energy": np.concatenate([p["energy"] for p in parts]),
        "ok": np.concatenate([p["ok"] for p in parts]),
        "t_final": np.concatenate([p["t_final"] for p in parts]),
        "failures": failures,
        "stopped_by_event": stopped,
        "steps": np.concatenate([p["steps"] for p in parts]),
        "rejected": np.concatenate([p["rejected"] for p in parts]),
        "rhs_evals": np.concatenate([p["rhs_evals"] for p in parts]),
    }
    batch = Batch(result, n)
    if errors == "raise" and failures:
        index, t, reason = failures[0]
        raise IntegrationError(
            f"integration of `{model.name}` stopped in run {index} of {count}: {reason} "
            f"({len(failures)} run(s) failed; errors='keep' returns the batch)",
            None if t != t else t, reason, batch)
    return batch


def _workers(executor: Any) -> int:
    """The number of workers behind ``executor`` (1 when it cannot tell)."""
    info = getattr(executor, "scheduler_info", None)
    if callable(info):
        try:
            return max(len(info().get("workers", {})), 1)
        except Exception:  # a client not yet connected
            return 1
    return max(int(getattr(executor, "_max_workers", 1) or 1), 1)
