"""Time-domain Monte Carlo simulation of a crowd walking over a footbridge (docs: theory, The coupled time-domain model).

Each pedestrian is a moving force on a rigid floor plus, with HSI, a moving mass-spring-damper
(MSD) whose unsprung mass rides on the deck (paper Eq. 1–4; docs: theory, Equations of motion and State-space form). The crowd is a
stationary Poisson stream with the deck already populated at the start (docs: theory, Poisson arrivals). The
numerics (fixed-step RK4 over the pedestrians on the deck) live in :mod:`crowdvib.response._kernels`.

Public: :func:`simulate` (the record) and :func:`simulate_psd` (its Welch PSD and summaries,
in memory that does not grow with the duration); the walkers come from :mod:`.traffic`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from . import _kernels, _slots
from .._memory import MEMORY_SHARE as _MEMORY_SHARE, available_memory
from .._plausibility import warn_notes
from .._validation import check_positive, check_type
from ..errors import ParameterError
from ..models.crowd import JAM_DENSITY, Crowd
from ..models.damper import as_dampers
from ..models.loading import STANDARD_GRAVITY, as_force_model
from ..models.measured import REPLAY_HARMONICS, ReplayDraws
from ..models.pedestrian import MSDModel
from ..models.profile import CrowdProfile
from ..signals.spectrum import ResponsePSD
from ..signals.welch import DISPERSION_LAGS, dispersion_ratio, segment_periodograms
from .results import Simulation, SimulationPSD
from .traffic import (STREAM_BLOCK, Pedestrian, _Stream, _Walkers, check_duration, _check_structure,
                      _seed_from)

if TYPE_CHECKING:
    from .._typing import ForceModel, Seed
    from ..models.damper import TunedMassDamper
    from ..models.structure import ModalModel

__all__ = ["simulate", "simulate_psd"]

#: Internal RK4 steps per period of the highest natural frequency of the states (structural
#: modes, f_h1). RK4's numerical damping and period error grow with (ω h)⁶ and (ω h)⁴: at 10
#: steps per period (ω h = 0.63, the accuracy docs: theory, Time stepping validated) a lightly damped mode
#: loses far less per cycle than its own damping takes.
STEPS_PER_PERIOD = 10
#: Internal steps per period of the fastest force component (a walker's 5th harmonic). A force
#: is only sampled, at the three RK4 stage times, so its error falls as (ω h)⁴/2880 ≈ 2e-4 at 6
#: steps per period: it need not limit the step the way a lightly damped state does.
FORCE_STEPS_PER_PERIOD = 6
#: Default simulated seconds per kernel call (progress granularity; results do not depend on it).
DEFAULT_CHUNK_DURATION = 60.0
#: Simulated seconds of arrivals handed to the kernel at once (at least a chunk's): the window of
#: the stream is rebuilt this seldom (a few hundred walkers; the rebuild costs about a millisecond).
WINDOW_DURATION = 600.0
#: Bytes a walker costs while its block is drawn: its per-component DLF, ratio and phase rows
#: and some twenty scalars, in float64, about three times over for the temporaries of the draws.
_BYTES_PER_WALKER = 3 * 8 * 20
#: Bytes every walker of the record costs for the whole run: its arrival time (twice), time
#: off the deck and rank in the stream (``traffic._Stream``).
_STREAM_BYTES_PER_WALKER = 4 * 8
def _check_memory(structure, crowd, force, duration, warm_up, sample_rate, n_samples,
                  record_modal_load, records=1, keep_record=True):
    """Refuse a run whose records and walkers will not fit, before anything is allocated.

    A duration of 1e9 s once took 13 GB over two minutes before numpy gave up (issue 24): the
    sizes are known from the inputs, so the answer can come at once, naming the parameter.
    ``records``: runs whose results are all kept (:func:`crowdvib.simulate_many`'s seeds);
    ``keep_record``: False for :func:`simulate_psd`, which keeps no samples.
    """
    # The outputs, the modal loads and a row for n_on_deck (a quarter of one, counted whole).
    rows = (structure.n_outputs + (structure.n_modes if record_modal_load else 0) + 1
            if keep_record else 0)
    walkers = 0.0
    if crowd is not None and crowd.density > 0:
        walkers = (crowd.arrival_rate(structure.width) * (duration + warm_up)
                   + crowd.density * structure.area)
    components = np.size(force.ratios)
    drawn = min(walkers, 3 * STREAM_BLOCK)          # the blocks held at once
    need = records * (8.0 * rows * n_samples + walkers * _STREAM_BYTES_PER_WALKER
                      + drawn * _BYTES_PER_WALKER * (1 + components / 10))
    have = available_memory()
    if need > _MEMORY_SHARE * have:
        batch = "" if records == 1 else f" for {records} seeds"
        raise ParameterError(
            f"duration = {duration:g} s at sample_rate = {sample_rate:g} Hz{batch} needs about "
            f"{need / 1e9:.3g} GB ({n_samples:.3g} samples × {rows} rows, {walkers:.3g} "
            f"walkers per record), more than half the {have / 1e9:.3g} GB of memory available: "
            "simulate shorter records" + (" (simulate_many runs several)" if records == 1
                                          else " or fewer seeds at a time"))


def _scan_stream(structure, stream, msd, sample_rate):
    """One pass over the stream, block by block: the integer number of RK4 steps per output
    sample and whether any walker brings an unsprung mass (the mass matrix then changes).

    h = 1/(sample_rate · substeps) with h <= 1/(STEPS_PER_PERIOD · f_state), f_state the highest
    mode or f_h1, and h <= 1/(FORCE_STEPS_PER_PERIOD · f_force), f_force the highest force
    component of any walker (docs: theory, Time stepping: h = 0.01 s reproduces the spectral model).
    """
    state = float(np.max(structure.frequencies))
    if msd is not None:
        state = max(state, msd.frequency)
    force, added_mass = 0.0, False
    for table, people in stream.tables():
        active = table["dlf"] != 0
        if active.any():
            omega = 2.0 * np.pi * table["ratio"] * table["step_frequency"][:, np.newaxis]
            force = max(force, float(np.max(omega[active])) / (2 * np.pi))
        draws = ReplayDraws(*table["replay"])
        replayed = draws.record >= 0                  # measured forces: up to their 5th harmonic
        if replayed.any():
            fastest = float(np.max(draws.step_frequency[replayed]))
            force = max(force, REPLAY_HARMONICS * fastest)
        if msd is not None:
            mass = table["body_mass"][:people]
            added_mass = added_mass or bool(np.any(mass - msd.sprung_mass(mass) > 0))
    per_second = max(STEPS_PER_PERIOD * state, FORCE_STEPS_PER_PERIOD * force)
    return max(1, math.ceil(per_second / sample_rate - 1e-9)), added_mass


def _replay_arguments(walkers, table):
    """The kernel's ``replay`` tuple (docs: theory, Measured walking forces); a 1×1 dummy table without."""
    draws = walkers.replay
    weight = walkers.body_mass * STANDARD_GRAVITY * draws.factor
    table = np.zeros((1, 1)) if table is None else np.ascontiguousarray(table, dtype=float)
    return (np.ascontiguousarray(draws.record, dtype=np.int64), np.ascontiguousarray(draws.offset),
            np.ascontiguousarray(draws.speed), np.ascontiguousarray(weight), table)


def _uniform_spacing(positions):
    """1/Δx when the stations are evenly spaced (the kernel then finds a segment by one
    multiplication), else 0."""
    spacing = np.diff(positions)
    uniform = np.all(np.abs(spacing - spacing.mean()) <= 1e-12 * spacing.mean())
    return 1.0 / spacing.mean() if uniform else 0.0


def kernel_for(structure, hsi):
    """The compiled kernel that runs ``structure`` with (``hsi``) or without MSDs."""
    return _kernels.entry_point(hsi, structure.n_modes,
                                _uniform_spacing(structure.positions) > 0.0,
                                structure.lanes.size)


def kernel_needs_compiling(structure, hsi):
    """Whether the first run of this kind compiles its kernel (for a while): nothing compiled in
    this process and no numba cache index beside ``_kernels.py`` (``cache=True``) for it."""
    kernel = kernel_for(structure, hsi)
    cache = Path(_kernels.__file__).parent / "__pycache__"
    return not kernel.signatures and not list(cache.glob(f"_kernels.{kernel.__name__}-*.nbi"))


class _Integrator:
    """The state of one run between kernel calls: a chunk boundary changes nothing.

    The kernel sees a window of the stream (:class:`.traffic._Stream`): the walkers on the deck
    and those who step on during the call, so memory does not grow with the record (issue 28
    §3). Each call records its output samples into chunk buffers (``acceleration``,
    ``modal_load``, ``n_on_deck``; :meth:`advance` says which samples they hold).

    Private; the tests read the state to check energy conservation.
    """

    def __init__(self, structure, stream, msd, sample_rate, substeps, first_step,
                 record_modal_load, include_static_weight, dampers=(), force_table=None,
                 added_mass=False):
        self.structure = structure
        self.stream = stream
        self.msd = msd
        self.dampers = tuple(dampers)
        self.include_static_weight = include_static_weight
        self.force_table = force_table
        self.substeps = substeps
        self.h = 1.0 / (sample_rate * substeps)
        self.step = first_step
        n_modes = structure.n_modes
        self.hsi = msd is not None or bool(dampers)   # dampers are MSD entries of the kernel
        self.n_dampers = len(dampers)
        # Any unsprung mass on the deck makes the mass matrix change with time.
        self.added_mass = bool(added_mass)
        omega_n = 2 * np.pi * structure.frequencies
        self.modal_masses = np.ascontiguousarray(structure.modal_masses, dtype=float)
        self.modal_damping = 2 * structure.damping_ratios * structure.modal_masses * omega_n
        self.modal_stiffness = structure.modal_masses * omega_n**2
        self.shapes = np.ascontiguousarray(structure.mode_shapes)
        self.positions = np.ascontiguousarray(structure.positions)
        self.inverse_spacing = _uniform_spacing(self.positions)
        self.output_shapes = np.ascontiguousarray(structure.output_shapes)
        # Force components in pairs (the kernel advances two per pass): a zero one if odd.
        n_components = stream.width + stream.width % 2
        # The mode-shape table of the kernel, (mode, lane · station) with two zero lanes.
        self.table = _slots.shape_table(self.shapes)
        self.n_lanes = self.shapes.shape[0]
        # state: the walkers on the deck in slot order (docs: theory, Walkers on the deck as
        # arrays); shapes, forces and mass factors at the instants t, t + h/2, t + h.
        self.counters = np.zeros(2, dtype=np.int64)
        capacity = _slots.slot_capacity(stream.t_on, stream.t_off())
        zeros = _slots.aligned_zeros
        self.slots = zeros((_slots.N_FIELDS, capacity))
        self.index = zeros((_slots.N_INDICES, capacity), dtype=np.int64)
        self.z = np.zeros(n_modes)
        self.zd = np.zeros(n_modes)
        self.u = zeros(capacity)
        self.ud = zeros(capacity)
        self.phi = zeros((3, n_modes, capacity))
        self.force = zeros((3, capacity))
        self.wave_now = zeros((n_components, capacity))
        self.wave_prev = zeros((n_components, capacity))
        self.wave_cos = zeros((n_components, capacity))
        self.factor = np.zeros((3, n_modes, n_modes))
        _kernels.mass_factors(self.modal_masses, self.phi, self.slots, 0, _slots.NOW,
                              np.zeros(capacity), self.factor)
        self.record_modal_load = bool(record_modal_load)
        self.acceleration = np.zeros((structure.n_outputs, 0))
        self.modal_load = np.zeros((n_modes, 0))
        self.n_on_deck = np.zeros(0, dtype=np.int64)
        self.next_rank = 0                  # the stream's next walker to step on
        self.damper = np.zeros(0, dtype=np.int64)
        self.walkers = stream.window(0, 0)[0]
        # The first window (``walkers`` is everybody of a short run from the start, as
        # benchmarks/_numpy_reference.py reads it).
        self._refill(first_step * self.h + WINDOW_DURATION)
        # The compiled kernel for this kind of run (each kind compiles on first use).
        self.kernel = kernel_for(structure, self.hsi)

    def _load(self, walkers, damper):
        """The kernel's per-walker constants of a window (rows in the order given)."""
        self.walkers = walkers
        n = walkers.size
        mass = walkers.body_mass
        if self.msd is not None:
            self.sprung = self.msd.sprung_mass(mass)
            self.unsprung = mass - self.sprung
            self.stiffness = self.msd.stiffness(mass)
            self.damping = self.msd.damping(mass)
        else:
            self.sprung = np.ones(n)
            self.unsprung, self.stiffness, self.damping = np.zeros((3, n))
        if self.dampers:
            # Tuned mass dampers: the MSD entries of the kernel with their own spring, dashpot
            # and no unsprung mass (their walkers never move and carry no force).
            rows = np.flatnonzero(damper >= 0)
            own = [self.dampers[i] for i in damper[rows]]
            self.sprung[rows] = [d.mass for d in own]
            self.unsprung[rows] = 0.0
            self.stiffness[rows] = [d.stiffness() for d in own]
            self.damping[rows] = [d.damping() for d in own]
        self.damper = damper
        lanes = self.structure.lanes
        if lanes.size == 1:
            self.lane_low = np.zeros(n, dtype=np.int64)
            self.lane_weight = np.zeros(n)
        else:
            low = np.clip(np.searchsorted(lanes, walkers.lateral) - 1, 0, lanes.size - 2)
            self.lane_low = low.astype(np.int64)
            self.lane_weight = np.clip((walkers.lateral - lanes[low]) / (lanes[low + 1] - lanes[low]),
                                       0.0, 1.0)
        self.static = (mass * STANDARD_GRAVITY if self.include_static_weight else np.zeros(n))
        if self.dampers and self.include_static_weight:
            self.static[damper >= 0] = 0.0           # a damper's weight is the deck's dead load
        self.amplitude = np.ascontiguousarray(walkers.amplitude)
        self.omega = np.ascontiguousarray(walkers.omega)
        self.two_cos = 2.0 * np.cos(self.omega * self.h / 2)
        self.replay = _replay_arguments(walkers, self.force_table)

    def _refill(self, until):
        """Window the stream up to time ``until`` [s]: the walkers on the deck (renumbered
        0 … n_active − 1 in slot order) and everybody who steps on by then."""
        n_active = int(self.counters[1])
        entered = int(self.counters[0])
        kept = self.index[_slots.PEDESTRIAN, :n_active].copy()
        self.next_rank += entered - self._window_start
        stop = max(int(np.searchsorted(self.stream.t_on, until, "right")), self.next_rank)
        self._window_end = until
        arriving, damper = self.stream.window(self.next_rank, stop)
        walkers = _concatenate(_take(self.walkers, kept), arriving)
        self._load(walkers, np.concatenate([self.damper[kept], damper]))
        self.index[_slots.PEDESTRIAN, :n_active] = np.arange(n_active)
        self.counters[0] = n_active
        self._window_start = n_active

    _window_start = 0
    _window_end = -np.inf

    def advance(self, n_steps):
        """Integrate ``n_steps`` internal steps from the current state; return the first output
        sample recorded and how many (in ``acceleration[:, :count]`` etc.)."""
        end = (self.step + n_steps) * self.h
        if end > self._window_end:
            self._refill(max(end, self.step * self.h + WINDOW_DURATION))
        first_sample = -(-max(self.step, 0) // self.substeps)
        last = self.step + n_steps - 1                     # the call's last step
        count = max(0, last // self.substeps - first_sample + 1) if last >= 0 else 0
        if self.n_on_deck.size < count:
            self.acceleration = np.zeros((self.structure.n_outputs, count))
            self.modal_load = np.zeros((self.structure.n_modes,
                                        count if self.record_modal_load else 0))
            self.n_on_deck = np.zeros(count, dtype=np.int64)
        size = self.n_on_deck.size
        structure = (self.modal_masses, self.modal_damping, self.modal_stiffness, self.table,
                     self.positions, self.inverse_spacing, self.n_lanes, self.output_shapes)
        w = self.walkers
        walkers = (w.t_on, w.t_off, w.arrival, w.x_start, w.velocity, self.lane_low,
                   self.lane_weight, self.unsprung, self.sprung, self.stiffness, self.damping,
                   self.static, self.amplitude, self.omega, w.phase, self.two_cos, self.replay,
                   self.added_mass)
        state = (self.counters, self.slots, self.index, self.z, self.zd, self.u, self.ud,
                 self.phi, self.force, self.wave_now, self.wave_prev, self.wave_cos, self.factor)
        records = (self.acceleration, self.modal_load, self.record_modal_load, self.n_on_deck,
                   np.int64(first_sample))
        self.kernel(self.step, n_steps, self.substeps, self.h, structure, walkers, state, records)
        self.step += n_steps
        return first_sample, min(count, size)

    @property
    def time(self):
        """Current time t = n·h [s]."""
        return self.step * self.h

    @property
    def n_active(self):
        return int(self.counters[1])

    @property
    def active(self):
        """Row of ``walkers`` (the current window) of the walker in each slot (slots 0 …
        n_active − 1 are on the deck)."""
        return self.index[_slots.PEDESTRIAN]

    @property
    def phi_now(self):
        """Mode-shape row per slot at the current time, (slot, mode) (a view)."""
        return self.phi[_slots.NOW].T


def _take(walkers, rows):
    """The rows ``rows`` of :class:`.traffic._Walkers`."""
    return _Walkers(**{f.name: (type(value)(*(v[rows] for v in value)) if f.name == "replay"
                                else value[rows])
                       for f in dataclasses.fields(walkers)
                       for value in (getattr(walkers, f.name),)})


def _concatenate(first, second):
    """Two :class:`.traffic._Walkers` one after the other."""
    def join(a, b):
        return np.concatenate([a, b])
    return _Walkers(**{f.name: (type(a)(*map(join, a, b)) if f.name == "replay" else join(a, b))
                       for f in dataclasses.fields(first)
                       for a, b in ((getattr(first, f.name), getattr(second, f.name)),)})


def _check_run(structure, crowd, duration, pedestrians, msd, force, sample_rate,
               record_modal_load, warm_up, records=1, keep_record=True):
    """Validate a run's inputs and its memory (for ``records`` kept runs); return the force
    model, duration, sample rate and the recorded and warm-up sample counts."""
    _check_structure(structure)
    if crowd is None and pedestrians is None:
        raise ParameterError("crowd or pedestrians must be given, got neither")
    if crowd is not None:
        check_type("crowd", crowd, Crowd)
        if crowd.density >= JAM_DENSITY:
            raise ParameterError(
                f"crowd.density must be < the jam density {JAM_DENSITY} persons/m², "
                f"got {crowd.density:g}")
    if msd is not None and not isinstance(msd, MSDModel):
        raise ParameterError(f"msd must be an MSDModel or None, got {type(msd).__name__}")
    force = as_force_model(force, time_domain=True)
    duration, warm_up = check_duration(duration, warm_up)
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    highest = float(np.max(structure.frequencies))
    if sample_rate / 2 <= highest:
        raise ParameterError(
            f"sample_rate must put the Nyquist frequency (sample_rate/2) above the highest "
            f"structural mode {highest:g} Hz, got {sample_rate:g} Hz "
            f"(Nyquist {sample_rate / 2:g} Hz)")
    n_samples = int(round(duration * sample_rate))
    if n_samples < 1:
        raise ParameterError(
            f"duration × sample_rate must give at least one sample, got {duration:g} s × "
            f"{sample_rate:g} Hz")
    warm_up_samples = int(math.ceil(warm_up * sample_rate - 1e-9))
    _check_memory(structure, crowd, force, duration, warm_up, sample_rate,
                  n_samples + warm_up_samples, record_modal_load, records, keep_record)
    return force, duration, sample_rate, n_samples, warm_up_samples


def _with_profile(crowd, profile):
    """The crowd and profile a run uses: a varying profile with the crowd at its peak density
    (what the checks of memory and jam density see), a constant one as the stationary crowd
    of its density (the record is then bit-identical to that crowd's), no profile as given."""
    if profile is None:
        return crowd, None
    check_type("crowd_profile", profile, CrowdProfile)
    if crowd is None:
        raise ParameterError("crowd must be given with crowd_profile: the profile sets the "
                             "density, the crowd its walkers (speed, step frequencies, masses)")
    check_type("crowd", crowd, Crowd)
    crowd = crowd.with_density(profile.peak)
    return crowd, (None if profile.is_constant else profile)


def _prepare(structure, crowd, duration, pedestrians, msd, force, sample_rate, seed,
             include_static_weight, record_modal_load, warm_up, dampers=(), keep_record=True,
             profile=None):
    """Validate everything and build the integrator (no time stepping yet)."""
    crowd, profile = _with_profile(crowd, profile)
    force, duration, sample_rate, n_samples, warm_up_samples = _check_run(
        structure, crowd, duration, pedestrians, msd, force, sample_rate, record_modal_load,
        warm_up, keep_record=keep_record)
    if profile is not None:
        warn_notes(profile.implausibilities(duration), stacklevel=4)   # simulate's caller
    pedestrians = list(pedestrians) if pedestrians is not None else []
    rng = np.random.default_rng(seed)
    start = -warm_up_samples / sample_rate
    stream = _Stream(structure, crowd, pedestrians, start, duration, force, rng, dampers,
                     profile)
    substeps, added_mass = _scan_stream(structure, stream, msd, sample_rate)
    if dampers:      # the dampers' own frequencies bound the step like the modes'
        fastest = max(d.frequency for d in dampers)
        substeps = max(substeps, math.ceil(STEPS_PER_PERIOD * fastest / sample_rate - 1e-9))
    integrator = _Integrator(structure, stream, msd, sample_rate, substeps,
                             -warm_up_samples * substeps, record_modal_load,
                             include_static_weight, dampers, getattr(force, "table", None),
                             added_mass)
    return integrator, n_samples, warm_up_samples, sample_rate, duration


def _start(structure, crowd, duration, pedestrians, msd, force, sample_rate, rng, progress,
           include_static_weight, chunk_duration, record_modal_load, warm_up, dampers,
           keep_record, profile=None):
    """Check the options shared by :func:`simulate` and :func:`simulate_psd` and prepare the
    run: the seed, the integrator, the sample counts, the sample rate and the chunks to run."""
    seed = _seed_from(rng)
    if progress is not None and not callable(progress):
        raise ParameterError(f"progress must be callable or None, got {type(progress).__name__}")
    chunk_duration = (DEFAULT_CHUNK_DURATION if chunk_duration is None
                      else check_positive("chunk_duration", chunk_duration, unit="s"))
    integrator, n_samples, warm_up_samples, sample_rate, duration = _prepare(
        structure, crowd, duration, pedestrians, msd, force, sample_rate, seed,
        include_static_weight, record_modal_load, warm_up, as_dampers(dampers), keep_record,
        profile)
    total_steps = (warm_up_samples + n_samples) * integrator.substeps
    chunk_steps = max(1, int(round(chunk_duration * sample_rate))) * integrator.substeps
    chunks = _chunks(integrator, total_steps, chunk_steps, progress)
    return seed, integrator, n_samples, warm_up_samples, sample_rate, chunks


def _chunks(integrator, total_steps, chunk_steps, progress):
    """Run ``total_steps`` a chunk at a time; yield each chunk's first output sample and count
    (its samples are in the integrator's buffers until the next chunk)."""
    total_seconds = total_steps * integrator.h
    done = 0
    while done < total_steps:
        n = min(chunk_steps, total_steps - done)
        first, count = integrator.advance(n)
        done += n
        yield first, count
        if progress is not None:
            progress(done * integrator.h, total_seconds)


def simulate(structure: ModalModel, crowd: Crowd | None = None, duration: float | None = None,
             *, pedestrians: Sequence[Pedestrian] | None = None, msd: MSDModel | None = None,
             force: ForceModel | None = None, sample_rate: float = 100.0, rng: Seed = None,
             progress: Callable[[float, float], None] | None = None,
             include_static_weight: bool = False, chunk_duration: float | None = None,
             record_modal_load: bool = False, warm_up: float = 0.0,
             dampers: Sequence[TunedMassDamper] | None = None,
             crowd_profile: CrowdProfile | None = None) -> Simulation:
    """Accelerations of a footbridge under a crowd of moving forces and MSDs (docs: theory, The coupled time-domain model).

    The structure's modes carry every pedestrian on the deck: the force on a rigid floor
    p_k(t) = W Σ_c α_c sin(2π r_c f_s (t − t_k) + θ_c) (+ W with the static weight), applied at
    the mode-shape row φ_k(t) under the pedestrian, and with ``msd`` the contact force of a
    mass-spring-damper whose unsprung mass rides on the deck (paper Eq. 1–4; docs: theory, Equations of motion and State-space form):

        M(t) z̈ + C ż + K z = Σ_k φ_k [p_k − m_h0 φ_kᵀ z̈ + k_h1 (u_k − φ_kᵀ z) + c_h1 (u̇_k − φ_kᵀ ż)]
        m_h1 ü_k + c_h1 (u̇_k − φ_kᵀ ż) + k_h1 (u_k − φ_kᵀ z) = 0

    Parameters
    ----------
    structure : ModalModel
        The empty footbridge; its output points are recorded.
    crowd : Crowd, optional
        A stationary stream (docs: theory, Poisson arrivals): Poisson arrivals at rate d·B·v split between the
        directions by ``crowd.forward_fraction`` (the others start at the far end), the deck
        already populated at t = 0 (Poisson(d·B·L) people at uniform positions), lateral
        positions U[0, B], step frequencies N(μ_fs, σ_fs), body masses N(m_h, σ_m) (``crowd.body_mass``,
        ``crowd.body_mass_std``; fixed when σ_m = 0), DLFs
        and phases from ``force``.
    duration : float
        Record length [s], > 0.
    pedestrians : sequence of Pedestrian, optional
        Explicit pedestrians, in addition to (or instead of) the crowd.
    msd : MSDModel, optional
        Mass-spring-damper model of every pedestrian (HSI); None = moving forces only.
    force : ZivanovicForce, YoungForce, MeasuredForce or any models.loading.ForceModel, optional
        Walking force model (default Živanović 2007); a :class:`~crowdvib.models.MeasuredForce`
        replays measured force histories instead (docs: theory, Measured walking forces).
    sample_rate : float
        Output sample rate [Hz]; its Nyquist frequency must exceed the highest mode.
    rng : None, int or numpy.random.Generator
        Seed of the run. None draws a seed from OS entropy; a Generator gives one draw. The seed
        used is returned in ``Simulation.seed``: the same seed gives a bit-identical record on
        the same computer (on a processor of another vector width the sums over walkers run in
        another order, and records agree to round-off).
    progress : callable, optional
        Called as ``progress(done_seconds, total_seconds)`` [s of simulated time, warm-up
        included] after each chunk.
    include_static_weight : bool
        Add the weight W to each force (quasi-static moving load, docs: theory, Static weight). Off by
        default: it only adds content below ~v/L and Welch's detrending removes it.
    chunk_duration : float, optional
        Simulated seconds per kernel call (default 60 s). The state is carried over, so the
        record is bit-identical for any chunking.
    record_modal_load : bool
        Also record the modal walking load Q(t) = Σ_k φ_k(t) p_k(t) [N] (no interaction forces).
    warm_up : float
        Simulated time [s] before t = 0 that is not recorded: the structure starts at rest, so
        a lightly damped mode needs ~5/(ξ_1 ω_1) to reach a stationary response (the traffic is
        stationary from the start anyway). Default 0.
    dampers : sequence of TunedMassDamper, optional
        Tuned mass dampers fixed to the deck: each is a force-free mass-spring-damper entry of the
        integrator, standing at its position for the whole record (warm-up included), coupled
        through its mode-shape row like a pedestrian's MSD (docs: theory, Tuned mass dampers in
        the simulator).
    crowd_profile : CrowdProfile, optional
        A density that changes with time (t = 0 the first recorded sample): the crowd's walkers
        enter as a non-homogeneous Poisson stream of rate d(t)·B·v, the deck holding at the
        start whoever entered during the crossing before (docs: theory, A crowd that changes);
        ``crowd`` gives the walkers (speed, step frequencies, masses, directions), its density
        is not used. Only the stream changes: the same seed gives the same record, and a
        constant profile the record of ``crowd.with_density(d)``.

    Returns
    -------
    Simulation
        Accelerations at the output points [m/s²], shape (n_outputs, n_samples), with the time
        axis, pedestrians on the deck and the seed.

    See Also
    --------
    crowdvib.simulate_psd : the Welch PSD of a record too long to keep.
    crowdvib.simulate_many : many records, in parallel.
    crowdvib.response_psd : the expected PSD of the same crowd.

    Notes
    -----
    * Integration: classical RK4 with a fixed internal step h = 1/(sample_rate · m), m the
      smallest integer with h <= 1/(10 f_state) for the modes and f_h1 and h <= 1/(6 f_force)
      for the walkers' force components (docs: theory, Time stepping). Shapes and forces are evaluated at the stage
      times; the unsprung masses make the mass matrix position-dependent and it is factored at
      each stage time.
    * The convective terms of the contact kinematics (v ∂φ/∂x) are neglected (docs: theory, Equations of motion):
      u̇ of the contact point is taken as φᵀż.
    * A pedestrian enters (at an internal step) with the MSD at rest relative to the deck,
      u = φᵀz, u̇ = φᵀż, and leaves at the first step after walking off (docs: theory, Time stepping).
    * Only pedestrians on the deck cost time. Memory: the record (8 bytes per output sample, 2
      for ``n_on_deck``; the time axis is computed when read) and 32 bytes per pedestrian; the
      walkers' draws are made 65 536 at a time (docs: theory, Poisson arrivals). For a long run
      whose spectrum is all that is wanted, :func:`simulate_psd` keeps no record.

    References
    ----------
    K. Van Nimmen and P. Van den Broeck, "Using full-scale observations on footbridges to estimate
    the parameters governing human–structure interaction", *Journal of Bridge Engineering* 28(1),
    2023. The coupled equations of motion (Eq. 1–4).

    K. Van Nimmen, G. Lombaert, G. De Roeck and P. Van den Broeck, "The impact of vertical
    human–structure interaction on the response of footbridges to pedestrian excitation", *Journal
    of Sound and Vibration* 402:104–121, 2017. The crowd–structure model with MSD pedestrians.

    S. Živanović, A. Pavić and P. Reynolds, "Probability-based prediction of multi-mode vibration
    response to walking excitation", *Engineering Structures* 29(6):942–954, 2007. The walking force
    (default).

    The theory pages cite them (docs: theory, References).

    Examples
    --------
    >>> from crowdvib import Crowd, MSDModel, ModalModel, simulate
    >>> bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    >>> record = simulate(bridge, Crowd.from_density(0.5), 10.0, msd=MSDModel(), rng=1)
    >>> record.acceleration.shape
    (1, 1000)
    """
    seed, integrator, n_samples, warm_up_samples, sample_rate, chunks = _start(
        structure, crowd, duration, pedestrians, msd, force, sample_rate, rng, progress,
        include_static_weight, chunk_duration, record_modal_load, warm_up, dampers, True,
        crowd_profile)
    n_outputs, n_modes = structure.n_outputs, structure.n_modes
    acceleration = np.empty((n_outputs, n_samples))
    modal_load = np.empty((n_modes, n_samples)) if record_modal_load else None
    n_on_deck = np.empty(n_samples, dtype=np.int16)
    for first, count in chunks:
        done = slice(first, first + count)
        acceleration[:, done] = integrator.acceleration[:, :count]
        if record_modal_load:
            modal_load[:, done] = integrator.modal_load[:, :count]
        people = integrator.n_on_deck[:count] - integrator.n_dampers      # people only
        if people.size and people.max() > np.iinfo(n_on_deck.dtype).max:
            n_on_deck = n_on_deck.astype(np.int32)
        n_on_deck[done] = people
    return Simulation(
        time=None,                     # i / sample_rate, computed when read
        acceleration=acceleration,
        output_names=structure.output_names,
        n_on_deck=n_on_deck,
        sample_rate=sample_rate,
        seed=seed,
        duration=n_samples / sample_rate,
        modal_load=modal_load,
        time_step=integrator.h,
        n_pedestrians=integrator.stream.size - integrator.n_dampers,
        hsi=msd is not None,
        warm_up=warm_up_samples / sample_rate,
    )


class _WelchSums:
    """A Welch average taken chunk by chunk: the segments of ``welch_psd`` (Hann, constant
    detrend, density scaling, a step of T − ⌊T·overlap⌋ samples from the first sample), each
    periodogram added once the samples it covers have arrived; only the samples of the segment
    not yet complete are held.

    The dispersion of ``welch_psd`` from running sums: Σ P_i, Σ P_i², Σ P_i P_(i+l) for the
    lags l <= DISPERSION_LAGS, and the first and last L periodograms, which give the sums of
    the centred products Σ (P_i − m)(P_(i+l) − m) once the mean m is known.
    """

    def __init__(self, n_outputs, sample_rate, segment, overlap):
        self.sample_rate, self.segment = sample_rate, segment
        self.overlap = overlap
        self.step = segment - int(segment * overlap)
        self.held = np.zeros((n_outputs, 0))
        self.total = self.squares = 0.0
        self.lagged = [0.0] * DISPERSION_LAGS
        self.first = self.last = None
        self.count = 0
        self.frequency = None

    def _add_periodograms(self, periodograms):
        self.total = self.total + periodograms.sum(axis=-1)
        self.squares = self.squares + np.sum(periodograms**2, axis=-1)
        recent = (periodograms if self.last is None
                  else np.concatenate([self.last, periodograms], axis=-1))
        new = periodograms.shape[-1]
        for lag in range(1, DISPERSION_LAGS + 1):
            if recent.shape[-1] > lag:
                later = recent[..., max(lag, recent.shape[-1] - new):]
                earlier = recent[..., max(lag, recent.shape[-1] - new) - lag:-lag]
                self.lagged[lag - 1] = self.lagged[lag - 1] + np.sum(later * earlier, axis=-1)
        self.last = recent[..., -DISPERSION_LAGS:]
        self.first = recent[..., :DISPERSION_LAGS] if self.first is None or (
            self.first.shape[-1] < DISPERSION_LAGS) else self.first

    def dispersion(self):
        """``welch_psd``'s dispersion of the segments added (None below 8 segments)."""
        k = self.count
        if k < 8:
            return None
        mean = self.total / k
        variance = self.squares / k - mean**2
        for lag in range(1, min(DISPERSION_LAGS, k - 1) + 1):
            before = self.total - self.last[..., -lag:].sum(axis=-1)     # P_0 … P_(k-1-l)
            after = self.total - self.first[..., :lag].sum(axis=-1)      # P_l … P_(k-1)
            centred = self.lagged[lag - 1] - mean * (before + after) + (k - lag) * mean**2
            variance = variance + 2 * (1 - lag / k) * centred / k
        return dispersion_ratio(variance, mean, k, self.overlap)

    def add(self, samples):
        data = np.concatenate([self.held, samples], axis=1)
        complete = (data.shape[1] - self.segment) // self.step + 1 if (
            data.shape[1] >= self.segment) else 0
        if complete:
            used = (complete - 1) * self.step + self.segment
            self.frequency, periodograms = segment_periodograms(
                data[:, :used], self.sample_rate, self.segment, self.overlap)
            self._add_periodograms(periodograms)
            self.count += complete
        self.held = data[:, complete * self.step:]


def simulate_psd(structure: ModalModel, crowd: Crowd | None = None,
                 duration: float | None = None, *, window_length: float, overlap: float = 0.5,
                 pedestrians: Sequence[Pedestrian] | None = None, msd: MSDModel | None = None,
                 force: ForceModel | None = None, sample_rate: float = 100.0, rng: Seed = None,
                 progress: Callable[[float, float], None] | None = None,
                 include_static_weight: bool = False, chunk_duration: float | None = None,
                 warm_up: float = 0.0,
                 dampers: Sequence[TunedMassDamper] | None = None,
                 crowd_profile: CrowdProfile | None = None) -> SimulationPSD:
    """The Welch PSD and summaries of the record :func:`simulate` would return, without the
    record: memory does not grow with ``duration`` beyond 32 bytes a pedestrian (issue 28 §3;
    a month of the paper example fits in well under 1 GB).

    The samples are run a chunk at a time and each Welch segment's periodogram is added as soon
    as its samples are in: the PSD equals ``welch_psd(simulate(...).acceleration, ...)`` of the
    same seed and options to round-off (the segments are summed in another order). Every
    parameter but ``window_length`` and ``overlap`` is :func:`simulate`'s.

    Parameters
    ----------
    structure, crowd, duration, pedestrians, msd, force, sample_rate, rng, progress
        As for :func:`simulate`.
    include_static_weight, chunk_duration, warm_up, dampers, crowd_profile
        As for :func:`simulate`.
    window_length : float
        Welch segment length T [s] (Hann window, constant detrend, as
        :func:`crowdvib.welch_psd`).
    overlap : float
        Overlap of consecutive segments, fraction of T, in [0, 1).

    Returns
    -------
    SimulationPSD
        The PSD (``ResponsePSD``, ``source="welch"``, with the segments' dispersion as
        ``welch_psd`` measures it) with the RMS and peak |a| per output, the people on the deck
        and the run's metadata.

    See Also
    --------
    crowdvib.simulate : the record itself.
    crowdvib.welch_psd : the same PSD of a kept record.

    Notes
    -----
    No low-pass: ``welch_psd``'s filter is zero-phase (forward and backward over the whole
    record), which cannot be applied a chunk at a time. A model compared with this PSD should
    be taken unfiltered; filter a record of :func:`simulate` where the filter matters.

    References
    ----------
    K. Van Nimmen and P. Van den Broeck, "Using full-scale observations on footbridges to estimate
    the parameters governing human–structure interaction", *Journal of Bridge Engineering* 28(1),
    2023. The coupled equations of motion (Eq. 1–4).

    P. D. Welch, "The use of fast Fourier transform for the estimation of power spectra: a method
    based on time averaging over short, modified periodograms", *IEEE Transactions on Audio and
    Electroacoustics* 15(2):70–73, 1967. The averaged periodograms.

    The theory pages cite them (docs: theory, References).

    Examples
    --------
    >>> from crowdvib import Crowd, MSDModel, ModalModel, simulate_psd
    >>> bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    >>> result = simulate_psd(bridge, Crowd.from_density(0.5), 120.0, msd=MSDModel(), rng=1,
    ...                       window_length=20.0)
    >>> result.psd.n_windows
    11
    """
    window_length = check_positive("window_length", window_length, unit="s")
    if not 0.0 <= overlap < 1.0:
        raise ParameterError(f"overlap must lie in [0, 1), got {overlap!r}")
    seed, integrator, n_samples, warm_up_samples, sample_rate, chunks = _start(
        structure, crowd, duration, pedestrians, msd, force, sample_rate, rng, progress,
        include_static_weight, chunk_duration, False, warm_up, dampers, False, crowd_profile)
    segment = int(round(window_length * sample_rate))
    if segment < 8:
        raise ParameterError(
            f"window_length × sample_rate must give at least 8 samples, got {segment}")
    if n_samples < segment:
        raise ParameterError(
            f"duration must hold one window: {n_samples / sample_rate:g} s is shorter than "
            f"window_length = {window_length:g} s")
    welch = _WelchSums(structure.n_outputs, sample_rate, segment, overlap)
    squares = np.zeros(structure.n_outputs)
    peak = np.zeros(structure.n_outputs)
    people, most = 0, 0
    for _, count in chunks:
        samples = integrator.acceleration[:, :count]
        welch.add(samples)
        squares += np.sum(samples**2, axis=1)
        peak = np.maximum(peak, np.max(np.abs(samples), axis=1, initial=0.0))
        on_deck = integrator.n_on_deck[:count] - integrator.n_dampers
        people += int(on_deck.sum())
        most = max(most, int(on_deck.max(initial=0)))
    psd = ResponsePSD(frequency=welch.frequency, psd=welch.total / welch.count,
                      output_names=structure.output_names, window_length=segment / sample_rate,
                      n_windows=welch.count, source="welch", dispersion=welch.dispersion())
    return SimulationPSD(
        psd=psd, rms=np.sqrt(squares / n_samples), peak=peak, sample_rate=sample_rate,
        seed=seed, duration=n_samples / sample_rate, time_step=integrator.h,
        n_pedestrians=integrator.stream.size - integrator.n_dampers,
        mean_on_deck=people / n_samples, max_on_deck=most, hsi=msd is not None,
        warm_up=warm_up_samples / sample_rate)
