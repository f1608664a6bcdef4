"""The result of an HSI estimate: the MSD, its misfit, its uncertainty and its diagnostics.

docs: theory, The estimator; docs: theory, Statistical uncertainty of an estimate.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy import stats

from ..errors import ParameterError
from ..quantities import describe
from ..models.crowd import Crowd
from ..models.pedestrian import MSDModel

if TYPE_CHECKING:
    from ..models.crowd import Crowd
    from ..models.pedestrian import MSDModel

__all__ = ["HSIEstimate"]


@dataclass(frozen=True, eq=False)
class HSIEstimate:
    """Result of :func:`crowdvib.estimate_hsi` (paper Equations 5 and 6).

    Attributes
    ----------
    msd : MSDModel
        The estimated mass-spring-damper model (f_h1 [Hz], ξ_h1 [-], μ_h1 [-]).
    cost : float
        The misfit at the estimate [-]: the Whittle deviance D(θ̂) for the likelihood, or
        J(θ̂) = Σ_l γ_l ‖G̃_l − G_l(θ̂)‖² / ‖G̃_l‖² (paper Eq. 6) for least squares.
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
    method : str
        The misfit: ``"least_squares"`` (paper Eq. 6) or ``"likelihood"`` (Whittle deviance).
    covariance : ndarray, shape (n_free, n_free), or None
        Sandwich covariance of the free parameters (order of ``free_parameters``), from the
        Welch scatter of this one record (docs: theory, Statistical uncertainty of an estimate).
    intervals : dict
        Parameter → (low, high) profile (or bootstrap) interval at ``interval_level`` (empty if
        not computed). Fitted step frequencies have no profile interval: :meth:`interval` gives
        their Wald interval.
    interval_level : float
        Confidence level of ``intervals``.
    interval_on_bound : tuple of str
        Interval ends that stopped at a search bound, e.g. ``("damping_ratio:upper",)``; for
        an estimate on a bound its side, and its profile interval has NaN ends (not computed).
    crowd_model : str
        The expected-PSD model of the crowd: ``"smeared"`` or ``"fluctuating"``.
    crowd_model_details : tuple of dict
        With the fluctuating model, per record what its mixture is made of
        (:meth:`FluctuatingSpectralModel.details`: occupancy nodes, whether the drift
        correction is applied, κ, ε); empty with the smeared model.
    interval_method : str or None
        How ``intervals`` were found: ``"profile"`` or ``"bootstrap"`` (None: not computed).
    bootstrap_samples : ndarray, shape (n_boot, n_free), or None
        The refitted parameters of the parametric-bootstrap replicates.
    crowd : Crowd or None
        With ``free_step_frequencies``, the crowd with the fitted step-frequency distribution
        (``step_frequency_mean`` μ_fs, ``step_frequency_std`` σ_fs [Hz]); else None.
    density_uncertainty : float
        The relative standard uncertainty of the stated crowd density that the covariance and
        intervals carry (0: the density taken as exact, or no covariance).
    density_sensitivity : dict
        Parameter → ∂θ̂/∂ln ρ: how the estimate moves with the stated density (× 0.1: for a
        density stated 10 % high) [the parameter's unit]; empty without a covariance.
    density_share : dict
        Parameter → the fraction of its variance that the density's uncertainty makes [-]
        (docs: theory, The crowd density's uncertainty); empty when none was stated.

    See Also
    --------
    crowdvib.estimate_hsi : what makes it.
    """

    msd: MSDModel
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
    method: str = "least_squares"
    covariance: np.ndarray = None
    intervals: dict = field(default_factory=dict)
    interval_level: float = 0.95
    interval_on_bound: tuple = ()
    crowd_model: str = "smeared"
    crowd_model_details: tuple = ()
    interval_method: str = None
    bootstrap_samples: np.ndarray = None
    crowd: Crowd | None = None
    density_uncertainty: float = 0.0
    density_sensitivity: dict = field(default_factory=dict)
    density_share: dict = field(default_factory=dict)

    def value(self, parameter: str) -> float:
        """The estimated value of a free parameter (an MSD's or the fitted crowd's) [its unit].

        Parameters
        ----------
        parameter : str
            A name of ``free_parameters``.
        """
        if parameter not in self.free_parameters:
            raise ParameterError(f"parameter must be one of {list(self.free_parameters)}, "
                                 f"got {parameter!r}")
        source = self.msd if hasattr(self.msd, parameter) else self.crowd
        return float(getattr(source, parameter))

    @property
    def relative_cost(self) -> float:
        """J(θ̂)/J(no HSI) [-]: the paper's "residual relative to no HSI"."""
        return self.cost / self.cost_no_hsi if self.cost_no_hsi > 0 else np.nan

    @property
    def standard_errors(self) -> dict[str, float]:
        """Parameter → standard error from the sandwich covariance (units of the parameter)."""
        if self.covariance is None:
            return {}
        return {name: float(np.sqrt(max(self.covariance[i, i], 0.0)))
                for i, name in enumerate(self.free_parameters)}

    @property
    def correlation(self) -> np.ndarray | None:
        """Correlation matrix of the free parameters [-], or None."""
        if self.covariance is None:
            return None
        scale = np.sqrt(np.maximum(np.diag(self.covariance), 1e-300))
        return self.covariance / np.outer(scale, scale)

    def interval(self, parameter: str, level: float = 0.95) -> tuple[float, float]:
        """Confidence interval (low, high) of a free parameter.

        The profile interval when it was computed at this level, else the Wald interval
        estimate ± z·SE from the sandwich covariance; both clipped to the search bounds.

        Parameters
        ----------
        parameter : str
            A name of ``free_parameters`` (``"frequency"``, ``"damping_ratio"``, ...).
        level : float
            Confidence level, in (0, 1).
        """
        value = self.value(parameter)
        if not 0 < level < 1:
            raise ParameterError(f"level must lie in (0, 1), got {level!r}")
        if parameter in self.intervals and np.isclose(level, self.interval_level):
            return tuple(self.intervals[parameter])
        if self.covariance is None:
            raise ParameterError("this estimate carries no covariance (interval=None)")
        half = stats.norm.ppf(0.5 + level / 2) * self.standard_errors[parameter]
        low, high = self.bounds[parameter]
        return (max(value - half, low), min(value + half, high))

    def summary(self) -> str:
        """One line per free parameter: its words and unit (:mod:`crowdvib.quantities`), the
        estimate and, with a covariance, its interval at ``interval_level``."""
        lines = []
        for name in self.free_parameters:
            text = f"{describe(name)}: {self.value(name):.4g}"
            if self.covariance is not None:
                low, high = self.interval(name, self.interval_level)
                text += (f" ({self.interval_level:.0%} interval {low:.4g} – {high:.4g})"
                         if np.isfinite([low, high]).all() else
                         " (no interval: the estimate sits on a search bound)")
            lines.append(text)
        return "\n".join(lines)

    def __repr__(self):
        parts = []
        for name in self.free_parameters:
            value = self.value(name)
            text = f"{name}={value:.4g}"
            if name in self.intervals:
                low, high = self.intervals[name]
                text += f" [{low:.4g}, {high:.4g}]"
            parts.append(text)
        return (f"HSIEstimate({', '.join(parts)}, method={self.method!r}, "
                f"J/J_noHSI={self.relative_cost:.3g})")

    @classmethod
    def from_dict(cls, data: dict[str, Any], crowd: Crowd | None = None) -> HSIEstimate:
        """The estimate back from :meth:`to_dict` (a results.json's ``estimate`` and
        ``diagnostics``), holding what that dict holds.

        ``to_dict(from_dict(d)) == d`` (for a dict without ``covariance``, written before it was
        stored, the correlation and standard errors go through the covariance they are rebuilt
        into, equal to round-off); the bootstrap replicates are not stored
        (``bootstrap_samples`` is None).

        Parameters
        ----------
        data : dict
            ``{"estimate": {...}, "method": ..., "cost": ..., ...}`` as :meth:`to_dict` writes.
        crowd : Crowd, optional
            For a dict without its own ``crowd`` (written before crowdvib stored it): the crowd
            the step frequencies were fitted for (density, speed, masses), required when
            ``data`` holds fitted step frequencies, which replace its own.

        Raises
        ------
        ParameterError
            Fitted step frequencies in ``data``, no crowd in it and no ``crowd`` given.
        """
        from dataclasses import replace


        found, free = data["estimate"], tuple(data["free_parameters"])
        msd = MSDModel(found["frequency"], found["damping_ratio"], found["mass_ratio"])
        if isinstance(data.get("crowd"), dict):
            crowd = Crowd.from_dict(data["crowd"])
        elif "step_frequency_mean" in found:
            if crowd is None:
                raise ParameterError("crowd is required: the estimate holds fitted step "
                                     "frequencies, which replace those of the crowd they were "
                                     "fitted for")
            crowd = replace(crowd, step_frequency_mean=found["step_frequency_mean"],
                            step_frequency_std=found["step_frequency_std"])
        else:
            crowd = None
        interval, errors = found.get("interval"), found.get("standard_error")
        covariance = None
        if data.get("covariance") is not None:
            covariance = np.asarray(data["covariance"], dtype=float)
        elif errors is not None and data.get("correlation") is not None:
            # a dict written before the covariance was stored: equal to round-off
            scale = np.array([errors[name] for name in free])
            covariance = np.asarray(data["correlation"], dtype=float) * np.outer(scale, scale)
        ratio = data.get("level_ratio")
        density = data.get("density") or {}
        return cls(
            msd=msd, cost=data["cost"], cost_no_hsi=data["cost_no_hsi"],
            n_evaluations=data["n_evaluations"], success=data["success"],
            active_bounds=tuple(data["active_bounds"]), free_parameters=free,
            bounds={k: tuple(v) for k, v in data["bounds"].items()}, band=tuple(data["band"]),
            output_names=tuple(data["output_names"]),
            output_weights=np.asarray(data["output_weights"], dtype=float),
            starts=tuple(dict(s) for s in data.get("starts", ())),
            message=data.get("message", ""),
            level_ratio=None if ratio is None else np.asarray(ratio, dtype=float),
            method=data.get("method", "least_squares"), covariance=covariance,
            intervals={} if not interval else {  # null: no interval (estimate on a bound)
                name: tuple(np.nan if v is None else v for v in interval[name]) for name in free},
            interval_level=interval["level"] if interval else 0.95,
            interval_on_bound=tuple(data.get("interval_on_bound", ())),
            crowd_model=data.get("crowd_model", "smeared"),
            crowd_model_details=tuple(dict(d) for d in data.get("crowd_model_details", ())),
            interval_method=interval.get("method") if interval else None, crowd=crowd,
            density_uncertainty=float(density.get("uncertainty", 0.0)),
            density_sensitivity=dict(density.get("sensitivity", {})),
            density_share=dict(density.get("variance_share", {})))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict; the estimate sits under ``"estimate"`` with its interval."""
        estimate = self.msd.to_dict()
        if self.crowd is not None:
            estimate.update(step_frequency_mean=self.crowd.step_frequency_mean,
                            step_frequency_std=self.crowd.step_frequency_std)
        if self.covariance is not None:
            estimate["interval"] = {name: list(self.interval(name, self.interval_level))
                                    for name in self.free_parameters}
            estimate["interval"]["level"] = self.interval_level
            estimate["interval"]["method"] = self.interval_method or "wald"
            estimate["standard_error"] = self.standard_errors
        return {
            "estimate": estimate, "method": self.method, "crowd_model": self.crowd_model,
            "crowd_model_details": [dict(d) for d in self.crowd_model_details],
            "correlation": None if self.covariance is None else self.correlation.tolist(),
            "covariance": None if self.covariance is None else self.covariance.tolist(),
            "interval_on_bound": list(self.interval_on_bound),
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
            "density": {"uncertainty": self.density_uncertainty,
                        "sensitivity": dict(self.density_sensitivity),
                        "variance_share": dict(self.density_share)},
            **({} if self.crowd is None else {"crowd": self.crowd.to_dict()}),
        }
