"""Gaussian records with a given PSD: "measurements" whose Welch statistics are exact.

A stationary Gaussian process sampled at f_s over T = N/f_s is synthesised in the frequency
domain (spectral representation, docs: theory, Correlation of neighbouring Welch ordinates): each FFT bin k of the one-sided PSD
G gets an independent complex normal coefficient with E|Z_k|² = G(f_k) Δf N²/2 (Δf = 1/T), so
that Σ_k G(f_k) Δf is the variance (Parseval). Welch estimates of such records have the χ²_ν
scatter *and* the bin-to-bin correlation of real measurements, which
:func:`crowdvib.signals.synthetic_welch_psd` (independent bins) does not.

Several outputs with a given cross-spectral matrix S(f) (:func:`gaussian_cross_record`): the
coefficient vector of bin k is F_k ζ with F_k F_kᴴ = S(f_k) and ζ independent complex normals, so
E[Z_a conj(Z_b)] ∝ S_ab(f_k); the Welch cross-spectral matrices of such records have the complex
Wishart scatter of a measurement (docs: theory, The cross-spectral matrix).
"""

import numpy as np

from .._validation import check_positive
from ..errors import ParameterError

__all__ = ["record_frequencies", "gaussian_record", "gaussian_cross_record"]


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


def _hermitian_factor(matrices):
    """F with F Fᴴ = S for a stack of Hermitian positive semi-definite S (..., p, p).

    From the eigen-decomposition rather than Cholesky, so that a singular S (one mode seen by
    several outputs: rank 1) is factored too; round-off eigenvalues below zero are cut to 0.
    """
    values, vectors = np.linalg.eigh(matrices)
    return vectors * np.sqrt(np.maximum(values, 0.0))[..., np.newaxis, :]


def gaussian_cross_record(cross, sample_rate, rng=None) -> np.ndarray:
    """Gaussian records of several outputs with the one-sided cross-spectral matrix ``cross``.

    Parameters
    ----------
    cross : array_like of complex, shape (n_outputs, n_outputs, N/2 + 1)
        S_ab(f) = E[X_a conj(X_b)] [unit²/Hz] on :func:`record_frequencies` of the record,
        Hermitian positive semi-definite at every frequency (its diagonal the PSDs).
    sample_rate : float
        [Hz].
    rng : None, int or numpy.random.Generator

    Returns
    -------
    ndarray, shape (n_outputs, N)
        Records whose FFT coefficients Z satisfy E[Z_a conj(Z_b)] = S_ab Δf N²/2 (Δf N² at 0 Hz
        and at the Nyquist frequency, where they are real), as :func:`gaussian_record` for one
        output.
    """
    values = np.asarray(cross, dtype=complex)
    if values.ndim != 3 or values.shape[0] != values.shape[1] or values.shape[2] < 2:
        raise ParameterError(f"cross must have shape (n_outputs, n_outputs, n_frequencies >= 2), "
                             f"got {values.shape}")
    if not np.all(np.isfinite(values)):
        raise ParameterError("cross must be finite")
    matrices = np.moveaxis(values, -1, 0)                      # (n_f, p, p)
    asymmetry = np.abs(matrices - np.conj(np.swapaxes(matrices, 1, 2))).max()
    scale = np.abs(matrices).max()
    if asymmetry > 1e-9 * scale:
        raise ParameterError(f"cross must be Hermitian at every frequency (S_ba = conj S_ab), "
                             f"got a mismatch of {asymmetry:.3g} against entries up to "
                             f"{scale:.3g}")
    if np.any(np.einsum("fii->fi", matrices).real < 0):
        raise ParameterError("cross must have a diagonal (the PSDs) >= 0")
    # The 0 Hz and Nyquist bins of a real record are real: their factor comes from Re S.
    matrices = matrices.copy()
    matrices[[0, -1]] = matrices[[0, -1]].real
    factor = _hermitian_factor(0.5 * (matrices + np.conj(np.swapaxes(matrices, 1, 2))))
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    rng = np.random.default_rng(rng)
    n_outputs, n_bins = values.shape[0], values.shape[2]
    n_samples = 2 * (n_bins - 1)
    spacing = sample_rate / n_samples
    normal = (rng.standard_normal((n_bins, n_outputs))
              + 1j * rng.standard_normal((n_bins, n_outputs)))
    coefficients = (np.sqrt(spacing * n_samples**2 / 4.0)
                    * np.einsum("fab,fb->af", factor, normal))
    edges = rng.standard_normal((2, n_outputs))
    coefficients[:, [0, -1]] = (np.sqrt(spacing) * n_samples
                                * np.einsum("fab,fb->af", factor[[0, -1]].real, edges))
    return np.fft.irfft(coefficients, n=n_samples, axis=-1)
