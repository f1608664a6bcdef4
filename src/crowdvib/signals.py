"""Signal processing of acceleration records: low-pass filtering and Welch PSDs (physics.md §6).

Also the two facts the spectral model needs to mimic a measured PSD: the power gain of the
zero-phase filter and the expectation kernel of a Hann-window Welch estimate (physics.md §3.4).
Signals have time on the last axis: (n_channels, n_samples).
"""

from dataclasses import dataclass

import numpy as np
from scipy import signal as _signal

from ._validation import as_float_array, check_positive
from .errors import DataError, ParameterError
from .results import ResponsePSD

__all__ = ["LowPassFilter", "welch_psd", "welch_kernel", "welch_segment_count",
           "welch_degrees_of_freedom", "synthetic_welch_psd"]


@dataclass(frozen=True)
class LowPassFilter:
    """Zero-phase Butterworth low-pass filter (``scipy.signal.sosfiltfilt``).

    Parameters
    ----------
    cutoff : float
        Cut-off frequency [Hz] of one pass (10 Hz in the paper; 2.3 Hz for the step-frequency fit).
    order : int
        Butterworth order of one pass; the forward-backward filter has twice the roll-off.
    sample_rate : float
        Sample rate [Hz] of the records it is applied to.
    """

    cutoff: float = 10.0
    order: int = 4
    sample_rate: float = 100.0

    def __post_init__(self):
        check_positive("cutoff", self.cutoff, unit="Hz")
        check_positive("sample_rate", self.sample_rate, unit="Hz")
        if int(self.order) != self.order or not 1 <= self.order <= 20:
            raise ParameterError(f"order must be an integer in [1, 20], got {self.order!r}")
        if self.cutoff >= self.sample_rate / 2:
            raise ParameterError(
                f"cutoff must be below the Nyquist frequency {self.sample_rate / 2:g} Hz, "
                f"got {self.cutoff:g} Hz")

    def _sos(self):
        return _signal.butter(int(self.order), self.cutoff, btype="low", output="sos",
                              fs=self.sample_rate)

    def apply(self, signals):
        """Filtered copy of ``signals`` (time on the last axis)."""
        return _signal.sosfiltfilt(self._sos(), np.asarray(signals, dtype=float), axis=-1)

    def power_gain(self, frequency):
        """|H(f)|⁴ [-]: the PSD gain of the forward-backward filter (physics.md §3.4)."""
        _, response = _signal.sosfreqz(self._sos(), worN=np.asarray(frequency, dtype=float),
                                       fs=self.sample_rate)
        return np.abs(response) ** 4

    def to_dict(self):
        """The filter settings as a JSON-ready dict."""
        return {"cutoff": self.cutoff, "order": int(self.order), "sample_rate": self.sample_rate}


def welch_kernel(offset, window_length):
    """Expectation kernel of a Hann-window Welch PSD estimate [1/Hz] (physics.md §3.4).

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


def welch_segment_count(n_samples, segment_samples, overlap=0.5):
    """Number of Welch segments of ``segment_samples`` in a record of ``n_samples``."""
    step = segment_samples - int(segment_samples * overlap)
    return 0 if n_samples < segment_samples else 1 + (n_samples - segment_samples) // step


def welch_psd(signals, sample_rate, *, window_length, overlap=0.5, output_names=None,
              lowpass=None):
    """One-sided Welch PSD of acceleration records → :class:`ResponsePSD` (physics.md §6).

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
    """
    data = as_float_array("signals", signals)
    data = np.atleast_2d(data)
    if data.ndim != 2:
        raise ParameterError(f"signals must have shape (n_channels, n_samples), got {data.shape}")
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    window_length = check_positive("window_length", window_length, unit="s")
    if not 0.0 <= overlap < 1.0:
        raise ParameterError(f"overlap must lie in [0, 1), got {overlap!r}")
    segment = int(round(window_length * sample_rate))
    if segment < 8:
        raise ParameterError(
            f"window_length × sample_rate must give at least 8 samples, got {segment}")
    if data.shape[1] < segment:
        raise DataError(
            f"record of {data.shape[1] / sample_rate:g} s is shorter than one window of "
            f"{window_length:g} s")
    names = (tuple(f"ch{i}" for i in range(data.shape[0])) if output_names is None
             else tuple(output_names))
    if len(names) != data.shape[0]:
        raise ParameterError(
            f"output_names must name every channel ({data.shape[0]}), got {len(names)}")
    if lowpass is not None:
        if abs(lowpass.sample_rate - sample_rate) > 1e-9 * sample_rate:
            raise ParameterError(
                f"lowpass.sample_rate must equal sample_rate {sample_rate:g} Hz, "
                f"got {lowpass.sample_rate:g} Hz")
        data = lowpass.apply(data)
    frequency, psd = _signal.welch(data, fs=sample_rate, window="hann", nperseg=segment,
                                   noverlap=int(segment * overlap), detrend="constant",
                                   return_onesided=True, scaling="density", axis=-1)
    return ResponsePSD(frequency=frequency, psd=psd, output_names=names,
                       window_length=segment / sample_rate,
                       n_windows=welch_segment_count(data.shape[1], segment, overlap),
                       lowpass=lowpass, source="welch")


def welch_degrees_of_freedom(n_windows, overlap=0.5):
    """Equivalent degrees of freedom ν of a Hann-window Welch estimate of ``n_windows`` segments.

    ν = 2K / (1 + 2 Σ_j (1 − j/K) ρ_j), ρ_j the squared normalised overlap correlation of
    the window at a lag of j segment steps (Welch 1967; for Hann at 50 % overlap ρ₁ = 1/36).
    Each PSD ordinate is then distributed as G·χ²_ν/ν.
    """
    k = int(n_windows)
    if k < 1:
        raise ParameterError(f"n_windows must be >= 1, got {n_windows!r}")
    samples = 1024
    window = _signal.get_window("hann", samples)
    step = samples - int(samples * overlap)
    total = 0.0
    for j in range(1, k):
        lag = j * step
        if lag >= samples:
            break
        rho = (np.dot(window[:-lag], window[lag:]) / np.dot(window, window)) ** 2
        total += (1.0 - j / k) * rho
    return 2.0 * k / (1.0 + 2.0 * total)


def synthetic_welch_psd(expected, n_windows, rng=None):
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


# ----------------------------------------------------------------------------------------------
# Processing of measured records (physics.md §6): detrend, resample, time frames, convergence.
__all__ += ["detrend", "resample", "select_time_frame", "stationary_time_frame",
            "psd_convergence", "PSDConvergence"]


def _as_signals(signals):
    data = as_float_array("signals", signals)
    if data.ndim not in (1, 2):
        raise ParameterError(f"signals must have shape (n_channels, n_samples), got {data.shape}")
    return data


def detrend(signals, kind="constant"):
    """Remove the mean (``"constant"``, the paper's practice) or a straight line (``"linear"``).

    Parameters
    ----------
    signals : array_like, shape (n_channels, n_samples) or (n_samples,)
        Accelerations [m/s²]; time on the last axis.
    kind : {"constant", "linear"}

    Returns
    -------
    ndarray of the same shape
    """
    if kind not in ("constant", "linear"):
        raise ParameterError(f"kind must be 'constant' or 'linear', got {kind!r}")
    return _signal.detrend(_as_signals(signals), axis=-1, type=kind)


def resample(signals, sample_rate, new_sample_rate, *, max_denominator=1000):
    """Resample with a polyphase anti-aliasing filter (``scipy.signal.resample_poly``).

    The ratio new/old is approximated by a fraction up/down with down <= ``max_denominator``;
    the rate actually reached is returned with the samples.

    Parameters
    ----------
    signals : array_like, shape (n_channels, n_samples) or (n_samples,)
    sample_rate, new_sample_rate : float
        Old and new sample rates [Hz].
    max_denominator : int
        Largest down-sampling factor of the rational approximation.

    Returns
    -------
    resampled : ndarray, shape (..., n_new)
    rate : float
        The new sample rate [Hz] = sample_rate · up / down.
    """
    from fractions import Fraction

    data = _as_signals(signals)
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    new_sample_rate = check_positive("new_sample_rate", new_sample_rate, unit="Hz")
    ratio = Fraction(new_sample_rate / sample_rate).limit_denominator(int(max_denominator))
    if ratio == 0:
        raise ParameterError(f"new_sample_rate {new_sample_rate:g} Hz is too far below "
                             f"sample_rate {sample_rate:g} Hz for max_denominator {max_denominator}")
    if ratio == 1:
        return data.copy(), sample_rate
    out = _signal.resample_poly(data, ratio.numerator, ratio.denominator, axis=-1)
    return out, sample_rate * ratio.numerator / ratio.denominator


def select_time_frame(signals, sample_rate, start=None, end=None):
    """The samples with start <= t < end [s], t = index / sample_rate.

    Raises
    ------
    DataError
        When the frame holds fewer than 2 samples.
    """
    data = _as_signals(signals)
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    n = data.shape[-1]
    first = 0 if start is None else max(int(np.ceil(start * sample_rate - 1e-9)), 0)
    last = n if end is None else min(int(np.ceil(end * sample_rate - 1e-9)), n)
    if last - first < 2:
        raise DataError(f"time frame [{start}, {end}] s holds {max(last - first, 0)} sample(s) of "
                        f"a record of {n / sample_rate:g} s")
    return data[..., first:last]


def stationary_time_frame(signals, sample_rate, *, block_length=60.0, tolerance=0.5):
    """The longest stretch whose running RMS stays near the record's typical level [s].

    The record is cut into blocks of ``block_length``; a block is stationary when the RMS of every
    channel lies within ``tolerance`` (relative) of that channel's median block RMS. The longest
    run of consecutive stationary blocks is returned — a simple stand-in for choosing "a time
    frame with a stationary crowd" as the paper does by inspection.

    Parameters
    ----------
    signals : array_like, shape (n_channels, n_samples) or (n_samples,)
    sample_rate : float
        [Hz]
    block_length : float
        Block length [s] (one Welch window is a sensible choice).
    tolerance : float
        Allowed relative deviation of a block RMS from the median block RMS [-], > 0.

    Returns
    -------
    (float, float)
        Start and end [s] of the frame (start <= t < end).
    """
    data = np.atleast_2d(_as_signals(signals))
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    block_length = check_positive("block_length", block_length, unit="s")
    tolerance = check_positive("tolerance", tolerance)
    size = int(round(block_length * sample_rate))
    n_blocks = data.shape[1] // size if size > 0 else 0
    if n_blocks < 1:
        raise DataError(f"record of {data.shape[1] / sample_rate:g} s is shorter than one block "
                        f"of {block_length:g} s")
    blocks = data[:, :n_blocks * size].reshape(data.shape[0], n_blocks, size)
    rms = np.sqrt(np.mean((blocks - blocks.mean(axis=-1, keepdims=True)) ** 2, axis=-1))
    median = np.median(rms, axis=1, keepdims=True)
    good = np.all(np.abs(rms - median) <= tolerance * np.where(median > 0, median, 1.0), axis=0)
    best, best_start, run_start = 0, 0, None
    for i, ok in enumerate(np.append(good, False)):
        if ok and run_start is None:
            run_start = i
        elif not ok and run_start is not None:
            if i - run_start > best:
                best, best_start = i - run_start, run_start
            run_start = None
    if best == 0:
        raise DataError("no block of the record is stationary within the tolerance "
                        f"{tolerance:g}; raise the tolerance or choose the frame by hand")
    return best_start * size / sample_rate, (best_start + best) * size / sample_rate


@dataclass(frozen=True, eq=False)
class PSDConvergence:
    """Convergence of a Welch PSD with record length (paper Fig. 15; physics.md §6).

    Attributes
    ----------
    n_windows : ndarray of int, shape (n_T,)
        k = 1 … n_T: the first k·T seconds of the record are used.
    duration : ndarray, shape (n_T,)
        k·T [s].
    error : ndarray, shape (n_outputs, n_T)
        ΔG_kT = ‖G_kT − G_nT‖ / ‖G_nT‖ over the band [-]; 0 at k = n_T by construction.
    output_names : tuple of str
    window_length : float
        T [s].
    band : tuple of float
        [Hz] over which the norm is taken.
    norm : str
        ``"2"`` (Euclidean, default) or ``"inf"`` (largest deviation).
    """

    n_windows: np.ndarray
    duration: np.ndarray
    error: np.ndarray
    output_names: tuple
    window_length: float
    band: tuple
    norm: str

    def duration_to_reach(self, level):
        """Shortest k·T [s] from which ΔG stays below ``level`` for every output (None if never)."""
        below = np.all(self.error < level, axis=0)
        for k in range(below.size):
            if below[k:].all():
                return float(self.duration[k])
        return None

    def to_dict(self):
        """JSON-ready dict."""
        return {"n_windows": self.n_windows.tolist(), "duration": self.duration.tolist(),
                "error": self.error.tolist(), "output_names": list(self.output_names),
                "window_length": self.window_length, "band": list(self.band),
                "norm": self.norm}


def psd_convergence(signals, sample_rate, *, window_length, band=None, norm="2", overlap=0.5,
                    output_names=None, lowpass=None):
    """Convergence error of the Welch PSD as windows are added (paper Fig. 15; physics.md §6).

    For k = 1 … n_T = floor(record / T): G_kT is the Welch PSD (Hann, T, ``overlap``) of the first
    k·T seconds and ΔG_kT = ‖G_kT − G_nT‖ / ‖G_nT‖ over the band. The paper does not print the
    norm; the 2-norm over the band is the default (physics.md §6, DERIVED), ``norm="inf"`` gives
    the largest relative deviation of any bin instead.

    Parameters
    ----------
    signals : array_like, shape (n_channels, n_samples) or (n_samples,)
        Accelerations [m/s²].
    sample_rate : float
        [Hz]
    window_length : float
        T [s].
    band : (float, float), optional
        [Hz]; default 0 … Nyquist.
    norm : {"2", "inf"}
    overlap : float
        Welch overlap as a fraction of T.
    output_names : sequence of str, optional
    lowpass : LowPassFilter, optional
        Applied once to the whole record before it is cut (so every G_kT sees the same filter).

    Returns
    -------
    PSDConvergence
    """
    norm = str(norm)
    if norm not in ("2", "inf"):
        raise ParameterError(f"norm must be '2' or 'inf', got {norm!r}")
    data = np.atleast_2d(_as_signals(signals))
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    window_length = check_positive("window_length", window_length, unit="s")
    segment = int(round(window_length * sample_rate))
    n_total = data.shape[1] // segment if segment > 0 else 0
    if n_total < 1:
        raise DataError(f"record of {data.shape[1] / sample_rate:g} s is shorter than one window "
                        f"of {window_length:g} s")
    if lowpass is not None:
        data = lowpass.apply(data)
    full = welch_psd(data[:, :n_total * segment], sample_rate, window_length=window_length,
                     overlap=overlap, output_names=output_names)
    # G_kT averages the first welch_segment_count(k·T) segment periodograms of the same
    # segmentation, so one spectrogram and a running mean give every k (checked against
    # welch_psd in the tests) instead of n_T separate Welch estimates.
    frequency, _, periodograms = _signal.spectrogram(
        data[:, :n_total * segment], fs=sample_rate, window="hann", nperseg=segment,
        noverlap=int(segment * overlap), detrend="constant", return_onesided=True,
        scaling="density", mode="psd", axis=-1)
    running = np.cumsum(periodograms, axis=-1)
    counts_k = [welch_segment_count(k * segment, segment, overlap) for k in range(1, n_total + 1)]
    psds = [running[..., c - 1] / c for c in counts_k]
    lower, upper = (0.0, frequency[-1]) if band is None else (float(band[0]), float(band[1]))
    keep = (frequency >= lower) & (frequency <= upper)
    if not keep.any():
        raise ParameterError(f"band ({lower:g}, {upper:g}) Hz holds no frequency of the PSD")
    reference = psds[-1][:, keep]
    order = np.inf if norm == "inf" else 2
    scale = np.linalg.norm(reference, ord=order, axis=1)
    scale = np.where(scale > 0, scale, 1.0)
    error = np.stack([np.linalg.norm(p[:, keep] - reference, ord=order, axis=1) / scale
                      for p in psds], axis=1)
    counts = np.arange(1, n_total + 1)
    return PSDConvergence(n_windows=counts, duration=counts * segment / sample_rate, error=error,
                          output_names=full.output_names, window_length=segment / sample_rate,
                          band=(lower, upper), norm=norm)
