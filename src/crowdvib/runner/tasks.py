"""Running many independent tasks, in this process or on an executor, losing nothing.

The studies of :mod:`crowdvib.studies.modelling_error` are lists of deterministic tasks.
:func:`run_tasks` runs them in this process or on any ``concurrent.futures.Executor`` (the
local workers or the dask cluster of :func:`crowdvib.runner.engine.study_executor`);
every finished task is written at once, atomically and fsync'd, to a :class:`TaskStore`, so an
interrupted study resumes without recomputing what is done.

A task is stored under a key made from its content: its name, a hash of everything that
determines its result (every array, number and option of its payload, the function that computes
it and crowdvib's major version). A study resumed on changed inputs therefore finds no result for
the tasks whose inputs changed and computes them again, saying so in a :class:`StudyWarning`
that names what differs; the results of the old inputs stay in the store and are used again if
the inputs change back. A damaged task file (empty, truncated, holding another task, its content
no longer matching the SHA-256 recorded when it was written, a result lacking a field its study
reads) is computed again with a warning naming it: an edited value is never taken as a result.
"""

import concurrent.futures
import dataclasses
import functools
import hashlib
import json
import logging
import os
import warnings
from pathlib import Path

import numpy as np

from .._files import canonical_json, write_json
from ..errors import CrowdvibError, ParameterError, StudyWarning
from .._version import __version__

__all__ = ["TaskStore", "run_tasks", "fingerprint"]

logger = logging.getLogger(__name__)


# ------------------------------------------------------------------------------ content keys
def fingerprint(function, payload, *, memo=None):
    """The content hash of a task: ``(digest, parts)``.

    Parameters
    ----------
    function : callable
        The task's function (its module and qualified name enter the hash).
    payload : object
        The task's input: dataclasses, arrays, numbers, strings, sequences and dicts of them.
    memo : dict, optional
        Array hashes by object id, shared between the tasks of one study so that an array they
        all hold (the measured PSD, the record) is hashed once.

    Returns
    -------
    digest : str
        16 hex digits identifying function, crowdvib major version and payload.
    parts : dict
        Input path (``"crowd.density"``, ``"options.band"``, ``"measured.psd"`` …) → 16 hex
        digits, to name what differs between two tasks of the same name.
    """

    memo = {} if memo is None else memo
    parts = {path: hashlib.sha256(_token(value, memo).encode()).hexdigest()[:16]
             for path, value in _parts(payload)}
    whole = hashlib.sha256()
    whole.update(f"{function.__module__}.{function.__qualname__}\n".encode())
    whole.update(f"crowdvib {__version__.split('.')[0]}\n".encode())
    for path in sorted(parts):
        whole.update(f"{path}={parts[path]}\n".encode())
    return whole.hexdigest()[:16], parts


def _parts(payload):
    """(path, value) pairs two levels deep: the payload's fields and their fields or options."""
    if not _is_dataclass(payload):
        yield "payload", payload
        return
    for name, value in _fields(payload):
        if _is_dataclass(value):
            for inner, item in _fields(value):
                yield f"{name}.{inner}", item
        elif _is_options(value):
            for option, item in value:
                yield f"{name}.{option}", item
        else:
            yield name, value


def _is_dataclass(value):
    return dataclasses.is_dataclass(value) and not isinstance(value, type)


def _fields(value):
    # Fields computed in __post_init__ (init=False) follow from the others: leaving them out
    # keeps the parts to what a user set.
    return [(f.name, getattr(value, f.name)) for f in dataclasses.fields(value) if f.init]


def _is_options(value):
    return (isinstance(value, tuple) and value
            and all(isinstance(item, tuple) and len(item) == 2 and isinstance(item[0], str)
                    for item in value))


def _token(value, memo):
    """A string equal for two values exactly when they hold the same data (floats bit for bit)."""
    if value is None or isinstance(value, (bool, np.bool_, str)):
        return repr(value if not isinstance(value, np.bool_) else bool(value))
    if isinstance(value, (int, np.integer)):
        return f"int:{int(value)}"
    if isinstance(value, (float, np.floating)):
        return f"float:{float(value).hex()}"
    if isinstance(value, (complex, np.complexfloating)):
        return f"complex:{value.real.hex()},{value.imag.hex()}"
    if isinstance(value, np.ndarray):
        return _array_token(value, memo)
    if isinstance(value, (list, tuple)):
        return "[" + ",".join(_token(item, memo) for item in value) + "]"
    if isinstance(value, dict):
        items = sorted((_token(k, memo), _token(v, memo)) for k, v in value.items())
        return "{" + ",".join(f"{k}:{v}" for k, v in items) + "}"
    if isinstance(value, os.PathLike):
        return f"path:{os.fspath(value)!r}"
    kind = f"{type(value).__module__}.{type(value).__qualname__}"
    if _is_dataclass(value):
        return kind + _token(dict(_fields(value)), memo)
    if hasattr(value, "__dict__"):
        return kind + _token(vars(value), memo)
    raise ParameterError(f"a task's payload must be made of dataclasses, arrays, numbers, strings, "
                         f"sequences and dicts; got a {kind}")


def _array_token(array, memo):
    known = memo.get(id(array))
    if known is not None and known[1] is array:
        return known[0]
    if array.dtype.hasobject:
        token = f"objects{array.shape}:" + _token(array.tolist(), memo)
    else:
        contiguous = np.ascontiguousarray(array)
        token = (f"array:{contiguous.dtype.str}{contiguous.shape}:"
                 f"{hashlib.sha256(contiguous.data).hexdigest()}")
    memo[id(array)] = (token, array)     # holding the array keeps its id from being reused
    return token


# ------------------------------------------------------------------------------ store
class TaskStore:
    """A directory holding one JSON file per finished task, each written atomically and fsync'd.

    A task's file name is derived from its key, so a resumed study finds what is done without any
    index file that could be left half-written. Each file holds the task's ``key``, ``name``, the
    hashes of its ``inputs`` (see :func:`fingerprint`), its ``result`` and the ``sha256`` of all
    four (:func:`record_digest`): a file whose content no longer matches it was not written so
    by crowdvib, and is neither reused nor (see :mod:`crowdvib._manifest`) ever deleted.

    Parameters
    ----------
    directory : str or os.PathLike
        The folder of the task files, made if missing.
    """

    def __init__(self, directory):
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)

    def _path(self, key):
        return self.directory / _file_name(key)

    def _read(self, path):
        return read_task_file(path)

    def _damaged(self, path, reason):
        warnings.warn(f"task file {path} is damaged ({reason}); its task is computed again",
                      StudyWarning, stacklevel=4)

    def get(self, key):
        """The stored result of ``key``, or None (with a :class:`StudyWarning` if damaged).

        Parameters
        ----------
        key : str
            The task's key.
        """
        path = self._path(key)
        if not path.exists():
            return None
        try:
            record = self._read(path)
        except ValueError as error:
            self._damaged(path, error)
            return None
        return record["result"] if record["key"] == key else None

    def put(self, key, result, *, name=None, inputs=None):
        """Store the result of ``key`` atomically, on disk before this returns.

        Parameters
        ----------
        key : str
            The task's key (it names the file).
        result : object
            The task's result, JSON-serialisable.
        name : str, optional
            The task's function, for the record.
        inputs : dict, optional
            The task's inputs, stored as their hashes (:func:`fingerprint`).
        """
        record = {"key": key, "name": key if name is None else name, "inputs": inputs or {},
                  "result": result}
        record["sha256"] = record_digest(record)
        write_json(self._path(key), record, fsync=True)

    def records(self, *, warn=True, fields=()):
        """Every readable task record, by key; damaged files (or results lacking one of
        ``fields``) are skipped with a warning.

        Parameters
        ----------
        warn : bool
            Warn (:class:`StudyWarning`) of each file skipped.
        fields : sequence of str
            Keys every result must hold to be returned.

        Returns
        -------
        dict
            Key → the task's record (``key``, ``name``, ``inputs``, ``result``, ``sha256``).
        """
        records = {}
        for path in sorted(self.directory.glob("*.json")):
            try:
                record = self._read(path)
                missing = [f for f in fields if f not in record["result"]]
                if missing and "error" not in record["result"]:
                    raise ValueError(f"its result lacks {', '.join(missing)}")
            except (ValueError, OSError) as error:
                if warn:
                    self._damaged(path, error)
                continue
            record["modified"] = path.stat().st_mtime_ns
            records[record["key"]] = record
        return records

    def keys(self):
        """Keys of every readable stored task."""
        return list(self.records(warn=False))


def _file_name(key):
    return hashlib.sha1(key.encode()).hexdigest()[:16] + ".json"


def read_task_file(path):
    """The task record in ``path``; ValueError saying what is wrong with it.

    A record is crowdvib's only if its content matches the digest written with it and its file
    is named after its key: :mod:`crowdvib._manifest` deletes no other file of a store.
    """
    path = Path(path)
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError:
        raise ValueError("not UTF-8 text") from None
    if not text.strip():
        raise ValueError("empty")
    try:
        record = json.loads(text)
    except json.JSONDecodeError as error:
        raise ValueError(f"not valid JSON, truncated? ({error.msg} at byte {error.pos})") \
            from None
    if not (isinstance(record, dict) and isinstance(record.get("key"), str)
            and isinstance(record.get("result"), dict)):
        raise ValueError("not a task record (needs a 'key' and a 'result')")
    if record.get("sha256") != record_digest(record):
        raise ValueError("its content does not match the SHA-256 crowdvib recorded when it "
                         "wrote it: edited since?")
    if _file_name(record["key"]) != path.name:
        raise ValueError("holds the key of another task")
    return record


def record_digest(record):
    """SHA-256 of a task record's ``key``, ``name``, ``inputs`` and ``result`` as stored (NaN as
    null, canonical JSON): equal for the record written and the record read back."""
    content = {field: record.get(field) for field in ("key", "name", "inputs", "result")}
    return hashlib.sha256(canonical_json(content).encode()).hexdigest()


# ------------------------------------------------------------------------------ running
def run_tasks(function, tasks, *, executor=None, store=None, progress=None, fields=(),
              batch_size=None):
    """Run ``function(payload)`` for every ``(name, payload)`` of ``tasks``; results by name.

    Parameters
    ----------
    function : callable
        A picklable, module-level function of one payload returning a JSON-ready dict.
    tasks : sequence of (str, object)
        Unique names and payloads.
    executor : concurrent.futures.Executor, optional
        Where to run (default: in this process, one after the other). Crashed workers are the
        executor's business: crowdvib's local pool and a dask cluster run a dead worker's task
        again on another worker.
    store : TaskStore or path, optional
        Finished results are written here as they arrive, under keys made from their content
        (:func:`fingerprint`), and read back instead of recomputed.
    progress : callable, optional
        ``progress(done, total)`` after every finished task.
    fields : sequence of str
        Keys every result of ``function`` holds (unless it is an ``{"error": …}``): a stored
        result lacking one is computed again, with a warning naming its file.
    batch_size : int, optional
        Tasks sent to the executor together, as one of its tasks (each still stored, resumed
        and reported on its own). Default: what the executor asks for (its
        ``batch_size(n_tasks)``: a dask cluster's per-task overhead calls for batches of small
        tasks, :mod:`crowdvib.runner.engine`), else 1.

    Returns
    -------
    dict
        Name → result. A task that raises a crowdvib error is recorded (and stored) as
        ``{"error": message}`` and the rest goes on; a task its executor gave up on (its worker
        died more often than the executor retries) is reported the same way but not stored, so a
        resumed study tries it again. Ctrl-C (KeyboardInterrupt) cancels what has not finished and
        keeps what has.
    """
    tasks = list(tasks)
    names = [name for name, _ in tasks]
    if len(set(names)) != len(names):
        raise ParameterError("tasks must have unique names")
    if store is not None and not isinstance(store, TaskStore):
        if not isinstance(store, (str, os.PathLike)):
            raise ParameterError(f"store must be a folder (str or path), a TaskStore or None, "
                                 f"got {type(store).__name__} {store!r}"[:200])
        store = TaskStore(store)
    memo = {}
    keyed = []                                   # (name, payload, key, parts)
    for name, payload in tasks:
        digest, parts = fingerprint(function, payload, memo=memo)
        keyed.append((name, payload, f"{name}@{digest}", parts))
    del memo
    stored = store.records(fields=fields) if store is not None else {}
    results = {name: stored[key]["result"] for name, _, key, _ in keyed if key in stored}
    pending = [task for task in keyed if task[0] not in results]
    total = len(tasks)
    if pending and stored:
        _warn_changed(pending, stored, total, store)

    def finish(name, key, parts, result):
        results[name] = result
        if store is not None:
            store.put(key, result, name=name, inputs=parts)
        if progress is not None:
            progress(len(results), total)

    if progress is not None and results:
        progress(len(results), total)
    size = _batch_size(batch_size, executor, len(pending))
    if executor is None:
        for name, payload, key, parts in pending:
            finish(name, key, parts, _guarded(function, payload))
        return results
    batches = [pending[start:start + size] for start in range(0, len(pending), size)]
    futures = {(executor.submit(_guarded, function, batch[0][1]) if size == 1 else
                executor.submit(_guarded_batch, function, [task[1] for task in batch])): batch
               for batch in batches}
    try:
        for future in concurrent.futures.as_completed(futures):
            batch = futures[future]
            try:
                found = future.result()
            except CrowdvibError:        # the executor itself is lost (engine.SchedulerLost):
                raise                    # tasks' own errors are results (_guarded)
            except Exception as error:   # the executor gave up (KilledWorker, BrokenProcessPool)
                for name, *_ in batch:
                    logger.warning("task %s failed on its worker: %r", name, error)
                    results[name] = {"error": f"its worker failed ({error!r}); run the study "
                                              "again (resume) to retry it"}
                if progress is not None:
                    progress(len(results), total)
                continue
            for (name, _, key, parts), result in zip(batch, [found] if size == 1 else found):
                finish(name, key, parts, result)
    except BaseException:
        # Ctrl-C or a failed write: what has not started never will, what finished is stored.
        _cancel(executor)
        raise
    return results


def _cancel(executor):
    """Cancel every unfinished task of ``executor`` in one call (one by one, a dask cluster
    takes a round trip each: seconds for a study of a hundred tasks)."""
    try:
        executor.shutdown(wait=False, cancel_futures=True)     # concurrent.futures executors
    except TypeError:
        executor.shutdown(wait=False)        # dask's ClientExecutor cancels all on shutdown


def _warn_changed(pending, stored, total, store):
    """Warn that stored results of the same task names were computed from other inputs."""
    latest = {}
    for record in sorted(stored.values(), key=lambda r: r["modified"]):
        latest[record.get("name", record["key"])] = record
    changed = [task for task in pending if task[0] in latest]
    if not changed:
        return
    differs = set()
    for name, _, _, parts in changed:
        before = latest[name].get("inputs") or {}
        differs |= {path for path in parts.keys() | before.keys()
                    if parts.get(path) != before.get(path)}
    what = ", ".join(sorted(differs)) or "crowdvib's version or the task's function"
    warnings.warn(f"inputs changed since the study began ({what}): {len(changed)} of {total} "
                  f"tasks will be recomputed (the old results stay in {store.directory})",
                  StudyWarning, stacklevel=3)


def _batch_size(batch_size, executor, n_tasks):
    """Tasks per submission: as given, else as the executor asks (``batch_size(n)``), else 1."""
    if batch_size is None:
        ask = getattr(executor, "batch_size", None)
        return max(1, int(ask(n_tasks))) if callable(ask) else 1
    if isinstance(batch_size, bool) or not isinstance(batch_size, int) or batch_size < 1:
        raise ParameterError(f"batch_size must be an integer >= 1, got {batch_size!r}")
    return batch_size


def _guarded_batch(function, payloads):
    """Several tasks as one submission (:func:`_guarded` each): their results, in order."""
    return [_guarded(function, payload) for payload in payloads]


def _guarded(function, payload):
    """Run a task with one BLAS thread; a crowdvib error becomes a recorded result.

    The number of BLAS threads sets the order of BLAS sums, and the estimator turns a change
    in the last bits into one in the 7th digit (measured on eeklo_like: this process's 2 BLAS
    threads against a dask worker's 1). With one everywhere, a task gives the same bits in this
    process, on a local worker or on a remote one.
    """
    with _blas_threads().limit(limits=1, user_api="blas"):
        try:
            return function(payload)
        except CrowdvibError as error:
            return {"error": f"{type(error).__name__}: {error}"}


@functools.lru_cache(maxsize=1)
def _blas_threads():
    """The BLAS libraries of this process, found once (after numpy and scipy are loaded)."""
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController()
