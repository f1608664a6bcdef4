"""What every results.json is: the :class:`Results` base class and what all kinds share.

A result holds exactly what its file holds (schema :data:`~crowdvib.cases.schema.SCHEMA`,
docs: :doc:`/results`): ``Results.from_dict(r.to_dict()) == r``. Each kind of results is a
subclass in :mod:`crowdvib.cases.results` with its ``kind``, registered here when defined, so
that :meth:`Results.from_dict` builds the class a dict's ``kind`` names. Also the case tables
a results.json keeps, the software versions and provenance it records, and
:class:`AsResults`, what the ``crowdvib.cases`` computations share.

Light on purpose: the command line imports it at start-up (``crowdvib --help``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

from .._version import __version__
from ..errors import DataError
from .schema import KINDS, READABLE, estimate, hsi, upgrade
from .._files import sha256_file
from .._files import json_default
from .schema import case_name
from ..design.interval import SPANNED, MSDBox
from ..models.pedestrian import MSDModel
from .verdict import findings
from .verdict import in_doubt
from .verdict import fails_design
from ..quantities import describe
from .notebook import results_html

if TYPE_CHECKING:
    from ..design.interval import MSDBox
    from ..models.pedestrian import MSDModel
    from .verdict import Finding

__all__ = ["ESTIMATION_TABLES", "SIMULATION_TABLES", "DESIGN_TABLES", "software_versions",
           "provenance", "Results", "AsResults", "results_of"]

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


    created = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
    path = None if case is None else Path(case)
    return {"created": created,
            "case_sha256": sha256_file(path) if path is not None and path.is_file() else None}


#: The MSD's parameters (and the step frequencies fitted with it) in the order tables show them.
_PARAMETERS = ("frequency", "damping_ratio", "mass_ratio", "step_frequency_mean",
               "step_frequency_std")


#: kind → its Results subclass (registered by :meth:`Results.__init_subclass__`).
_CLASSES: dict[str, type] = {}


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

    def __init_subclass__(cls, **options):
        # Each kind's class registers itself: from_dict builds the one a dict's kind names.
        super().__init_subclass__(**options)
        if cls.kind:
            _CLASSES[cls.kind] = cls

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
        if schema not in READABLE:
            why = ("no schema (written by a crowdvib before results.json had one)"
                   if schema is None else f"schema {schema!r} (another crowdvib's)")
            raise DataError(f"{source} holds {why}; crowdvib {__version__} reads "
                            f"{' and '.join(map(repr, READABLE))}: run the command again to "
                            "write it")
        if kind not in _CLASSES:
            raise DataError(f"{source}: kind must be one of {list(KINDS)}, got {kind!r}")
        if cls.kind and kind != cls.kind:
            raise DataError(f"{source} holds {kind!r} results, not {cls.kind!r}")
        return _CLASSES[kind](_json(upgrade(data)))

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

    def parts(self) -> dict[str, Any]:
        """The typed parts of these results, by name, built from the dict.

        Each is an object of the library with its ``to_dict``/``from_dict``
        (:class:`~crowdvib.identification.HSIEstimate`, :class:`~crowdvib.design.DesignCheck`,
        …); a part the results do not hold is left out. The kinds name theirs in their
        ``parts``."""
        return {}

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

        return findings(self.data)

    @property
    def passes(self) -> bool:
        """True when the verdict has no doubt and no failure."""
        return all(finding.severity == "ok" for finding in self.verdict())

    @property
    def in_doubt(self) -> bool:
        """True when the verdict doubts the result (:func:`~crowdvib.cases.verdict.in_doubt`):
        the command line then exits with status 3 (1 with ``--strict``)."""

        return in_doubt(self.verdict())

    @property
    def fails_design(self) -> bool:
        """True when the bridge fails a design code at the result
        (:func:`~crowdvib.cases.verdict.fails_design`): an answer, not a doubt; the command line
        then exits with status 4 unless the result is also in doubt (3)."""

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

        return results_html(self, self.table() if self._view_table else (), self._shown_columns)

    def __repr__(self):
        found = self.estimate or {}
        shown = ", ".join(f"{k}={found[k]:.4g}" for k in _PARAMETERS[:3]
                          if isinstance(found.get(k), (int, float)))
        return (f"{type(self).__name__}({self.name!r}{', ' + shown if shown else ''}, "
                f"verdict={'ok' if self.passes else 'check before use'})")


def _json(data: dict) -> dict:
    """``data`` as write_json stores it and json reads it back: numpy as Python numbers and
    lists, tuples as lists, NaN and ±inf as null (``parse_constant``); a copy, in its order."""

    try:
        return json.loads(json.dumps(data, default=json_default), parse_constant=lambda _: None)
    except (TypeError, ValueError) as error:
        raise DataError(f"results must hold JSON values only: {error}") from None


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
