"""``crowdvib check``'s work on a case: the design checks of its ``[design]`` table, without and
with HSI, and the crowd stream's predicted response (docs: :ref:`theory-design`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from .._version import __version__
from ..errors import ParameterError
from .results import AsResults, DESIGN_TABLES, software_versions
from .schema import schema_header

if TYPE_CHECKING:
    from ..io.casefile import Case
    from ..models.pedestrian import MSDModel


__all__ = ["CaseCheck", "check_design_table", "design_msd", "check_case",
           "verdict_rows"]

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
    """

    case: Any
    msd: Any
    msd_source: str | None
    checks: dict
    dampers: list
    prediction: Any
    seconds: float

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
                "inputs": self.case.to_dict(DESIGN_TABLES),
                "msd": None if msd is None else {**msd.to_dict(), "source": self.msd_source},
                "design": {"verdict": self.rows,
                           "checks": {code: check.to_dict() for code, check in self.checks.items()},
                           "dampers": [d.to_dict() for d in self.dampers],
                           "prediction": None if self.prediction is None
                           else self.prediction.to_dict()},
                "elapsed_s": self.seconds}


def check_design_table(case) -> None:
    """Refuse a case without ``[design]``, and the ``[design]`` values only the design layer can
    judge: the registered codes (and a class given per code), the comfort class, the UK NA site
    factors (io reads the table without importing ``design``, issue 26 §4).

    Raises
    ------
    ParameterError
        Naming the case file, the key, the rule and the value.
    """
    from ..design import code_names
    from ..design.codes import COMFORT_CLASSES, ukna_limit

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


def design_msd(case):
    """The MSD a case's design checks use with HSI, and where it comes from.

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


def check_case(case: Case, *, msd: MSDModel | None = None,
               msd_source: str | None = None) -> CaseCheck:
    """Run ``crowdvib check``'s design checks on a case, without writing anything.

    Parameters
    ----------
    case : Case
        With a ``[design]`` table (docs: :doc:`/casefiles`).
    msd : MSDModel, optional
        The MSD of the HSI model (default :func:`design_msd`: the case's own).
    msd_source : str, optional
        Where ``msd`` comes from, for the results (given with ``msd``).

    Returns
    -------
    CaseCheck
        Every code of ``design.codes`` checked by :func:`crowdvib.design.design_check` (no HSI,
        added mass, and HSI), with the ``[design.damper]`` if any, and the crowd stream predicted
        by :func:`crowdvib.design.predict_response` if ``design.prediction``.
    """
    import time

    check_design_table(case)
    if msd is None:
        msd, msd_source = design_msd(case)
    spec = case.design
    started = time.perf_counter()
    dampers = _dampers(case, spec, msd)
    checks = {code: _check(case, spec, code, msd, dampers) for code in spec.codes}
    prediction = None
    if spec.prediction:
        from ..design.stochastic import predict_response

        crowd = case.crowd if spec.density is None else case.crowd.with_density(spec.density)
        prediction = predict_response(case.structure, crowd, msd=msd, dampers=dampers,
                                      duration=spec.duration, weighting=spec.weighting,
                                      force=case.force)
    return CaseCheck(case, msd, msd_source, checks, dampers, prediction,
                     time.perf_counter() - started)


def _dampers(case, spec, msd):
    """The ``[design.damper]`` as a list (tuned to the occupied structure when HSI is on)."""
    from ..design import TunedMassDamper, tune_damper

    damper = spec.damper
    if damper is None:
        return []
    if "mode" in damper:
        if damper["mode"] > case.structure.n_modes:
            raise ParameterError(f"{case.path.name}: design.damper.mode must be at most the "
                                 f"number of modes ({case.structure.n_modes}), got "
                                 f"{damper['mode']}")
        crowd = case.crowd if msd is not None else None
        return [tune_damper(case.structure, damper["mode"] - 1, damper["mass_ratio"],
                            crowd=crowd, msd=msd)]
    return [TunedMassDamper(**damper)]


def _check(case, spec, code, msd, dampers):
    from ..design import design_check

    traffic_class = spec.classes.get(code)
    density = spec.density
    if traffic_class is None and density is None:
        density = case.crowd.density            # no class: the case's own crowd
    options = {}
    if code == "ukna":
        options = {"site_factors": spec.site_factors, "weighting": spec.weighting}
    elif code in ("setra", "hivoss"):
        options = {"comfort_class": spec.comfort_class}
    return design_check(case.structure, code, traffic_class=traffic_class, density=density,
                        crowd=case.crowd, msd=msd, dampers=dampers, **options)


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
    from ..design.codes import comfort_class

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
