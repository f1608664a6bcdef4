"""The manifest of a results directory: which files crowdvib wrote there, so it touches no other.

Every command writes ``crowdvib-manifest.json`` into its ``--out``: the relative path, size and
SHA-256 of each file it wrote, crowdvib's version and the command. crowdvib deletes or replaces a
file only if the manifest lists it with the same size and digest; a file that is not listed, or
was edited since, is *foreign* and makes ``--force`` refuse rather than lose someone's work.

A resumable study also names *store* directories (its task stores): the task files it writes
there one by one, while it runs, are owned without being listed, so a study killed before its
manifest was completed can still be resumed or replaced. A task file proves itself: it is
crowdvib's only while its content matches the SHA-256 written into it
(:func:`crowdvib.runner.tasks.read_task_file`); any other file in a store, a user's
``*.json`` included, is foreign to ``--force``. Only ``--resume`` rewrites a damaged or edited
file named as a task file (its name is a digest of its task's key, which crowdvib chose),
computing its task again with a warning naming it. The temporaries of a store's atomic writes
(``.NAME.json.XXXX.part``, left by a kill), recognised by that name alone, as they are cut short.
"""

import contextlib
import datetime
import json
import os
import re
from pathlib import Path

from ._version import __version__
from ._files import MANIFEST_NAME, sha256_file, write_json
from .errors import DataError, ParameterError, UnverifiedWarning
from .runner.tasks import read_task_file

__all__ = ["MANIFEST_NAME", "read_manifest", "write_manifest", "only_stores", "foreign_files",
           "record_file", "remove_owned", "verified_file"]

_FORMAT = 1


def read_manifest(directory):
    """The manifest of ``directory`` as a dict, or None if it holds no valid crowdvib manifest."""
    path = Path(directory) / MANIFEST_NAME
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if (not isinstance(data, dict) or data.get("crowdvib_manifest") != _FORMAT
            or not isinstance(data.get("files"), list)):
        return None
    data["files"] = [f for f in data["files"] if isinstance(f, dict)
                     and isinstance(f.get("path"), str)]
    data["stores"] = [s for s in data.get("stores") or [] if isinstance(s, str)]
    return data


def _entry(directory, relative):
    path = Path(directory) / relative
    return {"path": relative, "size": path.stat().st_size, "sha256": sha256_file(path)}


def _walk(directory):
    """Relative POSIX paths of every file below ``directory`` (links not followed), sorted."""
    directory = Path(directory)
    found = []
    for root, dirs, files in os.walk(directory):
        dirs.sort()
        # A link to a directory is listed as an entry (never followed), so it counts as foreign.
        links = [name for name in dirs if (Path(root) / name).is_symlink()]
        for name in files + links:
            found.append((Path(root) / name).relative_to(directory).as_posix())
    return sorted(found)


def write_manifest(directory, command, *, stores=(), complete=True):
    """List every file now below ``directory`` in its manifest (call on a directory crowdvib made).

    Parameters
    ----------
    directory : pathlib.Path
        A staging directory crowdvib created, or a results directory whose foreign files were
        refused beforehand (:func:`foreign_files`).
    command : str
        The crowdvib command that wrote it.
    stores : sequence of str
        Subdirectories holding task stores (see the module docstring).
    complete : bool
        False while a resumable study is still running.
    """
    files = [_entry(directory, p) for p in _walk(directory) if p != MANIFEST_NAME
             and _owned_store_file(directory, p, stores) is not False]
    created = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
    return write_json(Path(directory) / MANIFEST_NAME, {
        "crowdvib_manifest": _FORMAT, "crowdvib_version": __version__, "command": command,
        "created": created, "complete": complete, "stores": list(stores), "files": files})


def _in_store(relative, stores):
    parts = relative.split("/")
    # A store holds the task files and, after a kill, the hidden temporaries of atomic writes.
    return (len(parts) == 2 and parts[0] in stores
            and (parts[1].endswith(".json") or parts[1].endswith(".part")))


#: The temporary of an atomic write of a task file (src/crowdvib/_files.py atomic_path).
_TEMPORARY = re.compile(r"\.[0-9a-f]+\.json\.[A-Za-z0-9_]+\.part")
#: A task file's name (src/crowdvib/runner/tasks.py _file_name).
_TASK_NAME = re.compile(r"[0-9a-f]{16}\.json")


def _owned_store_file(directory, relative, stores, resume=False):
    """None if ``relative`` is not in a store, else whether crowdvib may replace it: it provably
    wrote it, or (``resume``) it is named as a task file, which a resumed study recomputes."""

    if not _in_store(relative, stores):
        return None
    path = Path(directory) / relative
    if path.is_symlink():                 # crowdvib writes no links
        return False
    if _TEMPORARY.fullmatch(path.name) or (resume and _TASK_NAME.fullmatch(path.name)):
        return True
    try:
        read_task_file(path)
    except (ValueError, OSError):
        return False
    return True


def only_stores(directory, stores):
    """True if every file below ``directory`` is a task file of one of the ``stores``.

    Such a directory is a study interrupted before crowdvib wrote manifests: it may be resumed.
    """
    return bool(stores) and all(_in_store(f, stores) for f in _walk(directory))


def foreign_files(directory, manifest=None, *, resume=False):
    """Files below ``directory`` crowdvib did not write: not listed, or changed since.

    With ``resume``, damaged or edited task files are not counted (see the module docstring).

    Returns
    -------
    list of str
        Relative paths, sorted; empty if crowdvib may replace everything.
    """
    manifest = read_manifest(directory) if manifest is None else manifest
    listed = {} if manifest is None else {f["path"]: f for f in manifest["files"]}
    stores = () if manifest is None else manifest["stores"]
    foreign = []
    for relative in _walk(directory):
        if relative == MANIFEST_NAME and manifest is not None:
            continue
        owned = _owned_store_file(directory, relative, stores, resume)
        if owned is not None:       # a store's file is judged by its content, listed or not
            if not owned:
                foreign.append(relative)
            continue
        entry = listed.get(relative)
        path = Path(directory) / relative
        if (entry is None or path.is_symlink() or path.stat().st_size != entry.get("size")
                or sha256_file(path) != entry.get("sha256")):
            foreign.append(relative)
    return foreign


def record_file(directory, relative, command):
    """Add (or refresh) one file crowdvib just wrote in ``directory`` to its manifest."""
    if (Path(directory) / MANIFEST_NAME).exists() and read_manifest(directory) is None:
        raise ParameterError(f"{Path(directory) / MANIFEST_NAME} is not a crowdvib manifest: "
                             "crowdvib does not overwrite it")
    manifest = read_manifest(directory) or {
        "crowdvib_manifest": _FORMAT, "crowdvib_version": __version__, "command": command,
        "complete": True, "stores": [], "files": []}
    files = [f for f in manifest["files"] if f["path"] != relative]
    files.append(_entry(directory, relative))
    manifest["files"] = sorted(files, key=lambda f: f["path"])
    return write_json(Path(directory) / MANIFEST_NAME, manifest)


def verified_file(directory, relative, what):
    """``directory / relative``, a file of another run, once its SHA-256 matches the one the
    folder's manifest recorded (issue 35 §1: a results.json edited since is not used unseen).

    Without a manifest beside it the file is used with an :class:`UnverifiedWarning`; a missing
    file is returned for its reader to name.

    Parameters
    ----------
    directory : str or pathlib.Path
        The other run's results folder.
    relative : str
        The file, relative to it (``"results.json"``).
    what : str
        What the file is used for, for the messages (``"--msd-from"``).

    Raises
    ------
    DataError
        The manifest does not list the file, or lists another SHA-256: the message names the
        file, both digests and the manifest.
    """
    import warnings

    directory = Path(directory)
    path = directory / relative
    if not path.is_file():
        return path
    manifest = read_manifest(directory)
    if manifest is None:
        state = ("is not a crowdvib manifest" if (directory / MANIFEST_NAME).exists()
                 else "is missing")
        warnings.warn(f"{path} ({what}) cannot be verified: {directory / MANIFEST_NAME} "
                      f"{state}, so the SHA-256 its run recorded is unknown; it is used as it is",
                      UnverifiedWarning, stacklevel=2)
        return path
    entry = next((f for f in manifest["files"] if f["path"] == relative), None)
    if entry is None or path.is_symlink():
        raise DataError(f"{path} ({what}) is not a file crowdvib wrote there: "
                        f"{directory / MANIFEST_NAME} does not list it; refused")
    digest = sha256_file(path)
    if digest != entry.get("sha256"):
        raise DataError(f"{path} ({what}): its SHA-256 {digest} differs from the manifest's "
                        f"{entry.get('sha256')!s:.64} ({directory / MANIFEST_NAME}): the file "
                        "was changed since crowdvib wrote it, so it is not used; run the "
                        "command that wrote it again")
    return path


def remove_owned(directory):
    """Delete what crowdvib wrote in ``directory`` and the directories left empty.

    Only the files :func:`foreign_files` does not name are deleted, then the manifest, then
    empty subdirectories and ``directory`` itself if empty. Returns the files left behind
    (foreign ones), so a caller can say why the directory is still there.
    """
    directory = Path(directory)
    manifest = read_manifest(directory)
    foreign = set(foreign_files(directory, manifest))
    for relative in _walk(directory):
        if relative not in foreign and relative != MANIFEST_NAME:
            (directory / relative).unlink()
    if manifest is not None:
        (directory / MANIFEST_NAME).unlink(missing_ok=True)
    for root, dirs, _ in os.walk(directory, topdown=False):   # children before parents
        for name in dirs:
            with contextlib.suppress(OSError):   # not empty: it holds foreign files
                (Path(root) / name).rmdir()
    with contextlib.suppress(OSError):
        directory.rmdir()
    return sorted(foreign)
