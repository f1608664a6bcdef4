"""A case file's monitoring season: its records and a crowd table, run as one study (issue 28 §2).

The case file describes the bridge, the crowd's other properties (body mass, walking speed,
step frequencies when the table has none), how a record is read and processed
(``[measurement]``) and the estimator (``[estimation]``). The season's records are the
``measurement.files`` of the case, where a folder stands for every record file in it, or the
folder given; the crowd table (:func:`crowdvib.io.read_crowd_table`) names, per record or time
window, the crowd on the deck. :func:`season_case` estimates each row with ``crowdvib
estimate``'s pipeline (:func:`~crowdvib.cases.estimate_case`, bit for bit) and its crowd, as
the tasks of :func:`crowdvib.studies.season_study`, then one MSD for all rows.
"""

from __future__ import annotations

import dataclasses
import os
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from .._version import __version__
from ..errors import DataError, ParameterError
from .results import ESTIMATION_TABLES, AsResults, software_versions
from .schema import schema_header
from ..errors import CrowdvibWarning
from ..studies.season import season_row
from .estimate import estimate_case
from .._files import MANIFEST_NAME
from ..io.records import RECORD_FORMATS
from .._plausibility import derived, implausibility
from ..errors import PlausibilityWarning
from ..models.crowd import bruno_venuti_step_frequency, weidmann_speed
from ..io.crowdtable import CrowdTable, read_crowd_table
from ..studies.season import season_study
from .estimate import case_estimator

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    from ..io.casefile import Case
    from ..io.crowdtable import CrowdTable
    from ..studies.season import SeasonResult

__all__ = ["CaseSeason", "SeasonPlan", "plan_season", "season_case", "season_records"]


@dataclass(frozen=True)
class _Window:
    """One task of a season: the case as it reads one record (or window) with its crowd."""

    case: Case
    duration: float | None       # the crowd table's length of the record [s], checked


def _estimate_window(window):
    """A season's task: the row's estimate (:func:`~crowdvib.studies.season.season_row`)."""

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", CrowdvibWarning)
        fit = estimate_case(window.case)
    record = fit.records[0].measurement.record
    if window.duration is not None and abs(record.duration - window.duration) > max(
            0.01 * window.duration, 2.0 / record.sample_rate):
        raise DataError(f"{window.case.name}: the record is {record.duration:g} s long, the "
                        f"crowd table's duration is {window.duration:g} s: its count belongs to "
                        "another stretch of time")
    return season_row(fit.estimate, fit.records[0].measurement.psd, fit.crowd,
                      [w for w in caught if issubclass(w.category, CrowdvibWarning)],
                      duration=record.duration)


def season_records(case: Case, records: str | os.PathLike | Sequence | None = None,
                   table_path: str | os.PathLike | None = None) -> dict[str, Path]:
    """The record files of a season, by the names a crowd table may give them.

    Parameters
    ----------
    case : Case
        Its ``measurement.files`` (a folder among them stands for its record files) when
        ``records`` is None; with neither, the crowd table's folder.
    records : path or sequence of paths, optional
        A folder of records, or record files (and folders).
    table_path : path, optional
        The crowd table (its folder is the default; it is not a record itself).

    Returns
    -------
    dict
        Name → path, each record under its path relative to its folder (``day1/0800.npz``) and
        under its file name alone when that is unique.
    """

    if records is None:
        records = case.measurement.files or [Path(table_path).resolve().parent]
    elif isinstance(records, (str, os.PathLike)):
        records = [records]
    suffixes = {suffix for row in RECORD_FORMATS.values() for suffix in row}
    # A file of the crowd table's name is a crowd table (this season's or another's), not a record.
    skip = None if table_path is None else Path(table_path).name
    found = {}
    for entry in map(Path, records):
        if entry.is_dir():
            # crowdvib's own results folders (a --out placed among the records) hold outputs,
            # season.csv among them, never records.
            outputs = {m.parent for m in entry.rglob(MANIFEST_NAME)}
            for path in sorted(entry.rglob("*")):
                if (path.is_file() and path.suffix.lower() in suffixes and path.name != skip
                        and not outputs.intersection(path.parents)):
                    found[path.relative_to(entry).as_posix()] = path.resolve()
        else:
            found[entry.name] = entry.resolve()
    names = [Path(name).name for name in found]
    for name, path in list(found.items()):
        if names.count(path.name) == 1:
            found.setdefault(path.name, path)
    return found


def _crowd(case, table, row):
    """The crowd of a table row: the case's, at the row's density and step frequencies. A
    walking speed and a mean step frequency the case derives from its density are derived
    from the row's (Weidmann; Bruno & Venuti), as the case file would."""

    where = f"{table.path.name}: row {row.row}"
    area = case.structure.area
    density = row.density_on(area)
    notes = [implausibility(key, value, f"{where}, {key}") for key, value in (
        ("step_frequency_mean", row.step_frequency_mean),
        ("step_frequency_std", row.step_frequency_std)) if value is not None]
    if row.density is not None and row.density > 2.0:
        notes.append(f"{where}, density = {row.density:g} persons/m² is above 2, unusual for "
                     f"a crowd on a footbridge: a count of persons? ({row.density:g} persons "
                     f"on the {area:g} m² deck are {row.density / area:.3g} persons/m²)")
    for note in filter(None, notes):
        warnings.warn(note, PlausibilityWarning, stacklevel=4)
    changes = {"density": density}
    if "crowd.walking_speed" in case.not_set:
        changes["walking_speed"] = float(weidmann_speed(density))
    speed = changes.get("walking_speed", case.crowd.walking_speed)
    if row.step_frequency_mean is not None:
        changes["step_frequency_mean"] = row.step_frequency_mean
    elif "crowd.step_frequency_mean" in case.not_set:
        changes["step_frequency_mean"] = float(bruno_venuti_step_frequency(speed))
    if row.step_frequency_std is not None:
        changes["step_frequency_std"] = row.step_frequency_std
    try:
        with derived():            # judged above, with the row named
            return dataclasses.replace(case.crowd, **changes)
    except ParameterError as error:
        raise DataError(f"{where}: {error}") from None


def season_windows(case: Case, table, records: dict[str, Path],
                   where: str | None = None) -> list[tuple]:
    """The tasks of a season: ``(name, payload or None, info)`` per crowd-table row.

    Parameters
    ----------
    case : Case
    table : CrowdTable
    records : dict
        Name → path (:func:`season_records`).
    where : str, optional
        Where ``records`` were found, in words, for the message of a row naming none of them
        (default: only their number).

    Raises
    ------
    DataError
        A row naming a record that is not among ``records`` (file, row and column named).
    """
    windows = []
    for row in table.rows:
        path = records.get(row.record)
        if path is None:
            raise DataError(f"{table.path.name}: row {row.row}, column 'record': "
                            f"{row.record!r} is not among the season's "
                            f"{len(set(records.values()))} record(s)"
                            + (f": {where}" if where else ""))
        info = {"row": row.row, "record": row.record, "start": row.start, "end": row.end,
                "time": row.time, "count": row.count,
                "density": row.density_on(case.structure.area),
                "step_frequency_mean": row.step_frequency_mean,
                "step_frequency_std": row.step_frequency_std}
        if info["density"] == 0:
            info["skipped"] = "no crowd on the deck: nothing to estimate"
            windows.append((row.name, None, info))
            continue
        spec = dataclasses.replace(case.measurement, files=(path,), time_frame=(
            case.measurement.time_frame if row.start is None else (row.start, row.end)))
        block = dataclasses.replace(case, name=row.name, measurement=spec,
                                    crowd=_crowd(case, table, row), records=())
        windows.append((row.name, _Window(block, row.duration), info))
    return windows


def _records_origin(case, records, table_path, found):
    """Where :func:`season_records` took the season's records from, in words: a row naming
    none of them is most often a season run without its records (``--records`` forgotten), whose
    record is then the case file's own."""
    names = sorted({path.name for path in found.values()})
    shown = (", ".join(names[:3]) + (", …" if len(names) > 3 else "")) or "no record file"
    if records is not None:
        return f"the records given ({shown})"
    if case.measurement.files:
        own = (f"the case file's own record {shown}" if len(names) == 1
               else f"the case file's own records ({shown})")
        return (f"{own}, from its measurement.files, as no records were given: give the "
                "season's records with crowdvib season --records DIR (records= in Python)")
    return f"those beside the crowd table {Path(table_path).name} ({shown})"


@dataclass(frozen=True)
class SeasonPlan:
    """A season checked and ready to run (:func:`plan_season`): every input read, every row of
    its crowd table matched to a record and given its crowd, before anything is computed or
    written (``crowdvib season`` plans first, so that an input error leaves no results folder
    behind).

    Attributes
    ----------
    case : Case
    table : CrowdTable
    windows : list of tuple
        The tasks of :func:`crowdvib.studies.season_study`, one per row.
    unmatched : tuple of str
        Records found that no row of the crowd table names.
    records : int
        How many record files the season found.
    """

    case: Case
    table: CrowdTable
    windows: list
    unmatched: tuple
    records: int

    def run(self, *, joint: bool = True, joint_min_density: float = 0.0, executor=None,
            store=None, progress: Callable[[int, int], None] | None = None,
            batch_size: int | None = None, say: Callable[[str], None] | None = None
            ) -> CaseSeason:
        """Estimate every row, then all together.

        Parameters
        ----------
        joint, joint_min_density, executor, store, progress, batch_size
            As :func:`season_case`.
        say : callable, optional
            Called with a line before the joint estimate (a long step without progress).

        Returns
        -------
        CaseSeason
        """

        case = self.case
        # The joint fit is the rows' estimator (the case's method and crowd model), each row's
        # crowd held as its own fit left it: the likelihood's step frequencies fitted per
        # record. The paper's least squares jointly missed the truth of a synthetic season
        # (docs: theory, A season of records). Its interval is Wald's: over tens of records the
        # likelihood is quadratic (the profile's ends moved < 0.1 %) and the profile would
        # triple its cost.
        estimator = case_estimator(case).replace(free_step_frequencies=None)
        if estimator.interval == "profile":
            estimator = estimator.replace(interval="wald")
        season = season_study(self.windows, _estimate_window, case.structure,
                              estimator=estimator, joint=joint, rng=case.seed,
                              joint_min_density=joint_min_density, executor=executor,
                              store=store, progress=progress, batch_size=batch_size, say=say)
        return CaseSeason(case, self.table, season, self.unmatched, joint_min_density)


def plan_season(case: Case, crowd_table: str | os.PathLike | CrowdTable, *,
                records: str | os.PathLike | Sequence | None = None) -> SeasonPlan:
    """Check a season's inputs and match its crowd table to its records, computing nothing.

    Parameters
    ----------
    case, crowd_table, records
        As :func:`season_case`.

    Returns
    -------
    SeasonPlan
        ``plan.run(...)`` runs it.

    Raises
    ------
    ParameterError
        A case with a crowd profile of its own (the table gives each record's crowd).
    DataError
        A crowd table that cannot be read, a row naming a record that is not among the
        season's (saying where they were looked for), a row whose crowd is impossible.
    """

    if case.crowd.profile is not None:
        raise ParameterError(f"{case.path.name}: crowd.counts or crowd.density_profile must not "
                             "be given for a season: the crowd table gives each record's crowd "
                             "(its count or density per record or per window)")
    table = crowd_table if isinstance(crowd_table, CrowdTable) else read_crowd_table(crowd_table)
    found = season_records(case, records, table.path)
    windows = season_windows(case, table, found,
                             _records_origin(case, records, table.path, found))
    unmatched = tuple(sorted(path.name for path in set(found.values())
                             - {found[row.record] for row in table.rows}))
    return SeasonPlan(case, table, windows, unmatched, len(set(found.values())))


@dataclass(frozen=True)
class CaseSeason(AsResults):
    """What ``crowdvib season`` computes (:func:`season_case`).

    Attributes
    ----------
    case : Case
    table : CrowdTable
        The crowd table read.
    season : SeasonResult
        The table of estimates, the joint estimate, the trend figures.
    unmatched : tuple of str
        Records found that no row of the crowd table names (not estimated).
    joint_min_density : float
        Rows of a thinner crowd [persons/m²] were left out of the joint estimate.
    """

    case: Case
    table: CrowdTable
    season: SeasonResult
    unmatched: tuple = ()
    joint_min_density: float = 0.0

    def to_dict(self) -> dict:
        """The results ``crowdvib season`` writes to results.json (kind ``"season"``), without
        its figures, warnings and provenance: ``records`` the table, ``estimate`` and
        ``diagnostics`` the joint estimate's (docs: :doc:`/results`)."""
        case, season = self.case, self.season.to_dict()
        joint = season["joint"] or {}
        return {**schema_header("season"), "command": "season", "crowdvib_version": __version__,
                "versions": software_versions(), "seed": case.seed, "case": str(case.path),
                "crowd_table": str(self.table.path), "inputs": case.inputs(ESTIMATION_TABLES),
                "records": season["records"], "unmatched_records": list(self.unmatched),
                "joint_min_density": self.joint_min_density,
                "estimate": joint.get("estimate"), "joint_error": season["joint_error"],
                "diagnostics": {k: v for k, v in joint.items() if k != "estimate"} or None,
                "expected": dict(case.expected)}


def season_case(case: Case, crowd_table: str | os.PathLike | CrowdTable, *,
                records: str | os.PathLike | Sequence | None = None, joint: bool = True,
                joint_min_density: float = 0.0, executor=None, store=None,
                progress: Callable[[int, int], None] | None = None,
                batch_size: int | None = None) -> CaseSeason:
    """Run ``crowdvib season``: every row of a crowd table estimated, then all together.

    Parameters
    ----------
    case : Case
        From :func:`~crowdvib.io.load_case`: the bridge, the crowd's other properties, the
        record processing and the estimator (its ``[estimation]`` method for each row).
    crowd_table : path or CrowdTable
        The crowd table CSV (:func:`crowdvib.io.read_crowd_table`), or the table read.
    records : path or sequence of paths, optional
        Where the records are (:func:`season_records`; default the case's
        ``measurement.files``, else the crowd table's folder).
    joint : bool
        Also estimate one MSD for every row (:func:`crowdvib.estimate_hsi_joint` with the
        case's estimator, each row with the crowd its estimate ended with, Wald intervals).
    joint_min_density : float
        Rows of a thinner crowd [persons/m²] stay out of the joint estimate
        (:func:`~crowdvib.studies.season_study`).
    executor, store, progress, batch_size
        As for :func:`crowdvib.runner.run_tasks` (a store makes the season resumable).

    Returns
    -------
    CaseSeason
        ``season.to_dataframe()`` is the table; ``results()`` what results.json holds.
    """
    return plan_season(case, crowd_table, records=records).run(
        joint=joint, joint_min_density=joint_min_density, executor=executor, store=store,
        progress=progress, batch_size=batch_size)
