"""Frozen results of the time-domain simulator: simulated records and their Welch PSDs.

Each documents its fields with units, offers ``to_dict()`` for JSON and, where a picture helps,
``plot()`` which delegates to :mod:`crowdvib.reporting.plotting` (imported only then).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..._validation import frozen_array
from ...errors import ParameterError
from ...signals.spectrum import ResponsePSD, xarray_module
from ...signals.welch import welch_psd
from ...signals.weighting import running_rms
from .plots import plot_time_history

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..._figures import FigureAxes
    from ...signals.welch import LowPassFilter

__all__ = ["Simulation", "SimulationPSD"]


def count_dtype(counts) -> type:
    """int16 when every count fits it, else int32 (a deck holds far fewer than 2³¹ people)."""
    counts = np.asarray(counts)
    return np.int16 if counts.size == 0 or counts.max() <= np.iinfo(np.int16).max else np.int32


class _TimeAxis:
    """``Simulation.time``: the stored axis, or i / sample_rate computed on access when given
    as None (a day at 100 Hz would hold 69 MB of it). A data descriptor the dataclass assigns
    through; with no class default, so ``time`` stays a required field."""

    def __set_name__(self, owner, name):
        self.name = "_" + name

    def __get__(self, instance, owner=None):
        if instance is None:
            raise AttributeError("time")        # no default (the dataclass asks the class)
        stored = instance.__dict__[self.name]
        if stored is not None:
            return stored
        return frozen_array(np.arange(instance.n_samples) / instance.sample_rate)

    def __set__(self, instance, value):
        instance.__dict__[self.name] = None if value is None else frozen_array(value)


@dataclass(frozen=True, eq=False)
class Simulation:
    """Record of a time-domain simulation (:func:`crowdvib.simulate`, docs: theory, The coupled time-domain model).

    Attributes
    ----------
    time : ndarray, shape (n_samples,)
        Sample times [s], from 0 at 1/sample_rate. Given as None (what :func:`crowdvib.simulate`
        does), it is computed on each access, i / sample_rate, and never stored.
    acceleration : ndarray, shape (n_outputs, n_samples)
        Vertical accelerations at the output points [m/s²].
    output_names : tuple of str
        Names of the outputs (rows of ``acceleration``).
    n_on_deck : ndarray of int, shape (n_samples,)
        Pedestrians on the deck at each sample [-], stored in the smallest of int16 and int32
        that holds them (2 bytes a sample rather than 8 for any real deck).
    sample_rate : float
        Output sample rate [Hz].
    seed : int
        The seed actually used: ``simulate(..., rng=seed)`` repeats the record bit for bit.
    duration : float
        Record length n_samples / sample_rate [s].
    modal_load : ndarray, shape (n_modes, n_samples), or None
        Modal walking load Q(t) = Σ_k φ_k p_k [N] when recorded (no interaction forces).
    time_step : float or None
        Internal RK4 step [s].
    n_pedestrians : int or None
        Pedestrians generated for the run (including those already on the deck at the start).
    hsi : bool
        Whether the pedestrians were MSDs (True) or moving forces only.
    warm_up : float
        Simulated time before t = 0 that was discarded [s].
    """

    time: np.ndarray | None = _TimeAxis()
    acceleration: np.ndarray
    output_names: tuple
    n_on_deck: np.ndarray
    sample_rate: float
    seed: int
    duration: float
    modal_load: np.ndarray | None = None
    time_step: float | None = None
    n_pedestrians: int | None = None
    hsi: bool = False
    warm_up: float = 0.0

    def __post_init__(self):
        acceleration = np.atleast_2d(np.asarray(self.acceleration, dtype=float))
        names = tuple(str(n) for n in self.output_names)
        if acceleration.shape[0] != len(names):
            raise ParameterError(
                f"acceleration must have one row per output ({len(names)}), "
                f"got shape {acceleration.shape}")
        object.__setattr__(self, "acceleration", frozen_array(acceleration))
        object.__setattr__(self, "output_names", names)
        object.__setattr__(self, "n_on_deck", frozen_array(self.n_on_deck,
                                                           dtype=count_dtype(self.n_on_deck)))
        if self.modal_load is not None:
            object.__setattr__(self, "modal_load", frozen_array(self.modal_load))

    @property
    def n_samples(self) -> int:
        """Number of samples per output."""
        return self.acceleration.shape[-1]

    def psd(self, window_length: float, overlap: float = 0.5,
            lowpass: LowPassFilter | None = None) -> ResponsePSD:
        """Welch PSD of the accelerations → :class:`ResponsePSD` (docs: theory, Welch PSDs, filters and convergence).

        Parameters
        ----------
        window_length : float
            Segment length T [s] (Hann window).
        overlap : float
            Overlap of consecutive segments, fraction of T.
        lowpass : LowPassFilter, optional
            Zero-phase filter applied first.
        """
        return welch_psd(self.acceleration, self.sample_rate, window_length=window_length,
                         overlap=overlap, output_names=self.output_names, lowpass=lowpass)

    def summary(self, window: float = 1.0) -> dict[str, Any]:
        """What a comfort check reads first, per output: RMS, peak |a| and the largest running
        RMS over ``window`` seconds, all in m/s² (docs: theory, Design checks).

        Parameters
        ----------
        window : float
            Running-RMS window [s].

        Returns
        -------
        dict
            ``output_names``, ``rms``, ``peak``, ``max_running_rms`` (lists, one per output) and
            ``running_rms_window`` [s].
        """

        data = np.asarray(self.acceleration)
        full = data.shape[-1] >= round(window * self.sample_rate)   # a record shorter than
        moving = running_rms(data, self.sample_rate, window) if full else None  # one window
        return {"output_names": list(self.output_names),
                "rms": np.sqrt(np.mean(data ** 2, axis=-1)).tolist(),
                "peak": np.max(np.abs(data), axis=-1, initial=0.0).tolist(),
                "max_running_rms": (moving.max(axis=-1).tolist() if full
                                    else [None] * len(self.output_names)),
                "running_rms_window": float(window)}

    def plot(self, *, output: str | None = None, window: float = 1.0,
             axes: Sequence[Axes] | None = None, title: str | None = None,
             weighting: str | None = None) -> FigureAxes:
        """Draw the record, its running RMS (``weighting="Wb"``: of the W_b-weighted record)
        and the people on the deck (see :func:`crowdvib.reporting.plotting.plot_time_history`).

        Parameters
        ----------
        output : str, optional
            The output drawn (default the first).
        window : float
            Running-RMS window [s].
        axes : sequence of matplotlib.axes.Axes, optional
            Two axes to draw on (default a new figure).
        title : str, optional
            The figure's title.
        weighting : {"Wb"}, optional
            The running RMS of the W_b-weighted record (BS 6841) instead.

        Returns
        -------
        FigureAxes
        """

        return plot_time_history(self, output=output, window=window, axes=axes, title=title,
                                 weighting=weighting)

    def __repr__(self):
        return (f"Simulation({list(self.output_names)}, {self.duration:g} s at "
                f"{self.sample_rate:g} Hz, {self.n_pedestrians} pedestrians, "
                f"{'MSD' if self.hsi else 'forces only'}, seed={self.seed})")

    def metadata(self) -> dict[str, Any]:
        """JSON-ready metadata (no time series; write those with the I/O functions, which read
        them back whole)."""
        return {"output_names": list(self.output_names), "sample_rate": self.sample_rate,
                "n_samples": self.n_samples, "duration": self.duration, "seed": self.seed,
                "time_step": self.time_step, "n_pedestrians": self.n_pedestrians,
                "hsi": self.hsi, "warm_up": self.warm_up,
                "mean_on_deck": float(self.n_on_deck.mean()) if self.n_samples else 0.0,
                "rms": np.sqrt(np.mean(self.acceleration**2, axis=-1)).tolist(),
                "modal_load_recorded": self.modal_load is not None}

    def to_xarray(self) -> Any:
        """The record as an ``xarray.DataArray`` of dims (output, time), units in its attributes.

        Needs xarray (``pip install 'crowdvib[notebook]'``). The people on the deck come along
        as the coordinate ``n_on_deck`` on ``time``; the attributes (``units`` "m/s²",
        ``sample_rate`` [Hz], ``duration`` [s], ``seed``, ``hsi`` as 0 or 1, ``warm_up`` [s]
        and, when known, ``n_pedestrians`` and ``time_step`` [s]) are those a netCDF file can
        hold. The modal load stays with the Simulation.

        Returns
        -------
        xarray.DataArray
            Named ``"acceleration"``, the accelerations (a copy), coordinates ``output`` (the
            output names) and ``time`` [s].

        Raises
        ------
        ModuleNotFoundError
            xarray is not installed; the message names the extra that installs it.

        See Also
        --------
        crowdvib.ResponsePSD.to_xarray : the PSD of a record (:meth:`psd`).

        Examples
        --------
        >>> from crowdvib import Simulation
        >>> record = Simulation(time=None, acceleration=[[0.0, 0.1, -0.1]], output_names=("mid",),
        ...                     n_on_deck=[3, 3, 4], sample_rate=100.0, seed=1, duration=0.03)
        >>> array = record.to_xarray()
        >>> array.dims, array.attrs["units"], float(array.time[-1])
        (('output', 'time'), 'm/s²', 0.02)
        """
        xarray = xarray_module("Simulation.to_xarray")
        known = {"n_pedestrians": self.n_pedestrians, "time_step": self.time_step}
        attrs = {"units": "m/s²", "long_name": "vertical acceleration",
                 "sample_rate": self.sample_rate, "duration": self.duration, "seed": self.seed,
                 "hsi": int(self.hsi), "warm_up": self.warm_up,
                 **{k: v for k, v in known.items() if v is not None}}
        return xarray.DataArray(
            np.array(self.acceleration), dims=("output", "time"), name="acceleration",
            attrs=attrs,
            coords={"output": list(self.output_names),
                    "time": ("time", np.array(self.time), {"units": "s"}),
                    "n_on_deck": ("time", np.array(self.n_on_deck),
                                  {"long_name": "pedestrians on the deck"})})


@dataclass(frozen=True, eq=False)
class SimulationPSD:
    """What :func:`crowdvib.simulate_psd` keeps of a simulated record: its Welch PSD and summaries.

    Attributes
    ----------
    psd : ResponsePSD
        Welch PSD of the accelerations [(m/s²)²/Hz] (Hann, constant detrend, no low-pass).
    rms, peak : ndarray, shape (n_outputs,)
        RMS and largest |a| of each output over the record [m/s²].
    sample_rate : float
        Output sample rate [Hz].
    seed : int
        The seed used: ``simulate(..., rng=seed)`` gives the record itself.
    duration : float
        Record length [s].
    time_step : float
        Internal RK4 step [s].
    n_pedestrians : int
        Pedestrians generated for the run (including those on the deck at the start).
    mean_on_deck : float
        Mean number of pedestrians on the deck over the samples [-].
    max_on_deck : int
        Most pedestrians on the deck at one sample [-].
    hsi : bool
        Whether the pedestrians were MSDs.
    warm_up : float
        Simulated time before t = 0 that was discarded [s].
    """

    psd: ResponsePSD
    rms: np.ndarray
    peak: np.ndarray
    sample_rate: float
    seed: int
    duration: float
    time_step: float
    n_pedestrians: int
    mean_on_deck: float
    max_on_deck: int
    hsi: bool = False
    warm_up: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "rms", frozen_array(self.rms))
        object.__setattr__(self, "peak", frozen_array(self.peak))

    def __repr__(self):
        return (f"SimulationPSD({list(self.psd.output_names)}, {self.duration:g} s at "
                f"{self.sample_rate:g} Hz, {self.psd.n_windows} windows of "
                f"{self.psd.window_length:g} s, {self.n_pedestrians} pedestrians, seed={self.seed})")

    def metadata(self) -> dict[str, Any]:
        """JSON-ready summaries (no spectrum: ``psd`` is a :class:`ResponsePSD`, whose
        ``to_dict`` holds it)."""
        return {"output_names": list(self.psd.output_names), "sample_rate": self.sample_rate,
                "duration": self.duration, "seed": self.seed, "time_step": self.time_step,
                "n_pedestrians": self.n_pedestrians, "mean_on_deck": self.mean_on_deck,
                "max_on_deck": self.max_on_deck, "hsi": self.hsi, "warm_up": self.warm_up,
                "rms": self.rms.tolist(), "peak": self.peak.tolist(),
                "window_length": self.psd.window_length, "n_windows": self.psd.n_windows}
