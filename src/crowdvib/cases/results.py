"""Results that round-trip: what every command's results.json holds, as an object again.

Each command writes one results.json in the versioned schema :data:`~crowdvib.cases.schema.SCHEMA`
(docs: :doc:`/results`); :func:`load_results` reads it back as the :class:`Results` of its
``kind`` (:class:`EstimateResults`, :class:`SensitivityResults`, :class:`CheckResults`,
:class:`ModesResults`, :class:`SimulateResults`, :class:`MapResults`, :class:`DemoResults`).
A result holds exactly what the file holds, so ``load_results(path).to_dict()`` equals the file
and ``Results.from_dict(r.to_dict()) == r``; its methods give the typed objects back
(:meth:`EstimateResults.hsi_estimate` → :class:`~crowdvib.identification.HSIEstimate`), its
verdict (:meth:`Results.verdict`, the one the command line prints and report.html shows), a
notebook view (``_repr_html_``) and tables for pandas (:meth:`Results.to_dataframe`).

Also what every results.json shares: the case tables it keeps and the software versions.
Light on purpose: the command line imports it at start-up (``crowdvib --help``).
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

from .._version import __version__
from ..errors import DataError
from .schema import KINDS, SCHEMA, estimate, hsi

if TYPE_CHECKING:
    from ..design.interval import MSDBox
    from ..identification.result import HSIEstimate
    from ..models.pedestrian import MSDModel
    from .verdict import Finding

__all__ = ["ESTIMATION_TABLES", "SIMULATION_TABLES", "DESIGN_TABLES", "software_versions",
           "provenance",
           "Results", "EstimateResults", "SensitivityResults", "CheckResults", "ModesResults",
           "SimulateResults", "MapResults", "DemoResults", "SeasonResults", "ComfortResults",
           "AsResults",
           "load_results", "results_of"]

#: The case tables each kind of command reads; its results and report show no others.
ESTIMATION_TABLES = ("structure", "crowd", "hsi", "measurement", "estimation", "expected")
SIMULATION_TABLES = ("structure", "crowd", "hsi", "simulation", "expected")
DESIGN_TABLES = ("structure", "crowd", "hsi", "design")


def software_versions() -> dict:
    """The versions of crowdvib, numpy, scipy and Python, as every results.json records them."""
    import platform

    import numpy as np
    import scipy

    return {"crowdvib": __version__, "numpy": np.__version__, "scipy": scipy.__version__,
            "python": platform.python_version()}


def provenance(case: str | Path | None = None) -> dict:
    """Provenance keys for a ``results.json``, taken when the run starts.

    Parameters
    ----------
    case : str or pathlib.Path, optional
        The case file the run reads (None for an embedded example).

    Returns
    -------
    dict
        ``created`` (UTC, ISO 8601) and ``case_sha256`` (hex digest of the case file, or None):
        recorded at run time they stay true when the case file is edited later.
    """
    import datetime

    from .._files import sha256_file

    created = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
    path = None if case is None else Path(case)
    return {"created": created,
            "case_sha256": sha256_file(path) if path is not None and path.is_file() else None}


#: The MSD's parameters (and the step frequencies fitted with it) in the order tables show them.
_PARAMETERS = ("frequency", "damping_ratio", "mass_ratio", "step_frequency_mean",
               "step_frequency_std")


@dataclass(frozen=True, eq=False)
class Results:
    """What one results.json holds (schema :data:`~crowdvib.cases.schema.SCHEMA`).

    Build one with :func:`load_results` (from a file), :meth:`from_dict` (from its dict) or
    :func:`results_of` (from what a ``crowdvib.cases`` function returned). Two results are
    equal when their dicts are (numbers compared exactly).

    Attributes
    ----------
    data : dict
        The results.json object (JSON types only). Read it through the methods; it is the
        result's state, not to be changed in place.
    """

    #: The results.json ``kind`` of this class ("" for the base class, which any kind is).
    kind: ClassVar[str] = ""
    data: dict

    # ---------------------------------------------------------------------------- round trip
    @classmethod
    def from_dict(cls, data: dict, *, source: str = "results") -> Results:
        """The result of a results.json dict, of the class its ``kind`` names.

        Parameters
        ----------
        data : dict
            A results.json object: ``schema`` and ``kind`` required. Numbers may be numpy
            scalars or arrays; they are stored as JSON numbers and lists, NaN as null (as the
            commands write them).
        source : str
            What to call ``data`` in an error message (the file's path for :func:`load_results`).

        Raises
        ------
        DataError
            Not an object, a missing or unknown ``schema`` or ``kind``, or (on a subclass) a
            ``kind`` of another class.
        """
        if not isinstance(data, dict):
            raise DataError(f"{source} must hold a JSON object, got {type(data).__name__}")
        schema, kind = data.get("schema"), data.get("kind")
        if schema != SCHEMA:
            why = ("no schema (written by a crowdvib before results.json had one)"
                   if schema is None else f"schema {schema!r} (another crowdvib's)")
            raise DataError(f"{source} holds {why}; crowdvib {__version__} reads {SCHEMA!r}: "
                            "run the command again to write it")
        if kind not in _CLASSES:
            raise DataError(f"{source}: kind must be one of {list(KINDS)}, got {kind!r}")
        if cls.kind and kind != cls.kind:
            raise DataError(f"{source} holds {kind!r} results, not {cls.kind!r}")
        return _CLASSES[kind](_json(data))

    def to_dict(self) -> dict:
        """The results.json object (a copy: JSON types only)."""
        return json.loads(json.dumps(self.data))

    def __eq__(self, other):
        if not isinstance(other, Results):
            return NotImplemented
        return type(self) is type(other) and self.data == other.data

    __hash__ = None

    # ------------------------------------------------------------------------------ reading
    @property
    def command(self) -> str:
        """The command that wrote it (``kind`` but for results of older names)."""
        return self.data.get("command", self.data["kind"])

    @property
    def name(self) -> str:
        """The case's name."""
        from .schema import case_name

        return case_name(self.data)

    @property
    def warnings(self) -> tuple[str, ...]:
        """The warnings the run raised (``Category: message``), as the command caught them."""
        return tuple(self.data.get("warnings") or ())

    @property
    def estimate(self) -> dict | None:
        """The MSD estimate {frequency, damping_ratio, mass_ratio (, interval, …)}, or None."""
        return estimate(self.data)

    def interval(self, parameter: str) -> tuple[float, float, float] | None:
        """(low, high, level) of an estimated parameter's confidence interval, or None.

        Parameters
        ----------
        parameter : str
            ``"frequency"``, ``"damping_ratio"`` or ``"mass_ratio"``.
        """
        found = (self.estimate or {}).get("interval")
        ends = found.get(parameter) if isinstance(found, dict) else None
        if not isinstance(ends, list) or len(ends) != 2 or None in ends:
            return None
        return ends[0], ends[1], found["level"]

    def msd_box(self, msd: MSDModel | None = None) -> MSDBox | None:
        """The box of f_h1 and ξ_h1 these results allow, μ_h1 held
        (:class:`~crowdvib.design.interval.MSDBox`): a sensitivity study's statistical
        interval widened by its modelling bound (``combined``), else the estimate's
        statistical interval; None without an estimate or without an interval.

        Parameters
        ----------
        msd : MSDModel, optional
            The point the box is around (default the estimate, μ_h1 0.95 if it holds none).
        """
        from ..design.interval import SPANNED, MSDBox
        from ..models.pedestrian import MSDModel

        found = self.estimate or {}
        if msd is None:
            if not all(isinstance(found.get(k), (int, float)) for k in SPANNED):
                return None
            msd = MSDModel(found["frequency"], found["damping_ratio"],
                           found.get("mass_ratio") or 0.95)
        combined = self.data.get("combined")
        rows = {name: combined[name] for name in SPANNED
                if isinstance(combined, dict) and isinstance(combined.get(name), dict)}
        if rows:
            box = MSDBox.around(msd, {name: row.get("combined") for name, row in rows.items()},
                                next(iter(rows.values())).get("level"), widened=True)
            if box is not None:
                return box
        interval = found.get("interval") if isinstance(found.get("interval"), dict) else {}
        return MSDBox.around(msd, interval, interval.get("level"))

    # ------------------------------------------------------------------------------ verdict
    def verdict(self) -> tuple[Finding, ...]:
        """The verdict: a tuple of :class:`~crowdvib.cases.verdict.Finding` (severity ``"ok"``,
        ``"doubt"`` or ``"fail"``, text, key), as the command line prints it and report.html
        shows it."""
        from .verdict import findings

        return findings(self.data)

    @property
    def passes(self) -> bool:
        """True when the verdict has no doubt and no failure."""
        return all(finding.severity == "ok" for finding in self.verdict())

    @property
    def in_doubt(self) -> bool:
        """True when the verdict doubts the result (:func:`~crowdvib.cases.verdict.in_doubt`):
        the command line then exits with status 3 (1 with ``--strict``)."""
        from .verdict import in_doubt

        return in_doubt(self.verdict())

    @property
    def fails_design(self) -> bool:
        """True when the bridge fails a design code at the result
        (:func:`~crowdvib.cases.verdict.fails_design`): an answer, not a doubt; the command line
        then exits with status 4 unless the result is also in doubt (3)."""
        from .verdict import fails_design

        return fails_design(self.verdict())

    # ------------------------------------------------------------------------------- tables
    def table(self) -> list[dict]:
        """The result's main table as rows (dicts of one column each).

        :meth:`to_dataframe` makes it a pandas DataFrame. Here: one row per estimated parameter (name, value,
        interval, standard error, expected or true value); the kinds with a table of their own
        override it."""
        found = self.estimate or {}
        reference = self.data.get("truth") or self.data.get("expected") or {}
        errors = found.get("standard_error") if isinstance(found.get("standard_error"),
                                                           dict) else {}
        rows = []
        for key in _PARAMETERS:
            if key not in found:
                continue
            ends = self.interval(key)
            rows.append({"parameter": key, "value": found[key],
                         "low": None if ends is None else ends[0],
                         "high": None if ends is None else ends[1],
                         "level": None if ends is None else ends[2],
                         "standard_error": errors.get(key), "reference": reference.get(key)})
        return rows

    def to_dataframe(self) -> Any:
        """:meth:`table` as a pandas DataFrame (needs pandas: ``pip install 'crowdvib[notebook]'``
        or ``pip install pandas``).

        Raises
        ------
        ModuleNotFoundError
            pandas is not installed; the message names the command that installs it.
        """
        try:
            import pandas
        except ModuleNotFoundError as error:
            raise ModuleNotFoundError(
                "to_dataframe needs pandas, which is not installed: pip install pandas (or pip "
                "install 'crowdvib[notebook]')", name=error.name) from None
        return pandas.DataFrame(self.table())

    # ------------------------------------------------------------------------------ display
    def _headline(self) -> list[tuple[str, str]]:
        """(quantity, value) rows of the notebook view: the estimate with its intervals."""
        from ..quantities import describe

        rows = []
        for row in Results.table(self):
            text = f"{row['value']:.4g}"
            if row["low"] is not None:
                text += f" ({100 * row['level']:g} %: {row['low']:.4g} – {row['high']:.4g})"
            rows.append((describe(row["parameter"]), text))
        relative = hsi(self.data, "relative_cost")
        if isinstance(relative, (int, float)):
            rows.append(("J/J_noHSI (relative misfit)", f"{relative:.3g}"))
        return rows

    #: Whether the notebook view shows :meth:`table` (the kinds with a table of their own but
    #: the map, whose grid is a figure's), and which of its columns (empty: all).
    _view_table: ClassVar[bool] = False
    _shown_columns: ClassVar[tuple[str, ...]] = ()

    def _repr_html_(self) -> str:
        """A small view for notebooks: the headline values, the kind's own table (its first
        rows) and the verdict (:func:`crowdvib.cases.notebook.results_html`)."""
        from .notebook import results_html

        return results_html(self, self.table() if self._view_table else (), self._shown_columns)

    def __repr__(self):
        found = self.estimate or {}
        shown = ", ".join(f"{k}={found[k]:.4g}" for k in _PARAMETERS[:3]
                          if isinstance(found.get(k), (int, float)))
        return (f"{type(self).__name__}({self.name!r}{', ' + shown if shown else ''}, "
                f"verdict={'ok' if self.passes else 'check before use'})")


class EstimateResults(Results):
    """``crowdvib estimate``: the MSD with its intervals and diagnostics (:func:`estimate_case`)."""

    kind = "estimate"

    def hsi_estimate(self) -> HSIEstimate:
        """The :class:`~crowdvib.identification.HSIEstimate` (via ``HSIEstimate.from_dict``);
        its fitted step frequencies, if any, in the case's crowd (``inputs.crowd``).

        A joint fit's estimate has one crowd per record and is rebuilt without one.

        Raises
        ------
        DataError
            The results hold no estimate with diagnostics (a hand-edited file).
        """
        from ..identification.result import HSIEstimate
        from ..models.crowd import Crowd

        diagnostics = self.data.get("diagnostics")
        if not isinstance(diagnostics, dict) or not isinstance(self.data.get("estimate"), dict):
            raise DataError("these results hold no estimate with its diagnostics")
        crowd = (self.data.get("inputs") or {}).get("crowd")
        return HSIEstimate.from_dict({**diagnostics, "estimate": self.data["estimate"]},
                                     crowd=Crowd(**crowd) if isinstance(crowd, dict) else None)

    @property
    def msd(self) -> MSDModel:
        """The estimated :class:`~crowdvib.models.MSDModel`."""
        from ..models.pedestrian import MSDModel

        found = self.data["estimate"]
        return MSDModel(found["frequency"], found["damping_ratio"], found["mass_ratio"])

    def convergence_table(self) -> list[dict]:
        """The PSD's convergence with the record length: per output and number of windows,
        the record length [s] and the change ΔG [-] (paper Figure 15); empty for a joint fit."""
        found = hsi(self.data, "convergence")
        if not isinstance(found, dict):
            return []
        return [{"output": name, "n_windows": n, "duration": duration, "error": error}
                for name, row in zip(found["output_names"], found["error"])
                for n, duration, error in zip(found["n_windows"], found["duration"], row)]


class DemoResults(EstimateResults):
    """``crowdvib demo``: an estimate of a simulated record, with the truth it was made with."""

    kind = "demo"

    def hsi_estimate(self) -> HSIEstimate:
        """The :class:`~crowdvib.identification.HSIEstimate` (its keys sit at the top level;
        fitted step frequencies in the crowd of the paper's example, which the demo runs)."""
        from ..identification.result import HSIEstimate
        from ..models.examples import paper_example

        return HSIEstimate.from_dict(self.data, crowd=paper_example().crowd)


class MapResults(EstimateResults):
    """``crowdvib map``: the estimate and its objective on a grid of (f_h1, ξ_h1)."""

    kind = "map"

    def table(self) -> list[dict]:
        """The objective map: one row per grid point (frequency [Hz], damping ratio [-],
        cost); ``cost`` is stored one row per damping ratio."""
        found = self.data.get("objective_map") or {}
        return [{"frequency": f, "damping_ratio": x, "cost": c}
                for x, row in zip(found.get("damping_ratios", []), found.get("cost", []))
                for f, c in zip(found.get("frequencies", []), row)]

    def hsi_estimate(self) -> HSIEstimate:
        """The optimiser's :class:`~crowdvib.identification.HSIEstimate` (the map carries no
        interval)."""
        from ..identification.result import HSIEstimate

        return HSIEstimate.from_dict({**self.data["diagnostics"],
                                      "estimate": self.data["estimate"]})


class SensitivityResults(Results):
    """``crowdvib sensitivity``: the nominal estimate and the modelling-error study."""

    kind = "sensitivity"
    _view_table = True

    def table(self) -> list[dict]:
        """One row per modelling-error case: name, kind, level and the estimate's change
        Δf_h1, Δξ_h1 [%] (or its error)."""
        study = self.data.get("sensitivity") or {}
        return [{key: case.get(key) for key in ("name", "kind", "level", "delta_frequency",
                                                "delta_damping_ratio", "error")}
                for case in study.get("cases", []) if isinstance(case, dict)]


class CheckResults(Results):
    """``crowdvib check``: the design codes' verdict rows (:func:`check_case`)."""

    kind = "check"
    _view_table = True

    def table(self) -> list[dict]:
        """The verdict rows: code, class, model, output, governing acceleration, limit,
        utilisation, comfort class, passes."""
        return [dict(row) for row in (self.data.get("design") or {}).get("verdict", [])]

    def _headline(self) -> list[tuple[str, str]]:
        """The MSD of the HSI model, and where it comes from."""
        msd = self.data.get("msd")
        if not isinstance(msd, dict):
            return [("MSD", "none: no HSI model")]
        return [("MSD of the HSI model", ", ".join(
            f"{label} = {msd[key]:.4g}{unit}" for key, label, unit in (
                ("frequency", "f_h1", " Hz"), ("damping_ratio", "ξ_h1", ""),
                ("mass_ratio", "μ_h1", "")) if isinstance(msd.get(key), (int, float)))
            + f" ({msd.get('source', '?')})")]

    def interval(self, parameter: str) -> tuple[float, float, float]:
        """(low, high, level) of the interval of the MSD the checks spanned.

        ``crowdvib check --msd-from`` an estimate with its interval checks every code across
        it (``hsi_range``); a check of a given MSD has none, and asking for it is an error that
        says why, not a silent None.

        Parameters
        ----------
        parameter : str
            ``"frequency"`` or ``"damping_ratio"`` (μ_h1 is held at its estimate).

        Raises
        ------
        DataError
            The check spanned no interval (its MSD was given, not estimated; the estimate holds
            none; the check has no HSI model), or ``parameter`` is not one it spans.
        """
        ranges = self.data.get("hsi_range")
        row = next(iter(ranges.values()), None) if isinstance(ranges, dict) else None
        msd = self.data.get("msd") if isinstance(self.data.get("msd"), dict) else None
        if isinstance(row, dict) and isinstance(row.get(parameter), list):
            low, high = row[parameter]
            return low, high, row.get("level")
        if isinstance(row, dict):
            why = (f"{parameter!r} is not spanned: the checks span the interval of "
                   "'frequency' and 'damping_ratio', μ_h1 held at its estimate")
        elif msd is None:
            why = "the checks have no HSI model (no MSD), so no interval"
        elif str(msd.get("source", "")).startswith("the estimate"):
            why = (f"the MSD is {msd['source']}, which holds no interval (its estimation.interval "
                   "= \"none\"): the checks used its point estimate")
        else:
            why = (f"the MSD was given ({msd.get('source', 'the case file')}), not estimated, so "
                   "it has no interval; crowdvib check --msd-from an estimate's results folder "
                   "checks the codes across its interval")
        raise DataError(f"these check results hold no interval of {parameter}: {why}")


class ModesResults(Results):
    """``crowdvib modes``: the identified modes of an ambient test (:func:`identify_ambient`)."""

    kind = "modes"
    _view_table = True

    @property
    def name(self) -> str:
        return str(self.data.get("name") or super().name)

    def table(self) -> list[dict]:
        """One row per mode: frequency [Hz], damping ratio [-] and their standard deviations."""
        return [{key: mode.get(key) for key in ("frequency", "frequency_std", "damping_ratio",
                                                "damping_std")}
                for mode in self.data.get("modes", []) if isinstance(mode, dict)]


class SimulateResults(Results):
    """``crowdvib simulate``: the simulated record's response (:func:`simulate_case`)."""

    kind = "simulate"
    _view_table = True

    def table(self) -> list[dict]:
        """One row per output: RMS, peak |a| and the largest running RMS [m/s²]."""
        response = self.data.get("response") or {}
        keys = ("rms", "peak", "max_running_rms")
        return [{"output": name, **{key: response[key][i] for key in keys if key in response}}
                for i, name in enumerate(response.get("output_names", []))]


class SeasonResults(Results):
    """``crowdvib season``: every record's estimate and the joint one (:func:`season_case`)."""

    kind = "season"
    _view_table = True
    _shown_columns = ("row", "name", "time", "density", "frequency", "frequency_low",
                      "frequency_high", "damping_ratio", "damping_ratio_low",
                      "damping_ratio_high", "status", "in_joint")

    def table(self) -> list[dict]:
        """One row per record or window (:meth:`crowdvib.studies.SeasonResult.table`)."""
        return [dict(row) for row in self.data.get("records") or [] if isinstance(row, dict)]

    def to_dataframe(self) -> Any:
        """:meth:`table` as a pandas DataFrame (:func:`crowdvib.studies.season.season_dataframe`:
        numbers as floats, NaN where a row has none, ``time`` as datetimes)."""
        from ..studies.season import season_dataframe

        return season_dataframe(self.table())

    def _headline(self) -> list[tuple[str, str]]:
        """The joint estimate with its intervals, and what it rests on."""
        rows = self.table()
        states = [row.get("status") for row in rows]
        joint = sum(bool(row.get("in_joint")) for row in rows)
        counts = ", ".join(f"{states.count(s)} {s}" for s in ("ok", "doubt", "error", "skipped")
                           if s in states)
        found = [("rows of the crowd table", f"{len(rows)} ({counts})")]
        if self.estimate:
            found.append(("joint estimate", f"one MSD for the {joint} row(s) it rests on"))
        return found + super()._headline()


class ComfortResults(Results):
    """``crowdvib comfort``: a year of comfort per model (:func:`comfort_case`)."""

    kind = "comfort"

    def table(self) -> list[dict]:
        """One row per model and damper: hours a year per comfort class and the probability
        that a window exceeds each limit."""
        rows = (self.data.get("comfort") or {}).get("rows") or []
        return [{"model": row.get("label"), "damper": row.get("damper"),
                 **{f"hours_{k}": v for k, v in (row.get("hours_per_class") or {}).items()},
                 **{f"exceedance_{k}": v for k, v in (row.get("exceedance") or {}).items()}}
                for row in rows if isinstance(row, dict)]

    def comfort_year(self):
        """The :class:`~crowdvib.comfort.ComfortYear` it holds."""
        from ..comfort import ComfortYear

        return ComfortYear.from_dict(self.data["comfort"])


_CLASSES = {cls.kind: cls for cls in (EstimateResults, SensitivityResults, CheckResults,
                                      ModesResults, SimulateResults, MapResults, DemoResults,
                                      SeasonResults, ComfortResults)}


def _json(data: dict) -> dict:
    """``data`` as write_json stores it and json reads it back: numpy as Python numbers and
    lists, tuples as lists, NaN and ±inf as null (``parse_constant``); a copy, in its order."""
    from .._files import json_default

    try:
        return json.loads(json.dumps(data, default=json_default), parse_constant=lambda _: None)
    except (TypeError, ValueError) as error:
        raise DataError(f"results must hold JSON values only: {error}") from None


def load_results(path: str | Path) -> Results:
    """Read a results.json (or the results directory holding it) back as its result object.

    Parameters
    ----------
    path : str or pathlib.Path
        A ``results.json`` written by a crowdvib command, or its directory.

    Returns
    -------
    Results
        The subclass of its ``kind``, e.g. :class:`EstimateResults`.

    Raises
    ------
    DataError
        Naming the file: missing, not valid JSON, not an object, or without a known ``schema``
        and ``kind``.

    Examples
    --------
    >>> result = load_results("out/results.json")      # doctest: +SKIP
    >>> result.verdict()                               # doctest: +SKIP
    """
    path = Path(path)
    if path.is_dir():
        path = path / "results.json"
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise DataError(f"{path} does not exist: run a crowdvib command with --out "
                        f"{path.parent} first") from None
    except (OSError, UnicodeDecodeError) as error:
        raise DataError(f"{path} cannot be read: {error}") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as error:
        raise DataError(f"{path} is not valid JSON: {error}") from None
    except RecursionError:
        raise DataError(f"{path} is not a crowdvib results.json: its JSON is nested deeper than "
                        f"Python's recursion limit ({sys.getrecursionlimit()})") from None
    try:
        return Results.from_dict(data, source=str(path))
    except RecursionError:
        raise DataError(f"{path} is not a crowdvib results.json: its JSON is nested too deeply "
                        "to be results") from None


class AsResults:
    """What a ``crowdvib.cases`` function returns (:class:`CaseEstimate`, :class:`CaseMap`,
    :class:`CaseCheck`, :class:`CaseSimulation`, :class:`AmbientModes`): its results as the
    command writes them, and their verdict."""

    def results(self, **extra: Any) -> Results:
        """The :class:`Results` of this computation (:func:`results_of`)."""
        return results_of(self, **extra)

    def verdict(self) -> tuple[Finding, ...]:
        """The verdict on these results (:meth:`Results.verdict`), without the warnings the
        command line catches during the run."""
        return self.results().verdict()


def results_of(found: Any, **extra: Any) -> Results:
    """The result of what a ``crowdvib.cases`` function returned, as the command writes it
    (without the figures, warnings and provenance the command adds; give them as ``extra``).

    Parameters
    ----------
    found : CaseEstimate, CaseMap, CaseCheck, CaseSimulation or AmbientModes
        Anything whose ``to_dict()`` is a results.json object.
    **extra
        Keys to add (e.g. ``warnings=[...]``).
    """
    return Results.from_dict({**found.to_dict(), **extra})

