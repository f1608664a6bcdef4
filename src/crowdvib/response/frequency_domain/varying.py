"""The expected Welch PSD of a record whose crowd changes slowly (issue 28 §1; docs: theory, A
crowd that changes).

A Welch estimate averages the periodograms of its windows; when the crowd changes little within
a window's span, the bridge's memory 1/(2π ξ f) and a crossing, each window's expectation is the
stationary crowd's at the density then on the deck, and the record's is their average:

    Ḡ(f) = ∫ W(t) G(f; d_deck(t)) dt / ∫ W(t) dt,   W(t) = Σ_k w²(t − t_k),

W the Welch windows' summed Hann² weight (each window's periodogram weighs its samples by w²) and
d_deck the profile's mean over the last crossing (:meth:`CrowdProfile.deck_density`). The density
law seen this way is put on a few levels d_i by a Gauss rule of that law (exact for polynomials
in d of degree 2n − 1, the mean among them), and Ḡ = Σ_i p_i G(f; d_i) with a smeared or a
fluctuating model per level; the number of levels grows until the next changes Ḡ by less than
0.5 % of its peak.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..._estimators import DEFAULT_CROWD_MODEL
from ..._validation import check_positive, check_type
from ...errors import ParameterError
from ...models.crowd import Crowd
from ...models.pedestrian import MSDModel
from ...models.profile import CrowdProfile
from ...models.structure import ModalModel
from ...signals import ResponsePSD
from .fluctuation import FluctuatingSpectralModel, _gauss_rule, _mixture, spectral_model

__all__ = ["VaryingCrowdModel", "varying_response_psd", "density_law", "record_model",
           "record_duration"]

#: Level counts tried, and the change of Ḡ over its peak below which a count is enough.
_LEVEL_COUNTS = (1, 2, 3, 4, 5, 6, 8, 10, 12, 16)
_LEVEL_TOLERANCE = 5e-3
#: Options of a smeared model (the fluctuating model's own are left out when choosing levels).
_SMEARED_OPTIONS = ("force", "outputs", "lowpass", "dampers")
#: Reference MSD with which the level count is chosen (the paper's values).
_REFERENCE_MSD = MSDModel()
#: Time points per Welch window (or per record without windows) for the density law.
_POINTS_PER_WINDOW = 64
_MIN_POINTS = 4096


def _welch_weight(t, duration, window_length, overlap):
    """W(t): the summed Hann² weight of the Welch windows [0, T), [s, s + T), … that fit in
    [0, duration] (a step s = T − T·overlap); uniform without windows."""
    if window_length is None:
        return np.ones_like(t)
    step = window_length * (1 - overlap)
    count = int(np.floor((duration - window_length) / step + 1e-9)) + 1
    if count < 1:
        raise ParameterError(f"duration must hold one Welch window: {duration:g} s is shorter "
                             f"than welch_window_length = {window_length:g} s")
    weight = np.zeros_like(t)
    last = np.floor(t / step).astype(int)
    for back in range(int(np.ceil(1 / (1 - overlap))) + 1):
        k = last - back
        phase = (t - k * step) / window_length
        inside = (k >= 0) & (k < count) & (phase >= 0) & (phase < 1)
        weight += np.where(inside, np.sin(np.pi * phase) ** 4, 0.0)
    return weight


def density_law(structure: ModalModel, crowd: Crowd, duration: float, *,
                welch_window_length: float | None = None,
                overlap: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """The deck densities a record [0, duration] shows its Welch average, and their weights
    → (densities d(t_j) [persons/m²], weights summing to 1), on a regular time grid.

    d is the mean of the crowd's profile (``crowd.profile``) over the last crossing L/v at the
    crowd's speed; the weight of t_j is the Welch windows' summed Hann² there (uniform without
    ``welch_window_length``).
    """
    profile = _profile_of(crowd)
    duration = check_positive("duration", duration, unit="s")
    if welch_window_length is not None:
        welch_window_length = check_positive("welch_window_length", welch_window_length,
                                             unit="s")
    if not 0.0 <= overlap < 1.0:
        raise ParameterError(f"overlap must lie in [0, 1), got {overlap!r}")
    per = duration if welch_window_length is None else welch_window_length
    points = max(_MIN_POINTS, int(np.ceil(_POINTS_PER_WINDOW * duration / per)))
    t = (np.arange(points) + 0.5) * duration / points
    weight = _welch_weight(t, duration, welch_window_length, overlap)
    density = profile.deck_density(t, structure.length / crowd.walking_speed)
    return density, weight / weight.sum()


def _profile_of(crowd: Crowd) -> CrowdProfile:
    """The profile a crowd's density is, or a ParameterError: the record's model follows a
    density that changes (a stationary crowd's model is :func:`~crowdvib.response_psd`)."""
    profile = check_type("crowd", crowd, Crowd).profile
    if profile is None:
        raise ParameterError(
            f"crowd.density must be a CrowdProfile (the density against the record's time) for "
            f"the model of a crowd that changes, got the number {crowd.density:g}: "
            "Crowd(density=CrowdProfile(...), ...) or crowd.with_density(profile); "
            "crowdvib.response_psd models a stationary crowd")
    return profile


def _levels(density, weight, count):
    """The ``count``-point Gauss rule of a density law → (levels, probabilities): Σ p_i g(d_i)
    is exact for polynomials g of degree 2·count − 1 (Golub & Welsch, as the occupancy's rule).
    One density only: that density."""
    if np.all(density == density[0]):
        return density[:1].copy(), np.ones(1)
    if count == 1:
        return np.array([float(weight @ density)]), np.ones(1)
    return _gauss_rule(density, weight, count)


class VaryingCrowdModel:
    """Expected Welch PSD of a record whose crowd follows a :class:`CrowdProfile` (module
    docstring; docs: theory, A crowd that changes).

    The drop-in counterpart of :class:`~crowdvib.response.SpectralModel` and
    :class:`~crowdvib.response.FluctuatingSpectralModel` (``psd_array``, ``cross_psd_array``,
    ``psd``): Ḡ(f) = Σ_i p_i G(f; d_i) over the levels d_i of the record's density law.

    Parameters
    ----------
    structure : ModalModel
    crowd : Crowd
        The walkers (speed, step frequencies, body mass) and their density, a
        :class:`CrowdProfile` against time, t = 0 the record's first sample.
    frequency : array_like
        Frequencies [Hz].
    duration : float
        Record length [s].
    welch_window_length : float, optional
        Welch segment length T [s]: the model is what the Welch average sees (its kernel and its
        windows' weights over time). None: the exact PSD averaged uniformly over the record.
    weights_window_length : float, optional
        With ``welch_window_length`` None: the exact PSD averaged over the record as Welch
        windows of this length weigh its times (a parametric bootstrap's record, drawn from the
        exact PSD and then Welch-averaged; docs: theory, Parametric bootstrap).
    overlap : float
        Overlap of the Welch segments (default 0.5, as :func:`crowdvib.welch_psd`).
    crowd_model : {"fluctuating", "smeared"}
        The model of each level (docs: theory, The fluctuating crowd). The default is the
        estimator's (:func:`crowdvib.estimate_hsi`, the fluctuating crowd), as for
        :func:`crowdvib.response_psd`; ``"smeared"`` is the paper's mean crowd.
    levels : int, optional
        Density levels, the nodes of the Gauss rule of the record's density law (default: the
        fewest of 1, 2, 3, 4, 5, 6, 8, 10, 12, 16 that the next count changes by less than 0.5 %
        of the peak, judged with smeared models and the paper's MSD; one for a record at one
        density).
    **options
        Passed to each level's model (``force``, ``outputs``, ``lowpass``, ``dampers``; for the
        fluctuating model also ``n_nodes``, ``mode``, ``finite_crossing``, ``modulation``).

    Attributes
    ----------
    levels, probabilities : ndarray
        The density levels [persons/m²] and their shares of the Welch average.
    crowd : Crowd
        The walkers at the record's mean deck density (as the Welch average weighs it).
    """

    def __init__(self, structure: ModalModel, crowd: Crowd,
                 frequency: ArrayLike, *, duration: float,
                 welch_window_length: float | None = None,
                 weights_window_length: float | None = None, overlap: float = 0.5,
                 crowd_model: str = DEFAULT_CROWD_MODEL, levels: int | None = None,
                 **options: Any) -> None:
        check_type("structure", structure, ModalModel)
        profile = _profile_of(crowd)
        if levels is not None and (not isinstance(levels, (int, np.integer))
                                   or not 1 <= levels <= 40):
            raise ParameterError(f"levels must be an integer from 1 to 40, got {levels!r}")
        density, weight = density_law(structure, crowd, duration,
                                      welch_window_length=welch_window_length
                                      or weights_window_length, overlap=overlap)
        self.duration, self.overlap, self.crowd_model = float(duration), overlap, crowd_model
        smeared = {}

        def model(level, kind=crowd_model):
            return spectral_model(structure, crowd.with_density(level), frequency,
                                  crowd_model=kind, welch_window_length=welch_window_length,
                                  **{k: v for k, v in options.items()
                                     if kind == crowd_model or k in _SMEARED_OPTIONS})

        def mixture(rule):          # judged with the smeared models: cheap, and G(f; d) as smooth
            for level in rule[0]:
                if level not in smeared:
                    smeared[level] = model(level, "smeared")
            return _mixture(rule[1], [smeared[d] for d in rule[0]], _REFERENCE_MSD)

        if levels is None:
            current = _levels(density, weight, _LEVEL_COUNTS[0])
            for count in _LEVEL_COUNTS[1:] if np.ptp(density) > 0 else ():
                try:
                    finer = _levels(density, weight, count)
                except ParameterError:          # the law has fewer points than nodes
                    break
                coarse, fine = mixture(current), mixture(finer)
                if np.abs(coarse - fine).max() <= _LEVEL_TOLERANCE * fine.max():
                    break
                current = finer
        else:
            current = _levels(density, weight, levels)
        self.levels, self.probabilities = current
        self._models = [model(level) for level in self.levels]
        first = self._models[0]
        self.structure, self.frequency, self.force = structure, first.frequency, first.force
        self.output_names, self.lowpass = first.output_names, first.lowpass
        self.welch_window_length = first.welch_window_length
        self.profile = profile
        self.crowd = crowd.with_density(float(self.probabilities @ self.levels))

    def details(self) -> dict[str, Any]:
        """What the average is made of, for a report: the density levels and their range, the
        mean density, and for the fluctuating model the details of its heaviest level."""
        heaviest = self._models[int(np.argmax(self.probabilities))]
        own = heaviest.details()
        return dict(own, density_levels=int(self.levels.size),
                    density_range=(float(self.levels.min()), float(self.levels.max())),
                    mean_density=float(self.crowd.density))

    def with_step_frequencies(self, crowd: Crowd) -> VaryingCrowdModel:
        """The same average for walkers that differ only in their step-frequency distribution
        (the levels and their shares are kept).

        Parameters
        ----------
        crowd : Crowd
            The walkers with other step frequencies (the levels are kept: its density is not
            read).
        """
        check_type("crowd", crowd, Crowd)
        other = copy.copy(self)
        other.crowd = crowd.with_density(self.crowd.density)
        other._models = [m.with_step_frequencies(crowd.with_density(m.crowd.density))
                         for m in self._models]
        return other

    def psd_array(self, msd: MSDModel | None = None) -> np.ndarray:
        """Expected PSD [(m/s²)²/Hz], shape (n_outputs, n_frequencies).

        Parameters
        ----------
        msd : MSDModel, optional
            The pedestrians' MSD; None for the crowd as moving forces only (no HSI).
        """
        return _mixture(self.probabilities, self._models, msd)

    def cross_psd_array(self, msd: MSDModel | None = None) -> np.ndarray:
        """Expected cross-spectral matrix, shape (n_outputs, n_outputs, n_frequencies).

        Parameters
        ----------
        msd : MSDModel, optional
            The pedestrians' MSD; None for the crowd as moving forces only (no HSI).
        """
        return _mixture(self.probabilities, self._models, msd, cross=True)

    def variance_ratio(self, msd: MSDModel | None = None) -> np.ndarray:
        """Σ p_i G_i² / Ḡ² per output and bin [-], >= 1: how much more the Welch average of
        windows with different expectations scatters than a stationary record of Ḡ would, when
        the windows are independent (docs: theory, A crowd that changes).

        Parameters
        ----------
        msd : MSDModel, optional
            The pedestrians' MSD; None for the crowd as moving forces only (no HSI).
        """
        squares = sum(p * m.psd_array(msd) ** 2 for p, m in zip(self.probabilities,
                                                                self._models))
        mean = self.psd_array(msd)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(mean > 0, squares / mean**2, 1.0)

    #: Expected PSD at the outputs → :class:`ResponsePSD` (the same as the fluctuating model's).
    psd = FluctuatingSpectralModel.psd


def varying_response_psd(structure: ModalModel, crowd: Crowd,
                         frequency: ArrayLike, *, duration: float,
                         msd: MSDModel | None = None,
                         welch_window_length: float | None = None, overlap: float = 0.5,
                         crowd_model: str = DEFAULT_CROWD_MODEL,
                         outputs: str | Sequence[str] | None = None,
                         **options: Any) -> ResponsePSD:
    """The expected (Welch) PSD of a record of ``duration`` whose crowd's density follows a
    profile: :class:`VaryingCrowdModel` in one call (docs: theory, A crowd that changes).

    Parameters
    ----------
    structure, crowd, frequency, duration, welch_window_length, overlap, crowd_model
        As for :class:`VaryingCrowdModel`.
    msd : MSDModel, optional
        The pedestrians' MSD; None for no HSI.
    outputs : str or sequence of str, optional
        Output names (default all).
    **options
        Passed to :class:`VaryingCrowdModel` (``levels``, ``force``, ``lowpass``, ...).

    Returns
    -------
    ResponsePSD

    Examples
    --------
    >>> import numpy as np
    >>> from crowdvib import Crowd, MSDModel, ModalModel
    >>> from crowdvib.models import CrowdProfile
    >>> bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    >>> ramp = Crowd.from_density(0.6).with_density(CrowdProfile([0.0, 3600.0], [0.2, 1.0]))
    >>> psd = varying_response_psd(bridge, ramp, np.arange(60, 181) / 60, duration=3600.0,
    ...                            msd=MSDModel(), welch_window_length=60.0)
    >>> psd.psd.shape
    (1, 121)
    """
    return VaryingCrowdModel(structure, crowd, frequency, duration=duration,
                             welch_window_length=welch_window_length, overlap=overlap,
                             crowd_model=crowd_model, outputs=outputs, **options).psd(msd)


def record_model(structure: ModalModel, crowd: Crowd, frequency: ArrayLike, *,
                 record_windows: tuple[float | None, int | None] = (None, None),
                 crowd_model: str = "smeared", **options: Any) -> Any:
    """The expected PSD of a measured record: the stationary crowd's model
    (:func:`~crowdvib.response.fluctuation.spectral_model`), or for a crowd whose density is a
    profile the :class:`VaryingCrowdModel` of the record whose Welch estimate has
    ``record_windows`` =
    (window length [s], number of windows), the windows at 50 % overlap from t = 0 as
    :func:`crowdvib.welch_psd` places them (what the estimator fits and a report draws).
    ``options`` are the models' (``welch_window_length`` among them)."""
    if check_type("crowd", crowd, Crowd).profile is None:
        return spectral_model(structure, crowd, frequency, crowd_model=crowd_model, **options)
    window, n_windows = record_windows
    if not (window and n_windows):
        raise ParameterError(
            "a crowd whose density is a profile needs a Welch estimate (its window_length and "
            "n_windows known) to "
            f"place the record on the profile, got window_length = {window!r}, "
            f"n_windows = {n_windows!r}")
    return VaryingCrowdModel(structure, crowd, frequency,
                             duration=record_duration(window, n_windows),
                             crowd_model=crowd_model, **options)


def record_duration(window_length: float, n_windows: int) -> float:
    """The length [s] of a record whose Welch estimate has ``n_windows`` windows of
    ``window_length`` at 50 % overlap."""
    return window_length * (1 + 0.5 * (n_windows - 1))
