"""The inverse problem: MSD parameters from measured response PSDs (paper Eq. 5 and 6; physics.md §7).

J(θ) = Σ_l γ_l ‖G̃_l − G_l(θ)‖₂² / ‖G̃_l‖₂² over the analysis band, minimised by bounded
``scipy.optimize.least_squares(method="trf")`` from several starting points. The residual vector
r_{l,k} = sqrt(γ_l w_k) (G̃_l(f_k) − G_l(f_k; θ)) / ‖G̃_l‖₂ has Σ r² = J.
"""

import copy
import logging
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares

from .._validation import as_float_array, check_positive, check_type
from ..errors import (BoundWarning, ConvergenceWarning, EstimationError, ParameterError,
                      PlausibilityWarning)
from ..models.crowd import Crowd
from ..models.loading import STANDARD_GRAVITY
from ..models.pedestrian import MSDModel
from ..models.structure import ModalModel
from ..response.spectral import SpectralModel
from ..signals.spectrum import ResponsePSD

__all__ = ["estimate_hsi", "HSIEstimate", "PSDObjective", "DEFAULT_STARTS", "DEFAULT_BOUNDS"]

logger = logging.getLogger(__name__)

#: Starting points (f_h1 [Hz], ξ_h1 [-]) spread over the feasible region (physics.md §8.5).
DEFAULT_STARTS = ((1.5, 0.6), (5.0, 0.15), (2.2, 0.2), (4.0, 0.7))
#: Search bounds: f_h1 ≤ 10 Hz and ξ_h1 ≤ 100 % as in the paper; small positive lower bounds
#: stand for the strict inequalities f_h1 > 0, ξ_h1 > 0, 0 < μ_h1 < 1 (paper Eq. 5).
DEFAULT_BOUNDS = {"frequency": (1e-3, 10.0), "damping_ratio": (1e-3, 1.0),
                  "mass_ratio": (1e-3, 0.999)}
_PARAMETERS = ("frequency", "damping_ratio", "mass_ratio")
# A parameter within this fraction of its bound's range of the bound counts as on it.
_BOUND_TOLERANCE = 1e-4
#: Measured over modelled band variance beyond which (either way) the level itself is in doubt:
#: at a sound optimum the two agree within the Welch scatter and the modelling errors (a few
#: tens of per cent); a unit or gain mix-up is a factor of ~100 or more.
LEVEL_RATIO_LIMIT = 3.0
#: Unit mix-ups tried when the level is in doubt: factor on the measured PSD → likely cause.
_UNIT_MIXUPS = ((STANDARD_GRAVITY**2, "a record in g read as m/s²"),
                (STANDARD_GRAVITY**-2, "a record in m/s² declared as g"),
                (1e-6, "a record in mm/s² read as m/s²"),
                (1e6, "a record in m/s² declared as mm/s²"))


@dataclass(frozen=True, eq=False)
class HSIEstimate:
    """Result of :func:`crowdvib.estimate_hsi` (paper Eq. 5 and 6).

    Attributes
    ----------
    msd : MSDModel
        The estimated mass-spring-damper model (f_h1 [Hz], ξ_h1 [-], μ_h1 [-]).
    cost : float
        Objective J(θ̂) = Σ_l γ_l ‖G̃_l − G_l(θ̂)‖² / ‖G̃_l‖² [-] (paper Eq. 6).
    cost_no_hsi : float
        The same objective for the structure without HSI (crowd as moving forces only) [-].
    n_evaluations : int
        Forward-model evaluations over all starting points.
    success : bool
        Whether the best start converged (``least_squares`` status > 0).
    active_bounds : tuple of str
        Parameters of the optimum that sit on a bound, e.g. ``("damping_ratio:upper",)``.
    free_parameters : tuple of str
        The estimated parameters.
    bounds : dict
        Parameter → (lower, upper).
    band : tuple of float
        Analysis band [Hz].
    output_names : tuple of str
    output_weights : ndarray
        γ_l, normalised to sum 1.
    starts : tuple of dict
        Per starting point: ``start``, ``estimate``, ``cost``, ``n_evaluations``, ``status``.
    message : str
        The optimiser's message for the best start.
    level_ratio : ndarray
        Per output, measured over modelled variance in the band at the estimate [-]; far from 1
        (beyond a factor ``LEVEL_RATIO_LIMIT``) the level itself is wrong (units, gain, channel).
    """

    msd: object
    cost: float
    cost_no_hsi: float
    n_evaluations: int
    success: bool
    active_bounds: tuple
    free_parameters: tuple
    bounds: dict
    band: tuple
    output_names: tuple
    output_weights: np.ndarray
    starts: tuple = field(default=())
    message: str = ""
    level_ratio: np.ndarray = None

    @property
    def relative_cost(self):
        """J(θ̂)/J(no HSI) [-]: the paper's "residual relative to no HSI"."""
        return self.cost / self.cost_no_hsi if self.cost_no_hsi > 0 else np.nan

    def to_dict(self):
        """JSON-ready dict; the estimate sits under ``"estimate"``."""
        return {
            "estimate": self.msd.to_dict(),
            "cost": self.cost, "cost_no_hsi": self.cost_no_hsi,
            "relative_cost": self.relative_cost, "n_evaluations": self.n_evaluations,
            "success": self.success, "active_bounds": list(self.active_bounds),
            "free_parameters": list(self.free_parameters),
            "bounds": {k: list(v) for k, v in self.bounds.items()},
            "band": list(self.band), "output_names": list(self.output_names),
            "output_weights": np.asarray(self.output_weights).tolist(),
            "starts": [dict(s) for s in self.starts], "message": self.message,
            "level_ratio": None if self.level_ratio is None else
            np.asarray(self.level_ratio).tolist(),
        }


def _check_band(band, frequency):
    try:
        lower, upper = (float(b) for b in band)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"band must be a pair (lower, upper) in Hz, got {band!r}") from exc
    if not lower < upper:
        raise ParameterError(f"band must have lower < upper, got ({lower:g}, {upper:g}) Hz")
    if lower < frequency[0] - 1e-12 or upper > frequency[-1] + 1e-12:
        raise ParameterError(
            f"band must lie within the measured frequency grid [{frequency[0]:g}, "
            f"{frequency[-1]:g}] Hz, got ({lower:g}, {upper:g}) Hz")
    keep = (frequency >= lower) & (frequency <= upper)
    if keep.sum() < 3:
        raise ParameterError(
            f"band ({lower:g}, {upper:g}) Hz must hold at least 3 frequencies of the measured "
            f"grid, got {int(keep.sum())}")
    return (lower, upper), keep


def _normalised_weights(name, weights, size):
    if weights is None:
        return np.full(size, 1.0 / size)
    weights = as_float_array(name, weights, ndim=1)
    if weights.shape != (size,):
        raise ParameterError(f"{name} must have {size} entries, got {weights.size}")
    check_positive(name, weights)
    return weights / weights.sum()


class PSDObjective:
    """Residuals of paper Eq. (6) for a measured PSD and a spectral forward model.

    Parameters
    ----------
    measured : ResponsePSD
        Measured (or synthetic) PSDs, one row per output.
    structure, crowd, force
        The model assumed known.
    band : (float, float)
        Analysis band [Hz].
    outputs : sequence of str, optional
        Outputs used (default all of ``measured``); each must exist in ``structure``.
    output_weights : array_like, optional
        γ_l > 0, normalised to sum 1 (default equal).
    frequency_weights : callable or array_like, optional
        w(f) > 0 on the band frequencies (a function of f [Hz] or an array).
    match_welch : bool
        Model what a Welch estimate with the measured window length (and low-pass filter) sees
        (physics.md §3.4); only when ``measured.window_length`` is known.
    """

    def __init__(self, measured, structure, crowd, *, band, force=None, outputs=None,
                 output_weights=None, frequency_weights=None, match_welch=True):
        if not isinstance(measured, ResponsePSD):
            raise ParameterError(f"measured must be a ResponsePSD, got {type(measured).__name__}")
        measured.check_measured()
        check_type("structure", structure, ModalModel)
        check_type("crowd", crowd, Crowd)
        if crowd.density <= 0:
            raise ParameterError(
                f"crowd.density must be > 0 to estimate HSI (no crowd, no interaction), "
                f"got {crowd.density:g}")
        outputs = measured.output_names if outputs is None else tuple(
            [outputs] if isinstance(outputs, str) else outputs)
        structure.output_index(outputs)
        self.band, keep = _check_band(band, measured.frequency)
        self.frequency = measured.frequency[keep]
        self.target = measured.select(outputs).psd[:, keep]
        # Work on PSDs divided by each output's peak in the band: J is unchanged, and no square
        # over- or underflows whatever the level (a record in the wrong units reaches the
        # plausibility check below instead of a cost of 0 or inf).
        self.level = self.target.max(axis=1)
        for name, level in zip(outputs, self.level):
            if not level > 0:
                raise ParameterError(f"measured PSD of output {name!r} is zero over the band")
        self._target = self.target / self.level[:, np.newaxis]
        norms = np.linalg.norm(self._target, axis=1)
        self.output_names = outputs
        self.output_weights = _normalised_weights("output_weights", output_weights, len(outputs))
        if frequency_weights is None:
            w = np.ones(self.frequency.size)
        elif callable(frequency_weights):
            w = as_float_array("frequency_weights", frequency_weights(self.frequency), ndim=1)
        else:
            w = as_float_array("frequency_weights", frequency_weights, ndim=1)[keep]
        check_positive("frequency_weights", w)
        self._scale = (np.sqrt(self.output_weights)[:, np.newaxis] * np.sqrt(w)
                       / norms[:, np.newaxis])
        window = measured.window_length if match_welch else None
        lowpass = measured.lowpass if match_welch else None
        self._model_inputs = dict(structure=structure, force=force, outputs=outputs,
                                  welch_window_length=window, lowpass=lowpass)
        self.model = self.spectral_model(crowd)
        self.evaluations = 0

    def spectral_model(self, crowd):
        """The forward model on the band grid for another crowd (same structure, filter, window)."""
        inputs = dict(self._model_inputs)
        return SpectralModel(inputs.pop("structure"), crowd, self.frequency, **inputs)

    def residuals(self, msd, *, model=None):
        """Residual vector r (Σ r² = J) for an MSD model, or for no HSI with ``msd=None``.

        ``model`` replaces the objective's own forward model (e.g. one for another crowd).
        """
        self.evaluations += 1
        model = self.model if model is None else model
        modelled = model.psd_array(msd) / self.level[:, np.newaxis]
        return ((self._target - modelled) * self._scale).ravel()

    def level_ratio(self, msd):
        """Measured over modelled variance in the band, per output [-] (1 for a consistent level).

        ∫ G̃_l df / ∫ G_l(θ) df over the band: far from 1 at the optimum means the data and the
        model disagree on the level itself (units, gain, channel), which no MSD can fix.
        """
        modelled = self.model.psd_array(msd) / self.level[:, np.newaxis]
        with np.errstate(divide="ignore"):
            return self._target.sum(axis=1) / modelled.sum(axis=1)

    def cost(self, msd):
        """J(θ) of paper Eq. (6) [-]."""
        r = self.residuals(msd)
        return float(r @ r)


def estimate_hsi(measured, structure, crowd, *, band, outputs=None, output_weights=None,
                 frequency_weights=None, starts=None, bounds=None, mass_ratio=0.95,
                 free_mass_ratio=False, force=None, match_welch=True):
    """Estimate the pedestrians' MSD parameters from measured response PSDs (paper Eq. 5, 6).

    Parameters
    ----------
    measured : ResponsePSD
        Measured one-sided acceleration PSDs [(m/s²)²/Hz] at named outputs of ``structure``.
    structure : ModalModel
        Modal model of the empty footbridge (assumed known).
    crowd : Crowd
        Density, speed, step-frequency distribution and body mass (assumed known), density > 0.
    band : (float, float)
        Analysis band [Hz] inside the measured frequency grid (the paper: 0–10 Hz for the
        numerical example, 2.5–8 Hz for Eeklo, 2–6 Hz for Waalse Krook).
    outputs : sequence of str, optional
        Outputs to fit (default all outputs in ``measured``).
    output_weights : array_like, optional
        γ_l > 0 per output, normalised to sum 1 (paper Eq. 6).
    frequency_weights : callable or array_like, optional
        Frequency weight w(f) > 0 (the paper's γ_ω).
    starts : sequence of tuple, optional
        Starting points (f_h1, ξ_h1) or (f_h1, ξ_h1, μ_h1); default four spread points
        (physics.md §8.5). Points outside the bounds are moved just inside.
    bounds : dict, optional
        Parameter → (lower, upper); defaults f_h1 ∈ [0.001, 10] Hz, ξ_h1 ∈ [0.001, 1],
        μ_h1 ∈ [0.001, 0.999] (paper: upper bounds of 10 Hz and 100 %).
    mass_ratio : float
        μ_h1 when it is held fixed (paper: 0.95).
    free_mass_ratio : bool
        Estimate μ_h1 too.
    force : ZivanovicForce or YoungForce, optional
        Walking force model (default Živanović 2007).
    match_welch : bool
        Compare with what a Welch estimate of the measured window length would see (default).

    Returns
    -------
    HSIEstimate
        The best of the starts; ``HSIEstimate.msd`` is the estimated :class:`MSDModel`.

    Warns
    -----
    BoundWarning
        When the optimum sits on a bound.
    ConvergenceWarning
        When no start converged.
    """
    MSDModel(mass_ratio=mass_ratio)  # validates mass_ratio with the model's own rule
    objective = PSDObjective(measured, structure, crowd, band=band, force=force,
                             outputs=outputs, output_weights=output_weights,
                             frequency_weights=frequency_weights, match_welch=match_welch)
    for note in structure.implausibilities():
        warnings.warn(f"structure: {note}", PlausibilityWarning, stacklevel=2)
    names = _PARAMETERS if free_mass_ratio else _PARAMETERS[:2]
    limits = _merge_bounds(bounds, DEFAULT_BOUNDS)
    if limits["mass_ratio"][1] >= 1:
        raise ParameterError(f"bounds['mass_ratio'] must stay below 1, got {limits['mass_ratio']}")
    lower = np.array([limits[n][0] for n in names])
    upper = np.array([limits[n][1] for n in names])

    def to_msd(theta):
        values = dict(zip(names, theta))
        return MSDModel(frequency=values["frequency"], damping_ratio=values["damping_ratio"],
                        mass_ratio=values.get("mass_ratio", mass_ratio))

    points = _starting_points(starts, names, mass_ratio, lower, upper)

    def fit(objective):
        return _multistart(lambda theta: objective.residuals(to_msd(theta)), points, lower, upper,
                           objective)

    absurd = objective.level_ratio(None)
    if np.any(~((absurd > 1e-100) & (absurd < 1e100))):
        raise ParameterError(
            "measured PSD level must be within a factor 1e100 of the model's without HSI over the "
            f"band (no unit or gain mix-up goes further), got measured/model variance "
            f"{', '.join(f'{v:.3g}' for v in absurd)} for outputs {list(objective.output_names)}")
    best, runs = fit(objective)
    msd = to_msd(best.x)
    active, success, table = _diagnose(best, runs, names, lower, upper,
                                       "the optimum sits on a bound", "check the model inputs")
    level_ratio = objective.level_ratio(msd)
    _check_level(objective, level_ratio, 2 * best.cost, fit, to_msd)
    return HSIEstimate(
        msd=msd, cost=float(2 * best.cost), cost_no_hsi=objective.cost(None),
        n_evaluations=sum(n for _, _, n in runs), success=success, active_bounds=active,
        free_parameters=names, bounds={n: (float(lo), float(hi)) for n, lo, hi in
                                       zip(names, lower, upper)},
        band=objective.band, output_names=objective.output_names,
        output_weights=objective.output_weights, starts=table, message=str(best.message),
        level_ratio=level_ratio)


def _check_level(objective, ratio, cost, fit, to_msd):
    """Warn when the measured level disagrees with the fitted model's, naming the likely cause.

    Each unit mix-up of ``_UNIT_MIXUPS`` is tried by fitting the rescaled data again; one that
    makes the level consistent and fits ten times better is named in the warning (the estimate itself is
    left as it is: the user must correct the input).
    """
    off = (ratio > LEVEL_RATIO_LIMIT) | (ratio < 1 / LEVEL_RATIO_LIMIT)
    if not off.any():
        return
    where = ", ".join(f"{name!r}: {value:.3g}" for name, value, bad in
                      zip(objective.output_names, ratio, off) if bad)
    hint = "check the units, the sensor gain and the channel mapping"
    found = []
    for factor, cause in _UNIT_MIXUPS:
        rescaled = copy.copy(objective)
        rescaled.level = objective.level * factor
        best, _ = fit(rescaled)
        msd = to_msd(best.x)
        ratios = rescaled.level_ratio(msd)
        if np.all((ratios <= LEVEL_RATIO_LIMIT) & (ratios >= 1 / LEVEL_RATIO_LIMIT)):
            found.append((2 * best.cost, cause, msd))
    if found:
        rescaled_cost, cause, msd = min(found, key=lambda item: item[0])
        # Named only when it explains the data: a consistent level AND a fit ten times better
        # (a mere gain error can come within the level limit after a wrong rescaling).
        if rescaled_cost < 0.1 * cost:
            hint = (f"{cause}? Rescaled so, the data fit with J = {rescaled_cost:.3g} instead of "
                    f"{cost:.3g} and give f_h1 = {msd.frequency:.3g} Hz, "
                    f"ξ_h1 = {msd.damping_ratio:.3g}")
    warnings.warn(
        f"the measured PSD level over the band is not the fitted model's (measured/model "
        f"variance {where}; a consistent level lies within a factor {LEVEL_RATIO_LIMIT:g}), so "
        f"the estimate is not to be trusted: {hint}", PlausibilityWarning, stacklevel=3)


def _merge_bounds(bounds, defaults):
    """The default bounds updated by the user's, each checked: 0 < lower < upper."""
    limits = dict(defaults)
    for key, value in (bounds or {}).items():
        if key not in defaults:
            raise ParameterError(f"bounds keys must be among {list(defaults)}, got {key!r}")
        try:
            low, high = (float(v) for v in value)
        except (TypeError, ValueError):
            raise ParameterError(f"bounds[{key!r}] must be a pair (lower, upper), got {value!r}")
        if not 0 < low < high:
            raise ParameterError(f"bounds[{key!r}] must satisfy 0 < lower < upper, got {value!r}")
        limits[key] = (low, high)
    return limits


def _multistart(residuals, points, lower, upper, objective):
    """Bounded trust-region least squares from every start → (best result, runs).

    ``runs`` holds (result, start, forward-model evaluations) per start.
    """
    runs = []
    for start in points:
        evaluations_before = objective.evaluations
        try:
            result = least_squares(residuals, start, method="trf", bounds=(lower, upper),
                                   x_scale="jac")
        except ValueError as exc:  # non-finite residuals
            raise EstimationError(f"objective could not be evaluated from start {start}: {exc}")
        runs.append((result, start, objective.evaluations - evaluations_before))
        logger.info("start %s -> %s, J = %.4g", start, result.x, 2 * result.cost)
    best, _, _ = min(runs, key=lambda run: run[0].cost)
    return best, runs


def _diagnose(best, runs, names, lower, upper, what, hint):
    """Active bounds and convergence of the best run (warned about), and the per-start table.

    The warnings point at the caller of the public estimator (stacklevel 3).
    """
    span = upper - lower
    active = tuple(
        f"{name}:{side}" for name, x, lo, hi, width in zip(names, best.x, lower, upper, span)
        for side, hit in (("lower", x - lo <= _BOUND_TOLERANCE * width),
                          ("upper", hi - x <= _BOUND_TOLERANCE * width)) if hit)
    if active:
        warnings.warn(f"{what} ({', '.join(active)}): widen the bounds or {hint}", BoundWarning,
                      stacklevel=3)
    success = best.status > 0
    if not success:
        warnings.warn(f"least_squares did not converge: {best.message}", ConvergenceWarning,
                      stacklevel=3)
    table = tuple({"start": [float(v) for v in start], "estimate": [float(v) for v in r.x],
                   "cost": float(2 * r.cost), "n_evaluations": int(n), "status": int(r.status)}
                  for r, start, n in runs)
    return active, success, table


def _starting_points(starts, names, mass_ratio, lower, upper):
    """Starting points as arrays strictly inside the bounds (trf needs interior points)."""
    if starts is None:
        starts = [s + ((mass_ratio,) if len(names) == 3 else ()) for s in DEFAULT_STARTS]
    points = []
    for start in starts:
        start = as_float_array("starts", start, ndim=1)
        if start.size == 2 and len(names) == 3:
            start = np.append(start, mass_ratio)
        if start.size != len(names):
            raise ParameterError(
                f"starts must hold {len(names)} values {names}, got {start.tolist()}")
        margin = 1e-3 * (upper - lower)
        points.append(np.clip(start, lower + margin, upper - margin))
    if not points:
        raise ParameterError("starts must hold at least one starting point")
    return points
