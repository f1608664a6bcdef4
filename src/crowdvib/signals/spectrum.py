"""PSDs at named outputs: the one container that measured and modelled spectra share.

:class:`ResponsePSD` is made by :func:`crowdvib.welch_psd` from records and by
:func:`crowdvib.response_psd` from the spectral model, and compared by the estimator.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .._validation import as_float_array, fields_from_dict, frozen_array, name_indices
from ..errors import DataError, ParameterError
from .plots import plot_psd_comparison
from .lowpass import LowPassFilter

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from .lowpass import LowPassFilter

__all__ = ["ResponsePSD"]


def xarray_module(method: str) -> Any:
    """The xarray module for ``method`` (an optional dependency, imported only when asked for).

    Raises
    ------
    ModuleNotFoundError
        xarray is not installed; the message names the extra that installs it.
    """
    try:
        import xarray
    except ModuleNotFoundError as error:
        raise ModuleNotFoundError(
            f"{method} needs xarray, which is not installed: pip install 'crowdvib[notebook]' (or "
            "pip install xarray)", name=error.name) from None
    return xarray


@dataclass(frozen=True, eq=False)
class ResponsePSD:
    """One-sided acceleration PSDs at named outputs.

    Attributes
    ----------
    frequency : ndarray, shape (n_frequencies,)
        Frequencies [Hz], strictly increasing.
    psd : ndarray, shape (n_outputs, n_frequencies)
        One-sided PSD per Hz [(m/s²)²/Hz], as ``scipy.signal.welch(scaling='density')``.
    output_names : tuple of str
        Names of the outputs (rows of ``psd``).
    window_length : float or None
        Welch segment length T [s] the PSD was estimated (or modelled) with; None for the exact
        (infinitely resolved) model PSD.
    n_windows : int or None
        Number of Welch segments averaged (measured PSDs).
    lowpass : LowPassFilter or None
        Zero-phase filter applied before the PSD.
    source : str
        Where it comes from: ``"model"``, ``"welch"`` or ``"synthetic"``.
    unit : str
        Unit of ``psd``.
    dispersion : ndarray, shape (n_outputs, n_frequencies), or None
        Variance of each ordinate, estimated from the scatter of the Welch segments, over the
        χ²_ν variance (2/ν)·G² of a stationary Gaussian record [-]: about 1 where the record
        behaves so, above where the crowd's occupancy changes or the response is not Gaussian
        (docs: theory, Statistical uncertainty of an estimate). None when unknown.
    cross : ndarray of complex, shape (n_outputs, n_outputs, n_frequencies), or None
        Cross-spectral matrix S_ab(f) = E[X_a conj(X_b)] [(m/s²)²/Hz] (one-sided, Hermitian in
        a, b, its diagonal ``psd``), kept when the estimate was asked for it
        (``welch_psd(..., cross=True)``); the likelihood of several outputs then uses it
        (docs: theory, The cross-spectral matrix). None otherwise.
    """

    frequency: np.ndarray
    psd: np.ndarray
    output_names: tuple
    window_length: float | None = None
    n_windows: int | None = None
    lowpass: LowPassFilter | None = None
    source: str = "model"
    unit: str = "(m/s²)²/Hz"
    dispersion: np.ndarray | None = None
    cross: np.ndarray | None = None

    def __post_init__(self):
        frequency = as_float_array("frequency", self.frequency, ndim=1)
        psd = np.atleast_2d(np.array(self.psd, dtype=float))
        names = tuple(str(n) for n in self.output_names)
        if psd.shape != (len(names), frequency.size):
            raise ParameterError(
                "psd must have shape (n_outputs, n_frequencies) = "
                f"({len(names)}, {frequency.size}), got {psd.shape}")
        if frequency.size and np.any(np.diff(frequency) <= 0):
            raise ParameterError("frequency must be strictly increasing")
        object.__setattr__(self, "frequency", frozen_array(frequency))
        object.__setattr__(self, "psd", frozen_array(psd))
        object.__setattr__(self, "output_names", names)
        if self.dispersion is not None:
            dispersion = np.array(self.dispersion, dtype=float)
            if dispersion.shape != psd.shape:
                raise ParameterError(f"dispersion must have the shape of psd {psd.shape}, got "
                                     f"{dispersion.shape}")
            object.__setattr__(self, "dispersion", frozen_array(dispersion))
        if self.cross is not None:
            cross = np.array(self.cross, dtype=complex)
            if cross.shape != (len(names), len(names), frequency.size):
                raise ParameterError(
                    f"cross must have shape (n_outputs, n_outputs, n_frequencies) = "
                    f"({len(names)}, {len(names)}, {frequency.size}), got {cross.shape}")
            object.__setattr__(self, "cross", frozen_array(cross, dtype=complex))

    def check_measured(self) -> ResponsePSD:
        """Raise a :class:`DataError` if the PSD holds NaN, infinite or negative values, is zero
        at every frequency of an output (a dead channel: nothing to fit), or its cross-spectra
        hold non-finite values."""
        for row, name in zip(self.psd, self.output_names):
            bad = np.flatnonzero(~np.isfinite(row) | (row < 0))
            if bad.size:
                raise DataError(
                    f"measured PSD of output {name!r} must be finite and >= 0, got {row[bad[0]]} "
                    f"at {self.frequency[bad[0]]:g} Hz (index {bad[0]})")
            if not np.any(row > 0):
                raise DataError(f"measured PSD of output {name!r} is zero at all {row.size} "
                                "frequencies: a dead or disconnected channel, or a record of "
                                "zeros, has no response to fit")
        if self.cross is not None and not np.all(np.isfinite(self.cross)):
            column = int(np.argwhere(~np.isfinite(self.cross))[0, -1])
            raise DataError(f"measured cross-spectra must be finite, got a non-finite entry at "
                            f"{self.frequency[column]:g} Hz (index {column})")
        return self

    def select(self, names: str | Sequence[str]) -> ResponsePSD:
        """The PSDs of the named outputs, in that order.

        Parameters
        ----------
        names : str or sequence of str
            Output names.
        """
        rows = name_indices(names, self.output_names)
        return self._with(psd=self.psd[rows],
                          output_names=tuple(self.output_names[i] for i in rows),
                          dispersion=None if self.dispersion is None else self.dispersion[rows],
                          cross=None if self.cross is None else self.cross[np.ix_(rows, rows)])

    def band(self, lower: float, upper: float) -> ResponsePSD:
        """The PSDs restricted to lower <= f <= upper [Hz].

        Parameters
        ----------
        lower, upper : float
            The band [Hz].
        """
        keep = (self.frequency >= lower) & (self.frequency <= upper)
        return self._with(frequency=self.frequency[keep], psd=self.psd[:, keep],
                          dispersion=None if self.dispersion is None
                          else self.dispersion[:, keep],
                          cross=None if self.cross is None else self.cross[..., keep])

    def variance(self, lower: float = 0.0, upper: float = np.inf) -> np.ndarray:
        """Band variance ∫ G df over [lower, upper] per output [(m/s²)²], trapezoid rule.

        Parameters
        ----------
        lower, upper : float
            The band [Hz] (default every frequency).
        """
        keep = (self.frequency >= lower) & (self.frequency <= upper)
        return np.trapezoid(self.psd[:, keep], self.frequency[keep], axis=-1)

    def rms(self, lower: float = 0.0, upper: float = np.inf) -> np.ndarray:
        """RMS value per output over a band [m/s²].

        Parameters
        ----------
        lower, upper : float
            The band [Hz] (default every frequency).
        """
        return np.sqrt(self.variance(lower, upper))

    def peak_frequency(self) -> np.ndarray:
        """Frequency of the PSD maximum per output [Hz]."""
        return self.frequency[np.argmax(self.psd, axis=-1)]

    def _with(self, **changes):
        fields = dict(frequency=self.frequency, psd=self.psd, output_names=self.output_names,
                      window_length=self.window_length, n_windows=self.n_windows,
                      lowpass=self.lowpass, source=self.source, unit=self.unit,
                      dispersion=self.dispersion, cross=self.cross)
        fields.update(changes)
        return ResponsePSD(**fields)

    def plot(self, *, output: str | None = None, band: tuple[float, float] | None = None,
             ax: Axes | None = None, title: str | None = None, label: str | None = None) -> Axes:
        """Draw the PSD of one output (see :func:`crowdvib.reporting.plotting.plot_psd_comparison`).

        Parameters
        ----------
        output : str, optional
            The output drawn (default the first).
        band : (float, float), optional
            Frequency range drawn [Hz] (default all).
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (default a new figure).
        title : str, optional
            The axes' title.
        label : str, optional
            The curve's legend label (default ``source``).

        Returns
        -------
        matplotlib.axes.Axes
        """

        return plot_psd_comparison({label or self.source: self}, output=output, band=band,
                                   ax=ax, title=title)

    def __repr__(self):
        f = self.frequency
        welch = ("" if not self.window_length else f", T = {self.window_length:g} s"
                 + (f", {self.n_windows} windows" if self.n_windows else ""))
        return (f"ResponsePSD({list(self.output_names)}, {f.size} frequencies "
                f"{f[0]:g}–{f[-1]:g} Hz{welch}, source={self.source!r})")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict of the PSD and its metadata (``"dispersion"`` and ``"cross"``, as its
        real and imaginary parts, only when the PSD carries them)."""
        fields = {"frequency": self.frequency.tolist(), "psd": self.psd.tolist(),
                  "output_names": list(self.output_names), "window_length": self.window_length,
                  "n_windows": self.n_windows, "source": self.source, "unit": self.unit,
                  "lowpass": None if self.lowpass is None else self.lowpass.to_dict()}
        if self.dispersion is not None:
            fields["dispersion"] = self.dispersion.tolist()
        if self.cross is not None:
            fields["cross"] = {"real": self.cross.real.tolist(), "imag": self.cross.imag.tolist()}
        return fields

    @classmethod
    def from_dict(cls, data: dict) -> ResponsePSD:
        """The PSD of :meth:`to_dict`.

        Parameters
        ----------
        data : dict
            What :meth:`to_dict` wrote (as read back from JSON).

        Raises
        ------
        DataError
            ``data`` is not a dict or lacks a field; ParameterError for values the constructor
            refuses.
        """

        cross = data.get("cross") if isinstance(data, dict) else None
        return fields_from_dict(
            cls, data,
            lowpass=None if data.get("lowpass") is None else LowPassFilter.from_dict(
                data["lowpass"]),
            cross=None if cross is None else (np.asarray(cross["real"], dtype=float)
                                              + 1j * np.asarray(cross["imag"], dtype=float)))

    def to_xarray(self) -> Any:
        """The PSDs as an ``xarray.DataArray`` of dims (output, frequency), units in its attributes.

        Needs xarray (``pip install 'crowdvib[notebook]'``). The attributes are those a netCDF
        file can hold: ``units``, ``source`` and, when known, ``window_length`` [s],
        ``n_windows`` and the low-pass filter's ``lowpass_cutoff`` [Hz] and ``lowpass_order``;
        the frequency coordinate has ``units`` "Hz". The dispersion and cross-spectra stay
        with the ResponsePSD.

        Returns
        -------
        xarray.DataArray
            Named ``"psd"``, the values of ``psd`` (a copy), coordinates ``output`` (the output
            names) and ``frequency`` [Hz].

        Raises
        ------
        ModuleNotFoundError
            xarray is not installed; the message names the extra that installs it.

        See Also
        --------
        crowdvib.Simulation.to_xarray : the record a PSD may come from.

        Examples
        --------
        >>> from crowdvib import ResponsePSD
        >>> psd = ResponsePSD([1.0, 2.0], [[0.1, 0.3]], ("midspan",), window_length=60.0)
        >>> array = psd.to_xarray()
        >>> float(array.sel(output="midspan", frequency=2.0))
        0.3
        """
        xarray = xarray_module("ResponsePSD.to_xarray")
        known = {"window_length": self.window_length, "n_windows": self.n_windows,
                 "lowpass_cutoff": None if self.lowpass is None else self.lowpass.cutoff,
                 "lowpass_order": None if self.lowpass is None else self.lowpass.order}
        attrs = {"units": self.unit, "long_name": "one-sided acceleration PSD",
                 "source": self.source, **{k: v for k, v in known.items() if v is not None}}
        return xarray.DataArray(
            np.array(self.psd), dims=("output", "frequency"), name="psd", attrs=attrs,
            coords={"output": list(self.output_names),
                    "frequency": ("frequency", np.array(self.frequency), {"units": "Hz"})})
