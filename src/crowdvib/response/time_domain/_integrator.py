"""The simulator's integrator: the state of one run between calls of the compiled kernel.

A run (``_run.Run``) is made into an :class:`_Integrator` by :func:`prepare`: the stream of
walkers drawn from the run's seed, the internal step that resolves the fastest state and force
(docs: theory, Time stepping) and the kernel for the kind of run. :meth:`_Integrator.advance`
then steps the coupled equations of motion (paper Eq. 1–4) a number of internal steps on,
windowing the stream so that memory does not grow with the record; the numerics (fixed-step
RK4 over the pedestrians on the deck) live in :mod:`crowdvib.response._kernels`.
"""

import dataclasses
import math

import numpy as np

from . import _kernels, _slots
from ..._plausibility import warn_notes
from ...models.loading import STANDARD_GRAVITY
from ...models.measured import REPLAY_HARMONICS, ReplayDraws
from .traffic import _Stream, _Walkers

#: Internal RK4 steps per period of the highest natural frequency of the states (structural
#: modes, f_h1). RK4's numerical damping and period error grow with (ω h)⁶ and (ω h)⁴: at 10
#: steps per period (ω h = 0.63, the accuracy docs: theory, Time stepping validated) a lightly damped mode
#: loses far less per cycle than its own damping takes.
STEPS_PER_PERIOD = 10
#: Internal steps per period of the fastest force component (a walker's 5th harmonic). A force
#: is only sampled, at the three RK4 stage times, so its error falls as (ω h)⁴/2880 ≈ 2e-4 at 6
#: steps per period: it need not limit the step the way a lightly damped state does.
FORCE_STEPS_PER_PERIOD = 6
#: Simulated seconds of arrivals handed to the kernel at once (at least a chunk's): the window of
#: the stream is rebuilt this seldom (a few hundred walkers; the rebuild costs about a millisecond).
WINDOW_DURATION = 600.0


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


def prepare(run):
    """The integrator of ``run`` (a checked ``_run.Run``) at its first step, warm-up included
    (no time stepping yet)."""
    if run.profile is not None:
        warn_notes(run.profile.implausibilities(run.duration), stacklevel=4)   # simulate's caller
    rng = np.random.default_rng(run.seed)
    start = -run.warm_up_samples / run.sample_rate
    stream = _Stream(run.structure, run.crowd, list(run.pedestrians), start, run.duration,
                     run.force, rng, run.dampers, run.profile)
    substeps, added_mass = _scan_stream(run.structure, stream, run.msd, run.sample_rate)
    if run.dampers:      # the dampers' own frequencies bound the step like the modes'
        fastest = max(d.frequency for d in run.dampers)
        substeps = max(substeps, math.ceil(STEPS_PER_PERIOD * fastest / run.sample_rate - 1e-9))
    return _Integrator(run.structure, stream, run.msd, run.sample_rate, substeps,
                       -run.warm_up_samples * substeps, run.record_modal_load,
                       run.include_static_weight, run.dampers, getattr(run.force, "table", None),
                       added_mass)
