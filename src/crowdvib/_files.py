"""Safe file output: atomic writes (a reader never sees a half-written file, a crash leaves the
old one intact), write failures as one error naming the path and the cause, a lock that keeps
two runs from writing one results folder, and file names from user strings that cannot leave
their directory."""

import contextlib
import datetime
import errno
import json
import math
import os
import socket
import sys
import tempfile
from pathlib import Path

from .errors import DataError, OutputError, ParameterError

#: File name of the manifest every command writes into its results folder (crowdvib._manifest):
#: a folder holding one is crowdvib's output, never anyone's input.
MANIFEST_NAME = "crowdvib-manifest.json"

# ------------------------------------------------------------------------------ write failures
#: What an errno means for someone writing results, and what to do about it.
_CAUSES = {
    errno.ENOSPC: "the disk is full: free space and run again; a study continues with --resume",
    errno.EDQUOT: "the disk quota is used up: free space and run again",
    errno.EROFS: "the file system is mounted read-only",
    errno.EFBIG: "over the file-size limit of this process, ulimit -f, or of the file system",
    errno.EACCES: "check the permissions of the file and its folder",
    errno.EPERM: "an immutable file or folder? see lsattr",
}


def os_error_text(error, path=None):
    """``PATH: cause (what it means)`` for an ``OSError``; ``path`` replaces the error's own (the
    result a temporary file was for)."""
    where = path if path is not None else error.filename
    hint = _CAUSES.get(error.errno)
    text = (error.strerror or str(error)) + (f" ({hint})" if hint else "")
    return text if where is None else f"{where}: {text}"


def output_error(error, path=None):
    """The :class:`OutputError` for an ``OSError`` met writing ``path`` (see
    :func:`os_error_text`)."""
    return OutputError(f"cannot write {os_error_text(error, path)}")


@contextlib.contextmanager
def atomic_path(path, *, fsync=False):
    """Yield a temporary path beside ``path``; on success it replaces ``path`` in one rename.

    With ``fsync``, the file's bytes reach the disk before the rename and the rename reaches it
    after: a power cut then leaves the old file or the new one, never an empty one (a rename
    alone orders nothing on ext4/xfs with delayed allocation).
    """
    path = Path(path)
    temporary = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part",
                                             dir=path.parent)
        os.close(handle)
        # mkstemp creates 0600 files; give the result the permissions a plain open() would.
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(temporary, 0o666 & ~umask)
        yield Path(temporary)
        if fsync:
            _fsync(temporary, os.O_RDONLY)
        os.replace(temporary, path)
        if fsync:
            _fsync(path.parent, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OutputError:
        raise
    except OSError as error:         # disk full, read-only, size limit: one line, no traceback
        raise output_error(error, path) from error
    finally:
        if temporary is not None and os.path.exists(temporary):
            os.unlink(temporary)


def _fsync(path, flags):
    descriptor = os.open(path, flags)
    try:
        os.fsync(descriptor)
    finally:
        os.close(descriptor)


def json_default(value):
    """``json.dumps``'s ``default``: numpy arrays and scalars as lists and Python numbers."""
    import numpy as np      # here: the command line's start-up (--help) does without numpy

    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"cannot write {type(value).__name__} to JSON")


def write_json(path, data, *, fsync=False):
    """Write ``data`` as indented JSON, atomically (NaN written as null); see :func:`atomic_path`."""
    text = json.dumps(_replace_nan(data), indent=2, default=json_default, allow_nan=False)
    with atomic_path(path, fsync=fsync) as temporary:
        temporary.write_text(text + "\n", encoding="utf-8")
    return Path(path)


def canonical_json(data):
    """``data`` as :func:`write_json` stores it, in one canonical line (sorted keys, no spaces):
    the same text for the data written and the data read back, for content hashes."""
    return json.dumps(_replace_nan(data), default=json_default, allow_nan=False,
                      sort_keys=True, separators=(",", ":"))


def _replace_nan(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _replace_nan(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_replace_nan(v) for v in value]
    return value


# ------------------------------------------------------------------------------ folder locks
#: Descriptors of the locks this process holds. A forked worker inherits them and with them the
#: lock (flock belongs to the open file, not the process): it closes its copies at once, so a
#: killed run's orphaned worker cannot keep its folder locked.
_HELD: set[int] = set()
if hasattr(os, "register_at_fork"):
    def _drop_inherited_locks():
        for descriptor in _HELD:
            with contextlib.suppress(OSError):
                os.close(descriptor)
        _HELD.clear()

    os.register_at_fork(after_in_child=_drop_inherited_locks)


def lock_path(directory):
    """The lock file of results folder ``directory``: beside it, ``.NAME.lock``, as it must
    outlive the folder being swapped for its staged replacement."""
    directory = Path(directory).resolve()
    return directory.parent / f".{directory.name}.lock"


#: errno of flock on a file system that keeps no locks (NFS without its lock service).
_NO_LOCKS = {errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOSYS}


@contextlib.contextmanager
def folder_lock(directory, command):
    """Hold the lock of results folder ``directory`` while the block runs.

    The lock is an ``flock`` on :func:`lock_path`, holding who took it (pid, host, start time,
    command). A second writer is refused with a :class:`ParameterError` naming that holder. The
    kernel drops the lock of a process that dies, so a lock file left by a killed run is taken
    over, with a note on stderr naming the run that left it.
    """
    path = lock_path(directory)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        descriptor, locked = _acquire(path, directory)
    except OSError as error:
        raise output_error(error, path) from error
    try:
        left = _holder(descriptor)
        if not locked:      # a network file system without a lock service: warn, not refuse
            print(f"crowdvib: note: {path.parent} cannot be locked: make sure no other run "
                  f"writes {directory} meanwhile"
                  + (f" (the last one: {_describe(left)})" if left else ""), file=sys.stderr,
                  flush=True)
        elif left:
            print(f"crowdvib: note: took over the lock of {directory} left by a run that ended "
                  f"without releasing it ({_describe(left)})", file=sys.stderr, flush=True)
        started = datetime.datetime.now().astimezone().isoformat(timespec="seconds")
        record = json.dumps({"pid": os.getpid(), "host": socket.gethostname(),
                             "started": started, "command": command}).encode()
        os.ftruncate(descriptor, 0)
        os.pwrite(descriptor, record, 0)
    except OSError as error:
        _release(descriptor, path)
        raise output_error(error, path) from error
    try:
        yield path
    finally:
        _release(descriptor, path)


def _acquire(path, directory):
    """Open and flock ``path`` → (descriptor, whether it is locked)."""
    import fcntl

    while True:
        descriptor = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
        _HELD.add(descriptor)
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder(descriptor)
            _HELD.discard(descriptor)
            os.close(descriptor)
            raise ParameterError(
                f"--out {directory} is being written by another crowdvib run "
                f"({_describe(holder)}): two runs may not write one results folder; wait "
                "for it to end or choose another --out") from None
        except OSError as error:
            if error.errno in _NO_LOCKS:
                return descriptor, False
            _HELD.discard(descriptor)
            os.close(descriptor)
            raise
        # The holder before us may have deleted the file after we opened it: lock the file
        # that is there now, or two runs would each hold a lock on a different file.
        with contextlib.suppress(FileNotFoundError):
            if os.stat(path).st_ino == os.fstat(descriptor).st_ino:
                return descriptor, True
        _HELD.discard(descriptor)
        os.close(descriptor)


def _release(descriptor, path):
    _HELD.discard(descriptor)
    with contextlib.suppress(OSError):
        os.unlink(path)             # while still locked: the next run finds no stale record
    os.close(descriptor)


def _holder(descriptor):
    """The record in a lock file ({} if empty or unreadable)."""
    try:
        data = json.loads(os.pread(descriptor, 4096, 0) or b"{}")
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def _describe(holder):
    if not holder:
        return "holder unknown"
    return (f"crowdvib {holder.get('command')}, pid {holder.get('pid')} on host "
            f"{holder.get('host')}, started {holder.get('started')}")


# ------------------------------------------------------------------------------ file names
#: Longest stem :func:`safe_filename` returns, in characters (ASCII, so bytes): leaves room for a
#: prefix, a collision counter and a suffix within the 255-byte limit of common file systems.
MAX_STEM = 120
#: Names Windows reserves for devices whatever the suffix (``NUL.png`` opens the null device).
_RESERVED = frozenset(["CON", "PRN", "AUX", "NUL", *(f"COM{i}" for i in range(10)),
                       *(f"LPT{i}" for i in range(10))])


def safe_filename(text):
    """A file-name stem made from a user string that cannot leave its directory.

    Accents are dropped (``Überbau`` → ``Uberbau``), anything but ASCII letters, digits, ``-``,
    ``_`` and ``.`` becomes ``_`` (so no path separator, NUL or control character survives),
    leading and trailing dots and spaces go (no ``.``, ``..`` or hidden files), Windows device
    names get a ``_`` appended, and a name longer than :data:`MAX_STEM` is cut and ends with a
    hash of the whole text so long names stay distinct. The result is never empty and
    ``safe_filename(safe_filename(t)) == safe_filename(t)``.

    Parameters
    ----------
    text : str
        Any string, e.g. an output or case name from a case file.

    Returns
    -------
    str
    """
    import hashlib
    import re
    import unicodedata

    text = str(text)
    ascii_text = "".join(c for c in unicodedata.normalize("NFKD", text)
                         if not unicodedata.combining(c))
    stem = re.sub(r"[^A-Za-z0-9._-]", "_", ascii_text).strip(". ") or "unnamed"
    if stem.split(".")[0].upper() in _RESERVED:
        stem = stem + "_"
    if len(stem) > MAX_STEM:
        digest = hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()[:12]
        stem = stem[:MAX_STEM - 13].rstrip(". ") + "-" + digest
    return stem


def unique_filenames(names, *, prefix="", suffix="", taken=()):
    """Distinct safe file names for distinct user strings → {name: file name}.

    Parameters
    ----------
    names : iterable of str
        User strings in a fixed order (the order decides who keeps the plain name).
    prefix, suffix : str
        Put around every :func:`safe_filename` stem, e.g. ``"psd_"`` and ``".png"``.
    taken : iterable of str
        File names already used in the directory (e.g. ``psd_convergence.png``).

    Returns
    -------
    dict
        Collisions, compared without case as on macOS and Windows, get ``-2``, ``-3`` … .
    """
    used = {name.lower() for name in taken}
    result = {}
    for name in names:
        if name in result:
            continue
        stem = safe_filename(name)
        candidate, count = f"{prefix}{stem}{suffix}", 1
        while candidate.lower() in used:
            count += 1
            candidate = f"{prefix}{stem}-{count}{suffix}"
        used.add(candidate.lower())
        result[name] = candidate
    return result


def child_path(directory, name):
    """``directory / name`` if ``name`` is a plain file name of an entry directly inside it.

    Returns None for names with separators, ``.``/``..``, NUL, or an entry that resolves
    (through a symbolic link) outside ``directory``: used for names read from files, such as
    the figure names of a ``results.json``.
    """
    name = str(name)
    if (not name or name in (".", "..") or "\x00" in name or "/" in name or "\\" in name
            or Path(name).name != name):
        return None
    path = Path(directory) / name
    try:
        if path.resolve().parent != Path(directory).resolve():
            return None
    except (OSError, RuntimeError):
        return None
    return path


#: What a report template may be called: an HTML page, or a Jinja2 file.
TEMPLATE_SUFFIXES = (".html", ".j2")


def template_within(folder, name):
    """``folder / name`` resolved, if it is a template file (:data:`TEMPLATE_SUFFIXES`) inside
    ``folder`` or below it, links followed; else the rule it breaks (a str).

    A template named by a file from someone else (a case file, a results.json) must not make
    crowdvib read any file of the machine into a report: ``/etc/passwd``, ``../../any.txt``.
    """
    folder = Path(folder).resolve()
    path = (folder / str(name)).resolve()
    if path.suffix.lower() not in TEMPLATE_SUFFIXES:
        return path, f"must be a {' or '.join(TEMPLATE_SUFFIXES)} file"
    if not path.is_relative_to(folder):
        return path, f"must lie in {folder.name or folder} or below it (links followed)"
    return path, None


def sha256_file(path):
    """Hex SHA-256 digest of a file's bytes, read in 1 MiB blocks."""
    import hashlib

    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def require_file(path, what):
    """A :class:`DataError` unless ``path`` is an existing regular file (naming a directory as
    such: the usual mix-up of a folder given for a file)."""
    path = Path(path)
    if path.is_dir():
        raise DataError(f"{path}: is a directory, expected a {what} file")
    if not path.is_file():
        raise DataError(f"{path}: {what} file not found")
    return path
