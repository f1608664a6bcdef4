"""What a logger's text export says about itself: units in the column headers, the time column,
metadata lines above the header row, and the output name a channel header stands for (issue 36
§2).

Loggers (catman, DEWESoft, Quantum, MR3000 …) write a few lines of metadata (device, date,
sample rate) above the header row, and the unit of each column in its header
(``Acc Z midspan [mg]``, ``a (g)``). :func:`header_unit` reads such a unit, :func:`find_header`
finds the header row below the metadata, :func:`output_name` makes a short output name of a
header (``midspan``) for ``crowdvib init``'s draft. The units crowdvib reads, and their scale to
m/s², are :data:`crowdvib.io.units.UNITS` (docs: theory, Conventions: g = 9.81 m/s²).
"""

import csv
import re

from ..errors import DataError
from ._common import quote, quote_names, where
from .units import unit_key

__all__ = ["header_unit", "find_header", "output_name", "DELIMITERS", "time_key"]

#: Column separators tried in turn: crowdvib's ",", then ";" and tab (spreadsheets of locales
#: whose decimal mark is a comma write ";" and "1,5").
DELIMITERS = (",", ";", "\t")
#: A unit closing a header: "name [unit]" or "name (unit)".
_HEADER_UNIT = re.compile(r"(.*?)\s*[\[(]\s*([^\[\]()]+?)\s*[\])]\s*")
#: Words of a header that say "an acceleration" or name an axis, not where the sensor is.
_GENERIC = {"acc", "accel", "acceleration", "accelerations", "beschleunigung", "besch",
            "accélération", "versnelling", "aceleración", "a", "x", "y", "z", "vert",
            "vertical", "ch", "chan", "channel"}
#: The usual headers of a time column (English, German, French, Dutch, Spanish, Italian, Nordic,
#: Polish, Finnish), with an optional unit: "Time [s]", "t (s)", "time_s", "Zeit/s".
_TIME_HEADER = re.compile(r"\s*(time|zeit|temps|tijd|tiempo|tempo|tid|czas|aika|t)\s*"
                          r"(?:[\[(]\s*(\w+)\s*[\])]|[_/ ]\s*(\w+))?\s*", re.IGNORECASE)
_SECONDS = {"s", "sec", "secs", "second", "seconds", "sek", "sekunden"}
_OTHER_TIME_UNITS = {"ms", "us", "µs", "ns", "min", "h", "hr", "hrs"}
#: Rows below a candidate header that must be numbers for it to be the header.
_CHECK_ROWS = 3
#: Lines searched for the header row (a logger's preamble is a few tens of lines).
_SEARCH_LINES = 200


def header_unit(name):
    """(the header without its unit, the unit's key) of a column header; the key is None and the
    header unchanged when it closes in no unit crowdvib reads (``"Acc Z midspan [mg]"`` →
    ``("Acc Z midspan", "mg")``; ``"a [V]"`` → ``("a [V]", None)``)."""
    match = _HEADER_UNIT.fullmatch(name)
    key = None if match is None else unit_key(match.group(2))
    return (name, None) if key is None else (match.group(1).strip(), key)


def output_name(header):
    """A short output name for a channel header: its unit, the words that say "acceleration"
    and the axis dropped, the rest joined by "_" (``"Acc Z midspan [g]"`` → ``"midspan"``);
    the whole header, so joined, when nothing else is left (``"Acc Z"`` → ``"Acc_Z"``)."""
    bare = header_unit(header)[0]
    words = [w for w in re.split(r"[^\w]+", bare) if w]
    kept = [w for w in words if w.lower() not in _GENERIC]
    return "_".join(kept or words)


def _numbers(cells):
    """Whether every cell is a number (a decimal comma allowed: the separator is then not ',')."""
    try:
        for cell in cells:
            float(cell.strip().replace(",", ".", 1))
    except ValueError:
        return False
    return bool(cells)


def _rows_below(lines, index):
    """Up to :data:`_CHECK_ROWS` non-blank lines after ``lines[index]``."""
    rows = []
    for line in lines[index + 1:index + 1 + 4 * _CHECK_ROWS]:
        if line.strip():
            rows.append(line.rstrip("\r\n"))
        if len(rows) == _CHECK_ROWS:
            break
    return rows


def _is_header(lines, index):
    """Whether ``lines[index]`` is a header row: for some separator, it names as many columns as
    each of the rows below it holds numbers, and it is no row of numbers itself (nor one with a
    dropout, an empty cell, among them)."""
    rows = _rows_below(lines, index)
    if not rows:
        return False
    for delimiter in DELIMITERS:
        names = next(csv.reader([lines[index]], delimiter=delimiter))
        if _numbers([name for name in names if name.strip()]):
            return False
        if all(len(cells) == len(names) and _numbers(cells)
               for cells in (row.split(delimiter) for row in rows)):
            return True
    return False


def find_header(lines, start=0):
    """(index of the header row, the lines above it from ``start`` that are not it) of a CSV.

    The header is the first line from ``start`` that names as many columns as each of the rows
    below it holds numbers. A file whose first line is its header gives ``(start, [])``; a
    logger export with metadata above the header gives the metadata lines (stripped, blank
    ones dropped). None is found in a file that is no table of numbers: ``(start, [])``, and the
    reader's own checks name what is wrong.
    """
    quotes = 0
    for index in range(start, min(len(lines), start + _SEARCH_LINES)):
        # A line inside a quoted name that holds a line break is none (RFC 4180 doubles a quote
        # inside a name, so an odd count above means an open quote).
        if quotes % 2 == 0 and lines[index].strip() and _is_header(lines, index):
            return index, [line.strip() for line in lines[start:index] if line.strip()]
        quotes += lines[index].count('"')
    return start, []


# ------------------------------------------------------------------------- the time column
def _time_unit(name):
    """The unit of a usual time header ("s", or e.g. "ms"); None for any other name (a capital
    "T" alone is left alone: a temperature or a period as often as a time)."""
    match = _TIME_HEADER.fullmatch(name)
    if match is None or match.group(1) == "T":
        return None
    unit = (match.group(2) or match.group(3) or "s").lower()
    return "s" if unit in _SECONDS else unit if unit in _OTHER_TIME_UNITS else None


def time_key(path, names, time_column, stated=None):
    """The time column (variable) among ``names``, or None.

    A ``time_column`` other than the default "time" is taken as given; otherwise the column the
    file itself names (``stated``: the ``# time_column`` comment crowdvib writes), else "time",
    else the one usual time header in seconds. Two candidates, or a time header in another
    unit, are refused rather than guessed.
    """
    if time_column != "time":
        return time_column if time_column in names else None
    for name in (stated, "time"):
        if name is not None and name in names:
            return name
    found = [name for name in names if _time_unit(name) is not None]
    if len(found) > 1:
        raise DataError(f"{where(path)}columns {quote_names(found)} all look like time stamps: "
                        "name the one to use with measurement.time_column (time_column=)")
    if found and _time_unit(found[0]) != "s":
        raise DataError(f"{where(path)}column {quote(found[0])} looks like time in "
                        f"{_time_unit(found[0])}, crowdvib reads time stamps in s: convert it to "
                        "seconds, or drop it and give measurement.sample_rate [Hz]")
    return found[0] if found else None
