"""The inverse problem: MSD parameters from measured response PSDs (paper Eq. 5 and 6).

docs: theory, The estimator.

J(θ) = Σ_l γ_l ‖G̃_l − G_l(θ)‖₂² / ‖G̃_l‖₂² over the analysis band, minimised by bounded
``scipy.optimize.least_squares(method="trf")`` from several starting points. The residual vector
r_{l,k} = sqrt(γ_l w_k) (G̃_l(f_k) − G_l(f_k; θ)) / ‖G̃_l‖₂ has Σ r² = J.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from .._estimators import (DEFAULT_DENSITY_UNCERTAINTY, DEFAULT_JOINT_METHOD, DEFAULT_METHOD,
                           check_density_uncertainty, estimator_defaults)
from .._plausibility import far_outside, warn_notes
from .._validation import check_flag
from ..errors import ParameterError
from ..models.pedestrian import MSDModel
from ..models.profile import CrowdProfile
from .diagnostics import _check_identifiability, _check_level, _diagnose, _refuse_gross_level
from ..response.frequency_domain.varying import record_duration
from .objective import PSDObjective
from .result import HSIEstimate
from .multistart import (DEFAULT_STARTS, FINAL_TOLERANCE, _merge_bounds, _multistart,
                         _starting_points)
from .sandwich import STEP_PARAMETERS, _covariance, _DensityTerm, _intervals

if TYPE_CHECKING:
    from .._validation import ForceModel, Seed
    from ..models.crowd import Crowd
    from ..models.structure import ModalModel
    from ..signals.spectrum import ResponsePSD

    #: The paper's γ_ω: a function of frequency [Hz] or one weight per measured frequency.
    FrequencyWeights = Callable[[np.ndarray], np.ndarray] | ArrayLike

__all__ = ["estimate_hsi", "estimate_hsi_joint", "HSIEstimate", "PSDObjective", "DEFAULT_STARTS",
           "DEFAULT_BOUNDS"]


#: Search bounds: f_h1 ≤ 10 Hz and ξ_h1 ≤ 100 % as in the paper; small positive lower bounds
#: stand for the strict inequalities f_h1 > 0, ξ_h1 > 0, 0 < μ_h1 < 1 (paper Eq. 5).
DEFAULT_BOUNDS = {"frequency": (1e-3, 10.0), "damping_ratio": (1e-3, 1.0),
                  "mass_ratio": (1e-3, 0.999)}
_PARAMETERS = ("frequency", "damping_ratio", "mass_ratio")
#: ftol and xtol of the likelihood's first fit of free step frequencies, which only chooses the
#: bins of the refit that follows from its optimum (estimate_hsi): the refit converges to
#: scipy's own 1e-8 from a start within ~1e-5, so the end moves by the refit's tolerance
#: (≤ 1e-6 relative on the paper example's record), while a start that crawls to a search
#: bound stops hundreds of iterations earlier (the gain mistake of tests/package/
#: test_plausibility.py, a record 20 times too strong: its first fit's model evaluations
#: 2897 → 1535; issue 39).
BIN_CHOICE_TOLERANCE = 1e-5
#: ... and after this many trial points (scipy's max_nfev; the Jacobian's not counted): 6–7 on
#: the paper example's records that fit, up to 294 for a start that crawls towards the
#: damping's bound on a record in wrong units (tests/package/test_plausibility.py, in m/s²
#: declared in g: 19.5 → 7.7 s of CPU, the same estimate and warnings); the refit, from the
#: best start's end, has scipy's own budget (issue 39).
BIN_CHOICE_STEPS = 50
#: Search bounds of (μ_fs, σ_fs) [Hz]: normal walking lies well inside 1–3 Hz, and a spread below
#: 0.01 Hz or above 0.6 Hz is not a crowd (the paper's values are 0.13–0.19 Hz).
DEFAULT_STEP_FREQUENCY_BOUNDS = {"step_frequency_mean": (1.0, 3.0),
                                 "step_frequency_std": (0.01, 0.6)}


def estimate_hsi(measured: ResponsePSD, structure: ModalModel, crowd: Crowd, *,
                 band: tuple[float, float], outputs: Sequence[str] | None = None,
                 output_weights: Sequence[float] | None = None,
                 frequency_weights: FrequencyWeights | None = None,
                 starts: Sequence[Sequence[float]] | None = None,
                 bounds: Mapping[str, tuple[float, float]] | None = None,
                 mass_ratio: float = 0.95, free_mass_ratio: bool = False,
                 free_step_frequencies: bool | None = None,
                 force: ForceModel | None = None, match_welch: bool = True,
                 method: str = DEFAULT_METHOD, interval: str = "profile", level: float = 0.95,
                 crowd_model: str | None = None, n_boot: int = 200,
                 rng: Seed = None,
                 density_uncertainty: float = DEFAULT_DENSITY_UNCERTAINTY,
                 check_level: bool = True) -> HSIEstimate:
    """Estimate the pedestrians' MSD parameters from measured response PSDs (paper Equations 5 and 6).

    Parameters
    ----------
    measured : ResponsePSD
        Measured one-sided acceleration PSDs [(m/s²)²/Hz] at named outputs of ``structure``.
    structure : ModalModel
        Modal model of the empty footbridge (assumed known).
    crowd : Crowd
        Density, speed, step-frequency distribution and body mass (assumed known), density > 0.
        A density that is a :class:`~crowdvib.models.CrowdProfile` over the record (t = 0 its
        first sample), e.g. from counts per interval (``CrowdProfile.from_counts``), makes the
        model the average of the Welch windows' expectations, each at the density on the deck
        during it (docs: theory, A crowd that changes). The interval takes the record's Welch
        statistics as measured: the scatter of its segments, which with a changing crowd
        includes the spread of their expectations.
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
        (docs: theory, Inverse problem). Points outside the bounds are moved just inside.
    bounds : dict, optional
        Parameter → (lower, upper); defaults f_h1 ∈ [0.001, 10] Hz, ξ_h1 ∈ [0.001, 1],
        μ_h1 ∈ [0.001, 0.999] (paper: upper bounds of 10 Hz and 100 %).
    mass_ratio : float
        μ_h1 when it is held fixed (paper: 0.95).
    free_mass_ratio : bool
        Estimate μ_h1 too.
    free_step_frequencies : bool, optional
        Estimate the crowd's step-frequency distribution N(μ_fs, σ_fs) with the MSD, from the
        whole band (docs: theory, Step frequencies fitted with the MSD); ``crowd`` gives the
        starting values, ``bounds`` may hold ``step_frequency_mean`` and ``step_frequency_std``.
        Default: True for the likelihood, which weighs the flanks of the load spectrum and so
        needs it unless the crowd's mean step frequency is known to a fraction of a per cent;
        False for least squares (the paper).
    force : ZivanovicForce or YoungForce, optional
        Walking force model (default Živanović 2007).
    match_welch : bool
        Compare with what a Welch estimate of the measured window length would see (default).
    method : {"likelihood", "least_squares"}
        The Whittle likelihood of the Welch ordinates (default) or the paper's normalised least
        squares (Eq. 6). By default the likelihood comes with the fluctuating crowd and the
        step frequencies fitted, least squares with the paper's smeared crowd and the crowd as
        given, so ``method="least_squares"`` is the paper's estimator; why the default is the
        likelihood, with its bias and coverage on simulated records, is in docs: theory,
        Calibration. A record with cross-spectra (``welch_psd(..., cross=True)``) and two or
        more outputs gets the complex-Wishart likelihood of its cross-spectral matrix (docs:
        theory, The likelihood of several outputs).
    interval : {"profile", "wald", "bootstrap", None}
        Statistical uncertainty from this record's Welch scatter: sandwich covariance with
        profile intervals (default), the covariance only (Wald intervals), the covariance with
        parametric-bootstrap percentile intervals (docs: theory, Parametric bootstrap), or
        nothing (fastest, for studies that re-estimate many times). Only for a Welch estimate
        (``measured.n_windows`` known); otherwise the estimate carries no interval.
    level : float
        Confidence level of the profile intervals (default 0.95).
    crowd_model : {"fluctuating", "smeared"}, optional
        The expected PSD: the mixture over the occupancy of a Poisson crowd, whose fluctuation
        widens the measured resonance (docs: theory, The fluctuating crowd; default with the
        likelihood), or the paper's smeared mean crowd (default with least squares). The
        default is also :func:`crowdvib.response_psd`'s: a noise-free PSD it makes with the
        measured Welch window is what the default estimate recovers exactly;
        ``response_psd(..., crowd_model="smeared")`` is what ``method="least_squares"`` does.
    n_boot : int
        Replicates of the parametric bootstrap (``interval="bootstrap"``), >= 20.
    rng : None, int or numpy.random.Generator
        Seed of the bootstrap replicates.
    density_uncertainty : float
        The relative standard uncertainty of the stated crowd density (or of the whole
        profile), in [0, 0.5]: 0.1 for a density known to ±10 % (one standard
        deviation). The intervals carry it as a nuisance of the sandwich covariance: a density
        stated too high moves every ordinate as a larger crowd would, and the estimate with it
        (docs: theory, The crowd density's uncertainty). Default 0.1: field densities are
        rarely known better; 0 for a density known exactly (a simulated record).
    check_level : bool
        Before any fit, refuse (:class:`~crowdvib.errors.DataError`) a measured level that no
        MSD within the bounds brings within a factor 10 of the model's, naming the likely unit
        mix-up, and a structure far outside plausible values (a damping ratio above 0.2): a
        fit to either runs for minutes to a warning (default True; False fits anyway).

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

    See Also
    --------
    crowdvib.estimate_hsi_joint : one MSD from several records, each with its own crowd.
    crowdvib.welch_psd : the measured PSD.
    crowdvib.response_psd : the forward model the estimate fits.
    crowdvib.studies.objective_map : the objective around the estimate.
    crowdvib.studies.modelling_error_study : the estimate's sensitivity to the assumed inputs.

    References
    ----------
    K. Van Nimmen and P. Van den Broeck, "Using full-scale observations on footbridges to estimate
    the parameters governing human–structure interaction", *Journal of Bridge Engineering* 28(1),
    2023. The inverse problem: the normalised misfit (Eq. 5) and the weighted objective (Eq. 6).

    P. Whittle, "Estimation and information in stationary time series", *Arkiv för Matematik*
    2(5):423–434, 1953. The likelihood of periodogram ordinates.

    V. P. Godambe, "An optimum property of regular maximum likelihood estimation", *Annals of
    Mathematical Statistics* 31(4):1208–1211, 1960. The sandwich information behind the intervals.

    The theory pages cite them (docs: theory, References).

    Examples
    --------
    The paper's numerical example, noise-free: the MSD that made a modelled Welch PSD of the
    paper's smeared crowd is found again by the paper's least squares:

    >>> import numpy as np
    >>> from crowdvib import Crowd, MSDModel, ModalModel, estimate_hsi, response_psd
    >>> bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    >>> crowd = Crowd.from_density(0.5)
    >>> measured = response_psd(bridge, crowd, np.arange(601) / 60, msd=MSDModel(3.0, 0.30, 0.95),
    ...                         welch_window_length=60.0, crowd_model="smeared")
    >>> fit = estimate_hsi(measured, bridge, crowd, band=(0.0, 10.0), method="least_squares",
    ...                    interval=None)
    >>> round(fit.msd.frequency, 3), round(fit.msd.damping_ratio, 3)
    (3.0, 0.3)
    """
    crowd_model, free_step_frequencies = estimator_defaults(method, crowd_model,
                                                            free_step_frequencies)
    free_step_frequencies = check_flag("free_step_frequencies", free_step_frequencies)
    _warn_implausible_profile(crowd, measured)
    profile = getattr(crowd, "profile", None)       # the objective checks the type

    def objective(walkers, model=crowd_model):
        # A fitted crowd (the first fit's) is numeric: it walks the record's profile again.
        walkers = walkers if profile is None else walkers.with_density(profile)
        return PSDObjective(measured, structure, walkers, band=band, force=force, outputs=outputs,
                            output_weights=output_weights, frequency_weights=frequency_weights,
                            match_welch=match_welch, method=method, crowd_model=model)

    # A wrong level (units, gain) is diagnosed at the crowd as given with the smeared model:
    # the question is one of level, which the two crowd models share to a few per cent, and
    # its five fits on data that fit nothing would cost minutes with the fluctuating one.
    given = [objective(crowd, "smeared")]
    _check_before_fit(given, structure, bounds, mass_ratio, free_mass_ratio,
                      free_step_frequencies, check_level)

    options = dict(starts=starts, bounds=bounds, mass_ratio=mass_ratio,
                   free_mass_ratio=free_mass_ratio, method=method, level=level, n_boot=n_boot,
                   rng=rng, free_step_frequencies=free_step_frequencies,
                   density_uncertainty=density_uncertainty)
    if free_step_frequencies and method == "likelihood":
        # The likelihood's bins are chosen from the crowd's model (within its dynamic range), so
        # a first fit from the given crowd is followed by the fit on the bins of the fitted
        # crowd: the answer then does not depend on the starting guess. The first fit only
        # chooses the bins (no diagnosis, no warning: the refit gives them). The refit starts
        # from its optimum only: the first fit's starts have found the basin, and the new bins
        # move the optimum by a fraction of its interval (a third of the estimate's time).
        # Its starts stop in the basin of an earlier one's optimum (join): the refit finds
        # that optimum again to its own tolerance (a third of the first fit's time).
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            first = _estimate([(objective(crowd), measured)], structure, given=(),
                              tolerance=BIN_CHOICE_TOLERANCE, max_nfev=BIN_CHOICE_STEPS,
                              join=True, **dict(options, interval=None))
        options["starts"] = [tuple(first.value(name) for name in first.free_parameters
                                   if name not in STEP_PARAMETERS)]
        second = _estimate([(objective(first.crowd), measured)], structure, interval=interval,
                           given=given, **options)
        return dataclasses.replace(second, n_evaluations=first.n_evaluations
                                   + second.n_evaluations, starts=first.starts + second.starts)
    return _estimate([(objective(crowd), measured)], structure, interval=interval, given=given,
                     **options)


def estimate_hsi_joint(measurements: Sequence[ResponsePSD], structure: ModalModel,
                       crowds: Sequence[Crowd], *, band: tuple[float, float],
                       outputs: Sequence[str] | None = None,
                       output_weights: Sequence[float] | None = None,
                       frequency_weights: FrequencyWeights | None = None,
                       starts: Sequence[Sequence[float]] | None = None,
                       bounds: Mapping[str, tuple[float, float]] | None = None,
                       mass_ratio: float = 0.95, free_mass_ratio: bool = False,
                       force: ForceModel | None = None, match_welch: bool = True,
                       method: str = DEFAULT_JOINT_METHOD, interval: str = "profile",
                       level: float = 0.95, crowd_model: str | None = None, n_boot: int = 200,
                       rng: Seed = None,
                       density_uncertainty: float = DEFAULT_DENSITY_UNCERTAINTY,
                       check_level: bool = True) -> HSIEstimate:
    """One MSD from several records, each with its own crowd (docs: theory, Joint estimation).

    The records are independent, so their misfits add (for the likelihood: their likelihoods
    multiply); the estimate minimises the sum, and its sandwich covariance sums each record's
    score variance and curvature. Records at different densities separate what one record
    cannot (μ_h1 from ξ_h1, for instance), and the joint interval is narrower than either.
    Each record's crowd is held as given, so the default is the paper's least squares with the
    smeared crowd (the likelihood at a fixed crowd is fragile to an error in its mean step
    frequency: docs: theory, Calibration).

    Parameters
    ----------
    measurements : sequence of ResponsePSD
        One measured PSD per record (each a Welch estimate for intervals).
    structure : ModalModel
    crowds : sequence of Crowd
        The crowd of each record, in the same order, each with its own density: a number, or
        a :class:`~crowdvib.models.CrowdProfile` against its record's time (as in
        :func:`estimate_hsi`).
    band, outputs, output_weights, frequency_weights, starts, bounds, mass_ratio
        As in :func:`estimate_hsi`, the same for every record.
    free_mass_ratio, force, match_welch, method, interval, level, crowd_model, n_boot, rng
        As in :func:`estimate_hsi`, the same for every record.
    density_uncertainty : float
        As in :func:`estimate_hsi`: the relative standard uncertainty of the stated densities,
        taken as one error common to every record (the same way of counting), so it does not
        average out over records.
    check_level : bool
        As in :func:`estimate_hsi`, for every record.

    Returns
    -------
    HSIEstimate
        ``output_names`` read ``"record 1: midspan"`` …; ``cost`` is the summed misfit.

    See Also
    --------
    crowdvib.estimate_hsi : the estimate from one record.

    References
    ----------
    K. Van Nimmen and P. Van den Broeck, "Using full-scale observations on footbridges to estimate
    the parameters governing human–structure interaction", *Journal of Bridge Engineering* 28(1),
    2023. The objective (Eq. 5 and 6) of each record.

    V. P. Godambe, "An optimum property of regular maximum likelihood estimation", *Annals of
    Mathematical Statistics* 31(4):1208–1211, 1960. The sandwich information summed over the
    records.

    The theory pages cite them (docs: theory, References).
    """
    measurements, crowds = list(measurements), list(crowds)
    crowd_model, _ = estimator_defaults(method, crowd_model)
    if not measurements or len(measurements) != len(crowds):
        raise ParameterError(f"measurements and crowds must pair up one record with one crowd, "
                             f"got {len(measurements)} measurement(s) and {len(crowds)} crowd(s)")
    for measured, crowd in zip(measurements, crowds):
        _warn_implausible_profile(crowd, measured)
    parts = [(PSDObjective(measured, structure, crowd, band=band, force=force, outputs=outputs,
                           output_weights=output_weights, frequency_weights=frequency_weights,
                           match_welch=match_welch, method=method, crowd_model=crowd_model),
              measured)
             for measured, crowd in zip(measurements, crowds)]
    _check_before_fit([objective for objective, _ in parts], structure, bounds, mass_ratio,
                      free_mass_ratio, False, check_level)
    return _estimate(parts, structure, starts=starts, bounds=bounds, mass_ratio=mass_ratio,
                     free_mass_ratio=free_mass_ratio, method=method, interval=interval,
                     level=level, n_boot=n_boot, rng=rng, density_uncertainty=density_uncertainty)


def _check_before_fit(objectives, structure, bounds, mass_ratio, free_mass_ratio,
                      free_step_frequencies, check_level):
    """The checks before any fit (``check_level``): a structure beyond the hard tier of the
    plausible ranges, then a measured level no θ within the bounds explains (issue 35 §2)."""
    if not check_flag("check_level", check_level):
        return
    # μ_h1 and the two switches by their rules (interval, n_boot and level: checked by the fit)
    free_mass_ratio, free_step_frequencies = _check_options(
        mass_ratio, free_mass_ratio, free_step_frequencies, None, 200, 0.5)
    far = [note for j, ratio in enumerate(structure.damping_ratios) if (note := far_outside(
        "damping_ratio", ratio, f"structure: damping_ratios[{j}]")) is not None]
    if far:
        raise ParameterError(f"{'; '.join(far)}. Correct it, or pass check_level=False (case "
                             "file: estimation.check_level = false) to estimate with it")
    # The crowd as given (as the diagnosis after the fit): free step frequencies narrowed to a
    # spike at the resonance would explain any level.
    parameters = _parametrisation(bounds, mass_ratio, free_mass_ratio,
                                  free_step_frequencies).held()
    for objective in objectives:
        _check_measured_level(objective)
    _refuse_gross_level(objectives, parameters.names, parameters.lower, parameters.upper,
                        mass_ratio, [f"structure: {note}" for note in structure.implausibilities()])


def _warn_implausible_profile(crowd, measured):
    """The doubtful values of a crowd's profile against the record it describes, as warnings
    (at the caller of the estimate)."""
    profile = getattr(crowd, "profile", None)       # the objective checks the types
    if (isinstance(profile, CrowdProfile)
            and getattr(measured, "window_length", None) and getattr(measured, "n_windows", None)):
        warn_notes(profile.implausibilities(record_duration(
            measured.window_length, measured.n_windows)), stacklevel=3)


class _Stacked:
    """Several records' misfits as one: residual vectors stacked."""

    def __init__(self, objectives):
        self.objectives = tuple(objectives)

    def residuals(self, msd, steps=None):
        return np.concatenate([o.residuals(msd, steps=steps) for o in self.objectives])

    def cost(self, msd):
        r = self.residuals(msd)
        return float(r @ r)


INTERVALS = ("profile", "wald", "bootstrap", None)


@dataclasses.dataclass(frozen=True)
class _Parameters:
    """The free parameters θ, their bounds and what θ stands for (the held μ_h1)."""

    names: tuple
    lower: np.ndarray
    upper: np.ndarray
    mass_ratio: float
    free_step_frequencies: bool

    def _msd_fields(self, theta):
        """θ → (f_h1, ξ_h1, μ_h1), the held μ_h1 where it is not free."""
        values = dict(zip(self.names, theta))
        return (values["frequency"], values["damping_ratio"],
                values.get("mass_ratio", self.mass_ratio))

    def msd(self, theta):
        return MSDModel(*self._msd_fields(theta))

    def state(self, theta):
        """θ → (MSD, (μ_fs, σ_fs) or None): what the misfit is evaluated at (θ inside the
        bounds, checked when they were merged: the MSD is not checked again)."""
        return (MSDModel._checked(*self._msd_fields(theta)),
                tuple(theta[-2:]) if self.free_step_frequencies else None)

    def misfit(self, target, theta):
        msd, steps = self.state(theta)
        return target.residuals(msd, steps=steps)

    def held(self):
        """The MSD's parameters alone, the crowd as given: the unit mix-up diagnosis fits so,
        as free step frequencies can take up part of a wrong level."""
        if not self.free_step_frequencies:
            return self
        n = len(self.names) - len(STEP_PARAMETERS)
        return dataclasses.replace(self, names=self.names[:n], lower=self.lower[:n],
                                   upper=self.upper[:n], free_step_frequencies=False)


def _estimate(parts, structure, *, starts, bounds, mass_ratio, free_mass_ratio, method,
              interval, level, n_boot=200, rng=None, free_step_frequencies=False, given=None,
              density_uncertainty=DEFAULT_DENSITY_UNCERTAINTY, tolerance=FINAL_TOLERANCE,
              max_nfev=None, join=False):
    """The estimate from one or several (objective, measured PSD) records (estimate_hsi).

    ``given``: the records' objectives at the crowd the user gave, where a wrong level is
    diagnosed (default the parts' own; empty: no diagnosis). ``tolerance``: the fits' (scipy's
    ftol and xtol; :data:`BIN_CHOICE_TOLERANCE` for a fit that only chooses a refit's bins) and
    ``max_nfev`` their budget of steps (scipy's; :data:`BIN_CHOICE_STEPS` for that fit);
    ``join``: a start stops in the basin of an earlier start's optimum (that fit too:
    :func:`.multistart._multistart`).

    A sequence of steps, each taking what the one before returned: the options and θ's
    parametrisation, the fit from every start, the objectives of the fitted crowd (when the
    step frequencies are free), the diagnostics, the covariance, the intervals, the result.
    """
    free_mass_ratio, free_step_frequencies = _check_options(
        mass_ratio, free_mass_ratio, free_step_frequencies, interval, n_boot, level)
    density_uncertainty = check_density_uncertainty(density_uncertainty)
    warn_notes([f"structure: {note}" for note in structure.implausibilities()], stacklevel=2)
    parameters = _parametrisation(bounds, mass_ratio, free_mass_ratio, free_step_frequencies)
    crowd = parts[0][0].model.crowd
    tail = {"mass_ratio": mass_ratio, "step_frequency_mean": crowd.step_frequency_mean,
            "step_frequency_std": crowd.step_frequency_std}
    points = _starting_points(starts, parameters.names, tail, parameters.lower, parameters.upper)
    for objective, _ in parts:
        _check_measured_level(objective)
    best, runs = _fit(_Stacked(o for o, _ in parts), parameters, points, tolerance, max_nfev,
                      join)
    given = [objective for objective, _ in parts] if given is None else given
    parts = _adopt_fitted_crowd(parts, parameters, best.x)
    stacked = _Stacked(o for o, _ in parts)
    active, success, table = _diagnose(best, runs, parameters.names, parameters.lower,
                                       parameters.upper, "the optimum sits on a bound",
                                       "check the model inputs", stacklevel=4)
    msd = parameters.msd(best.x)
    ratios, held = [objective.level_ratio(msd) for objective, _ in parts], parameters.held()
    held_points = [point[:len(held.names)] for point in points]
    for ratio, as_given in zip(ratios, given):
        # The diagnostics warn from here: their stack depth is fixed.
        _check_level(as_given, ratio, lambda target: _fit(target, held, held_points), held.msd)
    covariance, hessian, occupancies, density = None, None, None, _DensityTerm(0.0, None, None)
    # Intervals need the scatter of the ordinates: known for a Welch estimate (its n_windows),
    # not for a PSD of unknown origin (a model curve, a PSD read from a table).
    if interval is not None and all(measured.n_windows for _, measured in parts):
        covariance, hessian, occupancies, density = _covariance(parts, parameters, best.x,
                                                                density_uncertainty)
        _check_identifiability(parameters.names, covariance)
    intervals, on_bound, samples = _intervals(
        interval, parts, stacked, parameters, best.x, covariance, hessian, occupancies, level,
        n_boot, rng, density, active)
    single = len(parts) == 1
    output_names = tuple(name if single else f"record {r + 1}: {name}"
                         for r, (objective, _) in enumerate(parts)
                         for name in objective.output_names)
    return HSIEstimate(
        msd=msd, cost=float(2 * best.cost), cost_no_hsi=stacked.cost(None),
        n_evaluations=sum(n for _, _, n in runs), success=success, active_bounds=active,
        free_parameters=parameters.names,
        bounds={n: (float(lo), float(hi)) for n, lo, hi in
                zip(parameters.names, parameters.lower, parameters.upper)},
        band=parts[0][0].band, output_names=output_names,
        output_weights=np.concatenate([o.output_weights for o, _ in parts]) / len(parts),
        starts=table, message=str(best.message), level_ratio=np.concatenate(ratios),
        method=method, covariance=covariance, intervals=intervals, interval_level=level,
        interval_on_bound=on_bound, crowd_model=parts[0][0].crowd_model,
        crowd_model_details=tuple(objective.model.details() for objective, _ in parts
                                  if objective.crowd_model == "fluctuating"),
        interval_method=interval if intervals else None, bootstrap_samples=samples,
        crowd=parts[0][0].model.crowd if free_step_frequencies else None,
        density_uncertainty=density.uncertainty if covariance is not None else 0.0,
        density_sensitivity=density.sensitivities(parameters.names),
        density_share=density.shares(parameters.names, covariance))


def _check_options(mass_ratio, free_mass_ratio, free_step_frequencies, interval, n_boot, level):
    """The estimate's options, each against its rule (ParameterError naming it) → the two
    switches as booleans."""
    MSDModel(mass_ratio=mass_ratio)  # validates mass_ratio with the model's own rule
    # A switch given as "no" or 0 must not be read by its truth value ("no" frees μ_h1).
    free_mass_ratio = check_flag("free_mass_ratio", free_mass_ratio)
    free_step_frequencies = check_flag("free_step_frequencies", free_step_frequencies)
    if interval not in INTERVALS:
        raise ParameterError(f"interval must be one of {list(INTERVALS)}, got {interval!r}")
    if interval == "bootstrap" and not (isinstance(n_boot, (int, np.integer)) and n_boot >= 20):
        raise ParameterError(f"n_boot must be an integer >= 20 for a percentile interval, got "
                             f"{n_boot!r}")
    if not 0 < level < 1:
        raise ParameterError(f"level must lie in (0, 1), got {level!r}")
    return free_mass_ratio, free_step_frequencies


def _parametrisation(bounds, mass_ratio, free_mass_ratio, free_step_frequencies):
    """θ's names and bounds: (f_h1, ξ_h1), μ_h1 if free, (μ_fs, σ_fs) if free."""
    names = (_PARAMETERS if free_mass_ratio else _PARAMETERS[:2]) + (
        STEP_PARAMETERS if free_step_frequencies else ())
    limits = _merge_bounds(bounds, dict(DEFAULT_BOUNDS, **(
        DEFAULT_STEP_FREQUENCY_BOUNDS if free_step_frequencies else {})))
    if limits["mass_ratio"][1] >= 1:
        raise ParameterError(f"bounds['mass_ratio'] must stay below 1, got {limits['mass_ratio']}")
    return _Parameters(names, np.array([limits[n][0] for n in names]),
                       np.array([limits[n][1] for n in names]), mass_ratio,
                       free_step_frequencies)


def _check_measured_level(objective):
    """Refuse a measured PSD whose level no unit or gain mix-up explains (before any fit)."""
    absurd = objective.level_ratio(None)
    if np.any(~((absurd > 1e-100) & (absurd < 1e100))):
        raise ParameterError(
            "measured PSD level must be within a factor 1e100 of the model's without HSI "
            f"over the band (no unit or gain mix-up goes further), got measured/model "
            f"variance {', '.join(f'{v:.3g}' for v in absurd)} for outputs "
            f"{list(objective.output_names)}")


def _fit(target, parameters, points, tolerance=FINAL_TOLERANCE, max_nfev=None, join=False):
    """The multistart fit of a misfit (one objective or a stack) → (best result, runs)."""
    records = len(getattr(target, "objectives", (target,)))
    return _multistart(lambda theta: parameters.misfit(target, theta), points,
                       parameters.lower, parameters.upper, records=records, tolerance=tolerance,
                       max_nfev=max_nfev, join=join)


def _adopt_fitted_crowd(parts, parameters, theta):
    """The records with objectives whose own model is the fitted crowd's (free step frequencies).

    From here on the levels, the crowd-size term and the bootstrap's replicates use the fitted
    crowd; profiles still move (μ_fs, σ_fs) through θ. Held step frequencies: ``parts`` as given.
    """
    _, steps = parameters.state(theta)
    if steps is None:
        return parts
    return [(objective.with_step_frequencies(steps), measured) for objective, measured in parts]
