"""The zero-phase Butterworth low-pass filter of acceleration records and its power gain
(docs: theory, Welch PSDs, filters and convergence; The low-pass filter model).

Its own module because both the records' Welch PSDs (:mod:`crowdvib.signals.welch`) and the
PSD they give (:mod:`crowdvib.signals.spectrum`, which records the filter) use it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy import signal as _signal

from .._validation import FieldsFromDict, check_positive
from ..errors import ParameterError

__all__ = ["LowPassFilter"]


@dataclass(frozen=True)
class LowPassFilter(FieldsFromDict):
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

    def apply(self, signals: ArrayLike) -> np.ndarray:
        """Filtered copy of ``signals`` (time on the last axis).

        Parameters
        ----------
        signals : array_like
            Records sampled at ``sample_rate``.
        """
        return _signal.sosfiltfilt(self._sos(), np.asarray(signals, dtype=float), axis=-1)

    def power_gain(self, frequency: ArrayLike) -> np.ndarray:
        """|H(f)|⁴ [-]: the PSD gain of the forward-backward filter (docs: theory, What a Welch estimate sees: the expectation kernel).

        Parameters
        ----------
        frequency : array_like
            Frequencies [Hz].
        """
        # The digital Butterworth filter of scipy.signal.butter is the analogue prototype at
        # the pre-warped cut-off taken through the bilinear transform, so its gain is closed
        # form (docs: theory, The low-pass filter model): |H|² = 1/(1 + (t/t_c)^2n) with
        # t = tan(πf/f_s). It equals sosfreqz of _sos() to round-off (tests/signals/
        # test_conventions.py) at a fraction of the cost of designing the filter again per call
        # (a third of an estimate's time with a filter, issue 39).
        frequency = np.asarray(frequency, dtype=float)
        with np.errstate(over="ignore", divide="ignore"):
            ratio = (np.tan(np.pi * np.mod(frequency, self.sample_rate) / self.sample_rate)
                     / np.tan(np.pi * self.cutoff / self.sample_rate))
            return 1.0 / (1.0 + ratio ** (2 * int(self.order))) ** 2

    def to_dict(self) -> dict[str, float]:
        """The filter settings as a JSON-ready dict."""
        return {"cutoff": self.cutoff, "order": int(self.order), "sample_rate": self.sample_rate}
