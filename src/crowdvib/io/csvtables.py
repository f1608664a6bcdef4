"""The CSV tables of the modal readers (``modalfiles``: modal tables, shapes and output points;
``femodes``: FE node tables): read, column-checked, converted, and the walkway model built from
them before its outputs are placed."""

import difflib
import warnings
from pathlib import Path

import numpy as np

from .._files import require_file
from ..errors import DataError, ParameterError, PlausibilityWarning
from ..models.structure import ModalModel
from ._common import quote, reading
from .formats import read_table_cells

__all__ = ["read_csv_table", "require_columns", "number_columns", "quietly_built", "output_rows"]


def read_csv_table(path):
    """Header and rows (as strings) of a small CSV file; ``#`` lines are comments.

    The one guard of this reader: a missing, binary or malformed file is a :class:`DataError`
    naming it. Messages never repeat the file's lines (issue 9: a case could name any file).
    """
    path = require_file(path, "modal CSV")
    with reading(path, "a CSV"):
        with open(path, encoding="utf-8", newline="") as handle:
            lines = [line for line in handle
                     if line.strip() and not line.lstrip().startswith("#")]
        rows = read_table_cells(lines)
        if len(rows) < 2:
            raise DataError(f"{path.name}: must hold a header line and at least one row")
        header, body = rows[0], rows[1:]
        twice = next((name for i, name in enumerate(header) if name in header[:i]), None)
        if twice is not None:       # which of the two columns is meant? (issue 35 §3)
            raise DataError(f"{path.name}: column names must be unique, got {quote(twice)} "
                            f"as columns {header.index(twice) + 1} and "
                            f"{header.index(twice, header.index(twice) + 1) + 1}")
        for number, row in enumerate(body, start=1):
            if len(row) != len(header):
                raise DataError(f"{path.name}: row {number} has {len(row)} field(s), the header "
                                f"has {len(header)}")
    return header, body

def require_columns(path, header, columns):
    """DataError for required columns absent from ``header``; a near miss is named as such."""
    missing = [c for c in columns if c not in header]
    if missing:
        hints = "".join(f" ({quote(guess[0])}: did you mean {c!r}?)" for c in missing
                        for guess in [difflib.get_close_matches(c, header, n=1)] if guess)
        raise DataError(f"{Path(path).name}: missing column(s) {missing}{hints}; the header has "
                        f"{len(header)} column(s)")

def number_columns(path, header, rows, columns):
    """The named columns as finite floats; the first bad cell is named by row and column."""
    values = np.empty((len(rows), len(columns)))
    for i, row in enumerate(rows):
        for j, column in enumerate(columns):
            cell = row[header.index(column)]
            try:
                values[i, j] = float(cell)
            except ValueError:
                values[i, j] = np.nan
            if not np.isfinite(values[i, j]):
                raise DataError(f"{Path(path).name}: row {i + 1}, column {quote(column)} must "
                                f"hold a finite number, got {quote(cell)}")
    return values

def quietly_built(**fields):
    """The walkway's ModalModel without outputs, built only to place them: its plausibility is
    judged once, on the complete model the reader returns (each doubt warned once)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlausibilityWarning)
        return ModalModel(output_names=(), output_shapes=np.zeros((0, fields["frequencies"].size)),
                          **fields)

def output_rows(base, outputs):
    """Names and mode-shape rows of output points given as name → x or (x, y) on the walkway."""
    positions = base.positions
    names, rows = [], []
    for label, where in outputs.items():
        try:
            x, y = (float(where), None) if np.ndim(where) == 0 else (float(where[0]),
                                                                   float(where[1]))
        except (TypeError, ValueError, IndexError):
            raise ParameterError(f"outputs[{label!r}] must be a position x [m] or [x, y], "
                                 f"got {quote(where)}") from None
        if not positions[0] <= x <= positions[-1]:
            raise ParameterError(f"outputs[{label!r}] must lie on the walkway "
                                 f"[{positions[0]:g}, {positions[-1]:g}] m, got {x:g}")
        names.append(label)
        rows.append(base.shapes_at(np.array([x]), None if y is None else np.array([y]))[0])
    return names, np.array(rows, dtype=float).reshape(len(names), base.n_modes)
