"""Several independent records at once, in parallel over cores (docs: theory, Time stepping).

Each record is exactly :func:`crowdvib.simulate` with its own seed, so a batch is bit-identical
to one-at-a-time runs: the compiled kernel releases the GIL (numba ``nogil``) and every record
owns its state arrays, so records run side by side on threads of one process without sharing
anything but the read-only structure.
"""

import concurrent.futures
import numbers
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ..._resources import thread_budget
from ...errors import ParameterError
from ...models.crowd import Crowd
from ...models.structure import ModalModel
from .results import Simulation
from .simulation import checked_run, simulate

__all__ = ["simulate_many"]


def simulate_many(structure: ModalModel, crowd: Crowd | None = None,
                  duration: float | None = None, *, seeds: Sequence[int],
                  workers: int | None = None,
                  progress: Callable[[int, int], None] | None = None,
                  **options: Any) -> list[Simulation]:
    """One record per seed, run in parallel threads (docs: theory, Time stepping).

    Parameters
    ----------
    structure, crowd, duration
        As for :func:`crowdvib.simulate`.
    seeds : sequence of int
        One non-negative seed per record; record i is ``simulate(..., rng=seeds[i])`` bit for bit.
    workers : int, optional
        Threads (records running at once). Default: the cores this process may use (its share
        on a study worker, ``CROWDVIB_THREADS``; else the physical cores), at most one per seed.
    progress : callable, optional
        ``progress(done, total)`` in records, after each finished record.
    **options
        Any keyword of :func:`crowdvib.simulate` but ``rng``, ``progress`` and
        ``chunk_duration`` (``pedestrians``, ``msd``, ``force``, ``sample_rate``,
        ``include_static_weight``, ``record_modal_load``, ``warm_up``, ``dampers``).

    Returns
    -------
    list of Simulation
        In the order of ``seeds``.

    See Also
    --------
    crowdvib.simulate : one record.
    crowdvib.studies.monte_carlo : records reduced to statistics, resumable.

    Notes
    -----
    Every record is returned, so memory grows with seeds × duration (a one-hour record of one
    output at 100 Hz holds 3.6 MB: 10 000 of them 36 GB). For a large study use
    :func:`crowdvib.studies.monte_carlo`, which reduces each record to a summary as it
    goes, in resumable batches on any executor; for one long record whose spectrum is all
    that is wanted, :func:`crowdvib.simulate_psd`.
    """
    seeds = check_seeds(seeds)
    for name in ("rng", "progress", "chunk_duration"):
        if name in options:
            raise ParameterError(f"{name} is not an option of simulate_many (given {name}=...)")
    if workers is None:
        workers = thread_budget()
    elif isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ParameterError(f"workers must be an integer >= 1 or None, got {workers!r}")
    if progress is not None and not callable(progress):
        raise ParameterError(f"progress must be callable or None, got {type(progress).__name__}")

    # Every record is kept: the batch must fit as a whole, which each run alone cannot see.
    checked_run(structure, crowd, duration, records=len(seeds), rng=seeds[0], **options)

    def one(seed):
        return simulate(structure, crowd, duration, rng=seed, **options)

    workers = min(workers, len(seeds))
    if workers == 1:
        records = []
        for seed in seeds:
            records.append(one(seed))
            if progress is not None:
                progress(len(records), len(seeds))
        return records
    with concurrent.futures.ThreadPoolExecutor(workers) as pool:
        futures = [pool.submit(one, seed) for seed in seeds]
        try:
            for done, _ in enumerate(concurrent.futures.as_completed(futures), start=1):
                if progress is not None:
                    progress(done, len(seeds))
            return [future.result() for future in futures]
        except BaseException:
            # A bad input fails every record alike: do not start the others.
            pool.shutdown(wait=False, cancel_futures=True)
            raise


def check_seeds(seeds):
    """A non-empty list of non-negative integer seeds (also the Monte Carlo studies' check)."""
    if isinstance(seeds, np.ndarray):
        seeds = seeds.tolist()
    if isinstance(seeds, (str, bytes)) or not isinstance(seeds, Sequence):
        raise ParameterError(
            f"seeds must be a sequence of non-negative integers, got {type(seeds).__name__}")
    seeds = list(seeds)
    if not seeds:
        raise ParameterError("seeds must hold at least one seed, got an empty sequence")
    for seed in seeds:
        if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
            raise ParameterError(f"seeds must be non-negative integers, got {seed!r}")
    return [int(seed) for seed in seeds]
