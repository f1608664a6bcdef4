"""Monte Carlo over simulated records, in batches on the study engine (issue 14).

A Monte Carlo study (calibrating intervals, predicting a design's response) needs many seeded
time-domain records, each reduced to a few numbers. :func:`monte_carlo` cuts the seeds into
batches; each batch is one task of :func:`crowdvib.runner.tasks.run_tasks`, so it runs in
this process, on local workers or on a dask cluster
(:func:`crowdvib.runner.engine.study_executor`; a worker runs its batch's records in parallel threads, :func:`crowdvib.simulate_many`), and
each finished batch is kept in a :class:`~crowdvib.runner.tasks.TaskStore`: an
interrupted study resumes without simulating again what is done.
"""

import concurrent.futures
import importlib
import json
import numbers
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._files import json_default
from ..errors import CrowdvibError, ParameterError
from ..models.crowd import Crowd
from ..models.structure import ModalModel
from ..response.time_domain.batch import check_seeds, simulate_many
from ..response.time_domain.results import Simulation
from ..response.time_domain.traffic import check_duration
from ..runner.tasks import TaskStore, run_tasks

__all__ = ["monte_carlo", "record_statistics"]


def record_statistics(record: Simulation) -> dict:
    """Default summary of a record: seed, walkers, and RMS and peak |a| per output [m/s²].

    Parameters
    ----------
    record : Simulation
        A record of :func:`crowdvib.simulate`.

    Returns
    -------
    dict
        ``seed``, ``n_pedestrians``, ``rms`` and ``peak`` (lists, one value per output).
    """
    acceleration = record.acceleration
    return {"seed": record.seed, "n_pedestrians": record.n_pedestrians,
            "rms": np.sqrt(np.mean(acceleration**2, axis=1)).tolist(),
            "peak": np.abs(acceleration).max(axis=1).tolist()}


@dataclass(frozen=True)
class _Batch:
    """One task: the records of some seeds, each reduced by the named summary function."""

    structure: object
    crowd: object
    duration: float
    seeds: tuple
    summary: str            # "module:qualified name", resolved where the task runs
    options: tuple          # ((name, value), …) of simulate


def _batch_task(batch):
    summary = _resolve(batch.summary)
    records = simulate_many(batch.structure, batch.crowd, batch.duration,
                            seeds=list(batch.seeds), **dict(batch.options))
    # Through JSON and back: a fresh result has the same types as one read from the store.
    rows = [json.loads(json.dumps(summary(record), default=json_default)) for record in records]
    return {"records": rows}


def _summary_name(summary):
    """The importable name of ``summary`` ("module:qualname"); it enters the tasks' keys."""
    if not callable(summary):
        raise ParameterError(f"summary must be a function, got {type(summary).__name__}")
    module = getattr(summary, "__module__", None)
    qualname = getattr(summary, "__qualname__", "")
    if module is None or "<" in qualname:
        raise ParameterError(
            f"summary must be a module-level function (importable where the tasks run), "
            f"got {qualname or summary!r}")
    return f"{module}:{qualname}"


def _resolve(name):
    module, qualname = name.split(":")
    value = importlib.import_module(module)
    for part in qualname.split("."):
        value = getattr(value, part)
    return value


def monte_carlo(structure: ModalModel, crowd: Crowd | None, duration: float, *,
                seeds: Sequence[int], summary: Callable[[Simulation], dict] = record_statistics,
                batch_size: int = 10, executor: concurrent.futures.Executor | None = None,
                store: TaskStore | str | os.PathLike | None = None,
                progress: Callable[[int, int], None] | None = None,
                **options: Any) -> list[dict]:
    """Simulate one record per seed and reduce each with ``summary``, batch by batch.

    Parameters
    ----------
    structure, crowd, duration
        As for :func:`crowdvib.simulate`.
    seeds : sequence of int
        One non-negative seed per record: record i is ``simulate(..., rng=seeds[i])`` bit for
        bit, whatever the batch size or executor.
    summary : callable
        A module-level function Simulation → JSON-ready dict (its module must be importable
        where the tasks run); default :func:`record_statistics`.
    batch_size : int
        Records per task (the unit stored and resumed).
    executor, store, progress
        As for the studies (:func:`crowdvib.runner.run_tasks`): ``progress(done,
        total)`` counts batches.
    **options
        Keywords of :func:`crowdvib.simulate` (``msd``, ``sample_rate``, ``warm_up`` …) and
        ``workers`` (threads per batch, :func:`crowdvib.simulate_many`).

    Returns
    -------
    list of dict
        The summaries in the order of ``seeds``.

    Raises
    ------
    CrowdvibError
        If a batch failed (its error names the seeds); finished batches stay in ``store``.

    See Also
    --------
    crowdvib.simulate
    crowdvib.simulate_many
    crowdvib.studies.record_statistics
    """
    seeds = check_seeds(seeds)
    name = _summary_name(summary)
    if isinstance(batch_size, bool) or not isinstance(batch_size, numbers.Integral) \
            or batch_size < 1:
        raise ParameterError(f"batch_size must be an integer >= 1, got {batch_size!r}")
    duration, _ = check_duration(duration, 0.0)
    frozen = tuple(sorted(options.items()))
    tasks = []
    for start in range(0, len(seeds), batch_size):
        part = tuple(seeds[start:start + batch_size])
        tasks.append((f"seeds-{start}-{start + len(part) - 1}",
                      _Batch(structure, crowd, duration, part, name, frozen)))
    results = run_tasks(_batch_task, tasks, executor=executor, store=store, progress=progress)
    rows = []
    for task_name, batch in tasks:
        result = results[task_name]
        if "error" in result:
            raise CrowdvibError(f"Monte Carlo batch {task_name} (seeds {list(batch.seeds)}) "
                                f"failed: {result['error']}")
        rows.extend(result["records"])
    return rows
