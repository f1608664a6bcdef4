"""Running many independent tasks on any ``concurrent.futures.Executor``, losing nothing.

The studies of :mod:`crowdvib.identification.sensitivity` are lists of deterministic tasks. :func:`run_tasks`
runs them in this process, on a local process pool or on a dask.distributed cluster
(``Client.get_executor()``); every finished task is written at once, atomically, to a
:class:`TaskStore`, so an interrupted study resumes without recomputing what is done, a task whose
worker crashed is submitted again, and a task that fails on bad input is recorded with its error
while the rest goes on.
"""

import concurrent.futures
import hashlib
import json
import logging
from pathlib import Path

from .._files import write_json
from ..errors import CrowdvibError, ParameterError

__all__ = ["TaskStore", "run_tasks"]

logger = logging.getLogger(__name__)


class TaskStore:
    """A directory holding one JSON file per finished task, each written atomically.

    A task's file name is derived from its key, so a resumed study finds what is done without any
    index file that could be left half-written.
    """

    def __init__(self, directory):
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)

    def _path(self, key):
        digest = hashlib.sha1(key.encode()).hexdigest()[:16]
        return self.directory / f"{digest}.json"

    def get(self, key):
        """The stored result of ``key``, or None."""
        path = self._path(key)
        if not path.exists():
            return None
        record = json.loads(path.read_text(encoding="utf-8"))
        return record["result"] if record.get("key") == key else None

    def put(self, key, result):
        """Store the result of ``key`` atomically."""
        write_json(self._path(key), {"key": key, "result": result})

    def keys(self):
        """Keys of every stored task."""
        return [json.loads(p.read_text(encoding="utf-8"))["key"]
                for p in sorted(self.directory.glob("*.json"))]


def run_tasks(function, tasks, *, executor=None, store=None, progress=None, retries=1):
    """Run ``function(payload)`` for every ``(key, payload)`` of ``tasks``; results by key.

    Parameters
    ----------
    function : callable
        A picklable, module-level function of one payload returning a JSON-ready dict.
    tasks : sequence of (str, object)
        Unique keys and payloads.
    executor : concurrent.futures.Executor, optional
        Where to run (default: in this process, one after the other).
    store : TaskStore, optional
        Finished results are written here as they arrive and read back instead of recomputed.
    progress : callable, optional
        ``progress(done, total)`` after every finished task.
    retries : int
        How often a task whose worker crashed is submitted again. A task that raises a crowdvib
        error is not retried: it is recorded as ``{"error": message}`` and the rest goes on.
    """
    tasks = list(tasks)
    keys = [key for key, _ in tasks]
    if len(set(keys)) != len(keys):
        raise ParameterError("tasks must have unique keys")
    results = {}
    pending = []
    for key, payload in tasks:
        stored = store.get(key) if store is not None else None
        if stored is not None:
            results[key] = stored
        else:
            pending.append((key, payload))
    total = len(tasks)

    def finish(key, result):
        results[key] = result
        if store is not None:
            store.put(key, result)
        if progress is not None:
            progress(len(results), total)

    if progress is not None and results:
        progress(len(results), total)
    if executor is None:
        for key, payload in pending:
            finish(key, _guarded(function, payload))
        return results
    attempts = {key: 0 for key, _ in pending}
    while pending:
        futures = {executor.submit(_guarded, function, payload): (key, payload)
                   for key, payload in pending}
        pending = []
        for future in concurrent.futures.as_completed(futures):
            key, payload = futures[future]
            try:
                finish(key, future.result())
            except Exception as error:  # a worker died (BrokenProcessPool, dask KilledWorker)
                attempts[key] += 1
                if attempts[key] > retries:
                    finish(key, {"error": f"worker failed {attempts[key]} times: {error!r}"})
                else:
                    logger.warning("task %s failed on its worker (%r); submitting it again",
                                   key, error)
                    pending.append((key, payload))
    return results


def _guarded(function, payload):
    """Run a task; a crowdvib error becomes a recorded result instead of stopping the study."""
    try:
        return function(payload)
    except CrowdvibError as error:
        return {"error": f"{type(error).__name__}: {error}"}
