"""Mode shapes at FE nodes → a walkway :class:`ModalModel` (docs: theory, Modal models from FE exports).

Two exports are read: the universal file format (UFF data set 15, the nodes, and data sets 55,
one normal mode each, through pyuff) and a plain CSV node table (``node``, ``x``, ``y``, ``z`` and
one column per mode, or three per mode ending in ``_x``, ``_y``, ``_z``) with a modal table beside
it. :class:`FEModes` holds what the file says; :meth:`FEModes.modal_model` maps the deck nodes
onto the walkway stations and lanes by linear interpolation, scales every mode to 1 at its
antinode on the walkway (a mass-normalised export — modal masses 1 — becomes the engaged modal
mass), and drops modes that are not vertical enough to matter for walkers, saying which.
"""

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike
from scipy import interpolate
from scipy.spatial import QhullError

from .._validation import check_damping_ratio, check_positive
from ..errors import DataError, DataWarning, ParameterError, PlausibilityWarning
from ..models.structure import ModalModel
from .._files import require_file
from ._common import quote, reading
from .csvtables import number_columns, output_rows, quietly_built, read_csv_table, require_columns
from .formats import FileFormat, file_formats, register_format
from .formats import _check_uff_complete, _pyuff

__all__ = ["UFF_SUFFIXES", "FEModes", "read_fe_modes"]

#: A UFF file's suffixes: the formats table's (io.formats.FORMATS), shared with UFF 58 records.
UFF_SUFFIXES = file_formats("record")["uff"].suffixes
AXES = ("x", "y", "z")
#: Modal masses within this of 1 mark a mass-normalised export.
UNIT_MASS_TOLERANCE = 1e-4
#: No footbridge mode engages less mass [kg] (a 20 kg/m² deck of 10 m²): a mass-normalised
#: shape peaking above 1/√ of it is a unity-scaled shape read without its modal mass.
MIN_ENGAGED_MASS = 100.0
#: Node coordinates spanning more than this [m] are taken for millimetres (the longest
#: pedestrian bridges span about 720 m).
MAX_EXTENT = 5000.0


@dataclass(frozen=True)
class FEModes:
    """Normal modes at FE nodes as exported.

    Attributes
    ----------
    nodes : ndarray of int, (n_nodes,)
    coordinates : ndarray, (n_nodes, 3)
        x, y, z [m].
    shapes : ndarray, (n_nodes, n_modes, 3) or (n_nodes, n_modes, 1)
        Translations per node and mode (x, y, z), or the vertical one only.
    frequencies : ndarray [Hz]
    damping_ratios : ndarray [-] (0 where the export has none)
    modal_masses : ndarray [kg] in the export's scaling (1 for mass-normalised shapes)
    source : str
    """

    nodes: np.ndarray
    coordinates: np.ndarray
    shapes: np.ndarray
    frequencies: np.ndarray
    damping_ratios: np.ndarray
    modal_masses: np.ndarray
    source: str = "FE export"

    @property
    def n_modes(self) -> int:
        return self.frequencies.size

    @property
    def mass_normalised(self) -> bool:
        """True when every modal mass is 1: the shapes are mass-normalised."""
        return bool(np.all(np.abs(self.modal_masses - 1.0) <= UNIT_MASS_TOLERANCE))

    def _deck(self, deck_nodes):
        if deck_nodes is None:
            return np.arange(self.nodes.size)
        deck_nodes = np.asarray(deck_nodes).ravel()
        missing = np.setdiff1d(deck_nodes, self.nodes)
        if missing.size:
            raise ParameterError(f"deck_nodes must be nodes of {self.source}, got unknown node(s) "
                                 f"{missing[:5].tolist()}")
        return np.flatnonzero(np.isin(self.nodes, deck_nodes))

    def vertical_fractions(self, *, vertical: str = "z",
                           deck_nodes: ArrayLike | None = None) -> np.ndarray:
        """Share of each mode's translational motion on the deck that is vertical [-].

        Σ φ_v² / Σ (φ_x² + φ_y² + φ_z²) over the deck nodes; 1 when the export holds the vertical
        component only (it cannot say otherwise).

        Parameters
        ----------
        vertical : {"x", "y", "z"}
            The vertical axis of the export.
        deck_nodes : array_like, optional
            The deck's node numbers (default every node).

        Returns
        -------
        ndarray, shape (n_modes,)
        """
        rows = self._deck(deck_nodes)
        shapes = self.shapes[rows]
        if shapes.shape[2] == 1:
            return np.ones(self.n_modes)
        total = (shapes**2).sum(axis=(0, 2))
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(total > 0, (shapes[:, :, _axis(vertical)] ** 2).sum(axis=0) / total,
                            0.0)

    def modal_model(self, *, width: float, along: str = "x", across: str = "y",
                    vertical: str = "z", deck_nodes: ArrayLike | None = None,
                    lanes: ArrayLike | None = None, damping_ratios: ArrayLike | None = None,
                    outputs: dict | None = None, output_nodes: dict | None = None,
                    min_vertical: float = 0.5, name: str = "footbridge") -> ModalModel:
        """The walkway's :class:`ModalModel` (docs: theory, Modal models from FE exports).

        Parameters
        ----------
        width : float
            Walkway width B [m]; the walkway is centred on the deck nodes' mid ``across``
            coordinate.
        along, across, vertical : {"x", "y", "z"}
            The global axes along the walkway, across it and up.
        deck_nodes : sequence of int, optional
            Node numbers on the walkway (default every node of the export).
        lanes : sequence of float, optional
            Lanes y [m] in [0, B] at which shapes are interpolated across the deck (default: the
            deck nodes' distinct ``across`` coordinates, or one lane for a line of nodes).
        damping_ratios : float or sequence, optional
            ξ_j [-] per kept mode (or one for all); default the export's (must then be > 0).
        outputs : dict of str to float or (float, float), optional
            Output points as name → x [m] along the walkway (or (x, y)).
        output_nodes : dict of str to int, optional
            Output points as name → node number (the node's own vertical shape).
        min_vertical : float
            Modes whose vertical share on the deck (:meth:`vertical_fractions`) is below this are
            dropped, with a :class:`DataWarning` naming them.
        name : str
        """
        width = check_positive("width", width, unit="m")
        i_along, i_across, i_up = (_axis(a, label) for a, label in
                                   ((along, "along"), (across, "across"), (vertical, "vertical")))
        if len({i_along, i_across, i_up}) != 3:
            raise ParameterError(f"along, across and vertical must be three different axes, got "
                                 f"{along!r}, {across!r}, {vertical!r}")
        rows = self._deck(deck_nodes)
        fractions = self.vertical_fractions(vertical=vertical, deck_nodes=self.nodes[rows])
        keep = np.flatnonzero(fractions >= min_vertical)
        dropped = [j for j in range(self.n_modes) if j not in keep]
        if dropped:
            words = ", ".join(f"mode {j + 1} ({self.frequencies[j]:.3g} Hz, "
                              f"{fractions[j]:.0%} vertical)" for j in dropped)
            warnings.warn(f"{self.source}: dropped {len(dropped)} mode(s) not vertical enough to "
                          f"load the walkway (< {min_vertical:.0%}): {words}", DataWarning,
                          stacklevel=3)
        if keep.size == 0:
            raise DataError(f"{self.source}: no mode is at least {min_vertical:.0%} vertical on "
                            "the deck")
        vertical_shapes = self.shapes[:, keep, i_up if self.shapes.shape[2] == 3 else 0]
        damping = self._damping(damping_ratios, keep)
        x = self.coordinates[rows, i_along]
        y = self.coordinates[rows, i_across]
        positions = np.unique(x)
        if positions.size < 2:
            raise DataError(f"{self.source}: the deck nodes must span the walkway, got one "
                            f"{along} coordinate")
        centre_offset = 0.5 * (y.min() + y.max()) - width / 2     # walkway y = across − this
        flat = np.ptp(y) <= 1e-9 * max(1.0, np.ptp(x))
        if lanes is None:
            lanes = None if flat else np.unique(y - centre_offset)
        else:
            lanes = np.atleast_1d(np.asarray(lanes, dtype=float))
        grid = _interpolate(x, y, vertical_shapes[rows], positions,
                            None if lanes is None else lanes + centre_offset, flat, self.source)
        antinode = _antinode(grid)
        if np.any(antinode == 0):
            raise DataError(f"{self.source}: mode(s) {(keep[antinode == 0] + 1).tolist()} "
                            "have no vertical motion on the deck")
        if (outputs is None) == (output_nodes is None):
            raise ParameterError("give exactly one of outputs (name → position) and output_nodes "
                                 "(name → node number)")
        # Unity at the antinode: a mass-normalised export gets its engaged modal mass.
        base = quietly_built(frequencies=self.frequencies[keep], damping_ratios=damping,
                             modal_masses=self.modal_masses[keep] / antinode**2,
                             positions=positions - x.min(), mode_shapes=grid / antinode,
                             width=width, name=name,
                             **({} if lanes is None else {"lanes": lanes}))
        if output_nodes is not None:
            names, out_rows = [], []
            for label, node in output_nodes.items():
                hit = np.flatnonzero(self.nodes == node)
                if hit.size != 1:
                    raise ParameterError(f"output_nodes[{label!r}] must be a node of "
                                         f"{self.source}, got {quote(node)}")
                names.append(label)
                out_rows.append(vertical_shapes[hit[0]] / antinode)
        else:                       # the CSV route's positional outputs
            names, out_rows = output_rows(base, outputs)
        return base.replace(output_names=tuple(names), output_shapes=np.array(out_rows))

    def _damping(self, damping_ratios, keep):
        if damping_ratios is None:
            damping = self.damping_ratios[keep]
            if np.any(damping <= 0):
                raise ParameterError(f"damping_ratios must be given: {self.source} has no damping "
                                     f"ratio for mode(s) {(keep[damping <= 0] + 1).tolist()}")
            return damping
        damping = np.broadcast_to(np.asarray(damping_ratios, dtype=float), keep.shape) if np.ndim(
            damping_ratios) == 0 else np.asarray(damping_ratios, dtype=float)
        if damping.shape != keep.shape:
            raise ParameterError(f"damping_ratios must give one ratio per kept mode ({keep.size}), "
                                 f"got {damping.size}")
        return check_damping_ratio("damping_ratios", damping)


def _axis(name, label="vertical"):
    if name not in AXES:
        raise ParameterError(f"{label} must be one of {AXES}, got {name!r}")
    return AXES.index(name)


def _interpolate(x, y, values, positions, lane_coordinates, flat, source):
    """Shapes (n_lanes, n_positions, n_modes) at the walkway grid, linear between nodes."""
    if flat:
        order = np.argsort(x, kind="stable")
        xs, vs = x[order], values[order]
        _, first = np.unique(xs, return_index=True)
        line = np.column_stack([np.interp(positions, xs[first], vs[first, j])
                                for j in range(values.shape[1])])
        n_lanes = 1 if lane_coordinates is None else lane_coordinates.size
        return np.broadcast_to(line, (n_lanes,) + line.shape).copy()
    points = np.column_stack([x, y])
    lx, ly = np.meshgrid(positions, lane_coordinates)
    query = np.column_stack([lx.ravel(), ly.ravel()])
    try:
        linear = interpolate.LinearNDInterpolator(points, values)(query)
    except QhullError:
        raise DataError(f"{source}: the deck nodes must lie on a line along the walkway or "
                        f"span an area; they lie (nearly) on a line oblique to it (across "
                        f"extent {np.ptp(y):.3g} m over {np.ptp(x):.3g} m along): give "
                        f"coordinates with the walkway along one axis") from None
    nearest = interpolate.NearestNDInterpolator(points, values)(query)
    grid = np.where(np.isnan(linear), nearest, linear)     # outside the nodes' hull: nearest
    return grid.reshape(lane_coordinates.size, positions.size, values.shape[1])


def _antinode(grid):
    """Signed value of each mode at its largest |φ| on the walkway grid."""
    flat = grid.reshape(-1, grid.shape[2])
    return flat[np.argmax(np.abs(flat), axis=0), np.arange(grid.shape[2])]


def read_fe_modes(path: str | Path, modal_table: str | Path | None = None) -> FEModes:
    """Normal modes at FE nodes from a UFF file (15 + 55) or a CSV node table (+ modal table).

    Parameters
    ----------
    path : path
        ``.uff``/``.unv``: data set 15 (nodes) and one data set 55 per normal mode (frequency,
        modal mass, viscous damping ratio in its header). Otherwise a CSV node table with columns
        ``node``, ``x``, ``y``, ``z`` [m] and per mode one vertical column or three ending in
        ``_x``, ``_y``, ``_z``.
    modal_table : path, optional
        For the CSV route: ``frequency`` [Hz], optional ``damping_ratio`` [-] and ``modal_mass``
        [kg] (absent = mass-normalised shapes), one row per mode in the column order.

    Returns
    -------
    FEModes
    """
    source = require_file(path, "modal")
    if source.suffix.lower() in UFF_SUFFIXES:
        if modal_table is not None:
            raise ParameterError("modal_table must be None for a UFF file (its data sets 55 hold "
                                 "the frequencies and modal masses)")
        return _read_uff_modes(source)
    if modal_table is None:
        raise ParameterError("modal_table must be given with a CSV node table")
    return _read_csv_modes(source, modal_table)


def _read_uff_modes(path):
    _check_uff_complete(path)
    with reading(path, "a UFF"):
        sets = _pyuff().UFF(str(path)).read_sets()
        sets = [sets] if isinstance(sets, dict) else list(sets)
        node_sets = [s for s in sets if s.get("type") == 15]
        mode_sets = [s for s in sets if s.get("type") == 55 and s.get("analysis_type") == 2]
        if not node_sets or not mode_sets:
            raise DataError(f"{path.name}: must hold a data set 15 (nodes) and data sets 55 of "
                            f"normal modes (analysis type 2), got {len(node_sets)} and "
                            f"{len(mode_sets)}")
        for s in node_sets:
            if not len(s["node_nums"]) == len(s["x"]) == len(s["y"]) == len(s["z"]):
                raise DataError(f"{path.name}: data set 15 must give x, y, z for each of its "
                                f"{len(s['node_nums'])} node(s), got {len(s['x'])}")
        nodes = np.concatenate([np.asarray(s["node_nums"]) for s in node_sets]).astype(np.int64)
        coordinates = np.column_stack([np.concatenate([np.asarray(s[a], dtype=float)
                                                       for s in node_sets]) for a in AXES])
        if np.unique(nodes).size != nodes.size:
            raise DataError(f"{path.name}: node numbers of data set 15 must be unique")
        shapes = np.zeros((nodes.size, len(mode_sets), 3))
        for j, mode in enumerate(mode_sets):
            numbers = np.asarray(mode["node_nums"]).astype(np.int64)
            index = {n: i for i, n in enumerate(nodes)}
            if any(n not in index for n in numbers):
                raise DataError(f"{path.name}: mode {j + 1} names nodes absent from data set 15")
            rows = [index[n] for n in numbers]
            if any(len(mode[r]) != len(rows) for r in ("r1", "r2", "r3")):
                raise DataError(f"{path.name}: mode {j + 1} must give r1, r2, r3 for each of "
                                f"its {len(rows)} node(s)")
            shapes[rows, j] = np.column_stack([np.asarray(mode[r], dtype=float)
                                               for r in ("r1", "r2", "r3")])
        header = np.array([[float(m["freq"]), float(m["modal_damp_vis"]), float(m["modal_m"])]
                           for m in mode_sets])
    return _checked(path, nodes, coordinates, shapes, header)


def _read_csv_modes(path, modal_table):
    header, rows = read_csv_table(path)
    require_columns(path, header, ("node",) + AXES)
    columns = [c for c in header if c not in ("node",) + AXES]
    table_header, table_rows = read_csv_table(modal_table)
    require_columns(modal_table, table_header, ("frequency",))
    n_modes = len(table_rows)
    triples = len(columns) == 3 * n_modes and all(
        columns[3 * j + k].endswith(f"_{a}") for j in range(n_modes) for k, a in enumerate(AXES))
    if not triples and len(columns) != n_modes:
        raise DataError(f"{Path(path).name}: must have one column per mode of "
                        f"{Path(modal_table).name} ({n_modes}), or three ending in _x, _y, _z, "
                        f"besides node, x, y, z; got {len(columns)}")
    values = number_columns(path, header, rows, columns)
    shapes = values.reshape(len(rows), n_modes, 3 if triples else 1)
    node_values = number_columns(path, header, rows, ["node"])[:, 0]
    if np.any(node_values != np.round(node_values)):
        raise DataError(f"{Path(path).name}: column 'node' must hold integer node numbers")
    coordinates = number_columns(path, header, rows, list(AXES))
    table = np.column_stack([
        number_columns(modal_table, table_header, table_rows, [c])[:, 0] if c in table_header
        else np.full(n_modes, default)
        for c, default in (("frequency", 0.0), ("damping_ratio", 0.0), ("modal_mass", 1.0))])
    if "modal_mass" not in table_header:
        # Absent = mass-normalised, where φ is about 1/√m: a shape peaking near 1 is
        # unity-scaled, and would get an engaged modal mass of 1/max|φ|² ≈ 1 kg.
        peak = np.abs(shapes).max(axis=(0, 2))
        light = np.flatnonzero(peak > 1 / np.sqrt(MIN_ENGAGED_MASS))
        if light.size:
            raise DataError(
                f"{Path(modal_table).name}: no modal_mass column, so the shapes of "
                f"{Path(path).name} are taken as mass-normalised; but mode(s) "
                f"{(light + 1).tolist()} peak at |φ| = {np.round(peak[light], 4).tolist()}, "
                f"which gives engaged modal masses of "
                f"{np.round(1 / peak[light] ** 2, 3).tolist()} kg (a footbridge mode engages "
                f"more than {MIN_ENGAGED_MASS:g} kg): add a modal_mass column [kg] in the "
                f"scaling of the shapes")
    return _checked(path, node_values.astype(np.int64), coordinates, shapes, table)


def _checked(path, nodes, coordinates, shapes, table):
    """FEModes after the checks every export shares (finite, positive, unique)."""
    name = Path(path).name
    if np.unique(nodes).size != nodes.size:
        raise DataError(f"{name}: node numbers must be unique")
    if coordinates.shape != (nodes.size, 3) or shapes.shape[0] != nodes.size:
        raise DataError(f"{name}: every node must have coordinates and mode shapes: "
                        f"{nodes.size} node(s), {coordinates.shape[0]} coordinate and "
                        f"{shapes.shape[0]} shape row(s)")
    for label, array in (("coordinates", coordinates), ("mode shapes", shapes),
                         ("modal table", table)):
        if not np.all(np.isfinite(array)):
            raise DataError(f"{name}: {label} must be finite numbers")
    if np.any(table[:, 0] <= 0) or np.any(table[:, 2] <= 0):
        raise DataError(f"{name}: frequencies and modal masses must be > 0")
    if np.any(table[:, 1] < 0) or np.any(table[:, 1] >= 1):
        raise DataError(f"{name}: damping ratios must lie in [0, 1) (fractions, not percent), "
                        f"got {table[:, 1].tolist()}")
    extent = np.ptp(coordinates, axis=0)
    if extent.max() > MAX_EXTENT:
        axis = AXES[int(np.argmax(extent))]
        warnings.warn(f"{name}: the nodes span {extent.max():.6g} m along {axis}, unusual for "
                      f"a footbridge (< {MAX_EXTENT:g} m): coordinates in millimetres? (they "
                      f"would span {extent.max() / 1000:.4g} m)", PlausibilityWarning,
                      stacklevel=4)
    return FEModes(nodes=nodes, coordinates=coordinates, shapes=shapes, frequencies=table[:, 0],
                   damping_ratios=table[:, 1], modal_masses=table[:, 2], source=name)


# FE normal modes in the formats table (read only: crowdvib writes modal models as CSV).
register_format(FileFormat("uff", "modes", UFF_SUFFIXES, "a UFF 15 + 55", read_fe_modes,
                           extra="uff"))
