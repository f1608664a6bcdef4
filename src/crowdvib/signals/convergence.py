"""Convergence of a Welch PSD with record length (paper Fig. 15; docs: theory, Welch PSDs, filters and convergence)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._validation import FieldsFromDict, check_fraction, check_optional, check_positive
from ..errors import DataError, ParameterError
from .conditioning import _as_signals
from .welch import LowPassFilter, channel_names, segment_periodograms, welch_segment_count

__all__ = ["PSDConvergence", "psd_convergence"]


@dataclass(frozen=True, eq=False)
class PSDConvergence(FieldsFromDict):
    """Convergence of a Welch PSD with record length (paper Figure 15; docs: theory, Welch PSDs, filters and convergence).

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

    def duration_to_reach(self, level: float) -> np.ndarray:
        """Shortest k·T [s] from which ΔG stays below ``level`` for every output (None if never).

        Parameters
        ----------
        level : float
            The convergence level ΔG [-] (the paper: 0.1).
        """
        below = np.all(self.error < level, axis=0)
        for k in range(below.size):
            if below[k:].all():
                return float(self.duration[k])
        return None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {"n_windows": self.n_windows.tolist(), "duration": self.duration.tolist(),
                "error": self.error.tolist(), "output_names": list(self.output_names),
                "window_length": self.window_length, "band": list(self.band),
                "norm": self.norm}


def psd_convergence(signals: ArrayLike, sample_rate: float, *, window_length: float,
                    band: tuple[float, float] | None = None, norm: str = "2",
                    overlap: float = 0.5, output_names: Sequence[str] | None = None,
                    lowpass: LowPassFilter | None = None) -> PSDConvergence:
    """Convergence error of the Welch PSD as windows are added (paper Figure 15; docs: theory, Welch PSDs, filters and convergence).

    For k = 1 … n_T = floor(record / T): G_kT is the Welch PSD (Hann, T, ``overlap``) of the first
    k·T seconds and ΔG_kT = ‖G_kT − G_nT‖ / ‖G_nT‖ over the band. The paper does not print the
    norm; the 2-norm over the band is the default (docs: theory, Welch PSDs, filters and convergence, DERIVED), ``norm="inf"`` gives
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

    See Also
    --------
    crowdvib.welch_psd

    References
    ----------
    K. Van Nimmen and P. Van den Broeck, "Using full-scale observations on footbridges to estimate
    the parameters governing human–structure interaction", *Journal of Bridge Engineering* 28(1),
    2023. The convergence criterion (Figure 15).

    P. D. Welch, "The use of fast Fourier transform for the estimation of power spectra: a method
    based on time averaging over short, modified periodograms", *IEEE Transactions on Audio and
    Electroacoustics* 15(2):70–73, 1967.

    The theory pages cite them (docs: theory, References).
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
    check_fraction("overlap", overlap)
    names = channel_names(output_names, data.shape[0])
    if check_optional("lowpass", lowpass, LowPassFilter) is not None:
        data = lowpass.apply(data)
    names = channel_names(output_names, data.shape[0])
    # G_kT averages the first welch_segment_count(k·T) segment periodograms of the same
    # segmentation, so one spectrogram and a running mean give every k (checked against
    # welch_psd in the tests) instead of n_T separate Welch estimates.
    frequency, periodograms = segment_periodograms(data[:, :n_total * segment], sample_rate,
                                                   segment, overlap)
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
                          output_names=names, window_length=segment / sample_rate,
                          band=(lower, upper), norm=norm)
