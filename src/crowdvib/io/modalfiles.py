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
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from .._files import atomic_path
from ..errors import DataError, ParameterError
from ..models.structure import ModalModel
from .csvtables import number_columns, output_rows, quietly_built, read_csv_table, require_columns
from .femodes import FEModes, read_fe_modes
from .formats import FileFormat, register_format, suffix_format

__all__ = ["read_modal_model", "write_modal_model"]








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
    **fe_options
        For an FE export: the keywords of :meth:`crowdvib.io.femodes.FEModes.modal_model`.

    Returns
    -------
    ModalModel

    See Also
    --------
    write_modal_model, crowdvib.io.read_fe_modes
    """
    known = set(inspect.signature(FEModes.modal_model).parameters) - {"self", "width",
                                                                       "outputs", "name"}
    for option in sorted(set(fe_options) - known):
        guess = difflib.get_close_matches(option, known, n=1)
        raise ParameterError(f"{option!r} is not an option of read_modal_model"
                             f"{f' (did you mean {guess[0]!r}?)' if guess else ''}; the FE "
                             f"options are {sorted(known)}")
    uff = getattr(suffix_format(modal_table, "modes"), "name", None) == "uff"
    fe_route = uff or (
        mode_shapes is not None and Path(mode_shapes).is_file()
        and "node" in read_csv_table(mode_shapes)[0])
    if fe_route:
        if output_points is not None:
            raise ParameterError("output_points is for station CSVs; name FE outputs with "
                                 "output_nodes (name → node number) or outputs (name → x)")
        if uff:
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
    header, rows = read_csv_table(modal_table)
    require_columns(modal_table, header, ("frequency", "damping_ratio", "modal_mass"))
    table = number_columns(modal_table, header, rows, ["frequency", "damping_ratio", "modal_mass"])
    n_modes = table.shape[0]
    shape_header, shape_rows = read_csv_table(mode_shapes)
    require_columns(mode_shapes, shape_header, ("position",))
    mode_columns = [c for c in shape_header if c not in ("position", "lane")]
    if len(mode_columns) != n_modes:
        raise DataError(f"{Path(mode_shapes).name}: must have one column per mode of "
                        f"{Path(modal_table).name} ({n_modes}) besides 'position' and 'lane', "
                        f"got {len(mode_columns)}")
    values = number_columns(mode_shapes, shape_header, shape_rows, mode_columns)
    still = [c for c, column in zip(mode_columns, values.T) if not np.any(column)]
    if still:
        raise DataError(f"{Path(mode_shapes).name}: mode column(s) {still} are all zero: a mode "
                        "must move the walkway somewhere")
    position = number_columns(mode_shapes, shape_header, shape_rows, ["position"])[:, 0]
    if "lane" in shape_header:
        lane = number_columns(mode_shapes, shape_header, shape_rows, ["lane"])[:, 0]
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
        point_header, point_rows = read_csv_table(output_points)
        require_columns(output_points, point_header, ("name",))
        columns = [c for c in point_header if c != "name"]
        if len(columns) != n_modes:
            raise DataError(f"{Path(output_points).name}: must have one column per mode "
                            f"({n_modes}) besides 'name', got {len(columns)}")
        names = [row[point_header.index("name")] for row in point_rows]
        rows_ = number_columns(output_points, point_header, point_rows, columns)
    else:
        names, rows_ = output_rows(base, outputs)
    return base.replace(output_names=tuple(names), output_shapes=np.array(rows_, dtype=float))






def write_modal_model(structure, modal_table, mode_shapes, output_points=None, *, digits=10):
    """Write a :class:`ModalModel` as the CSV files :func:`read_modal_model` reads (atomically).

    Parameters
    ----------
    structure : ModalModel
        The model written.
    modal_table : path
        CSV written with ``mode``, ``frequency`` [Hz], ``damping_ratio`` [-] and ``modal_mass``
        [kg] per mode.
    mode_shapes : path
        CSV written with ``position`` [m] (and ``lane`` [m] for several lanes) and one column per
        mode.
    output_points : path, optional
        CSV written with the outputs' mode-shape rows (``name`` and one column per mode).
    digits : int
        Significant digits of every number written.

    See Also
    --------
    read_modal_model
    """
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


# The modal table and mode shapes as CSV in the formats table (io.formats.FORMATS).
register_format(FileFormat("csv", "modes", (".csv",), "a modal table CSV", read_modal_model,
                           write_modal_model))
