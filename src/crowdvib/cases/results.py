"""Results that round-trip: what every command's results.json holds, as an object again.

Each command writes one results.json in the versioned schema :data:`~crowdvib.cases.schema.SCHEMA`
(docs: :doc:`/results`); :func:`load_results` reads it back as the :class:`Results` of its
``kind`` (:class:`EstimateResults`, :class:`SensitivityResults`, :class:`CheckResults`,
:class:`ModesResults`, :class:`SimulateResults`, :class:`MapResults`, :class:`DemoResults`).
A result holds exactly what the file holds, so ``load_results(path).to_dict()`` equals the file
(of the current schema; an older one's is upgraded as read) and ``Results.from_dict(r.to_dict())
== r``; its :meth:`~Results.parts` are the typed objects of the library, each with its
``from_dict`` (:meth:`EstimateResults.hsi_estimate` →
:class:`~crowdvib.identification.HSIEstimate`), its verdict (:meth:`Results.verdict`, the one the command line prints and report.html shows), a
notebook view (``_repr_html_``) and tables for pandas (:meth:`Results.to_dataframe`).

What every kind shares, the base class among it, is in :mod:`crowdvib.cases.resultfile`.
Light on purpose: the command line imports it at start-up (``crowdvib --help``).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import DataError
from .resultfile import (DESIGN_TABLES, ESTIMATION_TABLES, SIMULATION_TABLES,
                         AsResults, Results, provenance, results_of, software_versions)
from .schema import hsi
from ..identification.result import HSIEstimate
from ..models.crowd import Crowd
from ..identification.step_frequencies import StepFrequencyEstimate
from ..signals.convergence import PSDConvergence
from ..models.pedestrian import MSDModel
from ..models.examples import paper_example
from ..response.frequency_domain.results import EffectiveModalProperties
from ..studies.landscape import ObjectiveMap
from ..studies.modelling_error import SensitivityResult
from ..design.check import DesignCheck
from ..design.stochastic import ResponsePrediction
from ..models.damper import TunedMassDamper
from ..oma.modeid import ModeIdentification
from ..studies.season import season_dataframe
from ..comfort.traffic import Traffic
from ..design.interval import MSDBox
from ..comfort import ComfortYear

if TYPE_CHECKING:
    from ..identification.result import HSIEstimate
    from ..models.pedestrian import MSDModel

__all__ = ["ESTIMATION_TABLES", "SIMULATION_TABLES", "DESIGN_TABLES", "software_versions",
           "provenance",
           "Results", "EstimateResults", "SensitivityResults", "CheckResults", "ModesResults",
           "SimulateResults", "MapResults", "DemoResults", "SeasonResults", "ComfortResults",
           "AsResults",
           "load_results", "results_of"]


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

        diagnostics = self.data.get("diagnostics")
        if not isinstance(diagnostics, dict) or not isinstance(self.data.get("estimate"), dict):
            raise DataError("these results hold no estimate with its diagnostics")
        crowd = (self.data.get("inputs") or {}).get("crowd")
        return HSIEstimate.from_dict({**diagnostics, "estimate": self.data["estimate"]},
                                     crowd=Crowd.from_dict(crowd) if isinstance(crowd, dict)
                                     else None)

    def parts(self) -> dict[str, Any]:
        """``estimate`` (:class:`~crowdvib.identification.HSIEstimate`), ``box`` (its
        :class:`~crowdvib.design.MSDBox`), ``convergence``
        (:class:`~crowdvib.signals.PSDConvergence`), ``step_frequencies``
        (:class:`~crowdvib.identification.StepFrequencyEstimate`, when fitted from the low
        band), ``crowd`` (the case's :class:`~crowdvib.models.Crowd`)."""

        crowd = (self.data.get("inputs") or {}).get("crowd")
        found = {"estimate": self.hsi_estimate(), "box": self.msd_box(),
                 "crowd": Crowd.from_dict(crowd) if isinstance(crowd, dict) else None}
        convergence, step = hsi(self.data, "convergence"), hsi(self.data, "step_frequencies")
        if isinstance(convergence, dict):
            found["convergence"] = PSDConvergence.from_dict(convergence)
        if isinstance(step, dict):
            found["step_frequencies"] = StepFrequencyEstimate.from_dict(step, crowd=found["crowd"])
        return {name: part for name, part in found.items() if part is not None}

    @property
    def msd(self) -> MSDModel:
        """The estimated :class:`~crowdvib.models.MSDModel`."""

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
        """The :class:`~crowdvib.identification.HSIEstimate` (for results written before it
        stored its crowd, fitted step frequencies in the crowd of the paper's example, which
        the demo runs)."""

        return HSIEstimate.from_dict({**self.data["diagnostics"],
                                      "estimate": self.data["estimate"]},
                                     crowd=paper_example().crowd)


    def parts(self) -> dict[str, Any]:
        """``estimate`` and ``box`` as for an estimate, ``paper_estimator`` (the paper's least
        squares' :class:`~crowdvib.identification.HSIEstimate`), ``truth``
        (:class:`~crowdvib.models.MSDModel`) and ``occupied_structure``
        (:class:`~crowdvib.response.EffectiveModalProperties`)."""

        return {"estimate": self.hsi_estimate(), "box": self.msd_box(),
                "paper_estimator": HSIEstimate.from_dict(self.data["paper_estimator"]),
                "truth": MSDModel.from_dict(self.data["truth"]),
                "occupied_structure": EffectiveModalProperties.from_dict(
                    self.data["occupied_structure"])}


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

        return HSIEstimate.from_dict({**self.data["diagnostics"],
                                      "estimate": self.data["estimate"]})

    def parts(self) -> dict[str, Any]:
        """``estimate`` (:class:`~crowdvib.identification.HSIEstimate`) and ``objective_map``
        (:class:`~crowdvib.studies.ObjectiveMap`)."""

        return {"estimate": self.hsi_estimate(),
                "objective_map": ObjectiveMap.from_dict(self.data["objective_map"])}


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

    def parts(self) -> dict[str, Any]:
        """``study`` (:class:`~crowdvib.studies.SensitivityResult`), ``box`` (the
        :class:`~crowdvib.design.MSDBox` of the interval widened by the modelling bound)."""

        found = {"study": SensitivityResult.from_dict(self.data["sensitivity"]),
                 "box": self.msd_box()}
        return {name: part for name, part in found.items() if part is not None}


class CheckResults(Results):
    """``crowdvib check``: the design codes' verdict rows (:func:`check_case`)."""

    kind = "check"
    _view_table = True

    def table(self) -> list[dict]:
        """The verdict rows: code, class, model, output, governing acceleration, limit,
        utilisation, comfort class, passes."""
        return [dict(row) for row in (self.data.get("design") or {}).get("verdict", [])]

    def parts(self) -> dict[str, Any]:
        """``checks`` (code → :class:`~crowdvib.design.DesignCheck`), ``msd``
        (:class:`~crowdvib.models.MSDModel` of the HSI model), ``dampers`` (tuple of
        :class:`~crowdvib.models.TunedMassDamper`), ``prediction``
        (:class:`~crowdvib.design.ResponsePrediction`) when asked for."""

        design = self.data.get("design") or {}
        msd, prediction = self.data.get("msd"), design.get("prediction")
        found = {"checks": {code: DesignCheck.from_dict(check)
                            for code, check in (design.get("checks") or {}).items()},
                 "msd": MSDModel.from_dict(msd) if isinstance(msd, dict) else None,
                 "dampers": tuple(TunedMassDamper.from_dict(d) for d in design.get("dampers")
                                  or ()),
                 "prediction": (ResponsePrediction.from_dict(prediction)
                                if isinstance(prediction, dict) else None)}
        return {name: part for name, part in found.items() if part is not None}

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

    def parts(self) -> dict[str, Any]:
        """``modes``: the :class:`~crowdvib.oma.ModeIdentification`."""

        return {"modes": ModeIdentification.from_dict(self.data)}

    def table(self) -> list[dict]:
        """One row per mode: frequency [Hz], damping ratio [-] and their standard deviations."""
        return [{key: mode.get(key) for key in ("frequency", "frequency_std", "damping_ratio",
                                                "damping_std")}
                for mode in self.data.get("modes", []) if isinstance(mode, dict)]


class SimulateResults(Results):
    """``crowdvib simulate``: the simulated record's response (:func:`simulate_case`)."""

    kind = "simulate"
    _view_table = True

    def parts(self) -> dict[str, Any]:
        """``msd``: the :class:`~crowdvib.models.MSDModel` simulated with (none: no HSI); the
        record itself is in the folder's record files (:func:`crowdvib.io.read_record`)."""

        msd = self.data.get("msd")
        return {"msd": MSDModel.from_dict(msd)} if isinstance(msd, dict) else {}

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

    def parts(self) -> dict[str, Any]:
        """``joint`` (the joint :class:`~crowdvib.identification.HSIEstimate`, when made) and
        its ``box``; every record's row is in :meth:`table`."""

        if not isinstance(self.data.get("diagnostics"), dict) or not self.estimate:
            return {}
        joint = HSIEstimate.from_dict({**self.data["diagnostics"], "estimate": self.estimate})
        return {"joint": joint, "box": self.msd_box()}

    def to_dataframe(self) -> Any:
        """:meth:`table` as a pandas DataFrame (:func:`crowdvib.studies.season.season_dataframe`:
        numbers as floats, NaN where a row has none, ``time`` as datetimes)."""

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

    def parts(self) -> dict[str, Any]:
        """``comfort`` (:class:`~crowdvib.comfort.ComfortYear`), ``traffic``
        (:class:`~crowdvib.comfort.Traffic`), ``msd`` (:class:`~crowdvib.models.MSDModel`)
        and ``box`` (:class:`~crowdvib.design.MSDBox`) when carried."""

        msd, box = self.data.get("msd"), self.data.get("msd_interval")
        found = {"comfort": self.comfort_year(), "traffic": Traffic.from_dict(self.data["traffic"]),
                 "msd": MSDModel.from_dict(msd) if isinstance(msd, dict) else None,
                 "box": MSDBox.from_dict(box) if isinstance(box, dict) and "msd" in box else None}
        return {name: part for name, part in found.items() if part is not None}

    def comfort_year(self):
        """The :class:`~crowdvib.comfort.ComfortYear` it holds."""

        return ComfortYear.from_dict(self.data["comfort"])


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
