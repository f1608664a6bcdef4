"""Walking force models: one person's force on a rigid floor and the spectral load of a crowd.

Each model describes the dynamic part of a pedestrian's vertical force as a sum of sinusoids at
multiples r_c of the step frequency f_s, p(t) = W Σ_c α_c sin(2π r_c f_s t + θ_c) (docs: theory, The walking force),
and gives

* ``sample``: dynamic load factors (DLFs) and phases of individual pedestrians (time domain);
* ``load_spectrum``: the one-sided PSD per unit crowd influence of a stationary Poisson crowd,
  G_QQ(f) = Ψ · s(f) (docs: theory, Modal load PSD of a Poisson crowd), used by the spectral response model.

Every constant sits in a table below with its provenance.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike
from scipy import special

from .._validation import check_non_negative, check_positive
from ..errors import ParameterError

if TYPE_CHECKING:
    from .crowd import Crowd
    from .structure import ModalModel

__all__ = ["ForceModel", "WalkingForce", "ZivanovicForce", "YoungForce", "STANDARD_GRAVITY",
           "as_force_model", "modal_load_psd"]

#: Gravitational acceleration g [m/s²] used to turn body mass into weight (docs: theory, Conventions).
STANDARD_GRAVITY = 9.81

# Živanović, Pavić & Reynolds (2007), harmonic form (docs: theory, Živanović, Pavić & Reynolds (2007)). Provenance: the DLF means,
# spreads and subharmonic regressions are SOURCED from a public implementation of the paper's
# table (docs: theory, Živanović, Pavić & Reynolds (2007), §10); the first-harmonic polynomial is Kerr's (1998) fit.
ZIVANOVIC_DLF1_POLYNOMIAL = (-0.2649, 1.3206, -1.7597, 0.7613)  # μ₁(f_s), highest power first
ZIVANOVIC_DLF1_COV = 0.16                                       # std of α₁ = 0.16 μ₁(f_s)
ZIVANOVIC_HARMONIC_MEAN = (None, 0.07, 0.05, 0.05, 0.03)         # h = 1..5 (h = 1: polynomial)
ZIVANOVIC_HARMONIC_STD = (None, 0.030, 0.020, 0.020, 0.015)
ZIVANOVIC_SUBHARMONIC_SLOPE = (0.026, 0.074, 0.012, 0.013, 0.015)   # α_s,h = a_h α₁ + b_h
ZIVANOVIC_SUBHARMONIC_OFFSET = (0.0031, 0.0100, 0.0160, 0.0093, 0.0072)

# Young (2001) mean DLFs, α_h = c_h + s_h · (h f_s), α₁ capped at 0.56 (docs: theory, Young (2001); formulas
# SOURCED, argument h·f_s per the public implementation cited there).
YOUNG_OFFSET = (-0.41 * 0.95, 0.069, 0.033, 0.013)
YOUNG_SLOPE = (0.41, 0.0056, 0.0064, 0.0065)
YOUNG_DLF1_CAP = 0.56


class _ReplayedForce:
    """Base of the forces that replay measured histories, time domain only
    (:class:`~crowdvib.models.measured.MeasuredForce`): named here so that
    :func:`as_force_model` knows them without importing measured.py, which builds on this module."""


@runtime_checkable
class ForceModel(Protocol):
    """What the package calls on a walking-force model (docs: theory, The walking force: your own model).

    * the spectral model (:class:`~crowdvib.response.frequency_domain.spectral.SpectralModel`, hence
      :func:`~crowdvib.response.frequency_domain.fluctuation.response_psd` and the estimator
      :func:`~crowdvib.identification.estimation.estimate_hsi`) calls ``load_spectrum`` only;
    * the simulator (:func:`~crowdvib.response.time_domain.simulation.simulate`) calls ``ratios`` and
      ``sample``: walker k's force is m_k g Σ_c α_kc sin(2π r_c f_s,k t + θ_kc).

    Any object with these three members works (no base class needed); subclassing
    :class:`WalkingForce` gives ``load_spectrum`` from ``mean_square_dlf``.
    """

    @property
    def ratios(self) -> np.ndarray:
        """Multiples r_c of the step frequency, shape (n_components,)."""

    def sample(self, step_frequency: ArrayLike,
               rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """DLFs α_c [-] and phases θ_c [rad], each shape (n_pedestrians, n_components).

        Parameters
        ----------
        step_frequency : array_like, shape (n_pedestrians,)
            Each walker's step frequency [Hz].
        rng : numpy.random.Generator
            The draws' generator.
        """

    def load_spectrum(self, frequency: ArrayLike, crowd: Crowd) -> np.ndarray:
        """One-sided crowd-load PSD per unit influence s(f) [N²/Hz], shape of ``frequency``.

        Parameters
        ----------
        frequency : array_like
            Frequencies [Hz].
        crowd : Crowd
            The crowd (its step-frequency distribution, body masses and density).
        """


#: The members each side calls (see :class:`ForceModel`).
_SPECTRAL_MEMBERS = ("load_spectrum",)
_TIME_DOMAIN_MEMBERS = ("ratios", "sample")


class WalkingForce:
    """Base of a force model from per-component DLF statistics (a :class:`ForceModel`).

    A subclass sets ``ratios``, ``mean_square_dlf`` and ``sample`` (and ``scale``, default 1);
    the crowd-load spectrum, the modal-load PSD and single time histories follow from them.
    """

    #: Scale factor on every DLF (1 = the model as published); set by each force model.
    scale: float = 1.0

    @property
    def ratios(self) -> np.ndarray:
        """Multiples r_c of the step frequency, one per force component."""
        raise NotImplementedError

    def mean_square_dlf(self, step_frequency: ArrayLike) -> np.ndarray:
        """E[α_c² | f_s] [-] of each component c at its own step frequency.

        Parameters
        ----------
        step_frequency : array_like, shape (n_components, ...)
            Row c holds the step frequencies at which component c is evaluated (broadcast a
            single array with ``np.broadcast_to(f_s, (n_components,) + f_s.shape)``).
        """
        raise NotImplementedError

    def sample(self, step_frequency: ArrayLike,
               rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """DLFs α_c [-] and phases θ_c [rad] of pedestrians with the given step frequencies.

        Parameters
        ----------
        step_frequency : array_like, shape (n_pedestrians,)
            Each walker's step frequency [Hz].
        rng : numpy.random.Generator
            The draws' generator.

        Returns
        -------
        amplitudes, phases : ndarray, shape (n_pedestrians, n_components)
        """
        raise NotImplementedError

    def load_spectrum(self, frequency: ArrayLike, crowd: Crowd) -> np.ndarray:
        """One-sided crowd-load PSD per unit influence s(f) [N²/Hz] (docs: theory, Modal load PSD of a Poisson crowd).

        s(f) = E[W²] Σ_c E[α_c² | f_s = f/r_c] / 2 · p_fs(f/r_c) / r_c, so that the modal-load
        cross-PSD is G_QQ(f) = Ψ s(f) with the crowd-influence matrix Ψ of docs: theory, The smeared crowd and the occupied bridge.
        Narrow-band approximation: the crossing time is long against 1/(r_c σ_fs).

        Parameters
        ----------
        frequency : array_like
            Frequencies f >= 0 [Hz].
        crowd : Crowd
            Step-frequency distribution and body mass.
        """
        frequency = np.asarray(check_non_negative("frequency", frequency, unit="Hz"))
        ratios = self.ratios.reshape((-1,) + (1,) * frequency.ndim)
        step = frequency / ratios                      # f_s at which component c sits at f
        terms = _half_mean_square_dlf(self, frequency, step) * crowd.step_frequency_pdf(step)
        return self.scale**2 * crowd.mean_square_weight() * (terms / ratios).sum(axis=0)

    def modal_load_psd(self, frequency: ArrayLike, crowd: Crowd,
                       structure: ModalModel) -> np.ndarray:
        """One-sided modal-load cross-PSD G_QQ(f) [N²/Hz], shape (n_f, n_modes, n_modes).

        Parameters
        ----------
        frequency : array_like
            Frequencies [Hz].
        crowd : Crowd
            The crowd.
        structure : ModalModel
            The structure whose modes the load projects on (its influence matrix Ψ).
        """
        return modal_load_psd(self, frequency, crowd, structure)

    def time_history(self, time: ArrayLike, step_frequency: float, body_mass: float,
                     rng: int | np.random.Generator | None = None) -> np.ndarray:
        """Force [N] of one pedestrian on a rigid floor, dynamic part only (docs: theory, Živanović, Pavić & Reynolds (2007)).

        Parameters
        ----------
        time : array_like
            Times [s].
        step_frequency : float
            f_s [Hz].
        body_mass : float
            m_h [kg].
        rng : None, int or numpy.random.Generator
            Seed or generator for the DLFs and phases.
        """
        step_frequency = check_positive("step_frequency", step_frequency, unit="Hz")
        rng = np.random.default_rng(rng)
        amplitudes, phases = self.sample(np.array([step_frequency]), rng)
        t = np.asarray(time, dtype=float)[..., np.newaxis]
        waves = np.sin(2 * np.pi * self.ratios * step_frequency * t + phases[0])
        return body_mass * STANDARD_GRAVITY * waves @ amplitudes[0]


def _half_mean_square_dlf(force, frequency, step):
    """E[α_c² | f_s = f/r_c] / 2 on the grid ``frequency``; ``step`` = f/r_c.

    It depends on the force model and the grid, not on the crowd: an estimate asks for it on
    one grid some 1600 times (each step-frequency distribution and occupancy node tried), so
    a frozen dataclass (the built-in models: equal fields, equal values) keeps its last grids.
    Other models are computed each time: one that can change after a call must not be
    answered from a cache.
    """
    params = getattr(force, "__dataclass_params__", None)
    if params is None or not params.frozen:
        return force.mean_square_dlf(step) / 2.0
    return _cached_half_mean_square_dlf((force, frequency.shape, frequency.tobytes()))


@functools.cache
def _harmonic_mean_squares():
    """E[α_c²] of the second to fifth harmonics' DLFs (Živanović): constants, as their draws do
    not follow the step frequency; computed once, not at every evaluation of the load."""
    squares = positive_normal_moments(np.asarray(ZIVANOVIC_HARMONIC_MEAN[1:]),
                                      np.asarray(ZIVANOVIC_HARMONIC_STD[1:]))[1]
    squares.flags.writeable = False
    return squares


@functools.lru_cache(maxsize=16)
def _cached_half_mean_square_dlf(key):
    force, shape, data = key
    frequency = np.frombuffer(data, dtype=float).reshape(shape)
    step = frequency / force.ratios.reshape((-1,) + (1,) * frequency.ndim)
    values = force.mean_square_dlf(step) / 2.0
    values.flags.writeable = False
    return values


def modal_load_psd(force: ForceModel, frequency: ArrayLike, crowd: Crowd,
                   structure: ModalModel) -> np.ndarray:
    """One-sided modal-load cross-PSD G_QQ(f) = Ψ s(f) [N²/Hz] of any force model, shape
    (n_f, n_modes, n_modes) (docs: theory, Modal load PSD of a Poisson crowd)."""
    psi = structure.influence_matrix(crowd.density)
    return np.asarray(force.load_spectrum(frequency, crowd))[:, np.newaxis, np.newaxis] * psi


def _check_scale(scale):
    return check_positive("scale", scale)


@dataclass(frozen=True)
class ZivanovicForce(WalkingForce):
    """Živanović, Pavić & Reynolds (2007) probabilistic walking force, harmonic form.

    Five harmonics (r = 1…5) and five subharmonics (r = 0.5…4.5) with random DLFs and phases
    uniform in [0, 2π) (docs: theory, Živanović, Pavić & Reynolds (2007)).

    Parameters
    ----------
    subharmonics_follow_sampled_dlf : bool
        True: the subharmonic DLFs follow each pedestrian's sampled α₁ (docs: theory, Živanović, Pavić & Reynolds (2007) default);
        False: they follow the mean μ₁(f_s), as the public implementation does (and as the
        check values of docs: theory, Spectral-model numbers assume).
    scale : float
        Factor on every DLF (1 = the published model); for load-model sensitivity studies.

    See Also
    --------
    YoungForce : Young's mean DLFs.
    MeasuredForce : measured walking forces replayed.
    crowdvib.response_psd

    References
    ----------
    S. Živanović, A. Pavić and P. Reynolds, "Probability-based prediction of multi-mode vibration
    response to walking excitation", *Engineering Structures* 29(6):942–954, 2007.

    K. Van Nimmen, P. Van den Broeck, G. Lombaert and F. Tubino, "Pedestrian-induced vibrations of
    footbridges: an extended spectral approach", *Journal of Bridge Engineering*, 2020. The spectral
    load of the harmonics and subharmonics.

    The theory pages cite them (docs: theory, References).
    """

    subharmonics_follow_sampled_dlf: bool = True
    scale: float = 1.0

    def __post_init__(self):
        object.__setattr__(self, "scale", _check_scale(self.scale))

    @property
    def ratios(self) -> np.ndarray:
        return np.array([1.0, 2.0, 3.0, 4.0, 5.0, 0.5, 1.5, 2.5, 3.5, 4.5])

    @staticmethod
    def first_harmonic_dlf(step_frequency: ArrayLike) -> np.ndarray:
        """Mean first-harmonic DLF μ₁(f_s) (Kerr 1998 fit; docs: theory, Živanović, Pavić & Reynolds (2007)).

        Check value: μ₁(1.89) = 0.3644.

        Parameters
        ----------
        step_frequency : array_like
            Step frequencies f_s [Hz].
        """
        return np.polyval(ZIVANOVIC_DLF1_POLYNOMIAL, step_frequency)

    def mean_square_dlf(self, step_frequency: ArrayLike) -> np.ndarray:
        mu1 = self.first_harmonic_dlf(np.asarray(step_frequency, dtype=float))
        column = (slice(None),) + (np.newaxis,) * (mu1.ndim - 1)
        slope = np.asarray(ZIVANOVIC_SUBHARMONIC_SLOPE)[column]
        offset = np.asarray(ZIVANOVIC_SUBHARMONIC_OFFSET)[column]
        # The moments of the DLFs the sampler draws: normal, redrawn while not positive
        # (positive_normal), so the spectral load and the simulator see the same crowd.
        harmonics = np.broadcast_to(_harmonic_mean_squares()[column], mu1[1:5].shape)
        if self.subharmonics_follow_sampled_dlf:     # α_s = a α₁ + b with the sampled α₁
            # the first harmonic's and the subharmonics' α₁ in one call (elementwise: the
            # same values; a stencil's few frequencies cost the calls, not the arithmetic)
            drawn = mu1[[0, 5, 6, 7, 8, 9]]
            means, squares = positive_normal_moments(drawn, ZIVANOVIC_DLF1_COV * np.abs(drawn))
            first_square, sub_mean, sub_square = squares[:1], means[1:], squares[1:]
            sub = slope**2 * sub_square + 2 * slope * offset * sub_mean + offset**2
        else:
            first_square = positive_normal_moments(mu1[:1],
                                                   ZIVANOVIC_DLF1_COV * np.abs(mu1[:1]))[1]
            sub = (slope * mu1[5:] + offset) ** 2
        return np.concatenate([first_square, harmonics, sub])

    def sample(self, step_frequency: ArrayLike,
               rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        step_frequency = np.asarray(step_frequency, dtype=float)
        n = step_frequency.size
        mu1 = self.first_harmonic_dlf(step_frequency)
        means = np.column_stack([mu1] + [np.full(n, m) for m in ZIVANOVIC_HARMONIC_MEAN[1:]])
        stds = np.column_stack([ZIVANOVIC_DLF1_COV * np.abs(mu1)]
                               + [np.full(n, s) for s in ZIVANOVIC_HARMONIC_STD[1:]])
        main = positive_normal(means, stds, rng)
        alpha1 = main[:, :1] if self.subharmonics_follow_sampled_dlf else mu1[:, np.newaxis]
        sub = (np.asarray(ZIVANOVIC_SUBHARMONIC_SLOPE) * alpha1
               + np.asarray(ZIVANOVIC_SUBHARMONIC_OFFSET))
        amplitudes = self.scale * np.concatenate([main, np.maximum(sub, 0.0)], axis=1)
        phases = rng.uniform(0.0, 2 * np.pi, size=amplitudes.shape)
        return amplitudes, phases


def positive_normal_moments(means, stds):
    """E[X] and E[X²] of the draws of :func:`positive_normal` (docs: theory, The walking force).

    For a positive mean the draws are N(μ, σ²) truncated to X > 0: with a = μ/σ and
    λ = φ(a)/Φ(a), E[X] = μ + σλ and E[X²] = μ² + σ² + μσλ (Johnson, Kotz & Balakrishnan 1994,
    §13.10). For a mean ≤ 0 they are max(X, 0): E[X] = μΦ(a) + σφ(a),
    E[X²] = (μ² + σ²)Φ(a) + μσφ(a).
    """
    means, stds = np.broadcast_arrays(np.asarray(means, dtype=float),
                                      np.asarray(stds, dtype=float))
    # a = μ/σ, +∞ for σ = 0 (divided only where σ > 0: no division warnings to silence)
    a = np.divide(means, stds, out=np.full(means.shape, np.inf), where=stds > 0)
    pdf = np.exp(-0.5 * np.minimum(np.abs(a), 40.0) ** 2) / np.sqrt(2 * np.pi)   # φ(a)
    cdf = special.ndtr(a)                                                          # Φ(a)
    truncated = means > 0
    # λ = φ/Φ where truncated (μ > 0, so a > 0 and Φ ≥ ½), 0 elsewhere
    ratio = np.divide(pdf, cdf, out=np.zeros(means.shape), where=truncated)
    first = np.where(truncated, means + stds * ratio, means * cdf + stds * pdf)
    second = np.where(truncated, means**2 + stds**2 + means * stds * ratio,
                      (means**2 + stds**2) * cdf + means * stds * pdf)
    return first, second


def positive_normal(means, stds, rng):
    """Normal draws N(means, stds) with non-positive values drawn again.

    For DLFs (docs: theory, Živanović, Pavić & Reynolds (2007): P(α < 0) ≤ 2.3 %), step frequencies and body masses, which are
    > 0. A mean that is itself not positive (μ₁ far outside the walking range) gives 0 rather
    than an endless redraw.
    """
    means = np.asarray(means, dtype=float)
    stds = np.broadcast_to(np.asarray(stds, dtype=float), means.shape)
    values = rng.normal(means, stds)
    for _ in range(50):
        negative = (values <= 0) & (means > 0)
        if not negative.any():
            break
        values[negative] = rng.normal(means[negative], stds[negative])
    return np.maximum(values, 0.0)


@dataclass(frozen=True)
class YoungForce(WalkingForce):
    """Young (2001) mean DLFs of the first four harmonics (docs: theory, Young (2001)).

    α₁ = 0.41 (f_s − 0.95) ≤ 0.56, α₂ = 0.069 + 0.0056·2f_s, α₃ = 0.033 + 0.0064·3f_s,
    α₄ = 0.013 + 0.0065·4f_s; deterministic DLFs, independent uniform phases.

    Parameters
    ----------
    scale : float
        Factor on every DLF.

    See Also
    --------
    ZivanovicForce : the default, with random DLFs and subharmonics.

    References
    ----------
    P. Young, "Improved floor vibration prediction methodologies", Arup Vibration Seminar on
    Engineering for Structural Vibration, 2001. Mean dynamic load factors.

    The theory pages cite them (docs: theory, References).
    """

    scale: float = 1.0

    def __post_init__(self):
        object.__setattr__(self, "scale", _check_scale(self.scale))

    @property
    def ratios(self) -> np.ndarray:
        return np.array([1.0, 2.0, 3.0, 4.0])

    def dlf(self, step_frequency: ArrayLike) -> np.ndarray:
        """Young's DLFs α_h [-] of harmonic h at the step frequencies in row h − 1.

        Parameters
        ----------
        step_frequency : array_like, shape (4, ...)
            Row h − 1 holds the step frequencies for harmonic h (see ``mean_square_dlf``).
        """
        step = np.asarray(step_frequency, dtype=float)
        column = (slice(None),) + (np.newaxis,) * (step.ndim - 1)
        harmonic = np.arange(1.0, 5.0)[column]
        alpha = np.asarray(YOUNG_OFFSET)[column] + np.asarray(YOUNG_SLOPE)[column] * harmonic * step
        alpha[0] = np.minimum(alpha[0], YOUNG_DLF1_CAP)
        return np.maximum(alpha, 0.0)

    def mean_square_dlf(self, step_frequency: ArrayLike) -> np.ndarray:
        return self.dlf(step_frequency) ** 2

    def sample(self, step_frequency: ArrayLike,
               rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        step = np.asarray(step_frequency, dtype=float)
        amplitudes = self.scale * self.dlf(np.broadcast_to(step, (4,) + step.shape)).T
        phases = rng.uniform(0.0, 2 * np.pi, size=amplitudes.shape)
        return amplitudes, phases


def as_force_model(force: object, *,
                   time_domain: bool = False) -> ForceModel | _ReplayedForce:
    """``force`` itself, or the default Živanović model for None; refuse anything that lacks
    what the caller needs (a :class:`ForceModel`'s members, see there).

    ``time_domain``: the caller is the simulator, which needs ``ratios`` and ``sample`` (or
    replays a :class:`~crowdvib.models.measured.MeasuredForce`); the spectral side needs
    ``load_spectrum``, which a replayed record does not have.
    """
    if force is None:
        return ZivanovicForce()
    if isinstance(force, _ReplayedForce):
        if time_domain:
            return force
        raise ParameterError(
            "force must be a ZivanovicForce or YoungForce here: a MeasuredForce replays measured "
            "histories and has no load PSD for the spectral model (use it with simulate)")
    needed = _TIME_DOMAIN_MEMBERS if time_domain else _SPECTRAL_MEMBERS
    missing = [name for name in needed if not hasattr(force, name)]
    if missing:
        kinds = "ZivanovicForce, YoungForce or MeasuredForce" if time_domain else (
            "ZivanovicForce or YoungForce")
        side = "the simulator" if time_domain else "the spectral model"
        raise ParameterError(
            f"force must be a {kinds}, got {type(force).__name__} (or any force model with "
            f"{', '.join(needed)}, which {side} calls: crowdvib.models.loading.ForceModel; it "
            f"lacks {', '.join(missing)})")
    return force
