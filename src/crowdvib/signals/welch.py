"""Signal processing of acceleration records: low-pass filtering and Welch PSDs (docs: theory, Welch PSDs, filters and convergence).

Also the two facts the spectral model needs to mimic a measured PSD: the power gain of the
zero-phase filter and the expectation kernel of a Hann-window Welch estimate (docs: theory, What a Welch estimate sees: the expectation kernel).
Signals have time on the last axis: (n_channels, n_samples).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike
from scipy import signal as _signal

from .._validation import as_float_array, check_fraction, check_names, check_optional, check_positive
from ..errors import DataError, ParameterError
from .lowpass import LowPassFilter
from .spectrum import ResponsePSD

__all__ = ["LowPassFilter", "welch_psd", "welch_kernel", "welch_segment_count",
           "welch_degrees_of_freedom", "welch_bin_correlation", "synthetic_welch_psd"]


def welch_kernel(offset: ArrayLike, window_length: float) -> np.ndarray:
    """Expectation kernel of a Hann-window Welch PSD estimate [1/Hz] (docs: theory, What a Welch estimate sees: the expectation kernel).

    E[Ĝ](f) = ∫ G(ν) K(f − ν) dν with K(ν) = |W_T(ν)|² / ∫ w², the continuous Hann window
    w(t) = ½(1 − cos 2πt/T) on [0, T]: K(ν) = (8T/3) [½ sinc(νT) + ¼ sinc(νT − 1) + ¼ sinc(νT + 1)]²,
    which has unit area (Parseval).

    Parameters
    ----------
    offset : array_like
        Frequency offsets f − ν [Hz].
    window_length : float
        Segment length T [s].
    """
    x = np.asarray(offset, dtype=float) * window_length
    # The three sincs share sin(πx) up to sign: ½ sinc x + ¼ sinc(x−1) + ¼ sinc(x+1)
    # = sin(πx) / (2πx(1 − x²)), with the removable limits ½ at x = 0 and ¼ at x = ±1.
    with np.errstate(divide="ignore", invalid="ignore"):
        amplitude = np.sin(np.pi * x) / (2 * np.pi * x * (1.0 - x * x))
    amplitude = np.where(np.abs(x) < 1e-9, 0.5, amplitude)
    amplitude = np.where(np.abs(np.abs(x) - 1.0) < 1e-9, 0.25, amplitude)
    return 8.0 * window_length / 3.0 * amplitude**2


def welch_segment_count(n_samples: int, segment_samples: int, overlap: float = 0.5) -> int:
    """Number of Welch segments of ``segment_samples`` in a record of ``n_samples``.

    Parameters
    ----------
    n_samples : int
        Samples in the record.
    segment_samples : int
        Samples in a segment.
    overlap : float
        Overlap of consecutive segments, fraction of a segment, in [0, 1).

    Returns
    -------
    int

    Examples
    --------
    >>> from crowdvib.signals import welch_segment_count
    >>> welch_segment_count(6000, 1000)    # 60 s at 100 Hz, T = 10 s, 50 % overlap
    11
    """
    step = segment_samples - int(segment_samples * overlap)
    return 0 if n_samples < segment_samples else 1 + (n_samples - segment_samples) // step


def channel_names(output_names, n_channels):
    """The channels' names: ``output_names`` checked against the count, or ch0, ch1, …"""
    names = (tuple(f"ch{i}" for i in range(n_channels)) if output_names is None
             else check_names("output_names", output_names, allow_one=False))
    if len(names) != n_channels:
        raise ParameterError(
            f"output_names must name every channel ({n_channels}), got {len(names)}")
    return names


def segment_periodograms(data, sample_rate, segment, overlap):
    """Frequencies [Hz] and the one-sided periodograms of every Welch segment, shape
    (n_channels, n_frequencies, n_segments): Hann window, constant detrend, density scaling,
    as ``scipy.signal.welch`` averages them."""
    overlap = check_fraction("overlap", overlap)
    frequency, _, periodograms = _signal.spectrogram(
        data, fs=sample_rate, window="hann", nperseg=segment, noverlap=int(segment * overlap),
        detrend="constant", return_onesided=True, scaling="density", mode="psd", axis=-1)
    return frequency, periodograms


def welch_psd(signals: ArrayLike, sample_rate: float, *, window_length: float,
              overlap: float = 0.5, output_names: Sequence[str] | None = None,
              lowpass: LowPassFilter | None = None, cross: bool = False) -> ResponsePSD:
    """One-sided Welch PSD of acceleration records → :class:`ResponsePSD` (docs: theory, Welch PSDs, filters and convergence).

    Hann window of length T, constant detrend per segment, ``scaling='density'``: the result
    G(f) integrates to the variance over 0…Nyquist [(m/s²)²/Hz].

    Parameters
    ----------
    signals : array_like, shape (n_channels, n_samples) or (n_samples,)
        Accelerations [m/s²].
    sample_rate : float
        Sample rate [Hz].
    window_length : float
        Segment length T [s]; frequency resolution 1/T.
    overlap : float
        Overlap of consecutive segments as a fraction of T, in [0, 1).
    output_names : sequence of str, optional
        Channel names; default ``ch0``, ``ch1``, ….
    lowpass : LowPassFilter, optional
        Applied (zero-phase) before the PSD and recorded in the result, so a model can apply the
        same filter.
    cross : bool
        Also keep the cross-spectral matrix S_ab = mean over segments of X_a conj(X_b), with the
        same window, detrend and scaling (``ResponsePSD.cross``; docs: theory, The
        cross-spectral matrix): what the likelihood of several coherent outputs needs.

    See Also
    --------
    crowdvib.signals.psd_convergence : how the PSD settles as the record grows.
    crowdvib.response_psd : the model it is compared with (``welch_window_length``).
    crowdvib.estimate_hsi : the MSD from the PSD.

    References
    ----------
    P. D. Welch, "The use of fast Fourier transform for the estimation of power spectra: a method
    based on time averaging over short, modified periodograms", *IEEE Transactions on Audio and
    Electroacoustics* 15(2):70–73, 1967.

    J. S. Bendat and A. G. Piersol, *Random Data: Analysis and Measurement Procedures*, 4th ed.,
    Wiley, 2010. PSD conventions and the statistics of averaged spectra.

    The theory pages cite them (docs: theory, References).

    Examples
    --------
    A sine of amplitude 1 m/s² at 2 Hz, 60 s at 100 Hz, in segments of T = 10 s:

    >>> import numpy as np
    >>> from crowdvib import welch_psd
    >>> t = np.arange(6000) / 100.0
    >>> psd = welch_psd(np.sin(2 * np.pi * 2.0 * t), 100.0, window_length=10.0)
    >>> psd
    ResponsePSD(['ch0'], 501 frequencies 0–50 Hz, T = 10 s, 11 windows, source='welch')
    >>> float(psd.peak_frequency()[0]), round(float(psd.rms()[0]), 3)   # RMS 1/√2
    (2.0, 0.707)
    """
    data = as_float_array("signals", signals)
    data = np.atleast_2d(data)
    if data.ndim != 2:
        raise ParameterError(f"signals must have shape (n_channels, n_samples), got {data.shape}")
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    window_length = check_positive("window_length", window_length, unit="s")
    segment = int(round(window_length * sample_rate))
    if segment < 8:
        raise ParameterError(
            f"window_length × sample_rate must give at least 8 samples, got {segment}")
    if data.shape[1] < segment:
        raise DataError(
            f"record of {data.shape[1] / sample_rate:g} s is shorter than one window of "
            f"{window_length:g} s")
    names = channel_names(output_names, data.shape[0])
    if check_optional("lowpass", lowpass, LowPassFilter) is not None:
        if abs(lowpass.sample_rate - sample_rate) > 1e-9 * sample_rate:
            raise ParameterError(
                f"lowpass.sample_rate must equal sample_rate {sample_rate:g} Hz, "
                f"got {lowpass.sample_rate:g} Hz")
        data = lowpass.apply(data)
    # The segments' periodograms (what scipy.signal.welch averages), kept to measure their
    # scatter as well as their mean.
    frequency, periodograms = segment_periodograms(data, sample_rate, segment, overlap)
    psd = periodograms.mean(axis=-1)
    n_windows = periodograms.shape[-1]
    return ResponsePSD(frequency=frequency, psd=psd, output_names=names,
                       window_length=segment / sample_rate, n_windows=n_windows,
                       lowpass=lowpass, source="welch",
                       dispersion=_dispersion(periodograms, psd, overlap),
                       cross=_cross_spectra(data, sample_rate, segment, overlap, psd)
                       if cross else None)


def _cross_spectra(data, sample_rate, segment, overlap, psd):
    """The Welch cross-spectral matrix, shape (n_channels, n_channels, n_frequencies).

    scipy's complex spectrogram with density scaling holds Z with |Z|² the two-sided periodogram;
    the one-sided density doubles every bin but 0 Hz and (for an even segment) the Nyquist bin,
    as ``welch`` does. The diagonal is set to ``psd`` itself (equal up to round-off).
    """
    frequency, _, spectra = _signal.spectrogram(
        data, fs=sample_rate, window="hann", nperseg=segment, noverlap=int(segment * overlap),
        detrend="constant", return_onesided=True, scaling="density", mode="complex", axis=-1)
    factor = np.full(frequency.size, 2.0)
    factor[0] = 1.0
    if segment % 2 == 0:
        factor[-1] = 1.0
    cross = np.einsum("afs,bfs->abf", spectra, spectra.conj()) * (factor / spectra.shape[-1])
    index = np.arange(data.shape[0])
    cross[index, index] = psd
    return cross


#: Segment lags over which the periodograms of a record are taken as correlated (the Hann
#: overlap at lag 1, a crowd crossing the deck in tens of seconds over the next few).
DISPERSION_LAGS = 3
#: Bins on each side over which the measured dispersion is averaged (its noise falls ~3×).
DISPERSION_SMOOTHING = 4


def _dispersion(periodograms, psd, overlap):
    """Measured variance of each Welch ordinate over its χ²_ν value, per bin (ResponsePSD).

    Var(Ĝ) = (γ₀ + 2 Σ_j (1 − j/K) γ_j)/K from the autocovariances γ_j of the segments'
    periodograms over segment lags j ≤ ``DISPERSION_LAGS`` (a batch estimate: whatever makes
    the segments scatter — the χ² of a Gaussian record, a changing crowd — is in it; the bias of
    centring on the sample mean, a factor 1 − (2L + 1)/K, is undone), divided
    by (2/ν) Ĝ² and averaged over ±``DISPERSION_SMOOTHING`` bins. None with fewer than 8
    segments, too few to tell.
    """
    k = periodograms.shape[-1]
    if k < 8:
        return None
    deviation = periodograms - psd[..., np.newaxis]
    variance = np.mean(deviation**2, axis=-1)
    lags = min(DISPERSION_LAGS, k - 1)
    for lag in range(1, lags + 1):
        covariance = np.sum(deviation[..., lag:] * deviation[..., :-lag], axis=-1) / k
        variance = variance + 2 * (1 - lag / k) * covariance
    return dispersion_ratio(variance, psd, k, overlap)


def dispersion_ratio(variance, psd, k, overlap):
    """The tail of :func:`_dispersion` from the batch variance γ₀ + 2 Σ_j (1 − j/K) γ_j of
    ``k`` >= 8 segments (also reached from running sums, ``crowdvib.simulate_psd``)."""
    lags = min(DISPERSION_LAGS, k - 1)
    # Centring on the sample mean biases each of the 2L + 1 terms by −γ₀/K: undo it.
    variance = variance / (1 - (2 * lags + 1) / k)
    reference = 2.0 / welch_degrees_of_freedom(k, overlap) * psd**2
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(reference > 0, np.maximum(variance / k, 0.0) / reference, 1.0)
    width = 2 * DISPERSION_SMOOTHING + 1
    padded = np.pad(ratio, [(0, 0), (DISPERSION_SMOOTHING, DISPERSION_SMOOTHING)], mode="edge")
    kernel = np.ones(width) / width
    return np.array([np.convolve(row, kernel, mode="valid") for row in padded])


def _segment_pair_sums(n_windows, overlap, max_lag):
    """Σ over the segment pairs (i, j) of a Welch average of |Σ_t w(t) w(t + Δ_ij) e^{−2πi d t/N}|²
    / (Σ_t w²)², for bin offsets d = 0 … ``max_lag`` (Hann window w, segment offsets Δ_ij).

    For Gaussian data this is the covariance of the averaged periodograms d bins apart, in units
    of G²/K² (white-noise limit; docs: theory, Correlation of neighbouring Welch ordinates).
    """
    k = int(n_windows)
    if k < 1:
        raise ParameterError(f"n_windows must be >= 1, got {n_windows!r}")
    samples = 1024
    window = _signal.get_window("hann", samples)
    step = samples - int(samples * overlap)
    phases = np.exp(-2j * np.pi * np.outer(np.arange(max_lag + 1), np.arange(samples)) / samples)
    total = np.zeros(max_lag + 1)
    for j in range(k):
        lag = j * step
        if lag >= samples:
            break
        product = np.zeros(samples)
        product[:samples - lag] = window[:samples - lag] * window[lag:]
        pairs = k if j == 0 else 2 * (k - j)
        total += pairs * np.abs(phases @ product) ** 2
    return total / np.dot(window, window) ** 2


def welch_degrees_of_freedom(n_windows: int, overlap: float = 0.5) -> float:
    """Equivalent degrees of freedom ν of a Hann-window Welch estimate of ``n_windows`` segments.

    ν = 2K / (1 + 2 Σ_j (1 − j/K) ρ_j), ρ_j the squared normalised overlap correlation of
    the window at a lag of j segment steps (Welch 1967; for Hann at 50 % overlap ρ₁ = 1/36).
    Each PSD ordinate is then distributed as G·χ²_ν/ν.

    Parameters
    ----------
    n_windows : int
        Segments averaged, K >= 1.
    overlap : float
        Overlap of consecutive segments, fraction of a segment, in [0, 1).

    Returns
    -------
    float
        ν: 2 for one segment, about 1.9 K for many at 50 % overlap.

    References
    ----------
    P. D. Welch, "The use of fast Fourier transform for the estimation of power spectra: a method
    based on time averaging over short, modified periodograms", *IEEE Trans. Audio
    Electroacoust.* 15(2):70–73, 1967.

    Examples
    --------
    >>> from crowdvib.signals import welch_degrees_of_freedom
    >>> round(float(welch_degrees_of_freedom(10)), 2)
    19.05
    """
    return 2.0 * int(n_windows) ** 2 / _segment_pair_sums(n_windows, overlap, 0)[0]


def welch_bin_correlation(n_windows: int, overlap: float = 0.5, max_lag: int = 3) -> np.ndarray:
    """Correlation of Welch PSD ordinates d = 0 … ``max_lag`` bins apart (white-noise limit).

    For Gaussian data the periodogram covariance of segments i, j at bins k, k + d is
    |Σ_t w(t) w(t + Δ_ij) e^{−2πi d t/N}|², Δ_ij the segments' offset; summed over the segment
    pairs of the average and normalised by d = 0 (docs: theory, Correlation of neighbouring Welch ordinates). For one Hann
    segment ρ(1) = (2/3)² = 4/9 and ρ(2) = (1/6)² = 1/36.

    Returns
    -------
    ndarray, shape (max_lag + 1,)
        ρ(0) = 1, ρ(1), …
    """
    sums = _segment_pair_sums(n_windows, overlap, max_lag)
    return sums / sums[0]


def synthetic_welch_psd(expected: ResponsePSD, n_windows: int,
                        rng: int | np.random.Generator | None = None) -> ResponsePSD:
    """A random PSD with the scatter of a Welch estimate around its expectation.

    Each ordinate is drawn as E[Ĝ]·χ²_ν/ν with ν from :func:`welch_degrees_of_freedom`
    (independent between bins — real Welch bins are mildly correlated across a Hann main lobe).
    Used to make a "measured" PSD from the spectral model without a time-domain simulation.

    Parameters
    ----------
    expected : ResponsePSD
        The Welch expectation (``response_psd(..., welch_window_length=T)``).
    n_windows : int
        Number of Welch segments of the imagined record (2·duration/T − 1 at 50 % overlap).
    rng : None, int or numpy.random.Generator
    """
    rng = np.random.default_rng(rng)
    dof = welch_degrees_of_freedom(n_windows)
    scatter = rng.chisquare(dof, size=expected.psd.shape) / dof
    return ResponsePSD(frequency=expected.frequency, psd=expected.psd * scatter,
                       output_names=expected.output_names, window_length=expected.window_length,
                       n_windows=int(n_windows), lowpass=expected.lowpass, source="synthetic")
