"""Atomic file output: a reader never sees a half-written file, a crash leaves the old one intact."""

import contextlib
import json
import os
import tempfile
from pathlib import Path

import numpy as np


@contextlib.contextmanager
def atomic_path(path, *, fsync=False):
    """Yield a temporary path beside ``path``; on success it replaces ``path`` in one rename.

    With ``fsync``, the file's bytes reach the disk before the rename and the rename reaches it
    after: a power cut then leaves the old file or the new one, never an empty one (a rename
    alone orders nothing on ext4/xfs with delayed allocation).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    os.close(handle)
    # mkstemp creates 0600 files; give the result the permissions a plain open() would.
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(temporary, 0o666 & ~umask)
    try:
        yield Path(temporary)
        if fsync:
            _fsync(temporary, os.O_RDONLY)
        os.replace(temporary, path)
        if fsync:
            _fsync(path.parent, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    finally:
        if os.path.exists(temporary):
            os.unlink(temporary)


def _fsync(path, flags):
    descriptor = os.open(path, flags)
    try:
        os.fsync(descriptor)
    finally:
        os.close(descriptor)


def _json_default(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"cannot write {type(value).__name__} to JSON")


def write_json(path, data, *, fsync=False):
    """Write ``data`` as indented JSON, atomically (NaN written as null); see :func:`atomic_path`."""
    text = json.dumps(_replace_nan(data), indent=2, default=_json_default, allow_nan=False)
    with atomic_path(path, fsync=fsync) as temporary:
        temporary.write_text(text + "\n", encoding="utf-8")
    return Path(path)


def _replace_nan(value):
    if isinstance(value, float) and not np.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _replace_nan(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_replace_nan(v) for v in value]
    return value
