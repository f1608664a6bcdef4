"""``crowdvib comfort``'s work on a case: a year of comfort from the case's bridge and crowd, a
traffic (a season's windows, or a design table or daily profile) and the identified MSD with its
interval (issue 37; docs: theory, A year of comfort)."""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .._version import __version__
from ..errors import DataError, DataWarning, ParameterError
from .results import AsResults, software_versions
from .schema import schema_header
from ..comfort import Traffic
from ..io.casecomfort import TrafficSpec, read_traffic_table
from ..design import tune_damper
from ..response.frequency_domain.fluctuation import dominant_mode
from .design import _dampers
from ..comfort import comfort_year
from .design import estimated_msd, msd_interval
from ..comfort.measure import thin_crowd_density
from ..comfort import loudest_output
from ..comfort.simulated import simulated_windows
from ..io.casecomfort import ComfortSpec

if TYPE_CHECKING:
    from ..comfort.traffic import Traffic
    from ..comfort.year import ComfortYear
    from ..io.casefile import Case
    from ..models.pedestrian import MSDModel

__all__ = ["CaseComfort", "comfort_case", "case_traffic", "comfort_dampers", "COMFORT_TABLES",
           "simulate_below"]

#: The case tables ``crowdvib comfort`` reads; its results and report show no others.
COMFORT_TABLES = ("structure", "crowd", "hsi", "design", "comfort", "traffic")


@dataclass(frozen=True)
class CaseComfort(AsResults):
    """What ``crowdvib comfort`` computes for a case (:func:`comfort_case`).

    Attributes
    ----------
    case : Case
    year : ComfortYear
    traffic : Traffic
    traffic_from : str
        Where the traffic comes from (the season's folder, a file, the case's ``[traffic]``).
    msd : MSDModel or None
    msd_source : str or None
    msd_box : dict or None
        The box of f_h1 and ξ_h1 carried (:func:`~crowdvib.cases.msd_interval`).
    dampers : list of TunedMassDamper
    seconds : float
        CPU time of the year [s].
    """

    case: Case
    year: ComfortYear
    traffic: Traffic
    traffic_from: str
    msd: MSDModel | None
    msd_source: str | None
    msd_box: dict | None
    dampers: list
    seconds: float

    def to_dict(self) -> dict:
        """The results ``crowdvib comfort`` writes to results.json (kind ``"comfort"``), without
        its figures, warnings and provenance."""
        case = self.case
        return {**schema_header("comfort"), "command": "comfort",
                "crowdvib_version": __version__, "versions": software_versions(),
                "seed": case.seed, "case": None if case.path is None else str(case.path),
                "inputs": case.inputs(COMFORT_TABLES), "traffic_from": self.traffic_from,
                "msd": None if self.msd is None else self.msd.to_dict(),
                "msd_source": self.msd_source, "msd_interval": self.msd_box,
                "comfort": self.year.to_dict(), "traffic": self.traffic.to_dict(),
                "seconds": self.seconds}


def case_traffic(case: Case, *, season: dict | None = None, traffic=None):
    """The traffic of a run: a season's windows, a traffic CSV or spec, or the case's
    ``[traffic]`` → (:class:`~crowdvib.comfort.Traffic`, where it comes from).

    Parameters
    ----------
    case : Case
    season : dict, optional
        A ``crowdvib season`` results.json.
    traffic : Traffic, TrafficSpec, str or pathlib.Path, optional
        A traffic, or a traffic CSV (:func:`crowdvib.io.casecomfort.read_traffic_table`).
    """
    from pathlib import Path


    spec = case.comfort
    if season is not None and traffic is not None:
        raise ParameterError("give the traffic by season or by traffic, not both")
    if season is not None:
        return (Traffic.from_season(season, unmeasured=spec.unmeasured if spec else "hour",
                                    area=case.structure.area), "the season's windows")
    if traffic is None:
        if case.traffic is None:
            raise ParameterError(f"{_name(case)}: no traffic: give a season (--season), a "
                                 "traffic CSV (--traffic) or a [traffic] table in the case")
        traffic, where = case.traffic, "the case's [traffic]"
    else:
        where = None
    if isinstance(traffic, Traffic):
        return traffic, where or "the traffic given"
    if isinstance(traffic, (str, Path)):
        traffic, where = read_traffic_table(traffic), f"the traffic table {Path(traffic).name}"
    if not isinstance(traffic, TrafficSpec):
        raise ParameterError(f"traffic must be a Traffic, a TrafficSpec or a CSV path, got "
                             f"{type(traffic).__name__}")
    if traffic.kind == "profile":
        return Traffic.from_profile(traffic.density, days=traffic.days), where
    return (Traffic.from_table(traffic.density, traffic.hours_per_year,
                               year_hours=traffic.year_hours), where)


def comfort_dampers(case: Case, msd) -> list:
    """The dampers of the "with damper" rows: the case's ``[design.damper]`` if any, else one of
    ``[comfort] damper_mass_ratio`` (default 2 %) tuned (Asami et al.) at the antinode of the
    mode with the largest resonant response, to the occupied mode with the MSD; none for 0.

    Parameters
    ----------
    case : Case
    msd : MSDModel or None
        The identified MSD (the damper is tuned to the occupied mode with it).
    """

    if case.design is not None and case.design.damper is not None:
        return _dampers(case, case.design, msd)
    ratio = case.comfort.damper_mass_ratio if case.comfort is not None else 0.02
    if not ratio:
        return []
    import numpy as np

    grid = np.linspace(0.0, 1.5 * case.structure.frequencies.max(), 2001)
    mode = dominant_mode(case.structure, case.stationary_crowd(), grid)
    crowd = case.stationary_crowd() if msd is not None else None
    return [tune_damper(case.structure, mode, ratio, crowd=crowd, msd=msd)]


def comfort_case(case: Case, *, season: dict | None = None, traffic=None,
                 msd_results: dict | None = None, msd_source: str | None = None,
                 rng=None, executor=None) -> CaseComfort:
    """Run ``crowdvib comfort`` on a case, without writing anything.

    Parameters
    ----------
    case : Case
        The bridge, the crowd's other properties, ``[comfort]`` (optional) and ``[traffic]``
        (unless ``season`` or ``traffic`` is given).
    season : dict, optional
        A ``crowdvib season`` results.json: its windows are the traffic, and its joint estimate
        the MSD unless ``msd_results`` is given.
    traffic : Traffic, TrafficSpec or path, optional
        The traffic instead (:func:`case_traffic`).
    msd_results : dict, optional
        The results.json of ``crowdvib estimate``, ``sensitivity`` or ``season``: its MSD and its
        interval (with ``sensitivity``, widened by the modelling bound) make the HSI row and band.
    msd_source : str, optional
        What ``msd_results`` is, for the results.
    rng : None, int or numpy.random.Generator
        Seeds the resampling of a season's windows (default the case's seed).
    executor : concurrent.futures.Executor, optional
        Where the windows of ``[comfort] simulate_below`` are simulated
        (:func:`crowdvib.runner.study_executor`); default this process.

    Returns
    -------
    CaseComfort
    """

    found, where = case_traffic(case, season=season, traffic=traffic)
    msd, box = case.msd, None
    msd_from = msd_results if msd_results is not None else season
    if msd_from is not None and isinstance(msd_from.get("estimate"), dict):
        msd = estimated_msd(case, msd_from, source=msd_source or "the MSD results")
        box = msd_interval(msd_from)
        msd_source = msd_source or ("the season's joint estimate" if msd_results is None
                                    else "the estimate")
    elif msd_results is not None:
        raise DataError(f"{msd_source or 'the MSD results'}: its results.json holds no MSD "
                        "estimate (estimate.frequency and estimate.damping_ratio)")
    else:
        if season is not None:
            warnings.warn("the season holds no joint estimate (its joint_error: "
                          f"{season.get('joint_error')}): the identified HSI row uses the case's "
                          "[hsi] MSD, without a band; give --msd-from an estimate", DataWarning,
                          stacklevel=2)
        msd_source = "[hsi]"
    spec = case.comfort
    options = {} if spec is None else {
        "duration": spec.duration, "rms_window": spec.rms_window,
        "peak_model": spec.peak_model, "output": spec.output,
        "n_densities": spec.densities, "n_resamples": spec.resamples,
        **({"crowd_model": spec.crowd_model} if spec.crowd_model else {})}
    started = time.process_time()
    dampers = comfort_dampers(case, msd)
    below = simulate_below(case)
    if below > 0:
        options.update(simulate_below=below,
                       simulated=_simulated(case, found, msd, dampers, below, executor))
    year = comfort_year(case.structure, case.stationary_crowd(), found, msd=msd, msd_box=box,
                        dampers=dampers, force=case.force,
                        rng=case.seed if rng is None else rng, **options)
    return CaseComfort(case, year, found, where, msd, msd_source, box, dampers,
                       time.process_time() - started)


#: Densities simulated below ``simulate_below`` (geometric between the lowest and the highest
#: there): the nearest stands in for each state.
_SIMULATED_DENSITIES = 3


def simulate_below(case) -> float:
    """The density [persons/m²] below which simulated windows stand in for the spectral route:
    ``[comfort] simulate_below``, by default that of a thin crowd
    (:func:`crowdvib.comfort.measure.thin_crowd_density`: fewer than 100 effective walkers on
    the walkway; docs: theory, A year of comfort); 0 switches it off."""

    spec = case.comfort
    if spec is None or spec.simulate_below is None:
        return thin_crowd_density(case.structure)
    return spec.simulate_below


def _simulated(case, traffic, msd, dampers, bound, executor):
    """The simulated windows of the no-HSI and HSI rows (each without and with the dampers) at
    the traffic's densities below ``bound`` (:func:`simulate_below`): (model, damper) → windows.

    The added-mass row stays spectral: its model has no walkers to simulate."""
    import numpy as np


    spec = case.comfort or ComfortSpec()
    below = traffic.density[(traffic.density > 0) & (traffic.density < bound)]
    if below.size == 0:
        return {}
    densities = np.unique(np.geomspace(below.min(), below.max(), _SIMULATED_DENSITIES)) \
        if below.max() > below.min() else below[:1]
    output = (case.structure.output_index([spec.output])[0] if spec.output is not None
              else loudest_output(case.structure, case.stationary_crowd(), traffic.density.max()))
    found = {}
    for model, model_msd in (("empty", None), ("hsi", msd)):
        if model == "hsi" and msd is None:
            continue
        for damper, tmds in ((False, []), (True, dampers)):
            if damper and not dampers:
                continue
            found[(model, damper)] = simulated_windows(
                case.structure, case.stationary_crowd(), densities, msd=model_msd, dampers=tmds,
                output=output, n_windows=spec.simulated_windows, duration=spec.duration,
                rms_window=spec.rms_window, seed=case.seed or 0, executor=executor)
    return found


def _name(case):
    return case.path.name if case.path is not None else case.name
