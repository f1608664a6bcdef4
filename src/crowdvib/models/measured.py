"""Measured walking forces replayed as the pedestrians' load (docs: theory, Measured walking forces).

Instead of a sum of sinusoids, each walker carries a measured vertical ground-reaction force
history F_r(τ) of one real walk r, divided by that walk's own mean force and multiplied by the
walker's weight:

    p_k(t) = s_k W_k [F_r(τ_k(t)) / F̄_r − 1],   τ_k(t) = τ_0,k + λ_k (t − t_k)

with a random record r and start τ_0,k (from the run's seed), the time scale λ_k = f_s,k / f_r
(replayed at the walker's own step frequency) or 1, and s_k = 1 or, to isolate the shape of the
force from its size, μ₁(f_s,k) / α₁,r (the first-harmonic DLF of the Živanović model over the
record's own). The history is periodically continued past its end and linearly interpolated.

Eight walks of the PhysioNet gait database ship with the package (``crowdvib/data``; provenance
and licence in ``WALKING_FORCES_PROVENANCE.txt`` beside them). Only the time-domain simulator can
use the model: a replayed record has no load PSD for the spectral model.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from importlib import resources
from typing import NamedTuple, cast

import numpy as np
from numpy.typing import ArrayLike
from scipy import signal

from .._validation import as_float_array, check_non_negative, check_positive
from ..errors import DataError, ParameterError
from .loading import STANDARD_GRAVITY, ZivanovicForce, _ReplayedForce

__all__ = ["MeasuredForce", "builtin_walking_forces"]

#: The packaged records (see WALKING_FORCES_PROVENANCE.txt in the same folder).
BUILTIN_FILE = "gaitpdb_walking_forces.npz"
#: Seconds cut at each end of a packaged walk: start, stop and the first turn are not steady
#: walking (the derived DLFs of the provenance file use the same cut).
BUILTIN_TRIM = 10.0
#: Step frequencies are looked for in this band [Hz] (walking: 1.2–2.6 Hz).
STEP_BAND = (1.2, 2.6)
#: Half-width [Hz] of the band around k·f_s whose power makes the k-th harmonic's DLF.
HARMONIC_HALF_BAND = 0.2
#: Smallest first-harmonic DLF of a record that walks: walking gives 0.2–0.5 (Živanović, Pavić
#: & Reynolds 2007's μ₁ over 1.5–2.5 Hz); a record below 0.02 holds no steps to replay (a
#: standing person, an unloaded plate), and its step frequency would be 0/0.
MIN_RECORD_DLF1 = 0.02
#: Harmonics of the step frequency that set the simulator's time step (as for the 5-harmonic
#: Živanović model): the records' content above 5 f_s is small and far above footbridge modes.
REPLAY_HARMONICS = 5


def builtin_walking_forces() -> tuple[tuple[str, ...], np.ndarray, float]:
    """The packaged walks: names, total vertical force [N] (n_walks, n_samples), sample rate [Hz]."""
    source = resources.files("crowdvib").joinpath("data", BUILTIN_FILE)
    with source.open("rb") as handle, np.load(handle) as data:
        return (tuple(str(n) for n in data["record"]), data["force"].astype(float),
                    float(data["sample_rate"]))


def step_frequency_and_dlfs(force: ArrayLike, sample_rate: float, n_harmonics: int = 3,
                            window: float = 30.0) -> tuple[float, np.ndarray]:
    """Step frequency [Hz] and DLFs α_1..n [-] of one force history from its Welch spectrum.

    α_k = sqrt(2 ∫ G_FF df) / F̄ over f within ±0.2 Hz of k·f_s, f_s the highest PSD peak in the
    walking band (docs: theory, Measured walking forces). The frequency resolution is 1/window.
    """
    force = np.asarray(force, dtype=float)
    mean = force.mean()
    nperseg = min(force.size, round(float(window * sample_rate)))
    frequency, psd = signal.welch(force - mean, sample_rate, nperseg=nperseg)
    band = (frequency >= STEP_BAND[0]) & (frequency <= STEP_BAND[1])
    step = float(frequency[band][np.argmax(psd[band])])
    df = frequency[1] - frequency[0]
    dlfs = [np.sqrt(2 * psd[np.abs(frequency - k * step) <= HARMONIC_HALF_BAND].sum() * df) / mean
            for k in range(1, n_harmonics + 1)]
    return step, np.array(dlfs)


def _mean_step_frequency(force, sample_rate, window=30.0):
    """Mean step frequency [Hz]: the power-weighted mean frequency within ±0.2 Hz of the peak.

    Welch spectrum with ``window``-second segments, zero-padded to ≈ 0.001 Hz. Real walking
    drifts in pace, so the first-harmonic peak is a hump, not a line: its centroid is the mean
    step frequency, where the highest bin can sit a few per cent off (docs: theory, Measured
    walking forces).
    """
    nperseg = min(force.size, round(float(window * sample_rate)))
    n_fft = max(nperseg, 1 << int(np.ceil(np.log2(sample_rate * 1000))))
    frequency, psd = signal.welch(force - force.mean(), sample_rate, nperseg=nperseg, nfft=n_fft)
    band = (frequency >= STEP_BAND[0]) & (frequency <= STEP_BAND[1])
    peak = frequency[band][np.argmax(psd[band])]
    hump = np.abs(frequency - peak) <= HARMONIC_HALF_BAND
    return float((frequency[hump] * psd[hump]).sum() / psd[hump].sum())


class ReplayDraws(NamedTuple):
    """Per-walker draws of a replay (the simulator's view; all arrays of one length)."""

    record: np.ndarray          # r, index into the table (int64)
    offset: np.ndarray          # τ_0 in table samples at the arrival time
    speed: np.ndarray           # table samples per second of simulated time (λ × sample rate)
    factor: np.ndarray          # s_k [-] on the walker's weight
    step_frequency: np.ndarray  # replayed step frequency λ f_r [Hz]


@dataclass(frozen=True, eq=False)
class MeasuredForce(_ReplayedForce):
    """Measured vertical walking forces replayed per walker (docs: theory, Measured walking forces).

    Parameters
    ----------
    records : sequence of str, optional
        Names of the packaged walks to use (default all eight: GaCo01_01 … GaCo05_01). Each walker
        replays one of them, drawn uniformly.
    time_scale : bool
        True (default): replay each record at the walker's drawn step frequency (time axis
        scaled by f_s / f_r); False: at the record's own step frequency.
    first_harmonic : {"measured", "zivanovic"}
        "measured" (default): the records' own dynamic load factors; "zivanovic": each walker's
        force scaled so that its first-harmonic DLF equals the Živanović mean μ₁(f_s) — the shape
        of real walking with the size the spectral model assumes.
    random_start : bool
        True (default): each walker starts at a random point of its record (drawn from the run's
        seed); False: at the record's first sample when it arrives — a walk replayed as measured.
    forces, sample_rate : array_like and float, optional
        Other records instead of the packaged ones: total vertical force [N], shape
        (n_records, n_samples) (or one 1-D record), at ``sample_rate`` [Hz]; used whole.

    See Also
    --------
    ZivanovicForce : the default harmonic model.

    Notes
    -----
    Usable with :func:`crowdvib.simulate` (``force=MeasuredForce()``) only; the spectral model
    needs a load PSD, which a replayed record does not have.

    References
    ----------
    A. L. Goldberger et al., "PhysioBank, PhysioToolkit, and PhysioNet: components of a new research
    resource for complex physiologic signals", *Circulation* 101(23):e215–e220, 2000. PhysioNet,
    which publishes the gait database.

    G. Yogev, N. Giladi, C. Peretz, S. Springer, E. S. Simon and J. M. Hausdorff, "Dual tasking,
    gait rhythmicity, and Parkinson's disease: which aspects of gait are attention demanding?",
    *European Journal of Neuroscience* 22(5):1248–1256, 2005. The study that recorded the packaged
    walks.

    The theory pages cite them (docs: theory, References).
    """

    records: tuple | None = None
    time_scale: bool = True
    first_harmonic: str = "measured"
    random_start: bool = True
    forces: np.ndarray | None = field(default=None, repr=False)
    sample_rate: float | None = None
    names: tuple = field(init=False, repr=False, compare=False)
    table: np.ndarray = field(init=False, repr=False, compare=False)
    record_step_frequency: np.ndarray = field(init=False, repr=False, compare=False)
    record_dlf1: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        if self.first_harmonic not in ("measured", "zivanovic"):
            raise ParameterError(f"first_harmonic must be 'measured' or 'zivanovic', got "
                                 f"{self.first_harmonic!r}")
        for flag in ("time_scale", "random_start"):
            if not isinstance(getattr(self, flag), (bool, np.bool_)):
                raise ParameterError(f"{flag} must be True or False, got {getattr(self, flag)!r}")
        if self.forces is None:
            if self.sample_rate is not None:
                raise ParameterError("sample_rate must be None with the packaged records "
                                     f"(they are at 100 Hz), got {self.sample_rate!r}")
            names, forces, rate = builtin_walking_forces()
            trim = round(BUILTIN_TRIM * rate)
            forces = forces[:, trim:-trim]
            if self.records is not None:
                wanted = tuple(self.records) if not isinstance(self.records, str) else (
                    self.records,)
                unknown = [n for n in wanted if n not in names]
                if unknown or not wanted:
                    raise ParameterError(f"records must name packaged walks {list(names)}, got "
                                         f"{list(wanted)}")
                forces = forces[[names.index(n) for n in wanted]]
                names = wanted
        else:
            if self.records is not None:
                raise ParameterError("records selects packaged walks; give it or forces, "
                                     "not both")
            rate = check_positive("sample_rate", self.sample_rate, unit="Hz")
            forces = as_float_array("forces", self.forces)
            forces = forces[np.newaxis] if forces.ndim == 1 else forces
            if forces.ndim != 2 or forces.shape[1] < 4 * rate:
                raise ParameterError(f"forces must be (n_records, n_samples) with at least 4 s "
                                     f"of samples, got shape {forces.shape}")
            check_positive("forces", forces.mean(axis=1), unit="N")
            names = tuple(f"record_{i + 1}" for i in range(forces.shape[0]))
        forces = np.asarray(forces, dtype=float)
        mean = forces.mean(axis=1, keepdims=True)
        dlf1 = np.array([step_frequency_and_dlfs(f, rate, n_harmonics=1)[1][0] for f in forces])
        for index, value in enumerate(dlf1):
            if not value >= MIN_RECORD_DLF1:
                raise DataError(
                    f"forces record {index} ({names[index]}) has no walking steps: its "
                    f"first-harmonic DLF in {STEP_BAND[0]:g}–{STEP_BAND[1]:g} Hz is {value:.3g}, "
                    f"below {MIN_RECORD_DLF1:g} (walking: 0.2–0.5): nothing to replay")
        steps = np.array([_mean_step_frequency(f, rate) for f in forces])
        for attribute, value in (("names", names), ("table", np.ascontiguousarray(forces / mean - 1)),
                                 ("record_step_frequency", steps), ("record_dlf1", dlf1),
                                 ("sample_rate", rate)):
            object.__setattr__(self, attribute, value)

    #: One component with zero amplitude: the replayed force replaces the harmonic sum.
    ratios = np.array([1.0])

    @property
    def n_records(self) -> int:
        return self.table.shape[0]

    def sample(self, step_frequency: ArrayLike,
               rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """No harmonic components (zero DLF, zero phase; draws nothing): see :meth:`sample_replay`.

        Parameters
        ----------
        step_frequency : array_like, shape (n_pedestrians,)
            Each walker's step frequency [Hz].
        rng : numpy.random.Generator
            Not used.
        """
        n = np.asarray(step_frequency).size
        return np.zeros((n, 1)), np.zeros((n, 1))

    def sample_replay(self, step_frequency: ArrayLike, rng: np.random.Generator) -> ReplayDraws:
        """Record, start, time scale and force factor of each walker (from ``rng``, in that order).

        Parameters
        ----------
        step_frequency : array_like, shape (n_pedestrians,)
            Each walker's step frequency [Hz]: the recorded walks are time-scaled to it.
        rng : numpy.random.Generator
            The draws' generator.
        """
        step_frequency = np.asarray(step_frequency, dtype=float).ravel()
        n = step_frequency.size
        record = rng.integers(0, self.n_records, size=n).astype(np.int64)
        offset = rng.uniform(0.0, self.table.shape[1], size=n)
        if not self.random_start:
            offset[:] = 0.0                  # drawn all the same: one stream for both options
        record_step = self.record_step_frequency[record]
        scale = step_frequency / record_step if self.time_scale else np.ones(n)
        if self.first_harmonic == "zivanovic":
            replayed = scale * record_step
            factor = ZivanovicForce.first_harmonic_dlf(replayed) / self.record_dlf1[record]
        else:
            factor = np.ones(n)
        rate = cast(float, self.sample_rate)        # set by __post_init__
        return ReplayDraws(record, offset, scale * rate, factor, scale * record_step)

    def time_history(self, time: ArrayLike, step_frequency: float, body_mass: float,
                     rng: int | np.random.Generator | None = None) -> np.ndarray:
        """Dynamic force [N] of one walker on a rigid floor, from t_k = 0 (as the simulator replays it).

        Parameters
        ----------
        time : array_like
            Times [s] after the walker's arrival.
        step_frequency : float
            f_s [Hz] (used when ``time_scale``).
        body_mass : float
            m_h [kg].
        rng : None, int or numpy.random.Generator
            Seed or generator of the record and start.
        """
        step_frequency = check_positive("step_frequency", step_frequency, unit="Hz")
        body_mass = check_positive("body_mass", body_mass, unit="kg")
        time = check_non_negative("time", time, unit="s")
        draws = self.sample_replay(np.array([step_frequency]), np.random.default_rng(rng))
        position = draws.offset[0] + draws.speed[0] * np.asarray(time, dtype=float)
        return (body_mass * STANDARD_GRAVITY * draws.factor[0]
                * replay_value(self.table[draws.record[0]], position))


def replay_value(row: np.ndarray, position: ArrayLike) -> np.ndarray:
    """Linear interpolation of a periodically continued table row at fractional sample ``position``.

    The numpy twin of the kernel's ``_replayed`` (response/_kernels.py); the tests hold them equal.
    """
    n = row.size
    position = np.asarray(position, dtype=float)
    wrapped = position - n * np.floor(position / n)
    low = np.minimum(wrapped.astype(np.int64), n - 1)
    fraction = wrapped - low
    high = np.where(low + 1 < n, low + 1, 0)
    return row[low] + fraction * (row[high] - row[low])
