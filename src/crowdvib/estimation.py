"""The inverse problem: MSD parameters from measured response PSDs (paper Eq. 5 and 6; physics.md §7).

J(θ) = Σ_l γ_l ‖G̃_l − G_l(θ)‖₂² / ‖G̃_l‖₂² over the analysis band, minimised by bounded
``scipy.optimize.least_squares(method="trf")`` from several starting points. The residual vector
r_{l,k} = sqrt(γ_l w_k) (G̃_l(f_k) − G_l(f_k; θ)) / ‖G̃_l‖₂ has Σ r² = J.
"""

import logging
import warnings
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import least_squares

from ._validation import as_float_array, check_positive
from .errors import BoundWarning, ConvergenceWarning, EstimationError, ParameterError
from .pedestrian import MSDModel
from .results import HSIEstimate, ResponsePSD
from .spectral import SpectralModel

__all__ = ["estimate_hsi", "DEFAULT_STARTS", "DEFAULT_BOUNDS", "estimate_step_frequencies",
           "StepFrequencyEstimate", "DEFAULT_STEP_FREQUENCY_BOUNDS"]

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
        norms = np.linalg.norm(self.target, axis=1)
        for name, norm in zip(outputs, norms):
            if norm == 0:
                raise ParameterError(f"measured PSD of output {name!r} is zero over the band")
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
        return ((self.target - model.psd_array(msd)) * self._scale).ravel()

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

    def residuals(theta):
        return objective.residuals(to_msd(theta))

    points = _starting_points(starts, names, mass_ratio, lower, upper)
    best, runs = _multistart(residuals, points, lower, upper, objective)
    msd = to_msd(best.x)
    active, success, table = _diagnose(best, runs, names, lower, upper,
                                       "the optimum sits on a bound", "check the model inputs")
    return HSIEstimate(
        msd=msd, cost=float(2 * best.cost), cost_no_hsi=objective.cost(None),
        n_evaluations=sum(n for _, _, n in runs), success=success, active_bounds=active,
        free_parameters=names, bounds={n: (float(lo), float(hi)) for n, lo, hi in
                                       zip(names, lower, upper)},
        band=objective.band, output_names=objective.output_names,
        output_weights=objective.output_weights, starts=table, message=str(best.message))


def _merge_bounds(bounds, defaults):
    """The default bounds updated by the user's, each checked: 0 < lower < upper."""
    limits = dict(defaults)
    for key, value in (bounds or {}).items():
        if key not in defaults:
            raise ParameterError(f"bounds keys must be among {list(defaults)}, got {key!r}")
        low, high = (float(v) for v in value)
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


# ----------------------------------------------------------------------------------------------
# The step-frequency distribution from the low band (paper, Waalse Krook; physics.md §7).

#: Search bounds of (μ_fs, σ_fs) [Hz]: normal walking lies well inside 1–3 Hz, and a spread below
#: 0.01 Hz or above 0.6 Hz is not a crowd (the paper's values are 0.13–0.19 Hz).
DEFAULT_STEP_FREQUENCY_BOUNDS = {"step_frequency_mean": (1.0, 3.0),
                                 "step_frequency_std": (0.01, 0.6)}
_STEP_PARAMETERS = ("step_frequency_mean", "step_frequency_std")


@dataclass(frozen=True, eq=False)
class StepFrequencyEstimate:
    """Result of :func:`estimate_step_frequencies`.

    Attributes
    ----------
    crowd : Crowd
        The input crowd with the fitted ``step_frequency_mean`` μ_fs and ``step_frequency_std``
        σ_fs [Hz].
    cost : float
        J(μ̂, σ̂) of paper Eq. (6) on the low-passed band [-].
    cost_initial : float
        J at the input crowd's (μ_fs, σ_fs) [-].
    n_evaluations : int
    success : bool
    active_bounds : tuple of str
    bounds : dict
        Parameter → (lower, upper) [Hz].
    band : tuple of float
        Fitted band [Hz].
    cutoff : float
        Low-pass cut-off [Hz] of the measured and modelled signals.
    output_names : tuple of str
    starts : tuple of dict
        Per start: ``start``, ``estimate``, ``cost``, ``n_evaluations``, ``status``.
    message : str
    """

    crowd: object
    cost: float
    cost_initial: float
    n_evaluations: int
    success: bool
    active_bounds: tuple
    bounds: dict
    band: tuple
    cutoff: float
    output_names: tuple
    starts: tuple = field(default=())
    message: str = ""

    def to_dict(self):
        """JSON-ready dict; the fitted distribution sits under ``"step_frequencies"``."""
        return {"step_frequencies": {"mean": self.crowd.step_frequency_mean,
                                     "std": self.crowd.step_frequency_std},
                "cost": self.cost, "cost_initial": self.cost_initial,
                "n_evaluations": self.n_evaluations, "success": self.success,
                "active_bounds": list(self.active_bounds),
                "bounds": {k: list(v) for k, v in self.bounds.items()}, "band": list(self.band),
                "cutoff": self.cutoff, "output_names": list(self.output_names),
                "starts": [dict(s) for s in self.starts], "message": self.message}


def estimate_step_frequencies(measured, structure, crowd, *, cutoff=2.3, band=None, starts=None,
                              bounds=None, outputs=None, output_weights=None, force=None,
                              match_welch=True):
    """Fit the crowd's step-frequency distribution N(μ_fs, σ_fs) to low-passed PSDs.

    The paper's procedure for the Waalse Krook bridge (physics.md §7): below the cut-off the
    response is the non-resonant first-harmonic content of the walking forces, which HSI barely
    changes, so the model runs without HSI and only (μ_fs, σ_fs) are free. The misfit is the
    normalised J of paper Eq. (6), minimised by bounded ``least_squares(method="trf")``. The model
    sees the same zero-phase filter as the measurement (PSD × |H_LP|⁴, physics.md §3.4).

    Parameters
    ----------
    measured : ResponsePSD
        Welch PSD of records low-pass filtered at ``cutoff``: ``welch_psd(..., lowpass=
        LowPassFilter(cutoff=2.3, sample_rate=...))``.
    structure : ModalModel
    crowd : Crowd
        Density, speed and body mass (kept); its (μ_fs, σ_fs) is the first starting point.
    cutoff : float
        Low-pass cut-off [Hz] (paper: 2.3 Hz); must be that of ``measured.lowpass``.
    band : (float, float), optional
        Fitted band [Hz]; default (0.5, cutoff).
    starts : sequence of (float, float), optional
        Starting points (μ_fs, σ_fs) [Hz]; default the crowd's values, (1.6, 0.1) and (2.0, 0.25).
    bounds : dict, optional
        ``step_frequency_mean`` / ``step_frequency_std`` → (lower, upper) [Hz]; defaults
        :data:`DEFAULT_STEP_FREQUENCY_BOUNDS`.
    outputs, output_weights, force, match_welch
        As for :func:`estimate_hsi`.

    Returns
    -------
    StepFrequencyEstimate
        ``.crowd`` is the input crowd with the fitted distribution.

    Warns
    -----
    BoundWarning, ConvergenceWarning
        As :func:`estimate_hsi`.
    """
    cutoff = check_positive("cutoff", cutoff, unit="Hz")
    if not isinstance(measured, ResponsePSD):
        raise ParameterError(f"measured must be a ResponsePSD, got {type(measured).__name__}")
    if measured.lowpass is None or abs(measured.lowpass.cutoff - cutoff) > 1e-9 * cutoff:
        got = None if measured.lowpass is None else f"{measured.lowpass.cutoff:g} Hz"
        raise ParameterError(
            f"measured.lowpass must be the low-pass filter at cutoff {cutoff:g} Hz that the "
            f"records went through (welch_psd(..., lowpass=LowPassFilter(cutoff={cutoff:g}, "
            f"sample_rate=...))), got {got}")
    band = (0.5, cutoff) if band is None else band
    objective = PSDObjective(measured, structure, crowd, band=band, force=force, outputs=outputs,
                             output_weights=output_weights, match_welch=match_welch)
    limits = _merge_bounds(bounds, DEFAULT_STEP_FREQUENCY_BOUNDS)
    lower = np.array([limits[n][0] for n in _STEP_PARAMETERS])
    upper = np.array([limits[n][1] for n in _STEP_PARAMETERS])
    if starts is None:
        starts = [(crowd.step_frequency_mean, crowd.step_frequency_std), (1.6, 0.1), (2.0, 0.25)]
    points = _starting_points(starts, _STEP_PARAMETERS, None, lower, upper)

    def to_crowd(theta):
        return replace(crowd, step_frequency_mean=float(theta[0]),
                       step_frequency_std=float(theta[1]))

    def residuals(theta):
        # The load spectrum depends on (μ_fs, σ_fs): one forward model per evaluation, no HSI.
        return objective.residuals(None, model=objective.spectral_model(to_crowd(theta)))

    best, runs = _multistart(residuals, points, lower, upper, objective)
    active, success, table = _diagnose(best, runs, _STEP_PARAMETERS, lower, upper,
                                       "the step-frequency optimum sits on a bound",
                                       "check the band and cut-off")
    return StepFrequencyEstimate(
        crowd=to_crowd(best.x), cost=float(2 * best.cost),
        cost_initial=float(np.sum(objective.residuals(None) ** 2)),
        n_evaluations=sum(n for _, _, n in runs), success=success, active_bounds=active,
        bounds={n: (float(lo), float(hi)) for n, lo, hi in zip(_STEP_PARAMETERS, lower, upper)},
        band=objective.band, cutoff=cutoff, output_names=objective.output_names, starts=table,
        message=str(best.message))
