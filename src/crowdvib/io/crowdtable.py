"""The crowd table of a monitoring season: who was on the bridge during each record (issue 28 §2).

Its columns and rules: :func:`read_crowd_table`. Registered in the formats table
(:mod:`crowdvib.io.formats`) as the ``"csv"`` format of ``"crowd"`` data.
"""

import datetime
import math
from dataclasses import dataclass
from pathlib import Path

from .._files import require_file
from ..errors import DataError
from ..errors import excerpt
from ._common import quote, quote_names, reading, where
from .formats import FileFormat, read_table_cells, register_format

__all__ = ["CrowdRow", "CrowdTable", "read_crowd_table", "CROWD_COLUMNS"]

#: Every column a crowd table may hold, in the order the season's table shows them.
CROWD_COLUMNS = ("record", "start", "end", "count", "density", "step_frequency_mean",
                 "step_frequency_std", "duration", "time")
_NUMBERS = ("start", "end", "count", "density", "step_frequency_mean", "step_frequency_std",
            "duration")


@dataclass(frozen=True)
class CrowdRow:
    """One row of a crowd table: a record, or a window of one, and its crowd.

    Attributes
    ----------
    record : str
        The record's file name as the table gives it.
    row : int
        The row's number in the file (1 = the first after the header), for messages.
    start, end : float or None
        The window [s] on the record's time axis (None: the whole record).
    count, density : float or None
        Persons on the deck, or persons/m² (exactly one is given).
    step_frequency_mean, step_frequency_std : float or None
        [Hz], None where the case file's crowd holds.
    duration : float or None
        The length [s] the count was taken over.
    time : str or None
        ISO 8601 start time of the record or window.
    """

    record: str
    row: int
    start: float | None = None
    end: float | None = None
    count: float | None = None
    density: float | None = None
    step_frequency_mean: float | None = None
    step_frequency_std: float | None = None
    duration: float | None = None
    time: str | None = None

    @property
    def name(self) -> str:
        """The row's name in the season's table: the record, with its window when it has one."""
        if self.start is None:
            return self.record
        return f"{self.record}[{self.start:g}-{self.end:g}s]"

    def density_on(self, area: float) -> float:
        """Persons/m² on a deck of ``area`` [m²]."""
        return self.density if self.density is not None else self.count / area


@dataclass(frozen=True)
class CrowdTable:
    """A crowd table read and checked (:func:`read_crowd_table`).

    Parameters
    ----------
    path : pathlib.Path
        The CSV file.
    rows : tuple of CrowdRow
        Its rows, in the file's order.
    """

    path: Path
    rows: tuple

    def __len__(self):
        return len(self.rows)


def read_crowd_table(path) -> CrowdTable:
    """Read and check a crowd table CSV: per record, or time window of one, its crowd.

    A CSV file, ``#`` lines comments, one header line, one row per record or per time window of a
    record::

        record,          start, end,  count, step_frequency_mean, time
        day1_0800.npz,       ,     ,   42,   1.85,                2026-05-04T08:00
        day1_0900.npz,      0,  600,   12,       ,                2026-05-04T09:00
        day1_0900.npz,    600, 1200,   30,       ,                2026-05-04T09:10

    Columns (any order; only ``record`` and one of ``count`` / ``density`` are required):

    ``record``
        The record's file name, relative to the records folder (or as listed in the case file).
    ``count`` or ``density``
        The mean number of persons on the deck, or the density [persons/m²]; one of them per row.
        A density of 0 (a night record) is kept in the table and not estimated.
    ``step_frequency_mean``, ``step_frequency_std``
        The crowd's step-frequency distribution [Hz] during the row (else the case file's).
    ``start``, ``end``
        A time window [s] on the record's time axis, as the case file's ``measurement.time_frame``
        (both or neither); a row without them is the whole record.
    ``duration``
        The length [s] the row's count was taken over: a record of another length is an error
        in its row (the count belongs to another stretch). Not with ``start``/``end``.
    ``time``
        When the record (or window) began, ISO 8601 (``2026-05-04T08:00``): the trend figures'
        time axis (else the rows' order).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file (UTF-8, a byte-order mark allowed).

    Returns
    -------
    CrowdTable

    Raises
    ------
    DataError
        A missing or unreadable file, a missing ``record`` column, neither or both of
        ``count`` and ``density`` in a row, a number that is not one, a negative count, density
        or time, a step frequency or duration <= 0, ``start`` >= ``end``, a window with a
        duration, a time that is not ISO 8601, or two rows of the same record and window: each
        names the file, the row and the column.
    """
    path = require_file(path, "crowd table")
    with reading(path, "a crowd table CSV"):
        with open(path, encoding="utf-8-sig", newline="") as handle:
            lines = [line for line in handle if line.strip() and not line.lstrip().startswith("#")]
        cells = read_table_cells(lines)
        if len(cells) < 2:
            raise DataError(f"{path.name}: must hold a header line and at least one row")
        header = [name.lower() for name in cells[0]]
        unknown = [name for name in header if name not in CROWD_COLUMNS]
        # The header line is someone else's text (`crowdvib season CASE /etc/passwd`): only
        # short escaped excerpts of it reach a message, never the line.
        if len(unknown) == len(header):
            raise DataError(f"{where(path)}is not a crowd table: its first line names none of "
                            f"the columns {list(CROWD_COLUMNS)} (it starts "
                            f"{excerpt(lines[0].strip())})")
        if unknown:
            raise DataError(f"{where(path)}unknown column(s) {quote_names(unknown)}; a crowd "
                            f"table has {list(CROWD_COLUMNS)}")
        if "record" not in header or not {"count", "density"} & set(header):
            raise DataError(f"{where(path)}needs a 'record' column and a 'count' or 'density' "
                            f"column, got {quote_names(header)}")
        rows = tuple(_row(path, header, values, number)
                     for number, values in enumerate(cells[1:], start=1))
    seen: dict[tuple, int] = {}
    for row in rows:
        key = (row.record, row.start, row.end)
        if key in seen:
            raise DataError(f"{path.name}: row {row.row} repeats row {seen[key]} (record "
                            f"{quote(row.record)}, the same window)")
        seen[key] = row.row
    return CrowdTable(path, rows)


def _row(path, header, values, number):
    """One checked row."""
    where = f"{path.name}: row {number}"
    if len(values) != len(header):
        raise DataError(f"{where} has {len(values)} field(s), the header has {len(header)}")
    given = {name: value for name, value in zip(header, values) if value != ""}
    if "record" not in given:
        raise DataError(f"{where}, column 'record' is empty: name the record's file")
    numbers = {}
    for name in _NUMBERS:
        if name in given:
            try:
                numbers[name] = float(given[name])
            except ValueError:
                numbers[name] = math.nan
            if not math.isfinite(numbers[name]):
                raise DataError(f"{where}, column {name!r} must hold a finite number, got "
                                f"{quote(given[name])}")
    if ("count" in numbers) == ("density" in numbers):
        raise DataError(f"{where}: give the crowd as 'count' or as 'density', exactly one")
    rules = {"count": (0.0, ">= 0 (persons on the deck)"),
             "density": (0.0, ">= 0 persons/m²"), "start": (0.0, ">= 0 s")}
    for name, (low, rule) in rules.items():
        if name in numbers and numbers[name] < low:
            raise DataError(f"{where}, column {name!r} must be {rule}, got {numbers[name]:g}")
    for name in ("step_frequency_mean", "step_frequency_std", "duration", "end"):
        if name in numbers and not numbers[name] > 0:
            raise DataError(f"{where}, column {name!r} must be > 0, got {numbers[name]:g}")
    if ("start" in numbers) != ("end" in numbers):
        raise DataError(f"{where}: a window needs both 'start' and 'end' [s], or neither")
    if "start" in numbers and not numbers["start"] < numbers["end"]:
        raise DataError(f"{where}: column 'start' must be before 'end', got "
                        f"{numbers['start']:g} >= {numbers['end']:g} s")
    if "start" in numbers and "duration" in numbers:
        raise DataError(f"{where}: a window ('start', 'end') has its own length: leave "
                        "'duration' empty")
    time = given.get("time")
    if time is not None:
        try:
            datetime.datetime.fromisoformat(time)
        except ValueError:
            raise DataError(f"{where}, column 'time' must be an ISO 8601 date and time "
                            f"(2026-05-04T08:00), got {quote(time)}") from None
    return CrowdRow(record=given["record"], row=number, time=time, **numbers)


register_format(FileFormat("csv", "crowd", (".csv",), "a crowd table CSV", read_crowd_table))
