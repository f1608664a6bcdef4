"""Where a study's tasks run: in this process, on a local dask cluster, or on a remote one.

:func:`study_executor` gives :func:`crowdvib.identification.tasks.run_tasks` an executor, and the
local and the remote case are one code path: a ``dask.distributed`` client, local workers being a
:class:`distributed.LocalCluster` on loopback (worker processes, one thread each, no dashboard).

Why dask.distributed rather than loky (or ``concurrent.futures``' process pool):

* a worker that dies (killed, out of memory) has its tasks run again on another worker by the
  scheduler, and the nanny starts a fresh worker; loky and the standard pool instead break the
  whole pool (``TerminatedWorkerError``/``BrokenProcessPool``) and leave the retry to us;
* ``--scheduler ADDRESS`` needs dask anyway, so local and remote runs share every line;
* a worker process exits at once when its parent dies, even by SIGKILL: the nanny holds one end of
  a pipe whose other end a thread of the worker reads, and the kernel closes it with the parent
  (``distributed.process.AsyncProcess``); the fault tests check this.

Its cost is about a second to start two workers; one worker runs in this process without any
cluster.

Threads: a machine's cores are shared out between its workers. Each local worker process starts
with BLAS (OpenMP, OpenBLAS, MKL) and numba limited to its share, cores // workers, so that two
workers on two cores do not run four threads (measured in issue 14: two workers with
multi-threaded BLAS were 1.36× slower than one). In this process (one worker) numba keeps all
cores. Inside a task, :func:`crowdvib.identification.tasks.run_tasks` further pins BLAS to one
thread so that a task gives the same bits wherever it runs.
"""

import contextlib
import logging
import signal
import threading

from .._threads import THREAD_VARIABLES, default_workers, thread_share
from ..errors import ParameterError

__all__ = ["study_executor"]


@contextlib.contextmanager
def study_executor(workers=1, scheduler=None):
    """The executor a study runs on, for a ``with`` block.

    Parameters
    ----------
    workers : int or None
        Local worker processes; 1 runs the tasks in this process (yields None); None = the
        physical cores when dask.distributed is installed, else 1. Each local worker's BLAS,
        OpenMP and numba pools get cores // workers threads.
    scheduler : str, optional
        Address of a running dask.distributed scheduler, e.g. ``"tcp://10.0.0.5:8786"``;
        ``workers`` is then ignored.

    Yields
    ------
    concurrent.futures.Executor or None

    Notes
    -----
    Leaving the block closes the client and the local cluster (about a second; a worker still
    alive after 2 s is killed). Left by Ctrl-C, ``run_tasks`` has already cancelled the
    unfinished tasks. Ctrl-C while the local cluster starts is held until it is up, so that it
    is closed like any other.
    """
    if workers is None:
        workers = default_workers()
    if scheduler is None:
        if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
            raise ParameterError(f"--workers must be >= 1, got {workers}")
        if workers == 1:
            yield None
            return
    try:
        import dask
        import distributed
    except ImportError:
        raise ParameterError("--workers > 1 and --scheduler need dask.distributed: "
                             "pip install 'crowdvib[dask]'") from None
    with contextlib.ExitStack() as stack:
        if scheduler is None:
            with _interrupts_held():
                client = _local_client(distributed, dask, workers, stack)
        else:
            try:
                client = distributed.Client(scheduler, timeout=10)
            except (OSError, TimeoutError, ValueError) as error:
                raise ParameterError(f"--scheduler {scheduler}: cannot connect ({error})") \
                    from None
            stack.callback(_close, client)
        # pure=False: tasks are told apart by run_tasks, hashing them again for dask is waste.
        yield client.get_executor(pure=False)


def _local_client(distributed, dask, workers, stack):
    """A client of a new local cluster, both closed by ``stack``."""
    # dask starts workers with MALLOC_TRIM_THRESHOLD_=65536, which turns off glibc's adaptive
    # mmap threshold: every large numpy temporary is then mapped and unmapped afresh, and the
    # page faults made a study on 2 workers slower than on 1 (measured: 6 s of system time per
    # worker for the 85 estimations of the paper example). Its OMP/OPENBLAS_NUM_THREADS=1 stays:
    # run_tasks gives every task one BLAS thread anyway, wherever it runs. Each worker's BLAS,
    # OpenMP and numba pools are sized to its share of the cores (set before numpy and numba load).
    share = str(thread_share(workers))
    environ = {f"distributed.nanny.pre-spawn-environ.{name}": share for name in THREAD_VARIABLES}
    environ["distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_"] = None
    # A study's tasks are long and few: dask's own bookkeeping need not poll. Its statistical
    # profiler (every 10 ms), GIL monitor (every 1 ms), system monitor (every 0.5 s) and event-
    # loop tick (every 20 ms) took 0.10 CPU-second per second on an idle 2-worker cluster,
    # 0.026 without (measured, issue 14): on 2 busy workers that is CPU taken from the tasks.
    environ.update({"distributed.worker.profile.enabled": False,
                    "distributed.admin.system-monitor.gil.enabled": False,
                    "distributed.admin.system-monitor.interval": "5s",
                    "distributed.admin.tick.interval": "100ms"})
    with dask.config.set(environ):
        # Loopback only; no dashboard, and the scheduler's health route on a free port (by
        # default it takes 8787, or warns when that is taken). dask's own log lines are
        # silenced: what matters reaches run_tasks through the futures, and on Ctrl-C a worker
        # would log the scheduler's closing with a traceback.
        cluster = distributed.LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
            dashboard_address=None, silence_logs=logging.CRITICAL,
            scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"})
    stack.callback(_stop, cluster)
    client = distributed.Client(cluster)
    stack.callback(_close, client)
    # Workers started later (a nanny replacing a dead one) may not inherit the held SIGINT.
    from ._dask_worker import IgnoreInterrupts

    client.register_plugin(IgnoreInterrupts(), name="crowdvib-ignore-sigint")
    return client


@contextlib.contextmanager
def _interrupts_held():
    """Hold Ctrl-C (SIGINT) while a local cluster starts; it is raised when the block ends.

    A KeyboardInterrupt inside dask's start-up leaves a half-built cluster whose clean-up took
    12 s (measured). Held, the signal waits until the cluster is up and registered for closing.
    The block is inherited by the threads and processes started meanwhile (dask's event loop and,
    through it, the workers), so a terminal's Ctrl-C reaches the parent alone.
    """
    if (not hasattr(signal, "pthread_sigmask")
            or threading.current_thread() is not threading.main_thread()):
        yield
        return
    # multiprocessing starts its resource tracker with SIGINT blocked and then *unblocks* it,
    # which would end the hold early: start the tracker first.
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()
    before = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)


def _close(resource):
    """Close a client or cluster quickly; a second Ctrl-C meanwhile is ignored, not a traceback."""
    main = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN) if main else None
    try:
        resource.close(timeout=2)
    except Exception:          # already closed or lost: nothing left to release
        pass
    finally:
        if main:
            signal.signal(signal.SIGINT, previous)


def _stop(cluster):
    """Close a local cluster; a worker still alive after the close's time-out is killed (a
    worker busy in a long task can take that long to notice), so none outlives the study."""
    import os

    import psutil                              # a dependency of distributed

    pids = [nanny.pid for nanny in cluster.workers.values() if nanny.pid]
    _close(cluster)
    for pid in pids:
        try:
            worker = psutil.Process(pid)
            if worker.ppid() == os.getpid():
                worker.kill()
        except psutil.Error:                   # gone already, as it should be
            pass
