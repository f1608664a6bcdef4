"""Worker processes on this machine for a study's tasks (the local half of
:func:`crowdvib.identification.engine.study_executor`).

A :class:`ProcessPool` is a ``concurrent.futures.Executor`` with one parent thread per worker
process, which hands its worker one task at a time and so always knows what each worker holds:

* **A worker that dies** (killed, out of memory) is replaced by a new one, and the task it held
  runs again there, up to ``attempts`` times in all; then that task alone fails (with
  :class:`WorkerDied`). ``concurrent.futures.ProcessPoolExecutor`` instead breaks as a whole.
* **The parent dies**, even by SIGKILL: every worker watches a lifeline pipe whose only write
  end the parent holds; the kernel closes it with the parent, and the worker exits at once,
  even in the middle of a task.
* **Ctrl-C** reaches a terminal's whole process group: workers ignore SIGINT, and the parent
  decides (``run_tasks`` cancels what has not started, :meth:`ProcessPool.close` kills the
  workers still busy).

Workers are started by ``fork`` where that is safe (Linux): they inherit every module and
compiled kernel the parent has loaded, so two of them start in milliseconds. A local dask
cluster took 2 s to start (spawned processes importing crowdvib again) and 0.5 s to close, a
tenth of the Eeklo-like sensitivity study on two workers (measured, issue 14). Elsewhere
(macOS, Windows) they are spawned. Each worker's BLAS, OpenMP and numba pools get its share of
the cores, cores // workers.
"""

import collections
import concurrent.futures
import multiprocessing
import multiprocessing.connection
import os
import signal
import sys
import threading
import traceback

from .._threads import THREAD_VARIABLES, thread_share
from ..errors import ParameterError

__all__ = ["ProcessPool", "WorkerDied"]


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


class ProcessPool(concurrent.futures.Executor):
    """``workers`` processes running submitted calls, surviving the death of any of them.

    Parameters
    ----------
    workers : int
        Worker processes (>= 1).
    attempts : int
        Tries a task gets: after ``attempts`` workers died running it, it fails with
        :class:`WorkerDied` (it is then likely the cause, e.g. by running out of memory).
    method : str, optional
        ``multiprocessing`` start method; default ``fork`` on Linux, else ``spawn``.
    """

    def __init__(self, workers, *, attempts=3, method=None):
        for name, value in (("workers", workers), ("attempts", attempts)):
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ParameterError(f"{name} must be an integer >= 1, got {value!r}")
        if method is None:
            method = "fork" if sys.platform.startswith("linux") else "spawn"
        self._context = multiprocessing.get_context(method)
        self._share = thread_share(workers)
        self._attempts = attempts
        self._queue = collections.deque()
        self._ready = threading.Condition()
        self._closed = False
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
        """Shut down; ``kill`` first kills the workers still running a task (after Ctrl-C:
        their results would be thrown away), their futures then fail."""
        self.shutdown(wait=False, cancel_futures=kill)
        if kill:
            for process in list(self._processes.values()):
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
        """Hand tasks to the worker of ``slot`` one at a time; replace it if it dies."""
        try:
            while True:
                item = self._next()
                if item is None:
                    break
                if item.attempts == 0 and not item.future.set_running_or_notify_cancel():
                    continue
                try:
                    outcome = _exchange(connection, process, item.call)
                except BaseException as error:      # a bug of ours: fail the task, not hang
                    item.future.set_exception(error)
                    raise
                if outcome is not None:
                    _settle(item.future, *outcome)
                    continue
                # The worker died holding this task.
                process.join()
                connection.close()
                item.attempts += 1
                with self._ready:
                    retry = item.attempts < self._attempts and not self._closed
                    if retry:
                        self._queue.appendleft(item)
                dead = process
                if not self._closed:            # the new worker first: then the failure is told
                    process, connection = self._start(slot)
                if not retry:
                    item.future.set_exception(WorkerDied(
                        f"the worker running this task died {item.attempts} time(s) "
                        f"(last exit code {dead.exitcode})"))
                if self._closed:
                    return
        finally:
            _stop(process, connection)


def _exchange(connection, process, call):
    """Send ``call`` to the worker and wait for its reply: ``(status, value, text)``, or None
    if the worker died first."""
    try:
        connection.send(call)
    except (BrokenPipeError, ConnectionResetError, EOFError):
        return None
    except Exception as error:          # the call cannot be pickled: nothing was sent
        return "error", error, None
    ready = multiprocessing.connection.wait([connection, process.sentinel])
    if connection in ready:
        try:
            return connection.recv()
        except (EOFError, ConnectionResetError):
            return None
    return None


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


def _block_interrupts():
    if hasattr(signal, "pthread_sigmask"):
        return signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    return None


def _restore_interrupts(held):
    if held is not None:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)


# ------------------------------------------------------------------------ worker side
def _work(connection, lifeline, lifeline_end, share):
    """A worker's life: ignore Ctrl-C, die with the parent, run calls until told to stop."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
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

    A forked worker inherits pools sized for the whole machine, so the environment variables
    (read when a library loads) are not enough: they are set for what loads later and for child
    processes, and the loaded libraries are limited directly.
    """
    for name in THREAD_VARIABLES:
        os.environ[name] = str(share)
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=share)
    if "numba" in sys.modules:
        import numba

        numba.set_num_threads(min(share, numba.config.NUMBA_NUM_THREADS))
