"""A year of comfort: hours a year in each comfort class, the probability that a 10-minute window
exceeds a limit, and when in the week it does, per model of the structure, with bands (docs:
theory, A year of comfort).

For every crowd state of a :class:`~crowdvib.comfort.Traffic` the 10-minute peak |a| has the law
of :func:`~crowdvib.comfort.measure.peak_cdf` (the spectral route). Its probability of lying in
comfort class k (Sétra/HiVoSS, :data:`crowdvib.design.codes.COMFORT_CLASSES`) times the state's
hours, summed over the states, gives the hours a year in class k; the classes partition the
peak's range, so the hours of the classes add up to the year's hours for every model.

The models are those of the design checks (:func:`crowdvib.design.check.structure_models`): no
HSI (the crowd as moving forces on the empty bridge), added mass, and with an MSD the identified
HSI; each without and, given dampers, with them. The response is computed at a grid of densities
(``n_densities``) and its spectral description interpolated between them: σ²/d, ν0, δ, the
running mean square's σ_r/σ² and ν_z, smooth in d.

Bands. ``msd_box`` (the box of f_h1 and ξ_h1 an estimate allows, with or without its modelling
bound: :func:`crowdvib.cases.msd_interval`) gives the HSI model at the box's corners as well: the
band is the range over the corners and the estimate. A season's traffic gives a second band:
its windows drawn again with replacement (``n_resamples`` times, from ``rng``), the central 95 %.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._estimators import DEFAULT_CROWD_MODEL
from .._validation import check_count, check_positive, check_type
from ..design.check import structure_models
from ..design.codes import COMFORT_CLASSES, EN1990_VERTICAL_LIMIT
from ..design.stochastic import frequency_grid
from ..errors import ParameterError
from ..models.crowd import Crowd
from ..models.damper import as_dampers
from ..models.pedestrian import MSDModel
from ..models.structure import ModalModel
from ..response.frequency_domain.fluctuation import spectral_model
from .measure import (PEAK_MODELS, WindowLaw, peak_cdf, peak_quantile, running_rms_quantile,
                      thin_crowd_density, window_law)
from .traffic import WEEK_HOURS, Traffic
from . import plots

__all__ = ["ComfortYear", "comfort_year", "MODEL_LABELS", "CLASS_NAMES", "CLASS_BOUNDS",
           "LIMITS", "QUANTILES", "response_table", "loudest_output"]

#: The models of the structure as tables and figures name them.
MODEL_LABELS = {"empty": "no HSI", "added_mass": "added mass", "hsi": "identified HSI"}
#: Comfort classes and their upper bounds of the peak [m/s²] (Sétra/HiVoSS).
CLASS_NAMES = tuple(name for name, _ in COMFORT_CLASSES)
CLASS_BOUNDS = tuple(bound for _, bound in COMFORT_CLASSES if np.isfinite(bound))
#: The limits [m/s²] whose probability of exceedance per window is given: the class bounds and
#: EN 1990's 0.7.
LIMITS = tuple(sorted(set(CLASS_BOUNDS) | {EN1990_VERTICAL_LIMIT}))
#: Quantiles of the window's peak and running RMS tabled per density.
QUANTILES = (0.5, 0.9, 0.99)
#: The band of a season's sampling: its central part.
_SAMPLING_LEVEL = 0.95


@dataclass(frozen=True, eq=False)
class ComfortYear:
    """A year of comfort (:func:`comfort_year`); JSON-ready through :meth:`to_dict`.

    Attributes
    ----------
    rows : tuple of dict
        One per model and damper: ``model``, ``label``, ``damper`` (bool), ``hours_per_class``
        {CL1…CL4: h}, ``hours_band_hsi`` and ``hours_band_sampling`` {class: [low, high]} or
        None, ``exceedance`` {limit: probability a window exceeds it}, ``exceedance_band_hsi``
        and ``exceedance_band_sampling`` {limit: [low, high]} or None, ``hours_above``
        {limit: h}, ``week_class`` (168 expected class numbers 1–4, or None).
    densities : tuple of float
        The densities of the response table [persons/m²].
    table : tuple of dict
        Per model, damper and density: the laws (``rms``, ``crossing_rate``, ``spread``) and
        the quantiles of the window's peak (``peak``) and running RMS (``running_rms``).
    settings : dict
        ``duration``, ``rms_window``, ``peak_model``, ``output``, ``crowd_model``,
        ``total_hours``, ``classes``, ``limits``, ``quantiles``, ``msd``, ``msd_box``,
        ``n_resamples``, the traffic's ``source``, ``filled`` hours and ``unmeasured`` rule.
    """

    rows: tuple
    densities: tuple
    table: tuple
    settings: dict = field(default_factory=dict)

    def __eq__(self, other):
        if not isinstance(other, ComfortYear):
            return NotImplemented
        return self.to_dict() == other.to_dict()

    def to_dict(self) -> dict:
        """JSON-ready (lists and plain numbers)."""
        return {"rows": [dict(row) for row in self.rows], "densities": list(self.densities),
                "table": [dict(row) for row in self.table], "settings": dict(self.settings)}

    @classmethod
    def from_dict(cls, data: dict) -> ComfortYear:
        """The year of :meth:`to_dict`.

        Parameters
        ----------
        data : dict
        """
        return cls(tuple(data["rows"]), tuple(data["densities"]), tuple(data["table"]),
                   dict(data["settings"]))

    def row(self, model: str, damper: bool = False) -> dict:
        """The row of a model, without or with the dampers.

        Parameters
        ----------
        model : {"empty", "added_mass", "hsi"}
        damper : bool
        """
        for row in self.rows:
            if row["model"] == model and row["damper"] == damper:
                return row
        raise ParameterError(f"no row for model {model!r} with damper={damper}: the rows are "
                             f"{[(r['model'], r['damper']) for r in self.rows]}")

    def plot(self, kind: str = "hours", **options: Any):
        """A figure (:mod:`crowdvib.comfort.plots`): ``"hours"`` per class as stacked bars,
        ``"exceedance"`` against density, ``"week"`` the heat map of the expected class,
        ``"peaks"`` the window's peak quantiles against density.

        Parameters
        ----------
        kind : {"hours", "exceedance", "week", "peaks"}
        **options
            The keywords of the figure's function (``axes``, ``title``, …).
        """

        functions = {"hours": plots.plot_class_hours, "exceedance": plots.plot_exceedance,
                     "week": plots.plot_week, "peaks": plots.plot_peaks}
        if kind not in functions:
            raise ParameterError(f"kind must be one of {list(functions)}, got {kind!r}")
        return functions[kind](self.to_dict(), **options)


# ------------------------------------------------------------------------------ response
def _variants(dampers):
    return [(False, [])] + ([(True, dampers)] if dampers else [])


def response_table(structure: ModalModel, crowd: Crowd, densities: np.ndarray, *,
                   msds: Sequence[MSDModel] = (), dampers: Sequence = (), output: int = 0,
                   rms_window: float = 1.0, crowd_model: str = DEFAULT_CROWD_MODEL,
                   force=None) -> dict:
    """The :class:`WindowLaw` of every model at every density (> 0).

    One spectral model of the empty bridge per density and damper gives no HSI (``msd=None``)
    and the HSI of every MSD of ``msds``; one of the added-mass bridge gives added mass
    (:func:`crowdvib.response.frequency_domain.fluctuation.spectral_model`, the PSD of
    :func:`crowdvib.response_psd`).

    Parameters
    ----------
    structure, crowd
        The empty bridge and the walkers (each density replaces the crowd's).
    densities : ndarray
        [persons/m²], > 0.
    msds : sequence of MSDModel
        The MSDs of the "hsi" model (the estimate, then the corners of its box).
    dampers : sequence of TunedMassDamper
        Every model again with them.
    output : int
        Index of the output judged.
    rms_window : float
        τ of the running RMS [s].
    crowd_model : {"fluctuating", "smeared"}
    force : ForceModel, optional

    Returns
    -------
    dict
        ``(model, damper, msd index or None)`` → list of WindowLaw, one per density.
    """
    top_msd = max(msds, key=lambda m: m.frequency) if msds else None
    found: dict = {}
    for damper, tmds in _variants(list(dampers)):
        grid = frequency_grid(structure, crowd, top_msd, tmds)
        for density in densities:
            here = crowd.with_density(float(density))
            added = structure_models(structure, here, float(density), None)["added_mass"][0]
            options = {"crowd_model": crowd_model, "force": force, "dampers": tmds}
            base = spectral_model(structure, here, grid, **options)
            name = base.output_names[output]
            heavy = spectral_model(added, here, grid, **options)
            at = base.output_names.index(name)
            psds = {("empty", damper, None): base.psd_array(None)[at],
                    ("added_mass", damper, None): heavy.psd_array(None)[at]}
            for index, msd in enumerate(msds):
                psds[("hsi", damper, index)] = base.psd_array(msd)[at]
            for key, psd in psds.items():
                found.setdefault(key, []).append(
                    window_law(base.frequency, psd, rms_window=rms_window))
    return found


def _interpolator(grid, laws):
    """Laws at any density by linear interpolation of smooth ratios (σ²/d, ν0, δ, σ_r/σ², ν_z)."""
    table = np.array([[law.rms**2 / d, law.crossing_rate, law.spread,
                       law.ms_std / law.rms**2 if law.rms else 0.0, law.ms_rate]
                      for d, law in zip(grid, laws)])

    def at(density):
        density = np.asarray(density, float)
        values = [np.interp(density, grid, column) for column in table.T]
        rms = np.sqrt(values[0] * density)
        return rms, values[1], values[2], values[3] * rms**2, values[4]
    return at


def _class_probabilities(rms, rate, spread, duration, peak_model):
    """P(class k) per state, shape (n_states, 4): differences of the peak's CDF at the bounds."""
    cdf = np.stack([peak_cdf(bound, rms, rate, spread, duration, peak_model)
                    for bound in CLASS_BOUNDS], axis=-1)
    cdf = np.concatenate([np.zeros(cdf.shape[:-1] + (1,)), cdf,
                          np.ones(cdf.shape[:-1] + (1,))], axis=-1)
    return np.diff(cdf, axis=-1)


def _year(traffic, at, duration, peak_model, simulated=None):
    """Hours per class (4,), exceedance probability per limit, hours above each limit, and
    the expected class per hour of the week (168,) or None.

    ``simulated`` = (SimulatedWindows, density below which they stand in for the spectral law):
    a state there takes the fractions of the windows simulated at the nearest density."""
    rms, rate, spread, _, _ = at(traffic.density)
    probabilities = _class_probabilities(rms, rate, spread, duration, peak_model)
    exceed = np.stack([1 - peak_cdf(limit, rms, rate, spread, duration, peak_model)
                       for limit in LIMITS], axis=-1)
    if simulated is not None:
        windows, below = simulated
        grid = np.array(windows.densities)
        for i in np.flatnonzero((traffic.density > 0) & (traffic.density < below)):
            peaks = windows.peak[int(np.argmin(np.abs(grid - traffic.density[i])))]
            cdf = [np.mean(peaks <= bound) for bound in CLASS_BOUNDS]
            probabilities[i] = np.diff([0.0, *cdf, 1.0])
            exceed[i] = [np.mean(peaks > limit) for limit in LIMITS]
    hours = traffic.hours @ probabilities
    above = traffic.hours @ exceed
    week = None
    if traffic.has_week:
        expected = probabilities @ np.arange(1, len(CLASS_NAMES) + 1)
        total = np.zeros(WEEK_HOURS)
        weighted = np.zeros(WEEK_HOURS)
        np.add.at(total, traffic.cell, traffic.hours)
        np.add.at(weighted, traffic.cell, traffic.hours * expected)
        week = np.where(total > 0, weighted / np.where(total > 0, total, 1.0), np.nan)
    return hours, above / traffic.total_hours, above, week


def _named(values, names):
    return {str(name): float(value) for name, value in zip(names, values)}


def _band(samples, names):
    return {str(name): [float(low), float(high)]
            for name, low, high in zip(names, samples.min(axis=0), samples.max(axis=0))}


def _limit_names():
    return [f"{limit:g}" for limit in LIMITS]


# ------------------------------------------------------------------------------ the year
def comfort_year(structure: ModalModel, crowd: Crowd, traffic: Traffic, *,
                 msd: MSDModel | None = None, msd_box: dict | None = None,
                 dampers: Sequence | None = None, duration: float = 600.0,
                 rms_window: float = 1.0, peak_model: str = "vanmarcke",
                 output: str | None = None, crowd_model: str = DEFAULT_CROWD_MODEL,
                 force=None, n_densities: int = 12, n_resamples: int = 200,
                 rng=None, simulated: dict | None = None,
                 simulate_below: float = 0.0) -> ComfortYear:
    """Hours a year per comfort class, exceedance probabilities and the week's map, per model.

    Parameters
    ----------
    structure : ModalModel
        The empty bridge.
    crowd : Crowd
        The walkers' speed, step frequencies and body mass (its density is the traffic's).
    traffic : Traffic
        The year's crowd states.
    msd : MSDModel, optional
        The identified MSD: adds the "hsi" model.
    msd_box : dict, optional
        ``frequency`` and ``damping_ratio`` [low, high] (with ``msd``): the HSI band.
    dampers : sequence of TunedMassDamper, optional
        Every model again with them.
    duration : float
        The window T [s] (default 10 minutes).
    rms_window : float
        τ of the running RMS [s].
    peak_model : {"vanmarcke", "davenport"}
        The law of the window's peak (:mod:`crowdvib.comfort.measure`).
    output : str, optional
        The output point judged (default: the one with the largest no-HSI RMS at the traffic's
        largest density).
    crowd_model : {"fluctuating", "smeared"}
        The expected PSD (:func:`crowdvib.response_psd`).
    force : ForceModel, optional
        The walking force (default Živanović 2007).
    n_densities : int
        Densities of the response table (between the traffic's smallest and largest > 0).
    n_resamples : int
        Resamples of a season's windows for its sampling band (0: none).
    rng : None, int or numpy.random.Generator
        Seeds the resampling.
    simulated : dict, optional
        ``(model, damper)`` → :class:`~crowdvib.comfort.simulated.SimulatedWindows` of that
        model (the estimate's MSD for "hsi"): below ``simulate_below`` their windows stand in
        for the spectral law, where the response is not Gaussian (the densities
        :func:`~crowdvib.comfort.simulated.simulated_check` names).
    simulate_below : float
        [persons/m²]; 0: the spectral route everywhere. ``crowdvib comfort`` simulates by
        default below :func:`~crowdvib.comfort.measure.thin_crowd_density` (fewer than 100
        effective walkers on the walkway); the year's settings name that density and the hours
        of the states below it left to the spectral route (``spectral_thin_hours``).

    Returns
    -------
    ComfortYear
    """
    check_type("structure", structure, ModalModel)
    check_type("crowd", crowd, Crowd).check_stationary("comfort_year")
    check_type("traffic", traffic, Traffic)
    if msd is not None:
        check_type("msd", msd, MSDModel)
    if msd_box is not None and msd is None:
        raise ParameterError("msd_box needs msd (the box is around the estimate)")
    duration = check_positive("duration", duration, unit="s")
    rms_window = check_positive("rms_window", rms_window, unit="s")
    if peak_model not in PEAK_MODELS:
        raise ParameterError(f"peak_model must be one of {list(PEAK_MODELS)}, got "
                             f"{peak_model!r}")
    n_densities = check_count("n_densities", n_densities, minimum=2)
    n_resamples = check_count("n_resamples", n_resamples)
    dampers = as_dampers(dampers)
    positive = traffic.density[traffic.density > 0]
    if positive.size == 0:
        raise ParameterError("traffic has no crowd on the deck in any state (every density 0): "
                             "nothing to judge")
    grid = _density_grid(positive, n_densities)
    index = structure.output_index([output])[0] if output is not None else \
        loudest_output(structure, crowd, grid[-1], crowd_model, force)
    msds = [] if msd is None else [msd] + _corners(msd, msd_box)
    laws = response_table(structure, crowd, grid, msds=msds, dampers=dampers, output=index,
                          rms_window=rms_window, crowd_model=crowd_model, force=force)
    streams = np.random.default_rng(rng)
    resampled = ([traffic.resample(streams) for _ in range(n_resamples)]
                 if traffic.source == "season" and n_resamples else [])
    rows, table = [], []
    for (model, damper, which), found in laws.items():
        if which not in (None, 0):
            continue                                # a corner of the box: in the band only
        at = _interpolator(grid, found)
        stand_in = (simulated or {}).get((model, damper))
        stand_in = None if stand_in is None or not simulate_below else (stand_in,
                                                                        simulate_below)
        hours, exceed, above, week = _year(traffic, at, duration, peak_model, stand_in)
        row = {"model": model, "label": MODEL_LABELS[model], "damper": damper,
               "hours_per_class": _named(hours, CLASS_NAMES),
               "exceedance": _named(exceed, _limit_names()),
               "hours_above": _named(above, _limit_names()),
               "week_class": None if week is None else [None if np.isnan(v) else float(v)
                                                        for v in week],
               "hours_band_hsi": None, "exceedance_band_hsi": None,
               "hours_band_sampling": None, "exceedance_band_sampling": None}
        if model == "hsi" and len(msds) > 1:
            years = [_year(traffic, _interpolator(grid, laws[(model, damper, k)]), duration,
                           peak_model) for k in range(len(msds))]
            row["hours_band_hsi"] = _band(np.array([y[0] for y in years]), CLASS_NAMES)
            row["exceedance_band_hsi"] = _band(np.array([y[1] for y in years]),
                                               _limit_names())
        if resampled:
            years = [_year(sample, at, duration, peak_model, stand_in) for sample in resampled]
            tail = (1 - _SAMPLING_LEVEL) / 2
            for key, column, names in (("hours_band_sampling", 0, CLASS_NAMES),
                                       ("exceedance_band_sampling", 1, _limit_names())):
                values = np.array([y[column] for y in years])
                ends = np.quantile(values, [tail, 1 - tail], axis=0)
                row[key] = {str(n): [float(lo), float(hi)]
                            for n, lo, hi in zip(names, *ends)}
        rows.append(row)
        for density, law in zip(grid, found):
            table.append({"model": model, "damper": damper, "density": float(density),
                          **_quantiles(law, duration, peak_model)})
    settings = {"duration": duration, "rms_window": rms_window, "peak_model": peak_model,
                "output": structure.output_names[index], "crowd_model": crowd_model,
                "total_hours": traffic.total_hours,
                "classes": [[name, None if not np.isfinite(bound) else float(bound)]
                            for name, bound in COMFORT_CLASSES],
                "limits": list(LIMITS), "quantiles": list(QUANTILES),
                "msd": None if msd is None else msd.to_dict(),
                "msd_box": None if msd_box is None else {k: list(map(float, msd_box[k]))
                                                         for k in ("frequency",
                                                                   "damping_ratio")},
                "n_resamples": len(resampled), "traffic_source": traffic.source,
                "filled_hours": list(traffic.filled), "unmeasured": traffic.unmeasured,
                "week_hours": traffic.week_hours().tolist() if traffic.has_week else None,
                "dampers": [d.to_dict() for d in dampers],
                "simulate_below": float(simulate_below) if simulated else 0.0,
                "simulated_rows": sorted([m, bool(d)] for m, d in (simulated or {})),
                **_thin_crowd(structure, traffic, simulate_below if simulated else 0.0)}
    return ComfortYear(tuple(rows), tuple(float(d) for d in grid), tuple(table), settings)


def _thin_crowd(structure, traffic, simulate_below):
    """The thin crowd's density (:func:`~crowdvib.comfort.measure.thin_crowd_density`) and the
    hours a year of the states below it that the no-HSI and HSI rows judge by the spectral
    route all the same (its upper quantiles read low there: docs, Where the Gaussian model
    holds)."""
    thin = thin_crowd_density(structure)
    spectral = (traffic.density > 0) & (traffic.density < thin) & \
        (traffic.density >= simulate_below)
    return {"thin_crowd_density": float(thin),
            "spectral_thin_hours": float(traffic.hours[spectral].sum())}


def _quantiles(law: WindowLaw, duration, peak_model):
    q = np.array(QUANTILES)
    return {"rms": law.rms, "crossing_rate": law.crossing_rate, "spread": law.spread,
            "peak": peak_quantile(q, law, duration, peak_model).tolist(),
            "running_rms": running_rms_quantile(q, law, duration).tolist()}


def _density_grid(positive, count):
    """``count`` densities from the smallest to the largest > 0 (geometric over a wide span)."""
    low, high = float(positive.min()), float(positive.max())
    if high <= low * (1 + 1e-9):
        return np.array([low])
    if high > 4 * low:
        return np.geomspace(low, high, count)
    return np.linspace(low, high, count)


def _corners(msd, box):
    """The MSDs at the four corners of the box of f_h1 and ξ_h1 (μ_h1 held)."""
    if box is None:
        return []
    return [MSDModel(f, xi, msd.mass_ratio) for f in box["frequency"]
            for xi in box["damping_ratio"]]


def loudest_output(structure, crowd, density, crowd_model=DEFAULT_CROWD_MODEL, force=None):
    """Index of the output with the largest no-HSI RMS at ``density``.

    Parameters
    ----------
    structure : ModalModel
    crowd : Crowd
    density : float
        [persons/m²], > 0.
    crowd_model : {"fluctuating", "smeared"}
    force : ForceModel, optional
    """
    if structure.n_outputs == 1:
        return 0
    here = crowd.with_density(float(density))
    grid = frequency_grid(structure, here, None, [])
    psd = spectral_model(structure, here, grid, crowd_model=crowd_model,
                         force=force).psd_array(None)
    return int(np.argmax(np.trapezoid(psd, grid, axis=-1)))
