"""The CSV record format: its reader and writer (the layout: :mod:`crowdvib.io.formats`).

The reader finds the header row below a logger's metadata lines and the unit its column headers
state (:mod:`crowdvib.io.headers`), takes decimal commas where the columns are not separated by
commas, and reads an empty cell (a logger's dropout) as NaN for :mod:`crowdvib.io.gaps`; the
writer guards names a spreadsheet would run as formulas.
"""

import csv
import io
import itertools
import re
import warnings
from pathlib import Path

import numpy as np

from .._files import atomic_path
from ..errors import DataError
from ._common import quote, refuse_transposed, stated_rate, where
from .headers import DELIMITERS, find_header, header_unit, time_key

__all__ = ["read_table_cells"]

#: A name a spreadsheet would run as a formula (OWASP "CSV injection": = + - @ first). The writer
#: puts one "'" before it (and before any "'" already there), the reader takes exactly one off.
_FORMULA = re.compile(r"'*[=+\-@]")
_ESCAPED = re.compile(r"'+[=+\-@]")
def _header(lines, start):
    """(column names, delimiter, index of the first line below the header) of a CSV whose header
    starts at ``lines[start]``: the first delimiter that splits the header into as many names as
    the first row into fields (RFC 4180 quoting; a quoted name may hold the delimiter)."""
    row = next((line for line in itertools.islice(lines, start + 1, None)
                if line.split("#", 1)[0].strip()), "")
    parsed = []
    for delimiter in DELIMITERS:
        reader = csv.reader(itertools.islice(lines, start, None), delimiter=delimiter)
        names = next(reader)
        parsed.append((names, delimiter, start + reader.line_num))
        if len(names) > 1 and len(names) == len(row.split(delimiter)):
            return parsed[-1]
    return parsed[0]


def read_table_cells(lines):
    """The cells (stripped) of a CSV table whose header is ``lines[0]``, in the records' dialect:
    the separator as :func:`_header` finds it (',' or ';' or tab), and below the header a number
    written with a decimal comma ("1,5" after ';' or tab) as Python reads it; other cells (a
    record's name, an ISO time) as they are. For crowdvib's other tables (crowd, counts, modal).
    """
    if not lines:
        return []
    delimiter = _header(lines, 0)[1]
    cells = [[cell.strip() for cell in row] for row in csv.reader(lines, delimiter=delimiter)]
    if delimiter == "," or not cells:
        return cells
    return cells[:1] + [[_decimal_point(cell) for cell in row] for row in cells[1:]]


def _decimal_point(cell):
    candidate = cell.replace(",", ".", 1)
    try:
        float(candidate)
    except ValueError:
        return cell
    return candidate if cell.count(",") == 1 else cell


def _column_names(path, names):
    """Header cells → column names: blanks around them dropped, the writer's formula guard
    taken off; a name given twice is refused (which of the two columns is meant?)."""
    names = [name.strip() for name in names]
    names = [name[1:] if _ESCAPED.match(name) else name for name in names]
    seen = {}
    for number, name in enumerate(names, start=1):
        if name in seen:
            raise DataError(f"{where(path)}channel_names must be unique: column {quote(name)} "
                            f"is both column {seen[name]} and column {number} of the header")
        seen[name] = number
    return names


def _body(path, lines, first, delimiter):
    """The rows below the header as text for numpy: comments cut off, decimal commas made points
    when the columns are not separated by commas (a mix of both marks is refused)."""
    rows = [line.partition("#")[0] if "#" in line else line
            for line in itertools.islice(lines, first, None)]
    if delimiter == ",":
        return rows
    comma = next((i for i, row in enumerate(rows) if "," in row), None)
    if comma is None:
        return rows
    point = next((i for i, row in enumerate(rows) if "." in row), None)
    if point is not None:
        raise DataError(f"{where(path)}mixes decimal commas (line {first + comma + 1}) and decimal "
                        f"points (line {first + point + 1}): refusing to guess which is meant")
    return [row.replace(",", ".") for row in rows]


def _first_bad_line(path, rows, first, header, delimiter):
    """Why the rows below the header are not a table of numbers (only run after a failure).

    A cell and its column are quoted only below a row of numbers: before that the file may be
    anything a case file named (never quote a file that is not the record we expected).
    """
    numbers = 0
    for number, text in enumerate(rows, start=first + 1):
        text = text.strip()
        if not text:
            continue
        cells = text.split(delimiter)
        if len(cells) != len(header):
            hint = (" (decimal commas? separate the columns with ';')"
                    if delimiter == "," and len(cells) > len(header) else "")
            return (f"line {number} (sample index {numbers}) has {len(cells)} field(s), the "
                    f"header names {len(header)} column(s){hint}")
        for name, cell in zip(header, cells):
            try:
                float(cell)
            except ValueError:
                if not numbers:
                    return (f"line {number} (sample index 0) is not a row of numbers "
                            f"separated by {delimiter!r}: is {path} a CSV record?")
                return (f"line {number} (sample index {numbers}), column {quote(name)}: "
                        f"{quote(cell.strip())} is not a number")
        numbers += 1
    return "its rows are not all numbers"


def _read_csv(path, *, sample_rate, time_column, header_row=None):
    # utf-8-sig: a spreadsheet's "CSV UTF-8" starts with a byte-order mark.
    # newline="": lines end at "\n", "\r\n" or "\r" only, for the csv module to join the lines
    # of a quoted name that holds one.
    lines = list(io.StringIO(Path(path).read_bytes().decode("utf-8-sig"), newline=""))
    meta = {}
    start = 0
    while start < len(lines) and (not lines[start].strip()
                                  or lines[start].lstrip().startswith("#")):
        match = re.match(r"#\s*([\w ]+?)\s*[=:]\s*(.+)$", lines[start].strip())
        if match:
            meta[match.group(1).strip().lower()] = match.group(2).strip()
        start += 1
    if header_row is not None:
        # Given (measurement.header_row): the lines above it are skipped whatever they hold.
        if header_row != int(header_row) or header_row > len(lines):
            raise DataError(f"{where(path)}header_row must be the number of a line of the file "
                            f"(1 to {len(lines)}), got {header_row:g}")
        start, skipped = int(header_row) - 1, [line.strip() for line in
                                               lines[:int(header_row) - 1] if line.strip()]
    else:
        start, skipped = find_header(lines, start)
    if start == len(lines):
        raise DataError(f"{where(path)}has no header line of column names")
    header, delimiter, first = _header(lines, start)
    # Before the rows are parsed (1e5 columns took 71 s): the line count bounds the samples.
    refuse_transposed(path, len(header), len(lines) - first)
    header = _column_names(path, header)
    rows = _body(path, lines, first, delimiter)
    values = _table(path, rows, first, header, delimiter)
    key = time_key(path, header, time_column, meta.get("time_column"))
    stored = None
    if "sample_rate" in meta:
        try:
            stored = float(meta["sample_rate"])
        except ValueError:
            raise DataError(f"{where(path)}comment 'sample_rate' must be a number, got "
                            f"{quote(meta['sample_rate'])}") from None
    rate, source = stated_rate(path, sample_rate, stored, "its comment 'sample_rate'")
    columns = [(name, values[:, i], None) for i, name in enumerate(header) if name != key]
    # The units a header states count where no "# unit" comment (crowdvib's own) states them.
    stated = {} if meta.get("unit") else {name: unit for name, _, _ in columns
                                          for unit in [header_unit(name)[1]] if unit is not None}
    return columns, dict(time=None if key is None else values[:, header.index(key)],
                         time_name=key, sample_rate=rate, rate_source=source,
                         units=meta.get("unit") or _header_units(path, stated, len(columns)),
                         header_units=stated, header_line=start + 1, skipped=skipped)


def _header_units(path, stated, n_columns):
    """The one unit the channels' headers state (None if none does); headers that state
    different units, or some a unit and others none, are refused: crowdvib reads one unit per
    file, and a guess could be 1000 times wrong."""
    units = set(stated.values())
    if not units:
        return None
    if len(units) > 1 or len(stated) != n_columns:
        raise DataError(f"{where(path)}its column headers must state one unit for every channel, "
                        "got " + ", ".join(f"{quote(name)}: {unit}"
                                           for name, unit in stated.items())
                        + (f" and {n_columns - len(stated)} channel(s) without a unit"
                           if len(stated) != n_columns else "")
                        + ": write each unit in its own file, or give measurement.units")
    return units.pop()


def _table(path, rows, first, header, delimiter):
    """The rows as a float array, one column per header name; an empty cell (a logger's
    dropout) is NaN, which the record's checks name with its channel and time."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")   # numpy warns on a table without rows: refused below
            values = np.loadtxt(rows, delimiter=delimiter, ndmin=2, dtype=float)
    except ValueError as exc:
        gaps = _with_gaps(rows, delimiter, len(header))
        if gaps is None:
            # numpy's message quotes the whole offending row: name the line and cell instead.
            raise DataError(f"{where(path)}cannot be read as a table of numbers: "
                            f"{_first_bad_line(path, rows, first, header, delimiter)}") from exc
        values = np.loadtxt(gaps, delimiter=delimiter, ndmin=2, dtype=float)
    if values.size == 0:
        raise DataError(f"{where(path)}has no rows of numbers below its header line")
    if values.shape[1] != len(header):
        raise DataError(f"{where(path)}has {values.shape[1]} columns of data but {len(header)} "
                        "names in its header line")
    return values


def _with_gaps(rows, delimiter, n_columns):
    """The rows with each empty cell written "nan", if that makes every row one of numbers (a
    dropout); else None (the table is wrong in another way)."""
    filled = []
    for row in rows:
        cells = row.rstrip("\r\n").split(delimiter)
        if not row.strip():
            filled.append(row)
            continue
        if len(cells) != n_columns:
            return None
        cells = [cell if cell.strip() else "nan" for cell in cells]
        try:
            [float(cell) for cell in cells]
        except ValueError:
            return None
        filled.append(delimiter.join(cells))
    return filled


# ------------------------------------------------------------------------------------ writer
def _csv_name(name):
    """A channel name as a header cell that reads back to the name and that a spreadsheet does
    not run as a formula (RFC 4180 quoting is the csv module's)."""
    return "'" + name if _FORMULA.match(name) else name


def _csv_line(cells):
    """One CSV line ending in "\n" (a writer told its line ends in "\r\n" quotes a name holding
    a "\r", which one told "\n" would leave bare)."""
    line = io.StringIO()
    csv.writer(line, lineterminator="\r\n").writerow(cells)
    return line.getvalue()[:-2] + "\n"


def _write_csv(record, path, dtype):
    digits = 8 if np.dtype(dtype) == np.float32 else 17
    time_name = "time"
    while time_name in record.channel_names:     # a channel may itself be called "time"
        time_name += "_"
    header = [time_name] + [_csv_name(n) for n in record.channel_names]
    columns = np.vstack([record.time, record.data]).T
    with atomic_path(path) as temporary:
        with open(temporary, "w", encoding="utf-8", newline="") as handle:
            handle.write(f"# crowdvib record\n# unit = m/s2\n"
                         f"# sample_rate = {record.sample_rate!r}\n# time_column = {time_name}\n")
            handle.write(_csv_line(header))
            np.savetxt(handle, columns, delimiter=",", fmt=f"%.{digits}g")
