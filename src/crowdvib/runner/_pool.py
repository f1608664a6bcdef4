"""Worker processes on this machine for a study's tasks (the local half of
:func:`crowdvib.runner.engine.study_executor`).

A :class:`ProcessPool` is a ``concurrent.futures.Executor`` with one parent thread per worker
process, which hands its worker one task at a time and so always knows what each worker holds:

* **A worker that dies** (killed, out of memory) is replaced by a new one, and the task it held
  runs again there, up to ``attempts`` times in all; then that task alone fails (with
  :class:`WorkerDied`). ``concurrent.futures.ProcessPoolExecutor`` instead breaks as a whole.
* **A worker that hangs** (stopped by SIGSTOP, stuck in native code) is noticed: a task that has
  run longer than max(``timeout_floor``, ``timeout_factor`` × the slowest task finished so far)
  has its worker killed, and is then handled as above (issue 24: a stopped worker used to stop
  the study forever, without a word).
* **The parent dies**, even by SIGKILL: every worker watches a lifeline pipe whose only write
  end the parent holds; the kernel closes it with the parent, and the worker exits at once,
  even in the middle of a task.
* **Ctrl-C** reaches a terminal's whole process group: workers ignore SIGINT, and the parent
  decides (``run_tasks`` cancels what has not started, :meth:`ProcessPool.close` kills the
  workers still busy).

Workers are forked by a fork server (POSIX) that has imported crowdvib's studies once, with a
single thread. Forking this process directly was faster to start (two workers in 0.1 s, issue
14), but it has threads (the pool's own, numba's, BLAS's) whose locks a fork copies as they are,
possibly held, and Python 3.12 and later warn of the deadlocks that follow; the replacement of a
dead worker was forked from a pool thread. Measured (issue 24, on a shared 2-core machine,
Python 3.11 and 3.13, first results of two workers): the first pool of a process waits 2.7–3.4 s
for the server to import crowdvib, every later one 0.15 s, as with fork (0.1–0.2 s); spawning
each worker instead took 7 s (each imports crowdvib). Kernels that numba has cached on disk load
in each worker. Elsewhere (Windows) workers are spawned. Each worker's BLAS, OpenMP and numba
pools get its share of the cores, cores // workers.
"""

import collections
import concurrent.futures
import logging
import math
import multiprocessing
import multiprocessing.connection
import numbers
import os
import signal
import threading
import time
import traceback
import warnings

from .._resources import BUDGET_VARIABLE, THREAD_VARIABLES, thread_share
from ..errors import ParameterError, PlausibilityWarning

__all__ = ["ProcessPool", "WorkerDied"]

logger = logging.getLogger(__name__)

#: What the fork server imports once, for every worker it forks: the studies and their kernels.
_PRELOAD = ["crowdvib.studies"]
#: Seconds the workers ended after Ctrl-C get to exit (and release their semaphores) before
#: they are killed.
_GRACE = 2.0

#: Seconds between two looks at a busy worker's time limit (it grows as tasks finish).
_POLL = 1.0

#: Beyond this a timeout_floor is more likely milliseconds than seconds.
_LONGEST_PLAUSIBLE_FLOOR = 6 * 3600.0


class WorkerDied(RuntimeError):
    """A task whose worker process died on every attempt."""


class _RemoteTraceback(Exception):
    """The traceback of an exception raised in a worker, as text (kept as ``__cause__``)."""

    def __str__(self):
        return self.args[0]


class _Item:
    """A submitted call and its future; ``attempts`` counts the workers that died running it."""

    __slots__ = ("future", "call", "attempts")

    def __init__(self, future, call):
        self.future, self.call, self.attempts = future, call, 0


#: What ``_exchange`` returns for a worker that did not answer within its task's time limit.
_HUNG = object()


class ProcessPool(concurrent.futures.Executor):
    """``workers`` processes running submitted calls, surviving the death of any of them.

    Parameters
    ----------
    workers : int
        Worker processes (>= 1).
    attempts : int
        Tries a task gets: after ``attempts`` workers died or hung running it, it fails with
        :class:`WorkerDied` (it is then likely the cause, e.g. by running out of memory).
    method : str, optional
        ``multiprocessing`` start method; default ``forkserver`` where there is one (POSIX),
        else ``spawn``. Tasks must be importable functions, as for ``spawn``.
    timeout_floor : float
        Seconds a task may always run (default 60); ``math.inf``: no time limit.
    timeout_factor : float
        A task may run this many times as long as the slowest task finished so far (default
        10: tasks of one study differ in size, and a worker's first task compiles or loads
        numba's kernels); the limit is max(``timeout_floor``, ``timeout_factor`` × slowest).
        Until a task has finished it is ``timeout_floor`` if ``timeout_factor`` is 0 (a fixed
        limit), else none.
    """

    def __init__(self, workers, *, attempts=3, method=None, timeout_floor=60.0,
                 timeout_factor=10.0):
        for name, value in (("workers", workers), ("attempts", attempts)):
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ParameterError(f"{name} must be an integer >= 1, got {value!r}")
        self._floor, self._factor = _check_timeout(timeout_floor, timeout_factor)
        self._slowest = None                   # seconds of the slowest finished task
        if method is None:
            method = ("forkserver" if "forkserver" in multiprocessing.get_all_start_methods()
                      else "spawn")
        self._context = multiprocessing.get_context(method)
        if method == "forkserver":
            _start_fork_server(self._context)
        self._share = thread_share(workers)
        self._attempts = attempts
        self._queue = collections.deque()
        self._ready = threading.Condition()
        self._closed = False
        self._ending = False                     # close(kill=True): the pool ends its workers
        # One lifeline for all workers: each closes the write end it inherits, so the parent
        # holds the only one and its death closes the pipe for every worker.
        self._lifeline, self._lifeline_end = self._context.Pipe(duplex=False)
        self._starting = threading.Lock()          # one fork at a time (no leaked pipe ends)
        self._processes = {}
        self._threads = []
        started = [self._start(slot) for slot in range(workers)]
        for slot, (process, connection) in enumerate(started):
            thread = threading.Thread(target=self._serve, args=(slot, process, connection),
                                      name=f"crowdvib-pool-{slot}", daemon=True)
            thread.start()
            self._threads.append(thread)

    # -------------------------------------------------------------------- Executor interface
    def submit(self, fn, /, *args, **kwargs):
        future = concurrent.futures.Future()
        with self._ready:
            if self._closed:
                raise RuntimeError("cannot submit to a closed ProcessPool")
            self._queue.append(_Item(future, (fn, args, kwargs)))
            self._ready.notify()
        return future

    def shutdown(self, wait=True, *, cancel_futures=False):
        """No new tasks; ``cancel_futures`` cancels those not started; ``wait`` waits for the
        running ones and for the workers to exit."""
        with self._ready:
            self._closed = True
            if cancel_futures:
                while self._queue:
                    item = self._queue.popleft()
                    if item.attempts == 0:
                        item.future.cancel()
                    else:                  # running once already: it cannot be cancelled
                        item.future.set_exception(concurrent.futures.CancelledError())
            self._ready.notify_all()
        if wait:
            for thread in self._threads:
                thread.join()

    def __exit__(self, *exc_info):
        self.close()
        return False

    def close(self, *, kill=False):
        """Shut down; ``kill`` first ends the workers still running a task (after Ctrl-C:
        their results would be thrown away), their futures then fail, without a word: the pool
        ended them, they did not die (issue 36 §3). Each is asked to exit (SIGTERM: it exits
        as a process does, releasing the semaphores numba made in it, which a kill leaks) and
        killed if it has not after :data:`_GRACE` s."""
        self.shutdown(wait=False, cancel_futures=kill)
        if kill:
            self._ending = True
            processes = list(self._processes.values())
            for process in processes:
                process.terminate()
            deadline = time.monotonic() + _GRACE
            for thread in self._threads:
                thread.join(timeout=max(deadline - time.monotonic(), 0.0))
            for slot, process in enumerate(processes):
                if self._threads[slot].is_alive():    # its worker has not exited yet
                    process.kill()
        for thread in self._threads:
            thread.join()
        self._lifeline_end.close()

    # -------------------------------------------------------------------- parent side
    def _start(self, slot):
        """A new worker process for ``slot`` and the parent's end of its task pipe."""
        ours, theirs = self._context.Pipe()
        process = self._context.Process(
            target=_work, name=f"crowdvib-worker-{slot}", daemon=True,
            args=(theirs, self._lifeline, self._lifeline_end if self._forks else None,
                  self._share))
        # The worker starts with SIGINT blocked (inherited from the forking thread) and ignores
        # it before unblocking: a Ctrl-C during its start cannot raise in it.
        with self._starting:
            held = _block_interrupts()
            try:
                process.start()
            finally:
                _restore_interrupts(held)
            theirs.close()
        self._processes[slot] = process
        return process, ours

    @property
    def _forks(self):
        return self._context.get_start_method() == "fork"

    def _next(self):
        """The next item to run, or None once closed and drained."""
        with self._ready:
            while not self._queue and not self._closed:
                self._ready.wait()
            return self._queue.popleft() if self._queue else None

    def _serve(self, slot, process, connection):
        """Hand tasks to the worker of ``slot`` one at a time; replace it if it dies or hangs."""
        try:
            while True:
                item = self._next()
                if item is None:
                    break
                if item.attempts == 0 and not item.future.set_running_or_notify_cancel():
                    continue
                started = time.monotonic()
                try:
                    outcome = self._exchange(connection, process, item.call, started)
                except BaseException as error:      # a bug of ours: fail the task, not hang
                    item.future.set_exception(error)
                    raise
                held = time.monotonic() - started
                if outcome is not None and outcome is not _HUNG:
                    with self._ready:
                        self._slowest = max(self._slowest or 0.0, held)
                    _settle(item.future, *outcome)
                    continue
                if outcome is _HUNG:
                    process.kill()                  # SIGKILL ends a stopped process too
                process.join()
                connection.close()
                if self._ending:                    # ended by close(kill=True), not dead
                    item.future.set_exception(WorkerDied("the pool ended its worker "
                                                         "(close(kill=True): interrupted)"))
                    return
                item.attempts += 1
                reason = (f"killed after {held:.1f} s without an answer, past the time limit "
                          f"{self._describe_limit()}" if outcome is _HUNG
                          else f"exit code {process.exitcode}")
                with self._ready:
                    retry = item.attempts < self._attempts and not self._closed
                    if retry:
                        self._queue.appendleft(item)
                logger.warning("worker %d (pid %d) %s; its task %s", slot, process.pid,
                               ("hung, " if outcome is _HUNG else "died, ") + reason,
                               f"runs again (attempt {item.attempts + 1} of {self._attempts})"
                               if retry else "fails")
                if not self._closed:            # the new worker first: then the failure is told
                    try:
                        process, connection = self._start(slot)
                    except BaseException as error:
                        self._break(error)
                        raise
                if not retry:
                    item.future.set_exception(WorkerDied(
                        f"the worker running this task died {item.attempts} time(s) "
                        f"(last {reason})"))
                if self._closed:
                    return
        finally:
            _stop(process, connection)

    def _limit(self):
        """Seconds a task may run now, or None (no task has finished to measure it by)."""
        if self._factor == 0:
            return self._floor
        if self._slowest is None:
            return None
        return max(self._floor, self._factor * self._slowest)

    def _describe_limit(self):
        return (f"{self._limit():.3g} s = max(timeout_floor {self._floor:g} s, timeout_factor "
                f"{self._factor:g} × {self._slowest or 0.0:.3g} s, the slowest finished task)")

    def _exchange(self, connection, process, call, started):
        """Send ``call`` to the worker and wait for its reply: ``(status, value, text)``; None
        if the worker died first, ``_HUNG`` if it ran past the time limit."""
        try:
            connection.send(call)
        except (BrokenPipeError, ConnectionResetError, EOFError):
            return None
        except Exception as error:          # the call cannot be pickled: nothing was sent
            return "error", error, None
        while True:
            # Looked at again every _POLL s: the limit appears and grows as other tasks finish.
            limit = self._limit()
            left = _POLL if limit is None else min(_POLL, started + limit - time.monotonic())
            ready = multiprocessing.connection.wait([connection, process.sentinel],
                                                    timeout=max(left, 0.0))
            if connection in ready:
                try:
                    return connection.recv()
                except (EOFError, ConnectionResetError):
                    return None
            if ready:
                return None
            if limit is not None and time.monotonic() - started >= limit:
                return _HUNG

    def _break(self, error):
        """No new worker could be started: fail every task left rather than wait for none."""
        with self._ready:
            self._closed = True
            while self._queue:
                self._queue.popleft().future.set_exception(WorkerDied(
                    f"no worker could be started to run this task ({error!r})"))
            self._ready.notify_all()


def _check_timeout(floor, factor):
    """``(timeout_floor, timeout_factor)`` as floats, or a ParameterError naming the bad one."""
    for name, value, rule in (("timeout_floor", floor, "a number of seconds > 0 (inf: no limit)"),
                              ("timeout_factor", factor, "a finite number >= 0")):
        if (isinstance(value, bool) or not isinstance(value, numbers.Real) or math.isnan(value)
                or value < 0 or (name == "timeout_floor" and value == 0)
                or (name == "timeout_factor" and math.isinf(value))):
            raise ParameterError(f"{name} must be {rule}, got {value!r}")
    if _LONGEST_PLAUSIBLE_FLOOR < floor < math.inf:
        warnings.warn(f"timeout_floor = {floor:g} s is {floor / 3600:.3g} h: milliseconds given "
                      f"for seconds? (it would then be {floor / 1000:g} s)", PlausibilityWarning,
                      stacklevel=3)
    if 0 < factor < 2:
        warnings.warn(f"timeout_factor = {factor:g} kills a task that runs less than twice as long "
                      "as the slowest one finished, which tasks of one study often do; a fraction "
                      f"given for a multiple? ({factor:g} → {100 * factor:g})",
                      PlausibilityWarning, stacklevel=3)
    return float(floor), float(factor)


def _settle(future, status, value, text):
    if status == "ok":
        future.set_result(value)
        return
    if text is not None:
        value.__cause__ = _RemoteTraceback(text)
    future.set_exception(value)


def _stop(process, connection):
    """Ask an idle worker to exit; kill it if it has not after 2 s."""
    try:
        connection.send(None)
    except (OSError, EOFError):
        pass
    process.join(timeout=2.0)
    if process.exitcode is None:
        process.kill()
        process.join()
    connection.close()


def _start_fork_server(context):
    """Start the fork server of this process, if not running, with crowdvib's studies loaded
    and Ctrl-C ignored: its children inherit that from their birth (Python keeps an ignored
    SIGINT across exec, the server hands it on), so a Ctrl-C while a worker starts cannot kill
    it with a traceback before :func:`_work` runs. Later pools of this process share it."""
    from multiprocessing import forkserver

    context.set_forkserver_preload(_PRELOAD)
    main = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN) if main else None
    try:
        forkserver.ensure_running()
    finally:
        if main:
            signal.signal(signal.SIGINT, previous)


def _block_interrupts():
    if hasattr(signal, "pthread_sigmask"):
        return signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    return None


def _restore_interrupts(held):
    if held is not None:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)


# ------------------------------------------------------------------------ worker side
def _end(signum, frame):
    """SIGTERM from :meth:`ProcessPool.close`: leave the task and the worker (SystemExit ends
    the process as a return would, its finalizers run)."""
    _ENDING.append(signum)
    raise SystemExit(1)


#: The signal that ended this worker, once it came.
_ENDING: list = []


def _work(connection, lifeline, lifeline_end, share):
    """A worker's life: ignore Ctrl-C, die with the parent, run calls until told to stop, exit
    when the pool ends it (SIGTERM)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, _end)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    if lifeline_end is not None:
        lifeline_end.close()                 # the copy fork gave us: the parent's must be alone
    threading.Thread(target=_watch, args=(lifeline,), daemon=True).start()
    _limit_threads(share)
    while True:
        try:
            call = connection.recv()
        except (EOFError, OSError):
            return
        if call is None:
            return
        function, args, kwargs = call
        try:
            reply = "ok", function(*args, **kwargs), None
        except Exception as error:
            reply = "error", error, traceback.format_exc()
        except BaseException as error:       # sys.exit() in a task must not end the parent
            if _ENDING:
                return
            reply = "error", RuntimeError(f"the task ended its worker: {error!r}"), None
        try:
            connection.send(reply)
        except Exception as error:           # a result or an exception that does not pickle
            connection.send(("error", RuntimeError(
                f"the task's {'result' if reply[0] == 'ok' else 'exception'} could not be sent "
                f"back from its worker: {error!r}"), None))


def _watch(lifeline):
    """Exit the moment the parent is gone (its end of the lifeline closes)."""
    try:
        lifeline.recv()
    except (EOFError, OSError):
        pass
    os._exit(1)


def _limit_threads(share):
    """BLAS, OpenMP and numba sized to this worker's share of the cores.

    A forked worker inherits libraries loaded with pools sized for the whole machine, so they are
    limited directly; the environment variables are set for what loads later and for child
    processes. ``NUMBA_NUM_THREADS`` is left alone: numba reads it again before each compilation
    and raises once its pool is running if it changed (numba.core.config, issue 24: every task
    of a study from a cold cache failed); crowdvib's own code reads ``CROWDVIB_THREADS``.
    """
    os.environ[BUDGET_VARIABLE] = str(share)
    for name in THREAD_VARIABLES:
        os.environ[name] = str(share)
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=share)
    import numba

    numba.set_num_threads(min(share, numba.config.NUMBA_NUM_THREADS))
