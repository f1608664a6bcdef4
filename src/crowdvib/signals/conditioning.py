"""Conditioning of measured records before their PSD: detrend, resample, time frames (docs: theory, Welch PSDs, filters and convergence).

Signals have time on the last axis: (n_channels, n_samples).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike
from scipy import signal as _signal

from .._validation import as_float_array, check_positive
from ..errors import DataError, ParameterError

__all__ = ["detrend", "resample", "select_time_frame", "stationary_time_frame"]


def _as_signals(signals):
    data = as_float_array("signals", signals)
    if data.ndim not in (1, 2):
        raise ParameterError(f"signals must have shape (n_channels, n_samples), got {data.shape}")
    return data


def detrend(signals: ArrayLike, kind: str = "constant") -> np.ndarray:
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


def resample(signals: ArrayLike, sample_rate: float, new_sample_rate: float, *,
             max_denominator: int = 1000) -> tuple[np.ndarray, float]:
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


def select_time_frame(signals: ArrayLike, sample_rate: float, start: float | None = None,
                      end: float | None = None) -> np.ndarray:
    """The samples with start <= t < end [s], t = index / sample_rate.

    Parameters
    ----------
    signals : array_like, shape (n_samples,) or (n_channels, n_samples)
        The records.
    sample_rate : float
        Sample rate [Hz], > 0.
    start, end : float, optional
        The frame [s] (default the record's first and last sample).

    Returns
    -------
    ndarray
        The samples of the frame, along the last axis.

    Raises
    ------
    DataError
        When the frame holds fewer than 2 samples.

    See Also
    --------
    stationary_time_frame : a frame where the record's RMS is steady.

    Examples
    --------
    >>> import numpy as np
    >>> from crowdvib.signals import select_time_frame
    >>> select_time_frame(np.arange(10.0), 2.0, start=1.0, end=3.0)
    array([2., 3., 4., 5.])
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


def stationary_time_frame(signals: ArrayLike, sample_rate: float, *, block_length: float = 60.0,
                          tolerance: float = 0.5) -> tuple[float, float]:
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

