"""Gaussian records with a given PSD: "measurements" whose Welch statistics are exact.

A stationary Gaussian process sampled at f_s over T = N/f_s is synthesised in the frequency
domain (spectral representation, docs: theory, Correlation of neighbouring Welch ordinates): each FFT bin k of the one-sided PSD
G gets an independent complex normal coefficient with E|Z_k|² = G(f_k) Δf N²/2 (Δf = 1/T), so
that Σ_k G(f_k) Δf is the variance (Parseval). Welch estimates of such records have the χ²_ν
scatter *and* the bin-to-bin correlation of real measurements, which
:func:`crowdvib.signals.synthetic_welch_psd` (independent bins) does not.
"""

import numpy as np

from .._validation import check_positive
from ..errors import ParameterError

__all__ = ["record_frequencies", "gaussian_record"]


def record_frequencies(duration, sample_rate):
    """The FFT grid k/T, k = 0 … N/2, of a record of ``duration`` [s] at ``sample_rate`` [Hz]."""
    duration = check_positive("duration", duration, unit="s")
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    n_samples = int(round(duration * sample_rate))
    if n_samples < 2 or n_samples % 2:
        raise ParameterError(f"duration × sample_rate must be an even number of samples >= 2, "
                             f"got {duration:g} s × {sample_rate:g} Hz = {n_samples}")
    return np.arange(n_samples // 2 + 1) * sample_rate / n_samples


def gaussian_record(psd, sample_rate, rng=None, *, coherent: bool = False) -> np.ndarray:
    """Gaussian records of the one-sided PSDs ``psd`` (rows) → (n_rows, N).

    Parameters
    ----------
    psd : array_like, shape (n_rows, N/2 + 1) or (N/2 + 1,)
        One-sided PSD [unit²/Hz] on :func:`record_frequencies` of the record.
    sample_rate : float
        [Hz].
    rng : None, int or numpy.random.Generator
    coherent : bool
        False: the rows are independent of each other. True: every row is the same unit record
        shaped by its own PSD (the same random coefficients), i.e. fully coherent rows with zero
        phase between them — outputs driven by one mode.

    Returns
    -------
    ndarray, shape (n_rows, N)
        One record per row.
    """
    values = np.atleast_2d(np.asarray(psd, dtype=float))
    if not np.all(np.isfinite(values)) or np.any(values < 0):
        raise ParameterError("psd must be finite and >= 0")
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    rng = np.random.default_rng(rng)
    n_samples = 2 * (values.shape[1] - 1)
    spacing = sample_rate / n_samples
    draws = (1, values.shape[1]) if coherent else values.shape
    sigma = np.sqrt(values * spacing * n_samples**2 / 4.0)
    coefficients = sigma * (rng.standard_normal(draws) + 1j * rng.standard_normal(draws))
    # The 0 Hz and Nyquist bins are real: E|Z|² = G Δf N² there, all of it in the real part.
    coefficients[:, [0, -1]] = (np.sqrt(values[:, [0, -1]] * spacing) * n_samples
                                * rng.standard_normal((draws[0], 2)))
    return np.fft.irfft(coefficients, n=n_samples, axis=-1)
