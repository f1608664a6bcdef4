"""A season of monitoring: many records, each estimated with its interval, and one MSD for all.

A bridge monitored for months gives hundreds of records and, from a camera or a counter, the
crowd during each (issue 28 §2). :func:`season_study` estimates every record (or time window of
one) on its own, as independent tasks of :func:`crowdvib.runner.run_tasks` (in this process, on
local workers or on a dask cluster, each finished one kept in a
:class:`~crowdvib.runner.TaskStore`, so a season resumes where it stopped), and then all of
them together with :func:`crowdvib.estimate_hsi_joint` (one MSD, each record with its own
crowd, by the records' estimator: docs: theory, A season of records). :class:`SeasonResult`
holds the table (one row per record: its crowd, f_h1 and ξ_h1 with their intervals, its status
and warnings), the joint estimate and the trend figures.

A task's function (:func:`crowdvib.cases.season_case` gives the one of a case file) returns
:func:`season_row` of its estimate: its numbers and its measured PSD over the band, which the
joint fit reads back, so that a resumed season reads no record twice.
"""

import dataclasses
import warnings

import numpy as np

from .._estimators import METHOD_WORDS
from .._plausibility import derived
from .._validation import fields_from_dict
from ..errors import CrowdvibError, DataWarning, StudyWarning
from ..identification.estimator import check_estimator
from ..models.crowd import Crowd
from ..runner.tasks import run_tasks
from ..signals.spectrum import ResponsePSD
from ..signals.welch import LowPassFilter
from ..io.records import Record, write_record
from ..response.time_domain.simulation import simulate as simulate_record
from ..response.frequency_domain.fluctuation import response_psd
from ..signals.synthesis import gaussian_record, record_frequencies
from .._files import atomic_path
from .plots import plot_season_trends
from ..identification.result import HSIEstimate

__all__ = ["SeasonResult", "season_study", "season_row", "season_dataframe",
           "write_synthetic_season", "TABLE_COLUMNS", "NUMBER_COLUMNS"]

#: The estimated parameters a season's table shows, each with its interval.
_PARAMETERS = ("frequency", "damping_ratio")
#: Keys of every row :func:`season_row` makes (a stored one lacking any is computed again).
_ROW_FIELDS = ("frequency", "damping_ratio", "mass_ratio", "interval", "relative_cost",
               "success", "active_bounds", "warnings", "crowd", "psd", "duration")
#: The columns of :meth:`SeasonResult.table`, in order.
TABLE_COLUMNS = ("row", "name", "record", "start", "end", "duration", "time", "count", "density",
                 "step_frequency_mean", "step_frequency_std", "frequency", "frequency_low",
                 "frequency_high", "damping_ratio", "damping_ratio_low", "damping_ratio_high",
                 "mass_ratio", "level", "relative_cost", "status", "warnings", "in_joint")


# ------------------------------------------------------------------------------ one record
def season_row(estimate, measured, crowd, caught=(), duration=None):
    """One record's estimate as a season's task returns it (JSON-ready).

    Parameters
    ----------
    estimate : HSIEstimate
        The record's estimate, with its interval (else the row has none).
    measured : ResponsePSD
        The record's measured PSD; kept over the estimate's band (one bin more each side) for
        the joint fit, without cross-spectra (the joint fit reads each output's PSD).
    crowd : Crowd
        The crowd the joint fit is to hold for this record: the one the estimate ended with
        (its fitted step frequencies, when they were free).
    caught : sequence of warnings.WarningMessage
        The warnings the estimate gave, kept as ``"Category: message"``.
    duration : float, optional
        The length of the record or window estimated [s] (the table's ``duration``).
    """
    interval, level = None, estimate.interval_level
    if estimate.covariance is not None:
        interval = {name: list(estimate.interval(name, level)) for name in _PARAMETERS}
    return {"frequency": estimate.msd.frequency, "damping_ratio": estimate.msd.damping_ratio,
            "mass_ratio": estimate.msd.mass_ratio, "interval": interval, "level": level,
            "relative_cost": estimate.relative_cost, "success": bool(estimate.success),
            "active_bounds": list(estimate.active_bounds),
            "warnings": [f"{w.category.__name__}: {w.message}" for w in caught],
            "crowd": {f.name: getattr(crowd, f.name) for f in dataclasses.fields(crowd)
                      if f.init},
            "psd": _psd_dict(measured, estimate.band), "duration": duration}


def _psd_dict(measured, band):
    """The PSD over ``band`` and one bin beyond each end (the estimator's band must lie inside
    the grid), with what the model needs to match it: window, windows, filter, scatter."""
    step = measured.frequency[1] - measured.frequency[0]
    keep = (measured.frequency >= band[0] - step) & (measured.frequency <= band[1] + step)
    return {"frequency": measured.frequency[keep].tolist(), "psd": measured.psd[:, keep].tolist(),
            "dispersion": None if measured.dispersion is None
            else measured.dispersion[:, keep].tolist(),
            "output_names": list(measured.output_names), "window_length": measured.window_length,
            "n_windows": measured.n_windows,
            "lowpass": None if measured.lowpass is None else measured.lowpass.to_dict()}


def _psd(found):
    """The ResponsePSD of :func:`_psd_dict`."""
    lowpass = found["lowpass"]
    return ResponsePSD(found["frequency"], found["psd"], tuple(found["output_names"]),
                       window_length=found["window_length"], n_windows=found["n_windows"],
                       lowpass=None if lowpass is None else LowPassFilter(**lowpass),
                       source="welch", dispersion=found["dispersion"])


# ------------------------------------------------------------------------------ the season
@dataclasses.dataclass(frozen=True, eq=False)
class SeasonResult:
    """A season: every record's estimate with its interval, and the joint estimate.

    Attributes
    ----------
    rows : tuple of dict
        One per record or window, in the order given: its ``name``, what the crowd table said
        of it (``row``, ``record``, ``start``, ``end``, ``time``, ``count``, ``density``, step
        frequencies), and its estimate (``frequency``, ``damping_ratio``, ``mass_ratio``,
        ``interval``, ``relative_cost``, ``success``, ``active_bounds``, ``warnings``) or its
        ``error``.
    joint : HSIEstimate or None
        One MSD for every estimated record, each with its crowd (None when not asked for, or
        fewer than one record was estimated).
    joint_error : str or None
        Why the joint estimate failed, if it did.
    """

    rows: tuple
    joint: object = None
    joint_error: str | None = None

    def table(self):
        """One dict per row with :data:`TABLE_COLUMNS`: the crowd, f_h1 and ξ_h1 with their
        interval ends (None without one) and ``status``: ``"ok"``, ``"doubt"`` (warnings, an
        estimate on a bound, an optimiser that did not converge), ``"skipped"`` (no crowd on
        the deck) or ``"error"`` (the message in ``warnings``)."""
        return [_table_row(row) for row in self.rows]

    def to_dataframe(self):
        """:meth:`table` as a pandas DataFrame (needs pandas: ``pip install pandas``):
        :func:`season_dataframe`."""
        return season_dataframe(self.table())

    def to_csv(self, path):
        """Write :meth:`table` as CSV (:data:`TABLE_COLUMNS`; empty cells for none), atomically;
        needs no pandas.

        Parameters
        ----------
        path : str or os.PathLike
            The CSV file written.
        """
        import csv


        with atomic_path(path) as partial, open(partial, "w", encoding="utf-8",
                                                newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=TABLE_COLUMNS)
            writer.writeheader()
            writer.writerows(self.table())
        return path

    def to_parquet(self, path):
        """Write :meth:`to_dataframe` as Parquet, atomically (needs pandas and pyarrow:
        ``pip install 'crowdvib[parquet]'``).

        Parameters
        ----------
        path : str or os.PathLike
            The Parquet file written.

        Raises
        ------
        ModuleNotFoundError
            pyarrow or pandas is missing; the message names the extra that installs them.
        """
        import importlib.util


        missing = [name for name in ("pandas", "pyarrow")
                   if importlib.util.find_spec(name) is None]
        if missing:
            raise ModuleNotFoundError(f"Parquet needs {' and '.join(missing)}, not installed: "
                                      "pip install 'crowdvib[parquet]' (the CSV table needs "
                                      "nothing)", name=missing[0])
        with atomic_path(path) as partial:
            self.to_dataframe().to_parquet(partial, engine="pyarrow", index=False)
        return path

    def coverage(self, truth):
        """Fraction of the rows with an interval whose interval holds ``truth``, per parameter.

        Parameters
        ----------
        truth : dict
            Parameter → value, for instance the MSD a synthetic season was made with.
        """
        rows = [row for row in self.rows if row.get("interval")]
        return {name: (float(np.mean([row["interval"][name][0] <= value
                                      <= row["interval"][name][1] for row in rows]))
                       if rows else float("nan"))
                for name, value in truth.items() if name in _PARAMETERS}

    def plot(self, *, axes=None, title=None):
        """The trend figures (:func:`crowdvib.studies.plots.plot_season_trends`).

        Parameters
        ----------
        axes : sequence of four matplotlib.axes.Axes, optional
            Axes to draw on (default a new figure).
        title : str, optional
            The figure's title.
        """

        return plot_season_trends(self.table(), joint=self.joint, axes=axes, title=title)

    @classmethod
    def from_dict(cls, data):
        """The season of :meth:`to_dict` (``records`` is derived from the rows, not read).

        Parameters
        ----------
        data : dict
            What :meth:`to_dict` wrote (as read back from JSON).

        Raises
        ------
        DataError
            ``data`` is not a dict or lacks its rows.
        """

        joint = data.get("joint") if isinstance(data, dict) else None
        return fields_from_dict(cls, data, joint=None if joint is None else
                                HSIEstimate.from_dict(joint))

    def to_dict(self):
        """JSON-ready: the rows, the table made of them (``records``), and the joint estimate
        (``HSIEstimate.to_dict``)."""
        return {"rows": [dict(row) for row in self.rows], "records": self.table(),
                "joint": None if self.joint is None else self.joint.to_dict(),
                "joint_error": self.joint_error}


#: Columns of :data:`TABLE_COLUMNS` that hold quantities (floats, a missing one NaN in a DataFrame).
NUMBER_COLUMNS = ("start", "end", "duration", "count", "density", "step_frequency_mean",
                  "step_frequency_std", "frequency", "frequency_low", "frequency_high",
                  "damping_ratio", "damping_ratio_low", "damping_ratio_high", "mass_ratio",
                  "level", "relative_cost")


def season_dataframe(rows):
    """A season's table as a pandas DataFrame: :data:`TABLE_COLUMNS`, the quantities
    (:data:`NUMBER_COLUMNS`) as floats with NaN where a row has none (a season without windows
    has no ``start``: NaN, not None), ``row`` as integers, the ``time`` as datetimes (NaT where
    the crowd table gives none).

    Parameters
    ----------
    rows : sequence of dict
        :meth:`SeasonResult.table`, or the ``records`` of a season's results.json.

    Raises
    ------
    ModuleNotFoundError
        pandas is not installed; the message says how to install it.
    """
    try:
        import pandas
    except ModuleNotFoundError as error:
        raise ModuleNotFoundError("to_dataframe needs pandas, which is not installed: pip "
                                  "install pandas", name=error.name) from None
    frame = pandas.DataFrame(list(rows), columns=list(TABLE_COLUMNS))
    for column in NUMBER_COLUMNS:
        frame[column] = pandas.to_numeric(frame[column], errors="coerce").astype(float)
    frame["row"] = pandas.to_numeric(frame["row"], errors="coerce")     # integers when known
    # ISO 8601 as the crowd table checked it; times of different offsets are kept as given
    # (an object column) rather than shifted.
    try:
        frame["time"] = pandas.to_datetime(frame["time"], format="ISO8601")
    except (ValueError, TypeError):
        pass
    frame["in_joint"] = frame["in_joint"].astype(bool)
    return frame


def _table_row(row):
    interval = row.get("interval") or {}
    crowd = row.get("crowd") or {}
    flat = {key: row.get(key) for key in TABLE_COLUMNS}
    flat["density"] = crowd.get("density", row.get("density"))
    for key in ("step_frequency_mean", "step_frequency_std"):
        flat[key] = crowd.get(key, row.get(key))
    for name in _PARAMETERS:
        ends = interval.get(name) or (None, None)
        flat[f"{name}_low"], flat[f"{name}_high"] = ends
    if "error" in row:
        flat["status"], flat["warnings"] = "error", row["error"]
    elif row.get("skipped"):
        flat["status"], flat["warnings"] = "skipped", row["skipped"]
    else:
        doubts = list(row["warnings"]) + [f"estimate on the bound {bound}"
                                          for bound in row["active_bounds"]]
        if not row["success"]:
            doubts.append("the optimiser did not converge")
        flat["status"] = "doubt" if doubts else "ok"
        flat["warnings"] = "; ".join(doubts)
    return flat


def season_study(windows, function, structure, *, estimator, joint=True,
                 joint_min_density=0.0, executor=None, store=None, progress=None,
                 batch_size=None, say=None, rng=None):
    """Estimate every record of a season with its interval, then one MSD for all of them.

    Parameters
    ----------
    windows : sequence of (str, object, dict)
        Per record or time window: a unique name, the payload of ``function`` and what the
        table shows of it (``record``, ``start``, ``end``, ``time``, ``count``, ``density`` …).
        A payload of None is a row not estimated, its dict saying why under ``skipped``.
    function : callable
        A module-level function payload → :func:`season_row` (run where the tasks run).
    structure : ModalModel
        The empty bridge, for the joint estimate.
    estimator : Estimator
        The estimator of the joint estimate (:class:`~crowdvib.identification.Estimator`, its
        ``band`` that of the records' estimates; fitted with
        :meth:`~crowdvib.identification.Estimator.fit_joint`, so its method is the one it
        states; :func:`crowdvib.cases.season_case` gives the case's estimator with Wald
        intervals). Without ``starts``, one start at the records' median estimate.
    joint : bool
        Make the joint estimate (:func:`crowdvib.estimate_hsi_joint`) of every record
        estimated, each with the crowd its row holds.
    joint_min_density : float
        Rows of a lower density [persons/m²] are left out of the joint estimate (column
        ``in_joint``). The paper's least squares weigh every record alike, and a record of a
        thin crowd holds little of the MSD: many of them pull its joint f_h1 low (measured in
        ``benchmarks/bench_season.py``: 200 records of a daily profile, f_h1 within 84 % of its
        95 % intervals below 0.3 persons/m², 92–96 % above); the likelihood weighs each record
        by what it holds. Default 0: every row.
    executor, store, progress, batch_size
        As for :func:`crowdvib.runner.run_tasks`: where the tasks run, where finished ones
        are kept (a season given the same store resumes), ``progress(done, total)``, tasks
        per submission.
    say : callable, optional
        Called with a line before the joint estimate (a long step without progress).
    rng : None, int or numpy.random.Generator
        Seed of the joint estimate's bootstrap replicates (``interval="bootstrap"``).

    Returns
    -------
    SeasonResult
    """
    if joint:
        check_estimator(estimator).options()     # its band given, before any row is estimated
    windows = list(windows)
    tasks = [(name, payload) for name, payload, _ in windows if payload is not None]
    if windows and not tasks:        # issue 35 §3: ended with "no warnings"
        reasons = sorted({str(info.get("skipped", "skipped")) for _, _, info in windows})
        warnings.warn(f"no row of the season was estimated: all {len(windows)} row(s) were "
                      f"skipped ({'; '.join(reasons)}); a crowd table whose counts or densities "
                      "are all 0 holds no crowd: check its count/density column", DataWarning,
                      stacklevel=2)
    results = run_tasks(function, tasks, executor=executor, store=store, progress=progress,
                        fields=_ROW_FIELDS, batch_size=batch_size)
    rows, done = [], []          # every row; the estimated ones the joint fit holds
    for name, payload, info in windows:
        found = results.get(name, {}) if payload is not None else {}
        used = bool(joint) and "frequency" in found and \
            found["crowd"]["density"] >= joint_min_density
        rows.append({"name": name, **info, **{k: v for k, v in found.items() if k != "psd"},
                     "in_joint": used})
        if used:
            done.append(found)
    estimate, failed = None, None
    if joint and done:
        with derived():               # each record's crowd was judged when its row was read
            crowds = [Crowd(**row["crowd"]) for row in done]
        if estimator.starts is None:
            estimator = estimator.replace(starts=[_median_start(done)])
        if say is not None:
            say(f"  joint estimate: one MSD for the {len(done)} row(s) estimated, each with "
                f"its crowd ({METHOD_WORDS[estimator.method]}) …")
        try:
            estimate = estimator.fit_joint([_psd(row["psd"]) for row in done], structure,
                                           crowds, rng=rng)
        except CrowdvibError as error:
            failed = f"{type(error).__name__}: {error}"
            warnings.warn(f"the joint estimate of the season failed ({failed}); the records' "
                          "own estimates stand", StudyWarning, stacklevel=2)
    return SeasonResult(tuple(rows), estimate, failed)


def _median_start(done):
    """The joint fit's one start: the records' median estimate, off a bound where some are.
    Every record's own fit has searched its basin; their median lies in the joint one, so one
    start does what four spread ones would at a quarter of the cost (the joint fit is the
    season's longest single step: a model of every record per evaluation)."""
    inside = [row for row in done if not row["active_bounds"]] or done
    return tuple(float(np.median([row[name] for row in inside]))
                 for name in ("frequency", "damping_ratio"))


# ------------------------------------------------------------------------------ synthetic
def write_synthetic_season(folder, structure, crowd, msd, *, densities, duration,
                           sample_rate, times=None, simulate=False, rng=None):
    """Write a season of records whose MSD is known, and its crowd table (how-tos, tests,
    benchmarks).

    Parameters
    ----------
    folder : path
        Where the records (``record_001.npz`` …) and ``crowd.csv`` are written (made if need be).
    structure : ModalModel
    crowd : Crowd
        The crowd's other properties (speed, step frequencies, body mass); each record's
        density is its own.
    msd : MSDModel
        The pedestrians' MSD (the truth to identify back).
    densities : sequence of float
        The density of each record [persons/m²].
    duration, sample_rate : float
        Of each record [s], [Hz].
    times : sequence of str, optional
        ISO 8601 start time of each record, written to the table's ``time`` column.
    simulate : bool
        False: a stationary Gaussian record of the smeared crowd's expected PSD (docs: theory,
        Correlation of neighbouring Welch ordinates), exactly what the paper's least squares
        assumes, milliseconds a record. True: the time-domain simulation of walkers
        (:func:`crowdvib.simulate`, with 100 s of warm-up), whose crowd fluctuates.
    rng : None, int or numpy.random.Generator
        Seeds the records, one stream each.

    Returns
    -------
    pathlib.Path
        The crowd table; its rows give each record's ``density`` (and ``time``).
    """
    from pathlib import Path


    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    densities = [float(d) for d in densities]
    streams = np.random.default_rng(rng).spawn(len(densities))
    lines = ["record,density" + (",time" if times is not None else "")]
    for number, (density, stream) in enumerate(zip(densities, streams), start=1):
        with derived():       # the crowd at another density: judged where it was built
            here = dataclasses.replace(crowd, density=density)
        if simulate:
            found = simulate_record(structure, here, duration, msd=msd, sample_rate=sample_rate,
                                    rng=stream, warm_up=100.0)
            data = found.acceleration
        else:
            frequency = record_frequencies(duration, sample_rate)
            expected = response_psd(structure, here, frequency, msd=msd, crowd_model="smeared")
            data = gaussian_record(expected.psd, sample_rate, stream)
        name = f"record_{number:03d}.npz"
        write_record(Record(data, sample_rate, tuple(structure.output_names)), folder / name)
        lines.append(f"{name},{density!r}" + (f",{times[number - 1]}" if times is not None
                                              else ""))
    table = folder / "crowd.csv"
    table.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return table
