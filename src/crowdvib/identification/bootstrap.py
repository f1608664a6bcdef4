"""Parametric bootstrap of an estimate (docs: theory, Parametric bootstrap).

Each replicate is a Welch PSD of a Gaussian record whose PSD is the fitted model's: the record is
synthesised on the FFT grid of a record as long as the measured one
(:func:`crowdvib.signals.synthesis.gaussian_record`) and averaged with the measured Welch segments,
so the replicate carries the χ²_ν scatter *and* the correlation of neighbouring bins of a real
measurement. Its deviation from the model is then widened by the record's measured dispersion
φ (the scatter its own segments show beyond a Gaussian record) and shifted by a draw of the
crowd size N of the record (relative variance 1/N), the two terms the sandwich covariance has.
Refitting every replicate from the estimate gives the bootstrap law of θ̂; the interval is its
percentile interval. For the Wishart likelihood of several outputs the replicate is the Welch
cross-spectral matrix of a multi-output Gaussian record with the fitted model's matrix
(:func:`crowdvib.signals.synthesis.gaussian_cross_record`), widened by the outputs' mean
dispersion and kept positive definite.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ..signals.synthesis import gaussian_cross_record, gaussian_record
from ..signals.welch import welch_psd
from .trust_region import trust_region_fit

__all__ = ["bootstrap_estimates", "percentile_interval"]

#: Kernel reach of the Welch expectation beyond the band [bins of 1/T]: ordinates at the band
#: edge see the record's PSD this far out (the spectral model uses 8).
_REACH_BINS = 10
#: Replicate ordinates are kept above this fraction of the model (a dispersion far above 1 can
#: push the widened deviation below zero, which no PSD can be).
_FLOOR = 0.02


class _Replicates:
    """Draws of one record's Welch PSD on its objective's bins, around a fitted model."""

    def __init__(self, objective, measured, msd, occupancy):
        self.objective = objective
        window, self.n_windows = measured.window_length, objective.n_windows
        top = objective.frequency[-1] + _REACH_BINS / window
        # Samples per window: a multiple of 4, at least 2·top·T, so that the 50 %-overlapped
        # segments tile a record of an even number of samples exactly.
        per_window = 4 * int(np.ceil(top * window / 2))
        self.sample_rate = per_window / window
        n_samples = per_window * (self.n_windows + 1) // 2
        self.grid = np.arange(n_samples // 2 + 1) * self.sample_rate / n_samples
        # The Wishart likelihood draws the cross-spectral matrix, with the records' coherence
        # (docs: theory, The likelihood of several outputs); otherwise fully coherent PSDs.
        self.cross = objective.wishart is not None
        exact = objective.exact_model(self.grid)
        self.exact = exact.cross_psd_array(msd) if self.cross else exact.psd_array(msd)
        self.window = window
        self.index = np.rint(objective.frequency * window).astype(int)
        # Welch expectation on the bins, and the level that undoes the objective's normalisation
        self.expected = (objective.model.cross_psd_array(msd) if self.cross
                         else objective.model.psd_array(msd))
        level = objective.level
        self.level = (np.sqrt(np.outer(level, level))[..., np.newaxis] if self.cross
                      else level[:, np.newaxis])
        self.spread = np.sqrt(objective.dispersion.mean(axis=0) if self.cross
                              else objective.dispersion)
        self.occupancy = occupancy

    def draw(self, rng, density_error=0.0):
        """One replicate; ``density_error``: the relative error of the stated density common to
        every record of this replicate (it moves the ordinates as a larger crowd would)."""
        if self.cross:
            record = gaussian_cross_record(self.exact, self.sample_rate, rng=rng)
            gaussian = welch_psd(record, self.sample_rate, window_length=self.window,
                                 cross=True).cross[..., self.index]
        else:
            record = gaussian_record(self.exact, self.sample_rate, rng=rng, coherent=True)
            gaussian = welch_psd(record, self.sample_rate, window_length=self.window).psd
            gaussian = gaussian[:, self.index]
        replicate = self.expected + self.spread * (gaussian - self.expected)
        if self.occupancy is not None:
            gradient, variance = self.occupancy
            replicate = replicate + ((rng.standard_normal() * np.sqrt(variance) + density_error)
                                     * gradient * self.level)
        if self.cross:
            return _floor_matrices(replicate, self.expected)
        return np.maximum(replicate, _FLOOR * self.expected)


def _floor_matrices(replicate, expected):
    """Hermitian replicates (p, p, K) kept positive definite: whitened by the expectation
    (C⁻¹ R C⁻ᴴ, C Cᴴ = E), their eigenvalues are held above ``_FLOOR``, as one ordinate is held
    above ``_FLOOR`` times its expectation. A tiny ridge (1e-9 of the trace) lets a singular
    expectation (one mode: rank 1) be whitened; the lift it allows there is of that size."""
    matrices, model = np.moveaxis(replicate, -1, 0), np.moveaxis(expected, -1, 0)
    ridge = 1e-9 * np.trace(model, axis1=1, axis2=2).real / model.shape[-1]
    factor = np.linalg.cholesky(model + ridge[:, np.newaxis, np.newaxis] * np.eye(model.shape[-1]))
    half = np.linalg.solve(factor, matrices)
    whitened = np.linalg.solve(factor, np.conj(np.swapaxes(half, 1, 2)))
    relative, basis = np.linalg.eigh(whitened)
    if np.all(relative >= _FLOOR):
        return replicate
    whitened = (basis * np.maximum(relative, _FLOOR)[:, np.newaxis, :]) @ np.conj(
        np.swapaxes(basis, 1, 2))
    return np.moveaxis(factor @ whitened @ np.conj(np.swapaxes(factor, 1, 2)), 0, -1)


def bootstrap_estimates(parts: Sequence[tuple], theta: np.ndarray, state: Callable,
                        lower: np.ndarray, upper: np.ndarray, occupancies: Sequence,
                        n_boot: int, rng: np.random.Generator, *,
                        density_uncertainty: float = 0.0) -> np.ndarray:
    """θ* of ``n_boot`` parametric-bootstrap replicates → array (n_boot, n_parameters).

    Parameters
    ----------
    parts : list of (PSDObjective, ResponsePSD)
        The record(s) of the estimate, each a Welch estimate (``n_windows`` and
        ``window_length`` known).
    theta : ndarray
        The estimate (free parameters), the model the replicates are drawn from and the start
        of every refit.
    state : callable
        θ → (MSDModel, (μ_fs, σ_fs) or None when the step frequencies are held).
    lower, upper : ndarray
        Search bounds.
    occupancies : list
        Per record, (∂G/∂ln n, 1/N) of the crowd-size term, or None.
    n_boot : int
        Number of replicates.
    rng : numpy.random.Generator
    density_uncertainty : float
        Relative standard uncertainty of the stated density: each replicate draws one error of
        it for all its records (docs: theory, The crowd density's uncertainty).
    """
    msd, _ = state(theta)       # each objective's model is already the fitted crowd's
    draws = [_Replicates(objective, measured, msd, occupancy)
             for (objective, measured), occupancy in zip(parts, occupancies)]
    start = np.clip(theta, lower + 1e-3 * (upper - lower), upper - 1e-3 * (upper - lower))
    estimates = np.empty((n_boot, theta.size))
    for b in range(n_boot):
        error = density_uncertainty * rng.standard_normal() if density_uncertainty else 0.0
        objectives = [d.objective.with_target(d.draw(rng, error)) for d in draws]

        def residuals(values, objectives=objectives):
            candidate, steps = state(values)
            return np.concatenate([o.residuals(candidate, steps=steps) for o in objectives])

        estimates[b] = trust_region_fit(residuals, start, (lower, upper)).x
    return estimates


def percentile_interval(samples: np.ndarray, level: float) -> tuple[float, float]:
    """(low, high): the (1 − level)/2 and (1 + level)/2 quantiles of the replicates."""
    low, high = np.quantile(samples, [(1 - level) / 2, (1 + level) / 2])
    return float(low), float(high)
