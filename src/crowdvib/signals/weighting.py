"""Frequency weighting W_b (BS 6841, ISO 10137) and running RMS of acceleration records.

W_b is the vertical whole-body weighting BS 6841:1987 defines and ISO 10137:2007 uses for
walkway vibration (docs: theory, Frequency weighting W_b and running RMS): the product of a band
limitation (second-order Butterworth high pass at f1 and low pass at f2) and the weighting proper,
an acceleration–velocity transition and an upward step,

    W_b(s) = H_h(s) H_l(s) · K (1 + s/ω3) / (1 + s/(Q4 ω4) + s²/ω4²)
                           · (1 + s/(Q5 ω5) + s²/ω5²) / (1 + s/(Q6 ω6) + s²/ω6²),

so K is the gain of the plateau between f1 and f3 (0.4) and K (f6/f5)² = 1.024 that above f6.
The filter is applied in the frequency domain (exact |W_b| and phase at every FFT frequency,
zero-padded so the impulse response does not wrap onto the record); the running RMS follows
ISO 2631-1's linear integration over a window τ (1 s).
"""

import numpy as np
from numpy.typing import ArrayLike

from .._validation import as_float_array, check_positive
from ..errors import ParameterError

__all__ = ["WB_CONSTANTS", "wb_response", "weight_wb", "running_rms"]

#: W_b constants: corner frequencies [Hz], quality factors [-] and gain K [-]. f3…f6, Q4…Q6 and
#: K = 0.4: SOURCED (a public BS 6841:1987 implementation, bs6841freqweight.m, "PY 23/05/02",
#: weighting 'b'). Band limits f1 = 0.4 Hz, f2 = 100 Hz: SOURCED (same file); their Q1 = Q2 =
#: 1/√2: SOURCED (ISO 8041's table of weighting parameters, reproduced in the Larson Davis HVM200
#: manual, Table 3.1; ISO 2631-4 rounds Q1 to 0.71), tested in tests/design/test_weighting_wb.py.
WB_CONSTANTS = {"f1": 0.4, "q1": 1 / np.sqrt(2), "f2": 100.0, "q2": 1 / np.sqrt(2),
                "f3": 16.0, "f4": 16.0, "q4": 0.55, "f5": 2.5, "q5": 0.9, "f6": 4.0,
                "q6": 0.95, "k": 0.4}


def wb_response(frequency: ArrayLike) -> np.ndarray:
    """Complex W_b(i 2π f) [-] at frequencies [Hz] (the analytic transfer function).

    Parameters
    ----------
    frequency : array_like
        Frequencies [Hz].

    Returns
    -------
    ndarray of complex
        W_b at each frequency (BS 6841:1987, docs: theory, References).

    See Also
    --------
    weight_wb : the weighting applied to records.
    """
    c = WB_CONSTANTS
    s = 2j * np.pi * np.asarray(frequency, dtype=float)
    w1, w2, w3, w4, w5, w6 = (2 * np.pi * c[key] for key in ("f1", "f2", "f3", "f4", "f5", "f6"))
    high = s**2 / (s**2 + s * w1 / c["q1"] + w1**2)
    low = w2**2 / (s**2 + s * w2 / c["q2"] + w2**2)
    transition = (1 + s / w3) / (1 + s / (c["q4"] * w4) + (s / w4) ** 2)
    step = (1 + s / (c["q5"] * w5) + (s / w5) ** 2) / (1 + s / (c["q6"] * w6) + (s / w6) ** 2)
    return high * low * c["k"] * transition * step


def weight_wb(acceleration: ArrayLike, sample_rate: float) -> np.ndarray:
    """W_b-weighted accelerations [m/s²] of records sampled at ``sample_rate`` [Hz].

    Parameters
    ----------
    acceleration : array_like, shape (..., n_samples)
        Records along the last axis [m/s²], starting from rest (the filter's state is zero).
    sample_rate : float
        [Hz], > 0.

    Returns
    -------
    ndarray, shape of ``acceleration``

    See Also
    --------
    wb_response : the weighting's transfer function.
    running_rms

    References
    ----------
    BSI, *Measurement and evaluation of human exposure to whole-body mechanical vibration and
    repeated shock*, BS 6841:1987. The W_b weighting.

    ISO, *Bases for design of structures — Serviceability of buildings and walkways against
    vibrations*, ISO 10137:2007. Weighted comfort values for walkways.

    The theory pages cite them (docs: theory, References).
    """
    values = np.asarray(as_float_array("acceleration", acceleration))
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    n = values.shape[-1]
    # Twice the record plus the 0.4 Hz high pass's memory (≈ 10/f1 s): no wrap-around.
    size = 1 << int(np.ceil(np.log2(2 * n + 10 * sample_rate / WB_CONSTANTS["f1"])))
    spectrum = np.fft.rfft(values, size, axis=-1)
    spectrum *= wb_response(np.fft.rfftfreq(size, 1.0 / sample_rate))
    return np.fft.irfft(spectrum, size, axis=-1)[..., :n]


def running_rms(acceleration: ArrayLike, sample_rate: float, window: float = 1.0) -> np.ndarray:
    """Running RMS over a sliding window (ISO 2631-1 linear integration) [m/s²].

    a_rms(t_k) = sqrt(mean of a² over the ``window`` seconds ending at t_k), for every sample
    with a full window behind it.

    Parameters
    ----------
    acceleration : array_like, shape (..., n_samples)
    sample_rate : float
        [Hz].
    window : float
        τ [s], default 1 s; at least one sample and at most the record.

    Returns
    -------
    ndarray, shape (..., n_samples − m + 1), m = round(window · sample_rate)

    See Also
    --------
    weight_wb

    References
    ----------
    ISO, *Bases for design of structures — Serviceability of buildings and walkways against
    vibrations*, ISO 10137:2007. Comfort limits as RMS values of the weighted acceleration.

    The theory pages cite them (docs: theory, References).
    """
    values = np.asarray(as_float_array("acceleration", acceleration))
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    window = check_positive("window", window, unit="s")
    m = round(window * sample_rate)
    n = values.shape[-1]
    if not 1 <= m <= n:
        raise ParameterError(f"window × sample_rate must give 1 to {n} samples (the record), "
                             f"got {window:g} s × {sample_rate:g} Hz = {m}")
    squares = np.cumsum(np.concatenate([np.zeros(values.shape[:-1] + (1,)), values**2],
                                       axis=-1), axis=-1)
    return np.sqrt(np.maximum(squares[..., m:] - squares[..., :-m], 0.0) / m)
