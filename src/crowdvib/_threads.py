"""How many cores there are and how many threads each worker of a study may use.

Kept apart from the engine so that the command line can state its defaults without importing
numpy, scipy or dask.
"""

import os

#: The environment variables that size the thread pools of BLAS and OpenMP in a process that has
#: not loaded them yet.
THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")

#: The threads crowdvib's own parallel code may use in this process (a study worker's share).
#: Not ``NUMBA_NUM_THREADS``: numba reads that again before every compilation and refuses a new
#: value once its thread pool runs (issue 24), so a worker leaves it alone.
BUDGET_VARIABLE = "CROWDVIB_THREADS"


def physical_cores() -> int:
    """Physical cores of this machine (psutil), else the logical CPUs that ``os`` counts."""
    try:
        import psutil
    except ImportError:
        cores = None
    else:
        cores = psutil.cpu_count(logical=False)
    return max(1, cores or os.cpu_count() or 1)


def default_workers() -> int:
    """Default local worker processes of a study: the physical cores."""
    return physical_cores()


def thread_share(workers: int, cores: int | None = None) -> int:
    """Threads each of ``workers`` processes may use on ``cores`` cores (default: physical; >= 1)."""
    cores = physical_cores() if cores is None else cores
    return max(1, cores // workers)


def thread_budget() -> int:
    """Threads this process may use: ``CROWDVIB_THREADS`` when set (a study worker's share),
    else the physical cores."""
    share = os.environ.get(BUDGET_VARIABLE, "")
    return int(share) if share.isdigit() and int(share) > 0 else physical_cores()
