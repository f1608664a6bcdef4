"""Where a study's tasks run: in this process, in local worker processes, or on a dask cluster.

:func:`study_executor` gives :func:`crowdvib.identification.tasks.run_tasks` an executor:

* one worker: none, the tasks run in this process;
* several: a :class:`~crowdvib.identification._pool.ProcessPool` of worker processes on this
  machine, forked from this one (on Linux) so that they start in milliseconds with every module
  and compiled kernel already loaded; a worker that dies is replaced and its task run again, the
  workers exit with this process even when it is killed, and they leave Ctrl-C to it;
* ``scheduler``: a ``dask.distributed`` client of a running cluster, whose scheduler reruns the
  tasks of a dead worker on another.

Why not a local dask cluster as well (it was used until issue 14): its workers are spawned and
import crowdvib again, 2 s to start two of them and 0.5 s to close them, and its bookkeeping
runs beside the tasks; on the Eeklo-like sensitivity study (40 s on one worker) that overhead
alone kept two workers below 1.8× (measured: see ``benchmarks/bench_study_scaling.py``).

Threads: a machine's cores are shared out between its workers. Each local worker runs BLAS
(OpenMP, OpenBLAS, MKL) and numba with its share, cores // workers, so that two workers on two
cores do not run four threads (measured in issue 14: two workers with multi-threaded BLAS were
1.36× slower than one). In this process (one worker) numba keeps all cores. Inside a task,
:func:`crowdvib.identification.tasks.run_tasks` further pins BLAS to one thread so that a task
gives the same bits wherever it runs.
"""

import contextlib
import signal
import threading

from .._threads import default_workers
from ..errors import ParameterError
from ._pool import ProcessPool

__all__ = ["study_executor"]


@contextlib.contextmanager
def study_executor(workers=1, scheduler=None, *, timeout_floor=60.0, timeout_factor=10.0):
    """The executor a study runs on, for a ``with`` block.

    Parameters
    ----------
    workers : int or None
        Local worker processes; 1 runs the tasks in this process (yields None); None = the
        physical cores. Each local worker's BLAS, OpenMP and numba pools get cores // workers
        threads.
    scheduler : str, optional
        Address of a running dask.distributed scheduler, e.g. ``"tcp://10.0.0.5:8786"``;
        ``workers`` is then ignored.
    timeout_floor, timeout_factor : float
        Local workers: a task running longer than max(``timeout_floor`` s, ``timeout_factor`` ×
        the slowest finished task) has its worker taken as hung, killed and replaced, and runs
        again elsewhere (see :class:`~crowdvib.identification._pool.ProcessPool`); defaults 60 s
        and 10.

    Yields
    ------
    concurrent.futures.Executor or None
        A :class:`~crowdvib.identification._pool.ProcessPool`, dask's executor, or None.

    Notes
    -----
    Leaving the block normally lets the local workers finish and exit (milliseconds when the
    study is done); left by an exception (Ctrl-C), it kills the workers still busy, whose
    results would be thrown away, after ``run_tasks`` has cancelled what had not started. A
    dask client is closed (a second Ctrl-C meanwhile is ignored).
    """
    if workers is None:
        workers = default_workers()
    if scheduler is not None:
        with _dask_client(scheduler) as client:
            # pure=False: tasks are told apart by run_tasks, hashing them again is waste.
            yield client.get_executor(pure=False)
        return
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ParameterError(f"--workers must be >= 1, got {workers}")
    if workers == 1:
        yield None
        return
    pool = ProcessPool(workers, timeout_floor=timeout_floor, timeout_factor=timeout_factor)
    try:
        yield pool
    except BaseException:
        pool.close(kill=True)
        raise
    pool.close()


@contextlib.contextmanager
def _dask_client(scheduler):
    """A client of the dask.distributed scheduler at ``scheduler``, closed on leaving."""
    try:
        import distributed
    except ImportError:
        raise ParameterError("--scheduler needs dask.distributed: pip install 'crowdvib[dask]'") \
            from None
    try:
        client = distributed.Client(scheduler, timeout=10)
    except (OSError, TimeoutError, ValueError) as error:
        raise ParameterError(f"--scheduler {scheduler}: cannot connect ({error})") from None
    try:
        yield client
    finally:
        _close(client)


def _close(resource):
    """Close a dask client quickly; a second Ctrl-C meanwhile is ignored, not a traceback."""
    main = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN) if main else None
    try:
        resource.close(timeout=2)
    except Exception:          # already closed or lost: nothing left to release
        pass
    finally:
        if main:
            signal.signal(signal.SIGINT, previous)

