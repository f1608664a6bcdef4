"""The comfort measure of one crowd state over a window, by the spectral route (docs: theory,
A year of comfort).

A stationary crowd of density d gives a stationary response whose one-sided acceleration PSD
G(f) is :func:`crowdvib.response_psd` (no physics is added here). Over a window of T = 600 s
the comfort measures are the peak |a| and the largest 1-s running RMS, both random: their laws
follow from the spectral moments m_k = ∫ f^k G df of a Gaussian response.

Peak. Crossings of the level ±x by a(t) counted as a Poisson stream (Rice, Davenport 1964):
P(max |a| ≤ x) = exp(−T ν(x)). With ``peak_model="davenport"`` ν(x) = 2 ν0 exp(−η²/2),
η = x/σ, ν0 = sqrt(m2/m0); with ``"vanmarcke"`` (default) the crossings of a narrow-band
response come in clumps, one per excursion of its envelope, and only the first of a clump counts
(Vanmarcke 1975): ν(x) = 2 ν0 exp(−η²/2) (1 − exp(−sqrt(π/2) δ η)) / (1 − exp(−η²/2)),
δ = sqrt(1 − m1²/(m0 m2)) the spread of the spectrum. A footbridge's response is narrow band
(δ ≈ 0.03 on the paper's bridge): the Poisson crossings read its 10-minute median 12–18 % high,
the clumped ones within 1.5 % of the simulator from 0.25 persons/m² on
(accuracy/comfort_validation.py, which also shows where the upper tail parts).

Running RMS. The 1-s running mean square r(t) of a narrow-band response is the mean of its
envelope square A²/2 over the window (the ripple at 2 f0 averages out). A²/2 has the mean σ²
and the autocovariance |Z(u)|², Z(u) = ∫ G(f) e^{2πifu} df (Gaussian process), so r has the
variance (2/τ) ∫_0^τ (1 − u/τ) |Z(u)|² du and its rate the variance 2 (|Z(0)|² − |Z(τ)|²)/τ².
r is read as a translation of a Gaussian process: its marginal a gamma law of those mean and
variance (exponential for τ → 0: the Rayleigh envelope), its level crossings those of the
Gaussian z = Φ⁻¹(F_Γ(r)) at the rate ν_z = σ_ṙ / (2π σ_r).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import special, stats

from .._validation import check_positive
from ..errors import ParameterError
from ..response.frequency_domain.fluctuation import occupancy_cumulants

__all__ = ["WindowLaw", "window_law", "PEAK_MODELS", "peak_cdf", "peak_quantile",
           "running_rms_quantile", "running_rms_cdf", "level_crossing_rate", "running_rms_rate",
           "bisect_level", "GAUSSIAN_TOLERANCE", "THIN_CROWD_WALKERS", "thin_crowd_density",
           "occupancy_shape_factor"]

#: The laws of the window's largest peak: clumped crossings (default) or Poisson crossings.
PEAK_MODELS = ("vanmarcke", "davenport")
#: Spectral and simulated quantiles within this (relative) count as agreeing: the response is
#: Gaussian enough for the spectral route (the issue's target).
GAUSSIAN_TOLERANCE = 0.05
#: A crowd whose effective number of walkers on the walkway is below this is "thin". The
#: occupancy λ = ψ/ψ̄ of mode j has the spread σ_λ = sqrt(κ_j/N) for N walkers expected
#: (Campbell), κ_j = A ∫φ_j⁴ dA / (∫φ_j² dA)² its shape factor: 1.5 for a half sine, more for a
#: mode that moves part of the walkway (a torsion mode, one span of several). N_eff = 1.5 N/κ_j
#: are the walkers of a half-sine mode with that spread. On the paper's bridge (κ = 1.5) the
#: spectral route's upper quantiles part from the simulator's by more than GAUSSIAN_TOLERANCE at
#: N = 15–75 (σ_λ ≥ 0.14) and agree within 2.4 % at N = 112 and 150 (σ_λ ≤ 0.12); on the
#: Waalse-Krook-like bridge's torsion antinode (κ = 2.87) they part at N = 26–104 (σ_λ ≥ 0.17)
#: and agree within 4.3 % at N = 172 (σ_λ = 0.13), where 100 walkers alone would have judged
#: N = 104 spectrally (accuracy/comfort_validation.py; docs: theory, A year of comfort, Where
#: the Gaussian model holds). 100 effective walkers (σ_λ = 0.12) lie between on both bridges.
THIN_CROWD_WALKERS = 100.0
#: κ of a half-sine mode shape over a walkway of uniform width: the shape of THIN_CROWD_WALKERS.
HALF_SINE_SHAPE_FACTOR = 1.5


def occupancy_shape_factor(structure) -> float:
    """max_j κ_j = A ∫φ_j⁴ dA / (∫φ_j² dA)² over the modes of ``structure`` [-]: N σ_λ² of the
    occupancy of its most unevenly loaded mode (Campbell;
    :func:`crowdvib.response.frequency_domain.fluctuation.occupancy_cumulants` at one person/m²)."""

    return float(max(occupancy_cumulants(structure, 1.0, mode, order=2)[1] * structure.area
                     for mode in range(structure.n_modes)))


def thin_crowd_density(structure) -> float:
    """The density [persons/m²] below which a crowd on ``structure`` is thin (where the simulator
    stands in for the spectral route by default, ``[comfort] simulate_below``): fewer than
    :data:`THIN_CROWD_WALKERS` effective walkers on the walkway, N κ_max/1.5 walkers expected
    (:func:`occupancy_shape_factor`: every mode's occupancy spreads by at most that of 100
    walkers on a half-sine mode; never fewer than 100 walkers), over the walkway's area."""
    factor = max(occupancy_shape_factor(structure), HALF_SINE_SHAPE_FACTOR)
    return THIN_CROWD_WALKERS * factor / HALF_SINE_SHAPE_FACTOR / structure.area


@dataclass(frozen=True)
class WindowLaw:
    """The spectral description of one stationary response at one output.

    Attributes
    ----------
    rms : float
        σ = sqrt(m0) [m/s²].
    crossing_rate : float
        ν0 = sqrt(m2/m0), the mean zero up-crossing rate [Hz].
    spread : float
        δ = sqrt(1 − m1²/(m0 m2)) [-] (0: a pure tone).
    ms_std : float
        Standard deviation of the running mean square [(m/s²)²].
    ms_rate : float
        ν_z of the running mean square's translation process [Hz].
    """

    rms: float
    crossing_rate: float
    spread: float
    ms_std: float
    ms_rate: float


def window_law(frequency: np.ndarray, psd: np.ndarray, *, rms_window: float = 1.0) -> WindowLaw:
    """:class:`WindowLaw` of a one-sided acceleration PSD on an even grid starting at 0 Hz.

    Parameters
    ----------
    frequency : ndarray
        f_k = k Δf [Hz].
    psd : ndarray
        G(f_k) [(m/s²)²/Hz], one output.
    rms_window : float
        τ of the running RMS [s].
    """
    frequency, psd = np.asarray(frequency, float), np.asarray(psd, float)
    step = frequency[1] - frequency[0]
    m0 = np.trapezoid(psd, frequency)
    if not m0 > 0:
        return WindowLaw(0.0, 0.0, 0.0, 0.0, 0.0)
    m1 = np.trapezoid(psd * frequency, frequency)
    m2 = np.trapezoid(psd * frequency**2, frequency)
    rate = np.sqrt(m2 / m0)
    spread = float(np.sqrt(max(1.0 - m1**2 / (m0 * m2), 0.0)))
    if not step * rms_window < 0.5:
        raise ParameterError(f"the frequency step must be < 1/(2 rms_window) = "
                             f"{0.5 / rms_window:g} Hz to resolve the running RMS, got {step:g}")
    # Z(u) = ∫ G e^{2πifu} df on the lags u = n/(N Δf) by one FFT (4× padded: lag step
    # 1/(4 f_top), fine for the slowly varying |Z|; the lags reach 1/Δf > 2 τ).
    size = 1 << int(np.ceil(np.log2(4 * psd.size)))
    weights = psd * step
    weights[[0, -1]] *= 0.5                      # the trapezoid rule of m0
    z = np.fft.ifft(weights, n=size) * size      # Σ G_k Δf e^{+2πi k n/N}
    lag = np.arange(size) / (size * step)
    inside = lag <= rms_window
    u, envelope = lag[inside], np.abs(z[inside]) ** 2
    # the window end |Z(τ)|² by interpolation (τ between two lags)
    at_tau = np.interp(rms_window, lag[:inside.sum() + 1], np.abs(z[:inside.sum() + 1]) ** 2)
    u, envelope = np.append(u, rms_window), np.append(envelope, at_tau)
    variance = 2 / rms_window * np.trapezoid((1 - u / rms_window) * envelope, u)
    rate_variance = 2 * (envelope[0] - at_tau) / rms_window**2
    ms_std = float(np.sqrt(max(variance, 0.0)))
    ms_rate = float(np.sqrt(max(rate_variance, 0.0)) / (2 * np.pi * ms_std)) if ms_std else 0.0
    return WindowLaw(float(np.sqrt(m0)), float(rate), spread, ms_std, ms_rate)


def level_crossing_rate(law_rms, law_rate, law_spread, level, peak_model):
    """ν(x) [Hz] of the level x by |a| (arrays broadcast)."""
    eta = np.asarray(level, float) / np.where(law_rms > 0, law_rms, np.inf)
    poisson = 2 * law_rate * np.exp(-eta**2 / 2)
    if peak_model == "davenport":
        return poisson
    # (1 − e^{−q η}) / (1 − e^{−η²/2}) → q sqrt(2/π)... finite as η → 0: use expm1 for both
    clump = -np.expm1(-np.sqrt(np.pi / 2) * law_spread * eta)
    below = -np.expm1(-eta**2 / 2)
    return poisson * np.where(below > 0, clump / np.where(below > 0, below, 1.0), 1.0)


def peak_cdf(level, rms, crossing_rate, spread, duration=600.0, peak_model="vanmarcke"):
    """P(max |a| over ``duration`` ≤ ``level``) (arrays broadcast).

    Parameters
    ----------
    level : array_like
        x [m/s²].
    rms, crossing_rate, spread : array_like
        σ, ν0 and δ of :class:`WindowLaw`.
    duration : float
        T [s].
    peak_model : {"vanmarcke", "davenport"}
    """
    _check_model(peak_model)
    rms = np.asarray(rms, float)
    rate = level_crossing_rate(rms, np.asarray(crossing_rate, float), np.asarray(spread, float),
                          level, peak_model)
    found = np.exp(-duration * rate)
    return np.where(rms > 0, found, 1.0)


def peak_quantile(probability, law: WindowLaw, duration=600.0, peak_model="vanmarcke"):
    """The level x [m/s²] the window's peak stays below with ``probability`` (bisection on
    :func:`peak_cdf`, monotone in x).

    Parameters
    ----------
    probability : array_like
        q, in (0, 1).
    law : WindowLaw
    duration : float
        T [s].
    peak_model : {"vanmarcke", "davenport"}
    """
    if law.rms == 0:
        return np.zeros_like(np.asarray(probability, float))
    return bisect_level(lambda x: peak_cdf(x, law.rms, law.crossing_rate, law.spread, duration,
                                           peak_model), probability, 12 * law.rms)


def bisect_level(cdf, probability, top):
    """The level x in [0, ``top``] where the increasing ``cdf(x)`` reaches ``probability``
    (bisection, elementwise over the probabilities)."""
    probability = np.asarray(probability, float)
    low = np.zeros_like(probability)
    high = np.full_like(probability, top)
    for _ in range(60):                          # 2^-60 of the top: exact in double precision
        middle = (low + high) / 2
        below = cdf(middle) < probability
        low, high = np.where(below, middle, low), np.where(below, high, middle)
    return (low + high) / 2


def _gamma(law):
    """Shape and scale of the running mean square's gamma marginal."""
    mean = law.rms**2
    shape = mean**2 / law.ms_std**2
    return shape, mean / shape


def running_rms_cdf(level, law: WindowLaw, duration=600.0):
    """P(largest running RMS over ``duration`` ≤ ``level``) (translation process).

    Parameters
    ----------
    level : array_like
        [m/s²].
    law : WindowLaw
    duration : float
        T [s].
    """
    level = np.asarray(level, float)
    if law.rms == 0:
        return np.ones_like(level)
    return np.exp(-duration * running_rms_rate(level, law.rms, law.ms_std, law.ms_rate))


def running_rms_rate(level, rms, ms_std, ms_rate):
    """Rate [Hz] at which the running RMS up-crosses ``level``: ν_z exp(−z²/2) of the
    translation process (arrays broadcast; 0 for a state without response, and a constant mean
    square crosses nothing above its RMS and everything below). Below the median (z < 0) the
    rate is held at ν_z, the Poisson crossings' largest: the CDF stays monotone, as the
    quantile's closed form (z_q ≥ 0) takes it."""
    level, rms = np.asarray(level, float), np.asarray(rms, float)
    ms_std, ms_rate = np.asarray(ms_std, float), np.asarray(ms_rate, float)
    spread = ms_std > 0
    mean = rms**2
    shape = np.where(spread, mean**2 / np.where(spread, ms_std, 1.0) ** 2, 1.0)
    scale = np.where(spread, mean / shape, 1.0)
    z = special.ndtri(stats.gamma.cdf(level**2, shape, scale=scale))
    rate = ms_rate * np.exp(-np.maximum(z, 0.0) ** 2 / 2)
    constant = np.where(level >= rms, 0.0, np.inf)
    return np.where(rms > 0, np.where(spread, rate, constant), 0.0)


def running_rms_quantile(probability, law: WindowLaw, duration=600.0):
    """The level [m/s²] the largest running RMS stays below with ``probability``: the
    translation of z_q = sqrt(2 ln(ν_z T / −ln q)), the Poisson crossings' quantile.

    Parameters
    ----------
    probability : array_like
        q, in (0, 1).
    law : WindowLaw
    duration : float
        T [s].
    """
    probability = np.asarray(probability, float)
    if law.rms == 0:
        return np.zeros_like(probability)
    if law.ms_std == 0:
        return np.full_like(probability, law.rms)
    shape, scale = _gamma(law)
    z = np.sqrt(2 * np.log(np.maximum(duration * law.ms_rate / -np.log(probability), 1.0)))
    return np.sqrt(stats.gamma.ppf(special.ndtr(z), shape, scale=scale))


def _check_model(peak_model):
    if peak_model not in PEAK_MODELS:
        raise ParameterError(f"peak_model must be one of {list(PEAK_MODELS)}, got "
                             f"{peak_model!r}")


def check_duration(duration):
    """The window's duration [s], checked."""
    return check_positive("duration", duration, unit="s")
