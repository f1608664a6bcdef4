"""Paths in a report relative to the case's folder: a report is sent on, so it names no folder of
the machine that ran it (issue 27 §4).

A ``results.json`` records absolute paths (the case file, its records, a warning's source); the
report shows each relative to the folder of the case file when it lies near it (at most two
levels up), else by its file name alone.
"""

import ntpath
import os
import posixpath
import re

__all__ = ["without_machine_paths", "relative_path", "case_folder"]

#: Levels up (``..``) a relative path may climb before only the file name is shown: a results
#: folder beside or inside the case's is two at most, anything further names the machine's tree.
_MAX_UP = 2

# An absolute path inside a text: a POSIX path after a space, quote or bracket (not the "/" of a
# unit such as m/s² or J/J_noHSI, which follows a letter), or a Windows drive path.
_EMBEDDED = re.compile(r"(?<![\w.\-/\\~])(?:/|[A-Za-z]:[\\/])[\w.\-+@~]+(?:[\\/][\w.\-+@~]+)*")


def _is_absolute(text):
    return posixpath.isabs(text) or bool(re.match(r"[A-Za-z]:[\\/]", text))


def case_folder(results):
    """The absolute folder of the case file a results dict names, or None."""
    for case in (results.get("case"), (results.get("inputs") or {}).get("path")
                 if isinstance(results.get("inputs"), dict) else None):
        if isinstance(case, str) and _is_absolute(case):
            return _parent(case)
    return None


def _parent(path):
    return ntpath.dirname(path) if re.match(r"[A-Za-z]:[\\/]", path) else posixpath.dirname(path)


def relative_path(path, base):
    """``path`` relative to the folder ``base`` (both absolute; POSIX separators), or its file
    name when it is not near ``base`` (see :data:`_MAX_UP`), is on another drive or ``base`` is
    None. A relative ``path`` is returned as it is."""
    path = str(path)
    if not _is_absolute(path):
        return path
    name = ntpath.basename(path) if "\\" in path else posixpath.basename(path.rstrip("/"))
    if base is None:
        return name
    try:
        relative = os.path.relpath(path, str(base)).replace("\\", "/")
    except ValueError:                  # Windows: another drive
        return name
    ups = relative.split("/").count("..")
    return relative if ups <= _MAX_UP and not _is_absolute(relative) else name


def without_machine_paths(data, base):
    """A copy of a JSON value with every absolute path (a whole string, or inside a text) made
    relative to ``base`` by :func:`relative_path`."""
    if isinstance(data, dict):
        return {key: without_machine_paths(value, base) for key, value in data.items()}
    if isinstance(data, list):
        return [without_machine_paths(value, base) for value in data]
    if isinstance(data, str):
        if _is_absolute(data) and "\n" not in data:
            return relative_path(data, base)
        return _EMBEDDED.sub(lambda m: relative_path(m.group(0), base), data)
    return data
