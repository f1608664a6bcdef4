"""Where a study's tasks run: in this process, in local worker processes, or on a dask cluster.

:func:`study_executor` gives :func:`crowdvib.runner.tasks.run_tasks` an executor:

* one worker: none, the tasks run in this process;
* several: a :class:`~crowdvib.runner._pool.ProcessPool` of worker processes on this
  machine, forked by a fork server that has imported crowdvib once (POSIX); a worker that dies or
  hangs (past max(``timeout_floor``, ``timeout_factor`` × the slowest finished task)) is
  replaced and its task run again, the workers exit with this process even when it is killed,
  and they leave Ctrl-C to it;
* ``scheduler``: a ``dask.distributed`` client of a running cluster, whose scheduler reruns the
  tasks of a dead worker on another; losing the scheduler ends the study with one
  :class:`SchedulerLost`.

Why not a local dask cluster as well (it was used until issue 14): its workers are spawned and
each imports crowdvib, 2 s to start two of them and 0.5 s to close them, and its bookkeeping
runs beside the tasks; on the Eeklo-like sensitivity study (40 s on one worker) that overhead
alone kept two workers below 1.8× (measured: see ``benchmarks/bench_study_scaling.py``). The
pool's fork server imports crowdvib once per process (2.7–3.4 s measured in issue 24 on a
shared, busy 2-core machine, where dask's 2 s were not measured again), closes in milliseconds,
and has no bookkeeping beside the tasks; it replaced forking this process (0.1–0.2 s), which has
threads whose locks a fork copies as they are (Python 3.12+ warns of deadlocks).

Threads: a machine's cores are shared out between its workers. Each local worker runs BLAS
(OpenMP, OpenBLAS, MKL) and numba with its share, cores // workers, so that two workers on two
cores do not run four threads (measured in issue 14: two workers with multi-threaded BLAS were
1.36× slower than one). In this process (one worker) numba keeps all cores. Inside a task,
:func:`crowdvib.runner.tasks.run_tasks` further pins BLAS to one thread so that a task
gives the same bits wherever it runs.
"""

import concurrent.futures
import contextlib
import functools
import logging
import signal
import threading
import time

from .._resources import default_workers
from ..errors import CrowdvibError, ParameterError
from ._pool import ProcessPool

__all__ = ["study_executor", "SchedulerLost"]


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
        again elsewhere (see :class:`~crowdvib.runner._pool.ProcessPool`); defaults 60 s
        and 10.

    Yields
    ------
    concurrent.futures.Executor or None
        A :class:`~crowdvib.runner._pool.ProcessPool`, dask's executor, or None. When
        the dask scheduler is lost (its connection closes, or it answers no ping for 30 s),
        every unfinished task fails with one :class:`SchedulerLost`, which ends the study.

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
        executor = None
        try:
            with _dask_client(scheduler) as client:
                executor = _ClusterExecutor(client, scheduler)
                try:
                    yield executor
                finally:
                    executor.shutdown(wait=False)
        finally:
            if executor is not None:        # after the client's close, which logs the loss too
                executor.unquiet()
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


class SchedulerLost(CrowdvibError, ConnectionError):
    """The dask scheduler of a study was lost: its unfinished tasks fail, finished ones are kept."""


#: Seconds between two pings of a study's dask scheduler, and how long it may take to answer
#: one: a frozen scheduler (stopped, its host gone) keeps its connection open and says nothing.
#: A sound one took 2.7 s to answer while it imported crowdvib to read the first tasks (dask
#: 2026.8 unpickles tasks in the scheduler; measured on loopback, issue 24).
_PING_EVERY, _PING_TIMEOUT = 5.0, 30.0

#: Batches per dask worker thread a study's tasks are cut into (:meth:`_ClusterExecutor.batch_size`).
_BATCHES_PER_THREAD = 16

#: dask's loggers that tell the loss of the scheduler, with tracebacks, while the client retries.
_QUIET_LOGGERS = ("distributed.client", "distributed.utils", "distributed.core")


class _ClusterExecutor(concurrent.futures.Executor):
    """dask's executor on ``client``, telling at once that the scheduler is lost.

    On losing its scheduler a dask client cancels every unfinished task, each of which would
    then be a bare ``CancelledError``, logs tracebacks while it tries to reconnect, and cannot
    tell a frozen scheduler from a busy one (issue 24: a study waited minutes without a word).
    Here every unfinished task fails with one :class:`SchedulerLost` naming the scheduler, which
    ends ``run_tasks``; the scheduler is pinged every ``_PING_EVERY`` s, and the client's logs
    of the loss are left out.
    """

    def __init__(self, client, address):
        self._client, self._address = client, address
        self._inner = client.get_executor(pure=False)   # tasks are told apart by run_tasks
        self._pending = set()
        self._lock = threading.Lock()
        self._lost = None
        self._done = threading.Event()
        self._started = time.monotonic()
        self._quiet = _Quiet(self)
        for name in _QUIET_LOGGERS:
            logging.getLogger(name).addFilter(self._quiet)
        threading.Thread(target=self._watch, name="crowdvib-scheduler-ping", daemon=True).start()

    def submit(self, fn, /, *args, **kwargs):
        if self._lost is not None:
            raise self._lost
        outer = concurrent.futures.Future()
        with self._lock:
            self._pending.add(outer)
        inner = self._inner.submit(fn, *args, **kwargs)
        inner.add_done_callback(functools.partial(self._relay, outer))
        outer.add_done_callback(lambda done: inner.cancel() if done.cancelled() else None)
        return outer

    def batch_size(self, n_tasks):
        """Tasks per dask task (:func:`crowdvib.runner.tasks.run_tasks`): a task through dask
        costs some 8 ms of CPU in the client and scheduler against 0.4 ms on the local pool
        (issue 28; ``benchmarks/bench_season.py``), so small tasks go in batches, 16 per worker
        thread and study at least, which leaves the last batches short against the whole."""
        threads = max(1, sum(self._client.nthreads().values()))
        return max(1, n_tasks // (_BATCHES_PER_THREAD * threads))

    def shutdown(self, wait=True, *, cancel_futures=False):
        self._done.set()
        self._inner.shutdown(wait=wait)     # dask's cancels every unfinished task

    def unquiet(self):
        """Let dask's logs through again."""
        for name in _QUIET_LOGGERS:
            logging.getLogger(name).removeFilter(self._quiet)

    def _relay(self, outer, inner):
        """Hand dask's outcome of a task to ``outer``; a task cancelled by the loss of the
        scheduler fails with SchedulerLost."""
        if inner.cancelled() and not self._done.is_set() and self._client.status != "running":
            self._lose("its connection closed")
        with self._lock:
            if outer not in self._pending:      # failed by _lose already
                return
            self._pending.discard(outer)
        if inner.cancelled():
            outer.cancel()
            outer.set_running_or_notify_cancel()     # wakes as_completed, as dask's does
        elif inner.exception() is not None:
            outer.set_exception(inner.exception())
        else:
            outer.set_result(inner.result())

    def _lose(self, how):
        """Fail every unfinished task with one SchedulerLost (once)."""
        with self._lock:
            if self._lost is not None:
                return
            since = time.monotonic() - self._started
            self._lost = SchedulerLost(
                f"the dask scheduler at {self._address} was lost {since:.0f} s into the study "
                f"({how}); {len(self._pending)} unfinished task(s) stopped, the finished ones "
                "are kept: run the study again (resume) once it is back")
            pending, self._pending = self._pending, set()
        for future in pending:
            if not future.cancelled():          # cancelled by its caller meanwhile
                future.set_exception(self._lost)

    def _watch(self):
        """Ping the scheduler until shut down; no answer in _PING_TIMEOUT s: it is lost."""
        while not self._done.wait(_PING_EVERY):
            try:
                self._client.sync(self._client.scheduler.identity, callback_timeout=_PING_TIMEOUT)
            except Exception as error:
                if not self._done.is_set():
                    self._lose(f"no answer to a ping within {_PING_TIMEOUT:g} s: "
                               f"{type(error).__name__}")
                return


class _Quiet(logging.Filter):
    """Leaves out dask's logs once the scheduler is known lost (SchedulerLost says it once)."""

    def __init__(self, executor):
        super().__init__()
        self._executor = executor

    def filter(self, record):
        return self._executor._lost is None


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

