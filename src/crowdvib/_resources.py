"""What this machine can hold and run: its cores and the threads each worker of a study may use,
its memory, and data whose declared size is refused before it is allocated.

Cores and threads are kept apart from the engine so that the command line can state its
defaults without importing numpy, scipy or dask.

A record file declares the shape and type of its arrays in a header; a reader that believes it
allocates what the header says. A 2.5 KB NPZ or MAT v7.3 (HDF5) file declaring 10.7 GB made
crowdvib allocate 10.7 GB (issue 35 §1). :func:`check_declared_size` compares the declared size
with what the file can hold, before anything is read: the bytes it stores for the array, or, for
compressed data, what deflate can expand them to, and always with the memory available
(:func:`available_memory`, which ``simulate`` plans its records with too).
"""

import os

from .errors import DataError

__all__ = ["physical_cores", "default_workers", "thread_share", "thread_budget",
           "THREAD_VARIABLES", "BUDGET_VARIABLE",
           "available_memory", "memory_limit", "check_declared_size", "MEMORY_SHARE"]

# ------------------------------------------------------------------------- cores and threads
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


# ------------------------------------------------------------------------------------ memory
#: Share of the available memory a run, or a file's data, may take (the rest: the caller, the
#: OS, copies).
MEMORY_SHARE = 0.5
#: Memory assumed available where neither psutil nor the OS can tell [bytes].
_FALLBACK_MEMORY = 4e9
#: Most that deflate (zip, HDF5's gzip filter, MAT v5's compressed elements) expands its
#: input: 1032:1 (zlib's technical notes: 258 bytes a 2-bit code, in the limit).
DEFLATE_RATIO = 1032


def available_memory() -> float:
    """Memory this process can still take [bytes]: psutil's ``available``, else the free
    physical pages the OS reports, else ``_FALLBACK_MEMORY``."""
    try:
        import psutil
    except ImportError:
        try:
            return float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
        except (AttributeError, ValueError, OSError):
            return _FALLBACK_MEMORY
    return float(psutil.virtual_memory().available)


def memory_limit() -> int:
    """Bytes one file's data may take: :data:`MEMORY_SHARE` of :func:`available_memory`."""
    return int(MEMORY_SHARE * available_memory())


def check_declared_size(prefix, what, shape, itemsize, *, stored=None, compressed=None):
    """Refuse an array whose declared size the file cannot hold, before it is allocated.

    Parameters
    ----------
    prefix : str
        The message's start, naming the file (``"record.npz: "``).
    what : str
        The array (``"array 'data'"``).
    shape : tuple of int
        Its declared shape.
    itemsize : int
        Bytes of one value.
    stored : int, optional
        Bytes the file holds for it as it is (not compressed): the declared size may not exceed
        them.
    compressed : int, optional
        Bytes of its compressed form: the declared size may not exceed what deflate expands
        them to (:data:`DEFLATE_RATIO`).

    Returns
    -------
    int
        The declared size [bytes].

    Raises
    ------
    DataError
        Naming the file, the array, its declared shape and size, and the rule.
    """
    declared = int(itemsize)
    for n in shape:
        declared *= int(n)
    said = f"{prefix}{what} declares shape {tuple(int(n) for n in shape)} × {itemsize} B = " \
           f"{declared} bytes"
    if stored is not None and declared > stored:
        raise DataError(f"{said}, but the file holds {max(int(stored), 0)} bytes for it: its "
                        "declared size is false (damaged or hostile file); nothing allocated")
    if compressed is not None and declared > DEFLATE_RATIO * int(compressed) + 4096:
        raise DataError(f"{said}, more than its {int(compressed)} compressed bytes can expand "
                        f"to ({DEFLATE_RATIO}:1): damaged or hostile file; nothing allocated")
    limit = memory_limit()
    if declared > limit:
        raise DataError(f"{said}, more than half the {2 * limit / 1e9:.3g} GB of memory "
                        "available: split the record into shorter files")
    return declared
