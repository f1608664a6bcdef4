"""``crowdvib check``'s work on a case: the design checks of its ``[design]`` table, without and
with HSI, and the crowd stream's predicted response (docs: :ref:`theory-design`)."""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeAlias

from .._version import __version__
from ..errors import ParameterError, PlausibilityWarning
from .results import DESIGN_TABLES, AsResults, software_versions
from .schema import schema_header
from ..design import code_names
from ..design.check import NEQ_DAMPINGS
from ..design.codes import COMFORT_CLASSES, UKNA_GAMMA_FIGURES, ukna_limit
from ..identification.result import HSIEstimate
from ..design import TunedMassDamper, tune_damper
from ..design import design_check
from ..design.registry import design_code
from ..design.codes import comfort_class
from ..response import modal_accelerance
from ..errors import DataError
from ..models.pedestrian import MSDModel
from .results import Results
from ..design.interval import MSDBox
from ..design.interval import check_grid, check_over_box
from ..design.stochastic import predict_response

if TYPE_CHECKING:
    from collections.abc import Mapping

    from ..design.interval import MSDBox
    from ..design.stochastic import ResponsePrediction
    from ..identification.result import HSIEstimate
    from ..io.casefile import Case
    from ..models.pedestrian import MSDModel
    from .results import Results

    #: What a design check takes the identified MSD from: an estimate made in Python, a loaded
    #: results folder, a box of f_h1 and ξ_h1, or a results.json object.
    EstimateLike: TypeAlias = HSIEstimate | Results | MSDBox | Mapping[str, Any]


__all__ = ["CaseCheck", "IntervalCheck", "check_design_table", "design_msd", "check_case",
           "estimated_msd", "msd_interval", "msd_box", "check_over_interval", "verdict_rows",
           "damper_frf"]

@dataclass(frozen=True)
class CaseCheck(AsResults):
    """What ``crowdvib check`` computes for a case (:func:`check_case`).

    Attributes
    ----------
    case : Case
    msd : MSDModel or None
        The MSD of the HSI model (None: no HSI).
    msd_source : str or None
        Where it comes from (``"[hsi]"``, ``"[design.msd]"`` or an estimate's results).
    checks : dict
        Code name → :class:`~crowdvib.design.DesignCheck`, in ``design.codes`` order.
    dampers : list of TunedMassDamper
    prediction : StochasticPrediction or None
        The crowd stream's predicted response (``design.prediction``).
    seconds : float
        Wall-clock time of the checks and the prediction [s].
    spread : IntervalCheck or None
        The checks across the estimate's interval (``estimate`` of :func:`check_case`).
    """

    case: Case
    msd: MSDModel | None
    msd_source: str | None
    checks: dict
    dampers: list
    prediction: ResponsePrediction | None
    seconds: float
    spread: IntervalCheck | None = None

    @property
    def rows(self) -> list[dict]:
        """The verdict table (:func:`verdict_rows`)."""
        return verdict_rows(self.checks)

    def to_dict(self) -> dict:
        """The results ``crowdvib check`` writes to results.json, without its figures,
        provenance and warnings."""
        msd = self.msd
        return {**schema_header("check"), "command": "check", "crowdvib_version": __version__,
                "versions": software_versions(), "case": str(self.case.path),
                "inputs": self.case.inputs(DESIGN_TABLES),
                "msd": None if msd is None else {**msd.to_dict(), "source": self.msd_source},
                "design": {"verdict": self.rows,
                           "checks": {code: check.to_dict() for code, check in self.checks.items()},
                           "dampers": [d.to_dict() for d in self.dampers],
                           "frf": damper_frf(self),
                           "prediction": None if self.prediction is None
                           else self.prediction.to_dict()},
                # Per code, the HSI utilisation's range over the estimate's interval (issue 27 §3).
                "hsi_range": None if self.spread is None else self.spread.hsi_range(),
                "elapsed_s": self.seconds}


def check_design_table(case) -> None:
    """Refuse a case without ``[design]``, and the ``[design]`` values only the design layer can
    judge: the registered codes (and a class given per code), the comfort class, the UK NA site
    factors and γ figure, the n_eq damping reading (io reads the table without importing
    ``design``, issue 26 §4).

    Parameters
    ----------
    case : Case
        The case whose ``[design]`` table is checked.

    Raises
    ------
    ParameterError
        Naming the case file, the key, the rule and the value.
    """

    spec = case.design
    if spec is None:
        raise ParameterError(f"{case.path.name}: crowdvib check needs a [design] table "
                             "(design.codes at least)")

    def refused(rule):
        return ParameterError(f"{case.path.name}: design.{rule}")

    if any(code not in code_names() for code in spec.codes):
        raise refused(f"codes must list codes among {list(code_names())}, got {list(spec.codes)}")
    for code in spec.classes:
        if code not in spec.codes:
            raise refused(f"classes.{code} is given but {code!r} is not in design.codes "
                          f"{list(spec.codes)}")
    classes = [name for name, _ in COMFORT_CLASSES[:-1]]
    if spec.comfort_class is not None and spec.comfort_class not in classes:
        raise refused(f"comfort_class must be one of {classes}, got {spec.comfort_class!r}")
    try:
        ukna_limit(spec.site_factors)
    except ParameterError as exc:
        raise refused(str(exc)) from None
    # Like comfort_class and the site factors, an option no listed code takes is left unused.
    for key, choices in (("gamma_figure", UKNA_GAMMA_FIGURES), ("neq_damping", NEQ_DAMPINGS)):
        given = getattr(spec, key)
        if given is not None and given not in choices:
            raise refused(f"{key} must be one of {list(choices)}, got {given!r}")


def design_msd(case):
    """The MSD a case's design checks use with HSI, and where it comes from.

    Parameters
    ----------
    case : Case
        A case with a ``[design]`` table.

    Returns
    -------
    (MSDModel or None, str or None)
        ``[design.msd]`` if given, else ``[hsi]``; (None, None) with ``design.hsi = false``.
    """
    spec = case.design
    if not spec.hsi:
        return None, None
    if spec.msd is not None:
        return spec.msd, "[design.msd]"
    return case.msd, "[hsi]"


def check_case(case: Case, *, msd: MSDModel | None = None, msd_source: str | None = None,
               estimate: EstimateLike | None = None, grid: int = 3) -> CaseCheck:
    """Run ``crowdvib check``'s design checks on a case, without writing anything.

    Parameters
    ----------
    case : Case
        With a ``[design]`` table (docs: :doc:`/casefiles`).
    msd : MSDModel, optional
        The MSD of the HSI model (default :func:`design_msd`: the case's own).
    msd_source : str, optional
        Where ``msd`` comes from, for the results (given with ``msd``).
    estimate : HSIEstimate, Results, MSDBox or dict, optional
        The estimated MSD (``crowdvib check --msd-from``): an :class:`~crowdvib.HSIEstimate`
        made in Python, the results of the run that estimated it (:func:`load_results`, or its
        results.json object), or the box itself. Its point estimate is the MSD (unless ``msd``
        is given) and its interval is carried into the checks (:func:`check_over_interval`,
        ``spread``).
    grid : int
        Points per parameter of :func:`check_over_interval`.

    Returns
    -------
    CaseCheck
        Every code of ``design.codes`` checked by :func:`crowdvib.design.design_check` (no HSI,
        added mass, and HSI), with the ``[design.damper]`` if any, and the crowd stream predicted
        by :func:`crowdvib.design.predict_response` if ``design.prediction``.
    """
    import time

    check_design_table(case)
    box = None if estimate is None else msd_box(case, estimate)
    if msd is None and estimate is not None:
        msd, msd_source = _point(case, estimate, box), msd_source or "the estimate"
    if msd is None:
        msd, msd_source = design_msd(case)
    spec = case.design
    started = time.perf_counter()
    dampers = _dampers(case, spec, msd)
    checks = {code: _check(case, spec, code, msd, dampers) for code in spec.codes}
    prediction = None
    if spec.prediction:

        crowd = (case.stationary_crowd() if spec.density is None
                 else case.crowd.with_density(spec.density))
        prediction = predict_response(case.structure, crowd, msd=msd, dampers=dampers,
                                      duration=spec.duration, weighting=spec.weighting,
                                      force=case.force)
    spread = None if box is None else check_over_interval(case, box, grid=grid)
    return CaseCheck(case, msd, msd_source, checks, dampers, prediction,
                     time.perf_counter() - started, spread)


def _point(case, estimate, box):
    """The point estimate of ``estimate`` (see :func:`check_case`)."""

    if box is not None:
        return box.msd
    return estimate.msd if isinstance(estimate, HSIEstimate) else estimated_msd(case, estimate)


def _dampers(case, spec, msd):
    """The ``[design.damper]`` as a list (tuned to the occupied structure when HSI is on)."""

    damper = spec.damper
    if damper is None:
        return []
    if "mode" in damper:
        if damper["mode"] > case.structure.n_modes:
            raise ParameterError(f"{case.path.name}: design.damper.mode must be at most the "
                                 f"number of modes ({case.structure.n_modes}), got "
                                 f"{damper['mode']}")
        crowd = case.stationary_crowd() if msd is not None else None
        return [tune_damper(case.structure, damper["mode"] - 1, damper["mass_ratio"],
                            crowd=crowd, msd=msd)]
    return [TunedMassDamper(**damper)]


def _check(case, spec, code, msd, dampers):
    traffic_class = spec.classes.get(code)
    density = spec.density
    if traffic_class is None and density is None:
        density = case.stationary_crowd().density      # no class: the case's own crowd
    # Each code gets the [design] options it takes (EN 1990 has one limit, no comfort class).
    given = {"site_factors": spec.site_factors, "weighting": spec.weighting,
             "gamma_figure": spec.gamma_figure, "neq_damping": spec.neq_damping,
             "comfort_class": spec.comfort_class if code != "en1990" else None}
    takes = design_code(code).options
    options = {name: value for name, value in given.items() if name in takes}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check = design_check(case.structure, code, traffic_class=traffic_class,
                             density=density, crowd=case.stationary_crowd(), msd=msd,
                             dampers=dampers,
                             **options)
    # design_check names the structure's implausible values again, "structure of the design
    # check: …": the case file's structure was named once, where it was read (issue 36 §3:
    # one line per finding). Every other warning goes on as raised.
    named = {f"structure of the design check: {note}"
             for note in case.structure.implausibilities()}
    for found in caught:
        if not (issubclass(found.category, PlausibilityWarning) and str(found.message) in named):
            warnings.warn_explicit(found.message, found.category, found.filename, found.lineno)
    return check


def verdict_rows(checks: dict) -> list[dict]:
    """One row per code, model and output: governing acceleration, limit, utilisation, class.

    Parameters
    ----------
    checks : dict
        Code name → :class:`~crowdvib.design.DesignCheck`.

    Returns
    -------
    list of dict
        ``code``, ``traffic_class``, ``model`` ("no HSI", "added mass", "HSI"), ``output``,
        ``governing`` [m/s²], ``limit`` [m/s²], ``utilisation``, ``comfort_class``, ``passes``.
    """

    labels = {"empty": "no HSI", "added_mass": "added mass", "hsi": "HSI"}
    rows = []
    for code, check in checks.items():
        for model in check.models:
            governing = check.governing_of(model)
            for output, value in zip(check.output_names, governing):
                rows.append({"code": code, "traffic_class": check.traffic_class,
                             "model": labels[model], "output": output,
                             "governing": float(value), "limit": float(check.limit),
                             "utilisation": float(value / check.limit),
                             "comfort_class": comfort_class(float(value)),
                             "passes": bool(value <= check.limit)})
    return rows


#: The FRF of :func:`damper_frf` spans the governing mode's frequency ∓ this fraction (wider than
#: the design checks' ∓ 25 % band, so both peaks of the split mode show).
_FRF_SPAN = 0.3


def damper_frf(found: CaseCheck) -> dict | None:
    """|FRF| of the governing mode at the governing output without and with the dampers, for
    the report's figure (issue 27 §4: what the damper buys).

    The governing check is the code whose primary model (HSI when checked, else no HSI) has the
    largest utilisation; at its governing output, the governing mode is the one with the largest
    peak acceleration. Its accelerance per unit modal force, |−ω² φ_o H(ω) e_j|
    (:func:`crowdvib.response.modal_accelerance`), is evaluated with that model (with HSI, the
    crowd of MSDs at the check's density) on f_j (1 ∓ 0.3), fine enough to resolve the
    undamped peak (a quarter of its half-power half-width).

    Parameters
    ----------
    found : CaseCheck
        The design check of a case (:func:`check_case`).

    Returns
    -------
    dict or None
        ``code``, ``model``, ``output``, ``mode`` (1-based), ``density`` [persons/m²],
        ``frequency`` [Hz], ``without_damper`` and ``with_damper`` [(m/s²) per unit modal
        force]; None without dampers.
    """
    import numpy as np


    if not found.dampers or not found.checks:
        return None
    check = max(found.checks.values(), key=lambda c: float(np.max(c.utilisation)))
    output = int(np.argmax(check.governing))
    primary = check.models.index(check.primary)
    mode = int(np.argmax(check.peak_accelerations[primary, output]))
    structure = found.case.structure
    centre, damping = structure.frequencies[mode], structure.damping_ratios[mode]
    size = int(np.clip(np.ceil(2 * _FRF_SPAN / (damping / 4)), 400, 4000))
    frequency = np.linspace((1 - _FRF_SPAN) * centre, (1 + _FRF_SPAN) * centre, size)
    hsi = check.primary == "hsi"
    crowd = found.case.crowd.with_density(check.density) if hsi else None
    msd = found.msd if hsi else None
    name = check.output_names[output]

    def magnitude(dampers):
        values = modal_accelerance(structure, frequency, crowd=crowd, msd=msd, dampers=dampers,
                                   outputs=[name])
        return np.abs(values[0, mode]).tolist()

    return {"code": check.code, "model": "HSI" if hsi else "no HSI", "output": name,
            "mode": mode + 1, "density": float(check.density), "frequency": frequency.tolist(),
            "without_damper": magnitude([]), "with_damper": magnitude(found.dampers)}


def estimated_msd(case: Case, results: Results | dict, *,
                  source: str = "the results") -> MSDModel:
    """The MSD another run estimated (``crowdvib check --msd-from``), with the case's mass ratio
    if the results hold none.

    Parameters
    ----------
    case : Case
    results : Results or dict
        The results (or results.json object) of ``crowdvib estimate``, ``sensitivity`` or
        ``demo``.
    source : str
        What the results are, for the error message.

    Raises
    ------
    DataError
        If the results hold no estimate of f_h1 and ξ_h1.
    """

    found = _as_results(results).estimate
    if not found or not {"frequency", "damping_ratio"} <= set(found):
        raise DataError(f"{source}: its results.json holds no MSD estimate "
                        "(estimate.frequency and estimate.damping_ratio)")
    return MSDModel(found["frequency"], found["damping_ratio"],
                    found.get("mass_ratio") or case.msd.mass_ratio)


def _as_results(results):
    """``results`` as a :class:`Results` (a results.json object is read as one)."""

    return results if isinstance(results, Results) else Results.from_dict(results)


def msd_interval(results: Results | dict) -> dict | None:
    """The box of f_h1 and ξ_h1 an estimate's results allow, as a dict (issue 27 §3):
    :meth:`Results.msd_box`'s :meth:`~crowdvib.design.interval.MSDBox.to_dict`.

    The results of ``crowdvib sensitivity`` give the statistical interval widened by the
    modelling bound (``combined``, :meth:`~crowdvib.studies.SensitivityResult.combined`),
    those of ``crowdvib estimate`` the statistical interval (``estimate.interval``). A parameter
    without an interval (held in the estimation) stays at its estimate.

    Parameters
    ----------
    results : Results or dict
        The results (or results.json object) of ``crowdvib estimate`` or ``sensitivity``.

    Returns
    -------
    dict or None
        ``frequency`` and ``damping_ratio`` [low, high], ``level`` (of the statistical
        interval), ``interval`` (what the box is: ``"estimate 95 %"`` or ``"estimate 95 % +
        modelling bound"``) and the point ``msd``; None if the results hold no interval
        (``estimation.interval = "none"``).
    """
    box = _as_results(results).msd_box()
    return None if box is None else box.to_dict()


def msd_box(case: Case, estimate: EstimateLike) -> MSDBox | None:
    """The box of f_h1 and ξ_h1 of ``estimate`` (see :func:`check_over_interval`), around the
    estimated MSD (:func:`estimated_msd`: μ_h1 the case's if the results hold none); None
    without an interval.

    Parameters
    ----------
    case : Case
    estimate : MSDBox, HSIEstimate, Results or dict
    """

    if isinstance(estimate, MSDBox):
        return estimate
    if isinstance(estimate, HSIEstimate):
        return MSDBox.from_estimate(estimate)
    results = _as_results(estimate)
    return results.msd_box(estimated_msd(case, results))


@dataclass(frozen=True)
class IntervalCheck:
    """The design checks across the box of f_h1 and ξ_h1 an estimate allows
    (:func:`check_over_interval`).

    Attributes
    ----------
    box : MSDBox
        The box, around the point estimate ``box.msd``.
    grid : int
        Points per parameter (``grid × grid`` checks; 2: the corners only).
    rows : list of dict
        Per code and model: ``code``, ``model`` and what
        :func:`~crowdvib.design.interval.check_over_box` gives of the largest utilisation over
        the outputs (``utilisation`` at the point estimate, ``low``/``high``,
        ``conservative_end``, ``monotone``, ``passes``, ``verdict``).
    """

    box: MSDBox
    grid: int
    rows: list

    @property
    def msd(self) -> MSDModel:
        """The point estimate."""
        return self.box.msd

    @property
    def interval(self) -> dict:
        """The box as a dict (:meth:`~crowdvib.design.interval.MSDBox.to_dict`)."""
        return self.box.to_dict()

    def hsi_range(self) -> dict:
        """results.json's ``hsi_range``: per code, the HSI model's row and the box."""
        box = self.box
        return {row["code"]: {**{k: v for k, v in row.items() if k not in ("code", "model")},
                              "interval": box.interval, "frequency": list(box.frequency),
                              "damping_ratio": list(box.damping_ratio), "level": box.level,
                              "grid": self.grid}
                for row in self.rows if row["model"] == "HSI"}


def check_over_interval(case: Case, estimate: EstimateLike, *,
                        grid: int = 3) -> IntervalCheck | None:
    """The design checks of :func:`check_case` with the estimated MSD, across its interval.

    Each code is checked with the MSD at the ``grid × grid`` points of the box of f_h1 and ξ_h1
    (:func:`msd_box`: the statistical interval, or with ``crowdvib sensitivity``'s results that
    widened by the modelling bound), μ_h1 held at the estimate
    (:func:`~crowdvib.design.interval.check_over_box`). The box is wider than the joint
    confidence region, so the range is on the safe side. A damper of ``[design.damper]`` is
    tuned once, to the point estimate: it is built, the MSD is what is uncertain. The crowd
    stream's prediction is not repeated.

    Parameters
    ----------
    case : Case
        With a ``[design]`` table.
    estimate : MSDBox, HSIEstimate, Results or dict
        The box itself; an estimate made in Python; or the results (or results.json object)
        of ``crowdvib estimate`` or ``sensitivity``.
    grid : int
        Points per parameter, at least 2 (the corners). The utilisation of the paper example is
        monotone in each parameter (tests/cli/test_check_interval.py), so the corners
        bound it; 3 also checks the monotony (``rows[...]["monotone"]``).

    Returns
    -------
    IntervalCheck or None
        None if the estimate holds no interval.
    """

    grid = check_grid(grid)         # before the work: the box may mean loading results
    check_design_table(case)
    box = msd_box(case, estimate)
    if box is None:
        return None
    spec = case.design
    dampers = _dampers(case, spec, box.msd)

    def largest(msd):
        """{(code, model): largest utilisation over the outputs} with this MSD."""
        checks = {code: _check(case, spec, code, msd, dampers) for code in spec.codes}
        found: dict = {}
        for row in verdict_rows(checks):
            key = (row["code"], row["model"])
            found[key] = max(found.get(key, float("-inf")), row["utilisation"])
        return found

    rows = [{"code": row["key"][0], "model": row["key"][1],
             **{k: v for k, v in row.items() if k != "key"}}
            for row in check_over_box(largest, box, grid=grid)]
    return IntervalCheck(box, grid, rows)
