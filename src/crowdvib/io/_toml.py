"""TOML case files, table by table: every key read through :class:`Table`, which checks its type
and rule and names the file and dotted key in every message (``c.toml: crowd.density must be > 0,
got -0.5``), and reports unknown (misspelt) keys.
"""

import difflib
import re
import tomllib
from pathlib import Path

import numpy as np

from .._validation import check_count
from ..errors import DataError, ParameterError
from .._files import require_file
from ._common import named_file, quote

__all__ = ["Table", "REQUIRED", "read_toml", "wrap"]

REQUIRED = object()


def _is_number(value):
    """A TOML integer or float (not a boolean, not a string of digits)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


class Table:
    """One TOML table with its dotted prefix and file, for messages that point at the key."""

    def __init__(self, data, prefix, path, defaulted=None):
        if not isinstance(data, dict):
            raise ParameterError(f"{path.name}: {prefix} must be a table, got {quote(data)}")
        self.data, self.prefix, self.path, self.used = data, prefix, path, set()
        # Dotted keys the file left out, shared by a table and its sub-tables: the report marks
        # their values as defaults, not as the user's inputs.
        self.defaulted = set() if defaulted is None else defaulted

    def key(self, name):
        return f"{self.prefix}.{name}" if self.prefix else name

    def error(self, name, rule, value):
        return ParameterError(f"{self.path.name}: {self.key(name)} {rule}, got {quote(value)}")

    def has(self, name):
        return name in self.data

    def raw(self, name, default=REQUIRED):
        self.used.add(name)
        if name not in self.data:
            if default is REQUIRED:
                near = difflib.get_close_matches(name, [k for k in self.data if k != name], n=1)
                hint = f" (found {quote(self.key(near[0]))}: misspelt?)" if near else ""
                raise ParameterError(f"{self.path.name}: {self.key(name)} is required{hint}")
            self.defaulted.add(self.key(name))
            return default
        return self.data[name]

    def number(self, name, default=REQUIRED, *, rule=None):
        value = self.raw(name, default)
        if value is None or value is default:
            return value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.error(name, "must be a number", value)
        value = float(value)
        if not np.isfinite(value):
            raise self.error(name, "must be finite", value)
        if rule == "positive" and not value > 0:
            raise ParameterError(f"{self.path.name}: {self.key(name)} must be > 0, got {value:g}")
        if rule == "non_negative" and not value >= 0:
            raise ParameterError(f"{self.path.name}: {self.key(name)} must be >= 0, got {value:g}")
        if rule == "fraction" and not 0 < value < 1:
            raise ParameterError(f"{self.path.name}: {self.key(name)} must lie in (0, 1) "
                                 f"(fractions, not percent), got {value:g}")
        return value

    def count(self, name, default=REQUIRED, *, minimum=1):
        """An integer >= ``minimum`` (2.0 too, not 2.5: a count is not rounded silently)."""
        value = self.number(name, default)
        if value is None or value is default:
            return value
        try:
            return check_count(self.key(name), value, minimum)
        except ParameterError as exc:
            raise ParameterError(f"{self.path.name}: {exc}") from None

    def string(self, name, default=REQUIRED, *, choices=None):
        value = self.raw(name, default)
        if value is None or value is default:
            return value
        if not isinstance(value, str):
            raise self.error(name, "must be a string", value)
        if choices is not None and value not in choices:
            raise self.error(name, f"must be one of {list(choices)}", value)
        return value

    def boolean(self, name, default):
        value = self.raw(name, default)
        if not isinstance(value, bool):
            raise self.error(name, "must be true or false", value)
        return value

    def pair(self, name, default=REQUIRED, *, increasing=True):
        value = self.raw(name, default)
        if value is None or value is default:
            return value
        # Only a list of two numbers: a string "19" would otherwise unpack to 1 and 9.
        if not (isinstance(value, list) and len(value) == 2 and all(map(_is_number, value))):
            raise self.error(name, "must be a pair [lower, upper] of numbers", value)
        low, high = (float(v) for v in value)
        if increasing and not low < high:
            raise self.error(name, "must have lower < upper", value)
        return low, high

    def strings(self, name, default=REQUIRED):
        value = self.raw(name, default)
        if value is None or value is default:
            return value
        value = [value] if isinstance(value, str) else value
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise self.error(name, "must be a string or a list of strings", value)
        return tuple(value)

    def numbers(self, name, default=REQUIRED, *, rule=None):
        value = self.raw(name, default)
        if value is None or value is default:
            return value
        if not (_is_number(value) or isinstance(value, list) and all(map(_is_number, value))):
            raise self.error(name, "must be a list of numbers", value)
        array = np.array(value, dtype=float)
        if not np.all(np.isfinite(array)):
            raise self.error(name, "must be finite", value)
        if rule == "positive" and np.any(array <= 0):
            raise self.error(name, "must be > 0", value)
        return array

    def table(self, name, *, required=False):
        value = self.raw(name, REQUIRED if required else {})
        return Table(value, self.key(name), self.path, self.defaulted)

    def file(self, name, default=REQUIRED):
        value = self.string(name, default)
        if value is None or value is default:
            return value
        return named_file((self.path.parent / value).resolve(),
                          f"{self.path.name}: {self.key(name)}", shown=value)

    def finish(self):
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            guesses = {k: difflib.get_close_matches(k, self.used, n=1) for k in unknown}
            hints = "".join(f" ({quote(self.key(k))}: did you mean {self.key(g[0])!r}?)"
                            for k, g in guesses.items() if g)
            names = ", ".join(quote(self.key(k)) for k in unknown)
            raise ParameterError(
                f"{self.path.name}: unknown key(s) [{names}]{hints}; "
                f"known keys are {[self.key(k) for k in sorted(self.used)]}")


def wrap(path, section, exc):
    """Re-raise a model's own ParameterError with the file and the section prefixed."""
    return ParameterError(f"{path.name}: {section}.{exc}")




def read_toml(path):
    """The top-level table of a TOML file; a missing, binary or malformed file is a
    :class:`DataError` naming it (the parser's message quotes only a line and column)."""
    require_file(path, "case")
    try:
        text = Path(path).read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise DataError(f"{Path(path).name}: is not a TOML case file: not UTF-8 text (byte "
                        f"{exc.start})") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        twice = _first_duplicate(text)
        if twice is not None:
            raise DataError(f"{Path(path).name}: {twice}") from None
        raise DataError(f"{Path(path).name}: not valid TOML: {exc}") from None


_PART = r"""(?:[\w-]+|"[^"\n]*"|'[^'\n]*')"""
_KEY = re.compile(rf"\s*({_PART}(?:\s*\.\s*{_PART})*)\s*=")
_HEADER = re.compile(rf"\s*(\[\[?)\s*({_PART}(?:\s*\.\s*{_PART})*)\s*\]")


def _dotted(key):
    return ".".join(part.strip().strip("\"'") for part in re.split(r"\s*\.\s*", key))


def _first_duplicate(text):
    """"key 'crowd.density' is given twice (lines 3 and 5) …" for the first key or table a file
    gives twice, else None: tomllib's "Cannot overwrite a value" names neither (issue 24).

    A line scan, run only once the parser has failed: keys of each ``[table]`` and each
    ``[[array]]`` entry, lines inside multi-line strings skipped.
    """
    seen, table, block, quoted = {}, "", 0, None
    for number, line in enumerate(text.splitlines(), start=1):
        for mark in ('"""', "'''"):
            if (quoted in (None, mark)) and line.count(mark) % 2:
                quoted = None if quoted else mark
                break
        else:
            if quoted:
                continue
        header = _HEADER.match(line)
        if header:
            table, block = _dotted(header.group(2)), number if header.group(1) == "[[" else 0
            if block:
                continue          # every [[array]] entry is a table of its own
            what, fix = f"table [{table}] is declared", "merge them"
        else:
            key = _KEY.match(line)
            if key is None:
                continue
            dotted = _dotted(key.group(1))
            what, fix = f"key {quote(f'{table}.{dotted}' if table else dotted)} is given", "keep one"
        first = seen.setdefault((block, what), number)
        if first != number:
            return f"{what} twice (lines {first} and {number}): {fix}"
    return None
