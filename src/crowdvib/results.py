"""Frozen result objects shared by the models, the estimator and the edges (I/O, plots, CLI).

Each result documents its fields with units, offers ``to_dict()`` for JSON and, where a picture
helps, ``plot()`` which delegates to :mod:`crowdvib.plotting` (imported only then).
"""

from dataclasses import dataclass, field

import numpy as np

from ._validation import as_float_array, frozen_array, name_indices
from .errors import DataError, ParameterError

__all__ = ["ResponsePSD", "FRF", "EffectiveModalProperties", "HSIEstimate", "Simulation"]


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
    """

    frequency: np.ndarray
    psd: np.ndarray
    output_names: tuple
    window_length: float = None
    n_windows: int = None
    lowpass: object = None
    source: str = "model"
    unit: str = "(m/s²)²/Hz"

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

    def check_measured(self):
        """Raise a :class:`DataError` if the PSD holds NaN, infinite or negative values."""
        for row, name in zip(self.psd, self.output_names):
            bad = np.flatnonzero(~np.isfinite(row) | (row < 0))
            if bad.size:
                raise DataError(
                    f"measured PSD of output {name!r} must be finite and >= 0, got {row[bad[0]]} "
                    f"at {self.frequency[bad[0]]:g} Hz (index {bad[0]})")
        return self

    def select(self, names):
        """The PSDs of the named outputs, in that order."""
        rows = name_indices(names, self.output_names)
        return self._with(psd=self.psd[rows],
                          output_names=tuple(self.output_names[i] for i in rows))

    def band(self, lower, upper):
        """The PSDs restricted to lower <= f <= upper [Hz]."""
        keep = (self.frequency >= lower) & (self.frequency <= upper)
        return self._with(frequency=self.frequency[keep], psd=self.psd[:, keep])

    def variance(self, lower=0.0, upper=np.inf):
        """Band variance ∫ G df over [lower, upper] per output [(m/s²)²], trapezoid rule."""
        keep = (self.frequency >= lower) & (self.frequency <= upper)
        return np.trapezoid(self.psd[:, keep], self.frequency[keep], axis=-1)

    def rms(self, lower=0.0, upper=np.inf):
        """RMS value per output over a band [m/s²]."""
        return np.sqrt(self.variance(lower, upper))

    def peak_frequency(self):
        """Frequency of the PSD maximum per output [Hz]."""
        return self.frequency[np.argmax(self.psd, axis=-1)]

    def _with(self, **changes):
        fields = dict(frequency=self.frequency, psd=self.psd, output_names=self.output_names,
                      window_length=self.window_length, n_windows=self.n_windows,
                      lowpass=self.lowpass, source=self.source, unit=self.unit)
        fields.update(changes)
        return ResponsePSD(**fields)

    def plot(self, *, output=None, band=None, ax=None, title=None, label=None):
        """Draw the PSD of one output (see :func:`crowdvib.plotting.plot_psd_comparison`)."""
        from .plotting import plot_psd_comparison

        return plot_psd_comparison({label or self.source: self}, output=output, band=band,
                                   ax=ax, title=title)

    def to_dict(self):
        """JSON-ready dict of the PSD and its metadata."""
        return {"frequency": self.frequency.tolist(), "psd": self.psd.tolist(),
                "output_names": list(self.output_names), "window_length": self.window_length,
                "n_windows": self.n_windows, "source": self.source, "unit": self.unit,
                "lowpass": None if self.lowpass is None else self.lowpass.to_dict()}


@dataclass(frozen=True, eq=False)
class FRF:
    """Accelerance frequency-response functions between points of the deck.

    Attributes
    ----------
    frequency : ndarray, shape (n_frequencies,)
        Frequencies [Hz].
    values : ndarray of complex, shape (n_outputs, n_inputs, n_frequencies)
        Acceleration at each output per unit vertical force at each input [(m/s²)/N].
    output_names, input_names : tuple of str
    occupied : bool
        True when the crowd's apparent mass is included.
    unit : str
    """

    frequency: np.ndarray
    values: np.ndarray
    output_names: tuple
    input_names: tuple
    occupied: bool = False
    unit: str = "(m/s²)/N"

    def __post_init__(self):
        object.__setattr__(self, "frequency", frozen_array(self.frequency))
        object.__setattr__(self, "values", frozen_array(self.values, complex))

    def plot(self, occupied=None, *, output=None, input=None, band=None, ax=None, title=None):
        """Draw |H| of one output/input pair, with an occupied FRF beside it if given
        (see :func:`crowdvib.plotting.plot_frf`)."""
        from .plotting import plot_frf

        return plot_frf(self, occupied, output=output, input=input, band=band, ax=ax,
                        title=title)

    def magnitude(self, output, input=None):
        """|H| [(m/s²)/N] of one output/input pair (input defaults to the output itself)."""
        o = self.output_names.index(output)
        i = self.input_names.index(output if input is None else input)
        return np.abs(self.values[o, i])


@dataclass(frozen=True, eq=False)
class EffectiveModalProperties:
    """Modal properties of the occupied structure (smeared crowd of MSDs, physics.md §2.7).

    Attributes
    ----------
    frequencies : ndarray, shape (n_modes,)
        Effective natural frequencies f = |λ|/2π [Hz], one per structural mode.
    damping_ratios : ndarray, shape (n_modes,)
        Effective damping ratios ξ = −Re λ/|λ| [-].
    participation : ndarray, shape (n_modes,)
        Share of the pole's modal kinetic energy in that structural mode [-]; near 1 for a
        structure-like pole.
    interaction_frequencies, interaction_damping_ratios : ndarray
        The remaining, MSD-like poles (the crowd's own resonance), kept apart [Hz], [-].
    """

    frequencies: np.ndarray
    damping_ratios: np.ndarray
    participation: np.ndarray
    interaction_frequencies: np.ndarray
    interaction_damping_ratios: np.ndarray

    def to_dict(self):
        """JSON-ready dict."""
        return {name: np.asarray(getattr(self, name)).tolist() for name in
                ("frequencies", "damping_ratios", "participation", "interaction_frequencies",
                 "interaction_damping_ratios")}


@dataclass(frozen=True, eq=False)
class HSIEstimate:
    """Result of :func:`crowdvib.estimate_hsi` (paper Eq. 5 and 6).

    Attributes
    ----------
    msd : MSDModel
        The estimated mass-spring-damper model (f_h1 [Hz], ξ_h1 [-], μ_h1 [-]).
    cost : float
        Objective J(θ̂) = Σ_l γ_l ‖G̃_l − G_l(θ̂)‖² / ‖G̃_l‖² [-] (paper Eq. 6).
    cost_no_hsi : float
        The same objective for the structure without HSI (crowd as moving forces only) [-].
    n_evaluations : int
        Forward-model evaluations over all starting points.
    success : bool
        Whether the best start converged (``least_squares`` status > 0).
    active_bounds : tuple of str
        Parameters of the optimum that sit on a bound, e.g. ``("damping_ratio:upper",)``.
    free_parameters : tuple of str
        The estimated parameters.
    bounds : dict
        Parameter → (lower, upper).
    band : tuple of float
        Analysis band [Hz].
    output_names : tuple of str
    output_weights : ndarray
        γ_l, normalised to sum 1.
    starts : tuple of dict
        Per starting point: ``start``, ``estimate``, ``cost``, ``n_evaluations``, ``status``.
    message : str
        The optimiser's message for the best start.
    """

    msd: object
    cost: float
    cost_no_hsi: float
    n_evaluations: int
    success: bool
    active_bounds: tuple
    free_parameters: tuple
    bounds: dict
    band: tuple
    output_names: tuple
    output_weights: np.ndarray
    starts: tuple = field(default=())
    message: str = ""

    @property
    def relative_cost(self):
        """J(θ̂)/J(no HSI) [-]: the paper's "residual relative to no HSI"."""
        return self.cost / self.cost_no_hsi if self.cost_no_hsi > 0 else np.nan

    def to_dict(self):
        """JSON-ready dict; the estimate sits under ``"estimate"``."""
        return {
            "estimate": self.msd.to_dict(),
            "cost": self.cost, "cost_no_hsi": self.cost_no_hsi,
            "relative_cost": self.relative_cost, "n_evaluations": self.n_evaluations,
            "success": self.success, "active_bounds": list(self.active_bounds),
            "free_parameters": list(self.free_parameters),
            "bounds": {k: list(v) for k, v in self.bounds.items()},
            "band": list(self.band), "output_names": list(self.output_names),
            "output_weights": np.asarray(self.output_weights).tolist(),
            "starts": [dict(s) for s in self.starts], "message": self.message,
        }


@dataclass(frozen=True, eq=False)
class Simulation:
    """Record of a time-domain simulation (:func:`crowdvib.simulate`, physics.md §2).

    Attributes
    ----------
    time : ndarray, shape (n_samples,)
        Sample times [s], from 0 at 1/sample_rate.
    acceleration : ndarray, shape (n_outputs, n_samples)
        Vertical accelerations at the output points [m/s²].
    output_names : tuple of str
        Names of the outputs (rows of ``acceleration``).
    n_on_deck : ndarray of int, shape (n_samples,)
        Pedestrians on the deck at each sample [-].
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

    time: np.ndarray
    acceleration: np.ndarray
    output_names: tuple
    n_on_deck: np.ndarray
    sample_rate: float
    seed: int
    duration: float
    modal_load: np.ndarray = None
    time_step: float = None
    n_pedestrians: int = None
    hsi: bool = False
    warm_up: float = 0.0

    def __post_init__(self):
        acceleration = np.atleast_2d(np.asarray(self.acceleration, dtype=float))
        names = tuple(str(n) for n in self.output_names)
        if acceleration.shape[0] != len(names):
            raise ParameterError(
                f"acceleration must have one row per output ({len(names)}), "
                f"got shape {acceleration.shape}")
        object.__setattr__(self, "time", frozen_array(self.time))
        object.__setattr__(self, "acceleration", frozen_array(acceleration))
        object.__setattr__(self, "output_names", names)
        object.__setattr__(self, "n_on_deck", frozen_array(self.n_on_deck, dtype=np.int64))
        if self.modal_load is not None:
            object.__setattr__(self, "modal_load", frozen_array(self.modal_load))

    @property
    def n_samples(self):
        """Number of samples per output."""
        return self.time.size

    def psd(self, window_length, overlap=0.5, lowpass=None):
        """Welch PSD of the accelerations → :class:`ResponsePSD` (physics.md §6).

        Parameters
        ----------
        window_length : float
            Segment length T [s] (Hann window).
        overlap : float
            Overlap of consecutive segments, fraction of T.
        lowpass : LowPassFilter, optional
            Zero-phase filter applied first.
        """
        from .signals import welch_psd  # signals imports this module

        return welch_psd(self.acceleration, self.sample_rate, window_length=window_length,
                         overlap=overlap, output_names=self.output_names, lowpass=lowpass)

    def plot(self, *, output=None, window=1.0, axes=None, title=None):
        """Draw the record, its running RMS and the people on the deck
        (see :func:`crowdvib.plotting.plot_time_history`)."""
        from .plotting import plot_time_history

        return plot_time_history(self, output=output, window=window, axes=axes, title=title)

    def to_dict(self):
        """JSON-ready metadata (no time series; write those with the I/O functions)."""
        return {"output_names": list(self.output_names), "sample_rate": self.sample_rate,
                "n_samples": self.n_samples, "duration": self.duration, "seed": self.seed,
                "time_step": self.time_step, "n_pedestrians": self.n_pedestrians,
                "hsi": self.hsi, "warm_up": self.warm_up,
                "mean_on_deck": float(self.n_on_deck.mean()) if self.n_samples else 0.0,
                "rms": np.sqrt(np.mean(self.acceleration**2, axis=-1)).tolist(),
                "modal_load_recorded": self.modal_load is not None}
