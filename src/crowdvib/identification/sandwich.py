"""The estimate's uncertainty: the sandwich covariance of θ̂, with the crowd-size and the stated
density's terms, and the intervals it calibrates (profile or bootstrap).

docs: theory, Sandwich covariance; Profile intervals; The crowd density's uncertainty.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np

from ..errors import BoundWarning
from .bootstrap import bootstrap_estimates, percentile_interval
from .uncertainty import profile_interval, sandwich_covariance

#: The crowd's step-frequency parameters of θ when they are fitted with the MSD.
STEP_PARAMETERS = ("step_frequency_mean", "step_frequency_std")


@dataclasses.dataclass(frozen=True)
class _DensityTerm:
    """The stated density's share of the sandwich (docs: theory, The crowd density's
    uncertainty): its relative standard uncertainty u, the score's move per unit of ln n summed
    over the records (one error common to all), and H⁻¹ (None without a covariance)."""

    uncertainty: float
    shift: np.ndarray | None
    inverse: np.ndarray | None

    @property
    def variance(self):
        """u² s sᵀ: the score variance a density error of relative s.d. u adds."""
        return self.uncertainty**2 * np.outer(self.shift, self.shift)

    def sensitivities(self, names):
        """Parameter → ∂θ̂/∂ln ρ_stated = H⁻¹ s: the estimate's move per unit of the stated
        density's log (×0.1: the move for a density stated 10 % high)."""
        if self.shift is None:
            return {}
        return dict(zip(names, (float(v) for v in self.inverse @ self.shift)))

    def shares(self, names, covariance):
        """Parameter → the fraction of its sandwich variance that the density's uncertainty makes."""
        if self.shift is None or not self.uncertainty > 0:
            return {}
        part = np.diag(self.inverse @ self.variance @ self.inverse)
        return {name: float(p / c) if c > 0 else 0.0
                for name, p, c in zip(names, part, np.diag(covariance))}


def _covariance(parts, parameters, theta, density_uncertainty):
    """Sandwich covariance of θ̂ (independent records: information adds) → (covariance,
    expected Hessian, per-record crowd-size terms, the stated density's term) (docs: theory,
    Sandwich covariance; The crowd density's uncertainty).

    A record's crowd size varies on its own (Poisson: relative variance 1/N); the stated density
    is wrong by one relative error ε ~ N(0, u²) for every record, so its score moves, Σ_r s_r,
    add before they are squared."""
    msd = parameters.msd(theta)
    variance, hessian, occupancies, shift = 0.0, 0.0, [], 0.0
    for objective, measured in parts:
        gradient = _model_gradient(objective, theta, parameters.state, parameters.lower,
                                   parameters.upper)
        occupancies.append(_occupancy(objective, msd, measured))
        part, curvature, move = objective.information(objective.modelled(msd), gradient,
                                                      occupancies[-1])
        variance, hessian = variance + part, hessian + curvature
        if move is not None:
            shift = shift + move
    inverse = np.linalg.pinv(hessian)
    density = _DensityTerm(density_uncertainty, None if np.isscalar(shift) else shift, inverse)
    if density.shift is not None:
        variance = variance + density.variance
    return sandwich_covariance(variance, hessian), hessian, occupancies, density


def _intervals(interval, parts, stacked, parameters, theta, covariance, hessian, occupancies,
               level, n_boot, rng, density, active=()):
    """The intervals the covariance allows → (name → (low, high), ends on a bound, bootstrap
    samples or None); none without a covariance or for ``interval`` "wald" or None.

    A parameter whose estimate sits on a search bound (``active``: "name:side") gets no profile
    interval but NaN ends and a BoundWarning: its profile runs along the bound for minutes and
    says only that the data do not bound it there (issue 35 §2)."""
    intervals, on_bound, samples = {}, (), None
    if covariance is None:
        return intervals, on_bound, samples
    names, lower, upper = parameters.names, parameters.lower, parameters.upper
    if interval == "bootstrap":
        samples = bootstrap_estimates(parts, theta, parameters.state, lower, upper, occupancies,
                                      n_boot, np.random.default_rng(rng),
                                      density_uncertainty=density.uncertainty)
        intervals = {name: percentile_interval(samples[:, i], level)
                     for i, name in enumerate(names)}
    if interval == "profile":
        # The MSD's parameters are profiled; the step frequencies (fitted with the MSD, not the
        # answer sought) keep their Wald interval, half the profile's cost when they are free.
        ends, stuck = [], [side for side in active if side.split(":")[0] not in STEP_PARAMETERS]
        for i, name in enumerate(names):
            if name in STEP_PARAMETERS:
                continue
            if any(side.startswith(f"{name}:") for side in stuck):
                intervals[name] = (np.nan, np.nan)
                continue
            intervals[name], hit = profile_interval(
                lambda values: parameters.misfit(stacked, values), theta, i, lower, upper,
                covariance, hessian, level)
            ends += [f"{name}:{side}" for side, h in zip(("lower", "upper"), hit) if h]
        on_bound = tuple(ends + stuck)
        if stuck:
            warnings.warn(f"no {level:.0%} interval for {', '.join(stuck)} (NaN ends): the "
                          "estimate sits on that search bound, where the data do not bound it; "
                          "check the inputs or widen the bounds", BoundWarning, stacklevel=4)
        if ends:
            warnings.warn(f"the {level:.0%} interval reaches a search bound "
                          f"({', '.join(ends)}): the data do not bound the parameter "
                          "there; widen the bounds or add data", BoundWarning, stacklevel=4)
    return intervals, on_bound, samples


def _occupancy(objective, msd, measured):
    """∂G/∂ln n and the relative variance 1/N of the crowd size a record averages over.

    Poisson arrivals: the record's time-average of the crowd influence Σ φ²(x_k(t)) counts the N
    pedestrians who crossed during it, so its relative variance is 1/N (Campbell's theorem for
    a record much longer than a crossing), N = d·v·B·T for a flow of density d at speed v over a
    walkway of width B (docs: theory, uncertainty). The record length T follows from the Welch
    segments at 50 % overlap.
    """
    crowd = objective.model.crowd
    duration = measured.window_length * (1 + 0.5 * (objective.n_windows - 1))
    crossings = crowd.arrival_rate(objective.model.structure.width) * duration
    if not crossings > 0:
        return None
    step = 1e-3
    up = objective.spectral_model(crowd.with_density(crowd.density * (1 + step)))
    down = objective.spectral_model(crowd.with_density(crowd.density * (1 - step)))
    gradient = (objective.modelled(msd, model=up)
                - objective.modelled(msd, model=down)) / (2 * step)
    return gradient, 1.0 / crossings


def _model_gradient(objective, theta, state, lower, upper):
    """∂G/∂θ at θ by central differences (one-sided at a bound), shape (L, K, n_parameters)."""
    columns = []
    for i in range(theta.size):
        step = 1e-5 * max(abs(theta[i]), 1e-2)
        up, down = theta.copy(), theta.copy()
        up[i] = min(theta[i] + step, upper[i])
        down[i] = max(theta[i] - step, lower[i])
        (msd_up, steps_up), (msd_down, steps_down) = state(up), state(down)
        columns.append((objective.modelled(msd_up, steps=steps_up)
                        - objective.modelled(msd_down, steps=steps_down)) / (up[i] - down[i]))
    return np.stack(columns, axis=-1)
