"""The crowd's step-frequency distribution from the low band of a measured PSD.

The paper's Waalse Krook procedure (docs: theory, The estimator).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from .._validation import check_positive, fields_from_dict
from ..errors import DataError, ParameterError
from ..signals.spectrum import ResponsePSD
from .diagnostics import _diagnose
from .estimation import DEFAULT_STEP_FREQUENCY_BOUNDS, PSDObjective
from .multistart import _merge_bounds, _multistart, _starting_points
from .sandwich import STEP_PARAMETERS
from ..models.crowd import Crowd

if TYPE_CHECKING:
    from .._validation import ForceModel
    from ..models.crowd import Crowd
    from ..models.structure import ModalModel

__all__ = ["estimate_step_frequencies", "StepFrequencyEstimate", "DEFAULT_STEP_FREQUENCY_BOUNDS"]



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

    crowd: Crowd
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

    @classmethod
    def from_dict(cls, data: dict, crowd: Crowd | None = None) -> StepFrequencyEstimate:
        """The estimate of :meth:`to_dict`.

        Parameters
        ----------
        data : dict
        crowd : Crowd, optional
            The crowd the step frequencies were fitted for, for a dict without its own
            ``crowd`` (written before crowdvib stored it); its step frequencies are replaced by
            the fitted ones.

        Raises
        ------
        DataError
            ``data`` is not such a dict, or holds no crowd and none is given.
        """

        fitted = data.get("step_frequencies") if isinstance(data, dict) else None
        if isinstance(data, dict) and isinstance(data.get("crowd"), dict):
            crowd = Crowd.from_dict(data["crowd"])
        elif crowd is not None and isinstance(fitted, dict):
            crowd = replace(crowd, step_frequency_mean=fitted["mean"],
                            step_frequency_std=fitted["std"])
        else:
            raise DataError("StepFrequencyEstimate.from_dict: the dict holds no crowd and none "
                            "is given (crowd=)")
        return fields_from_dict(cls, data, crowd=crowd)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict; the fitted distribution sits under ``"step_frequencies"``."""
        return {"step_frequencies": {"mean": self.crowd.step_frequency_mean,
                                     "std": self.crowd.step_frequency_std},
                "crowd": self.crowd.to_dict(),
                "cost": self.cost, "cost_initial": self.cost_initial,
                "n_evaluations": self.n_evaluations, "success": self.success,
                "active_bounds": list(self.active_bounds),
                "bounds": {k: list(v) for k, v in self.bounds.items()}, "band": list(self.band),
                "cutoff": self.cutoff, "output_names": list(self.output_names),
                "starts": [dict(s) for s in self.starts], "message": self.message}


def estimate_step_frequencies(measured: ResponsePSD, structure: ModalModel, crowd: Crowd, *,
                              cutoff: float = 2.3, band: tuple[float, float] | None = None,
                              starts: Sequence[Sequence[float]] | None = None,
                              bounds: Mapping[str, tuple[float, float]] | None = None,
                              outputs: Sequence[str] | None = None,
                              output_weights: Sequence[float] | None = None,
                              force: ForceModel | None = None,
                              match_welch: bool = True) -> StepFrequencyEstimate:
    """Fit the crowd's step-frequency distribution N(μ_fs, σ_fs) to low-passed PSDs.

    The paper's procedure for the Waalse Krook bridge (docs: theory, The estimator): below the cut-off the
    response is the non-resonant first-harmonic content of the walking forces, which HSI barely
    changes, so the model runs without HSI and only (μ_fs, σ_fs) are free. The misfit is the
    normalised J of paper Eq. (6), minimised by bounded ``least_squares(method="trf")``. The model
    sees the same zero-phase filter as the measurement (PSD × |H_LP|⁴, docs: theory, What a Welch estimate sees: the expectation kernel).

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

    See Also
    --------
    crowdvib.estimate_hsi : with ``free_step_frequencies=True``, the MSD and the step
        frequencies together.
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
                             output_weights=output_weights, match_welch=match_welch,
                             method="least_squares")     # paper Eq. (6), the smeared crowd
    limits = _merge_bounds(bounds, DEFAULT_STEP_FREQUENCY_BOUNDS)
    lower = np.array([limits[n][0] for n in STEP_PARAMETERS])
    upper = np.array([limits[n][1] for n in STEP_PARAMETERS])
    if starts is None:
        starts = [(crowd.step_frequency_mean, crowd.step_frequency_std), (1.6, 0.1), (2.0, 0.25)]
    points = _starting_points(starts, STEP_PARAMETERS, None, lower, upper)

    def to_crowd(theta):
        return replace(crowd, step_frequency_mean=float(theta[0]),
                       step_frequency_std=float(theta[1]))

    def residuals(theta):
        # The load spectrum depends on (μ_fs, σ_fs): one forward model per evaluation, no HSI.
        return objective.residuals(None, model=objective.spectral_model(to_crowd(theta)))

    best, runs = _multistart(residuals, points, lower, upper)
    active, success, table = _diagnose(best, runs, STEP_PARAMETERS, lower, upper,
                                       "the step-frequency optimum sits on a bound",
                                       "check the band and cut-off")
    return StepFrequencyEstimate(
        crowd=to_crowd(best.x), cost=float(2 * best.cost),
        cost_initial=float(np.sum(objective.residuals(None) ** 2)),
        n_evaluations=sum(n for _, _, n in runs), success=success, active_bounds=active,
        bounds={n: (float(lo), float(hi)) for n, lo, hi in zip(STEP_PARAMETERS, lower, upper)},
        band=objective.band, cutoff=cutoff, output_names=objective.output_names, starts=table,
        message=str(best.message))
