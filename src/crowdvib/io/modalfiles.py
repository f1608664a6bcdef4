"""Modal models from CSV files: a modal table and mode shapes along the walkway (issue 4).

The files an FE program or an operational modal analysis exports: one row per mode (frequency,
damping ratio, modal mass), the shapes at stations along the walkway (optionally per lane across
the width), and the output points by name. Any mode-shape scaling works as long as the modal
masses match it (docs: theory, Conventions): a mass-normalised export and a unity-scaled table are the same
physics.
"""

from __future__ import annotations

import csv
import difflib
import inspect
import os
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import DataError, ParameterError, PlausibilityWarning
from ..models.structure import ModalModel
from .._files import require_file
from ._common import quote, reading

__all__ = ["read_modal_model", "write_modal_model"]


def _read_csv_table(path):
    """Header and rows (as strings) of a small CSV file; ``#`` lines are comments.

    The one guard of this reader: a missing, binary or malformed file is a :class:`DataError`
    naming it. Messages never repeat the file's lines (issue 9: a case could name any file).
    """
    path = require_file(path, "modal CSV")
    with reading(path, "a CSV"):
        with open(path, encoding="utf-8", newline="") as handle:
            lines = [line for line in handle
                     if line.strip() and not line.lstrip().startswith("#")]
        rows = [[cell.strip() for cell in row] for row in csv.reader(lines)]
        if len(rows) < 2:
            raise DataError(f"{path.name}: must hold a header line and at least one row")
        header, body = rows[0], rows[1:]
        for number, row in enumerate(body, start=1):
            if len(row) != len(header):
                raise DataError(f"{path.name}: row {number} has {len(row)} field(s), the header "
                                f"has {len(header)}")
    return header, body


def _missing(path, header, columns):
    """DataError for required columns absent from ``header``; a near miss is named as such."""
    missing = [c for c in columns if c not in header]
    if missing:
        hints = "".join(f" ({quote(guess[0])}: did you mean {c!r}?)" for c in missing
                        for guess in [difflib.get_close_matches(c, header, n=1)] if guess)
        raise DataError(f"{Path(path).name}: missing column(s) {missing}{hints}; the header has "
                        f"{len(header)} column(s)")


def _numbers(path, header, rows, columns):
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


def read_modal_model(modal_table: str | os.PathLike, mode_shapes: str | os.PathLike | None = None,
                     *, width: float,
                     outputs: Mapping[str, float | tuple[float, float]] | None = None,
                     output_points: str | os.PathLike | None = None, name: str = "footbridge",
                     **fe_options: Any) -> ModalModel:
    """A :class:`ModalModel` from a modal table and mode shapes along the walkway (CSV), or from an FE export.

    FE exports (docs: theory, Modal models from FE exports): a UFF file (``.uff``/``.unv``, data
    sets 15 and 55) as ``modal_table`` alone, or a modal table with a CSV node table (a ``node``
    column and x, y, z) as ``mode_shapes``. The deck nodes are mapped onto the walkway, every mode
    is scaled to 1 at its antinode (a mass-normalised export gets its engaged modal mass) and
    modes not vertical enough are dropped with a warning; ``fe_options`` are the keywords of
    :meth:`crowdvib.io.femodes.FEModes.modal_model` (``along``, ``across``, ``vertical``,
    ``deck_nodes``, ``lanes``, ``damping_ratios``, ``output_nodes``, ``min_vertical``).

    Parameters
    ----------
    modal_table : path
        CSV with columns ``frequency`` [Hz], ``damping_ratio`` [-, fraction] and ``modal_mass``
        [kg, in the scaling of the shapes: 1 for a mass-normalised FE export], one row per mode;
        an optional ``mode`` column labels the modes.
    mode_shapes : path
        CSV with a ``position`` column [m] along the walkway, an optional ``lane`` column [m]
        across it (then one block of identical positions per lane) and one column per mode, in
        the order of the table (any other column names).
    width : float
        Walkway width [m].
    outputs : dict of str to float or (float, float), optional
        Output points as name → position x [m] (mid-width) or (x, y); shape rows interpolated.
    output_points : path, optional
        CSV with a ``name`` column and one column per mode: the mode-shape rows of the outputs
        (e.g. sensor nodes of an FE model). Either this or ``outputs``.
    name : str

    Returns
    -------
    ModalModel
    """
    from .femodes import UFF_SUFFIXES, FEModes, read_fe_modes

    known = set(inspect.signature(FEModes.modal_model).parameters) - {"self", "width",
                                                                       "outputs", "name"}
    for option in sorted(set(fe_options) - known):
        guess = difflib.get_close_matches(option, known, n=1)
        raise ParameterError(f"{option!r} is not an option of read_modal_model"
                             f"{f' (did you mean {guess[0]!r}?)' if guess else ''}; the FE "
                             f"options are {sorted(known)}")
    fe_route = Path(modal_table).suffix.lower() in UFF_SUFFIXES or (
        mode_shapes is not None and Path(mode_shapes).is_file()
        and "node" in _read_csv_table(mode_shapes)[0])
    if fe_route:
        if output_points is not None:
            raise ParameterError("output_points is for station CSVs; name FE outputs with "
                                 "output_nodes (name → node number) or outputs (name → x)")
        if Path(modal_table).suffix.lower() in UFF_SUFFIXES:
            if mode_shapes is not None:
                raise ParameterError("mode_shapes must be None with a UFF file (it holds them)")
            modes = read_fe_modes(modal_table)
        else:
            modes = read_fe_modes(mode_shapes, modal_table)
        return modes.modal_model(width=width, outputs=outputs, name=name, **fe_options)
    if fe_options:
        raise ParameterError(f"{sorted(fe_options)} apply to FE exports only (a UFF file or a "
                             "CSV node table with a 'node' column)")
    if mode_shapes is None:
        raise ParameterError("mode_shapes must be given with a modal table CSV")
    header, rows = _read_csv_table(modal_table)
    _missing(modal_table, header, ("frequency", "damping_ratio", "modal_mass"))
    table = _numbers(modal_table, header, rows, ["frequency", "damping_ratio", "modal_mass"])
    n_modes = table.shape[0]
    shape_header, shape_rows = _read_csv_table(mode_shapes)
    _missing(mode_shapes, shape_header, ("position",))
    mode_columns = [c for c in shape_header if c not in ("position", "lane")]
    if len(mode_columns) != n_modes:
        raise DataError(f"{Path(mode_shapes).name}: must have one column per mode of "
                        f"{Path(modal_table).name} ({n_modes}) besides 'position' and 'lane', "
                        f"got {len(mode_columns)}")
    values = _numbers(mode_shapes, shape_header, shape_rows, mode_columns)
    still = [c for c, column in zip(mode_columns, values.T) if not np.any(column)]
    if still:
        raise DataError(f"{Path(mode_shapes).name}: mode column(s) {still} are all zero: a mode "
                        "must move the walkway somewhere")
    position = _numbers(mode_shapes, shape_header, shape_rows, ["position"])[:, 0]
    if "lane" in shape_header:
        lane = _numbers(mode_shapes, shape_header, shape_rows, ["lane"])[:, 0]
        lanes = np.unique(lane)
        blocks = [np.flatnonzero(lane == y) for y in lanes]
        positions = position[blocks[0]]
        for y, block in zip(lanes, blocks):
            if block.size != positions.size or not np.allclose(position[block], positions):
                raise DataError(f"{Path(mode_shapes).name}: lane {y:g} m must list the same "
                                "positions as the first lane")
        shapes = np.stack([values[block] for block in blocks])
    else:
        lanes, positions, shapes = None, position, values
    base = quietly_built(frequencies=table[:, 0], damping_ratios=table[:, 1],
                         modal_masses=table[:, 2], positions=positions, mode_shapes=shapes,
                         width=width, lanes=lanes, name=name)
    if (outputs is None) == (output_points is None):
        raise ParameterError("give exactly one of outputs (name → position) and output_points "
                             "(a CSV of mode-shape rows)")
    if output_points is not None:
        point_header, point_rows = _read_csv_table(output_points)
        _missing(output_points, point_header, ("name",))
        columns = [c for c in point_header if c != "name"]
        if len(columns) != n_modes:
            raise DataError(f"{Path(output_points).name}: must have one column per mode "
                            f"({n_modes}) besides 'name', got {len(columns)}")
        names = [row[point_header.index("name")] for row in point_rows]
        rows_ = _numbers(output_points, point_header, point_rows, columns)
    else:
        names, rows_ = output_rows(base, outputs)
    return base.replace(output_names=tuple(names), output_shapes=np.array(rows_, dtype=float))


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


def write_modal_model(structure, modal_table, mode_shapes, output_points=None, *, digits=10):
    """Write a :class:`ModalModel` as the CSV files :func:`read_modal_model` reads (atomically)."""
    from .._files import atomic_path

    modes = [f"mode_{j + 1}" for j in range(structure.n_modes)]
    fmt = f"{{:.{digits}g}}"

    def write(path, header, rows):
        with atomic_path(path) as temporary:
            with open(temporary, "w", encoding="utf-8", newline="") as handle:
                writer = csv.writer(handle, lineterminator="\n")
                writer.writerow(header)
                writer.writerows([[v if isinstance(v, str) else fmt.format(v) for v in row]
                                  for row in rows])

    write(modal_table, ["mode", "frequency", "damping_ratio", "modal_mass"],
          [[modes[j], structure.frequencies[j], structure.damping_ratios[j],
            structure.modal_masses[j]] for j in range(structure.n_modes)])
    several = structure.lanes.size > 1
    rows = [([x, y] if several else [x]) + list(shape)
            for y, lane in zip(structure.lanes, structure.mode_shapes)
            for x, shape in zip(structure.positions, lane)]
    write(mode_shapes, ["position"] + (["lane"] if several else []) + modes, rows)
    if output_points is not None:
        write(output_points, ["name"] + modes,
              [[n] + list(row) for n, row in zip(structure.output_names, structure.output_shapes)])
