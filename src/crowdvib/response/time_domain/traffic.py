"""The walkers of a time-domain simulation: who arrives when, how fast, with which force.

A stationary Poisson stream with the deck already populated at the start (docs: theory, Poisson
arrivals), or an explicit list of :class:`Pedestrian`; each walker's step frequency, body mass and
force components are drawn from the crowd's distributions and the force model.
"""

import secrets
from dataclasses import dataclass

import numpy as np

from ..._validation import as_float_array, check_non_negative, check_positive, check_type
from ...errors import ParameterError
from ...models.crowd import Crowd
from ...models.loading import STANDARD_GRAVITY, as_force_model, positive_normal
from ...models.measured import MeasuredForce, ReplayDraws
from ...models.structure import ModalModel

__all__ = ["Pedestrian", "generate_traffic"]



@dataclass(frozen=True)
class Pedestrian:
    """One walker (or stander) with a fixed line, speed and step frequency (docs: theory, Kinematics).

    Parameters
    ----------
    arrival_time : float
        Time t_k [s] at which the pedestrian is at ``position`` (by default: steps onto the deck).
        May be negative: the pedestrian is then already on the deck at t = 0.
    walking_speed : float
        Speed v_k [m/s], >= 0. 0 gives a pedestrian standing (walking on the spot) at ``position``
        from ``arrival_time`` on.
    step_frequency : float
        Step frequency f_s [Hz], > 0.
    body_mass : float
        Body mass m_h [kg], > 0 (weight W = m_h g with g = 9.81 m/s²).
    direction : {+1, -1}
        +1 walks towards increasing x, −1 towards decreasing x.
    lane : float
        Lateral offset y − B/2 [m] of the walking line from the walkway centreline, within
        [−B/2, B/2]; matters for modes that twist the deck.
    harmonics : sequence of (float, float, float), optional
        The force components as (frequency multiple r_c [-], dynamic load factor α_c [-],
        phase θ_c [rad]): p(t) = W Σ_c α_c sin(2π r_c f_s (t − t_k) + θ_c). None draws DLFs and
        phases from the force model of :func:`simulate`; an empty sequence gives no walking force
        (an MSD only).
    position : float, optional
        Position x [m] along the walkway at ``arrival_time``; default the entry end (the first
        station for direction +1, the last for −1). Needed for a standing pedestrian.
    """

    arrival_time: float
    walking_speed: float
    step_frequency: float
    body_mass: float
    direction: int = 1
    lane: float = 0.0
    harmonics: tuple = None
    position: float = None

    def __post_init__(self):
        object.__setattr__(self, "arrival_time",
                           float(as_float_array("arrival_time", self.arrival_time, ndim=0)))
        object.__setattr__(self, "walking_speed",
                           check_non_negative("walking_speed", self.walking_speed, unit="m/s"))
        object.__setattr__(self, "step_frequency",
                           check_positive("step_frequency", self.step_frequency, unit="Hz"))
        object.__setattr__(self, "body_mass", check_positive("body_mass", self.body_mass, unit="kg"))
        if self.direction not in (1, -1):
            raise ParameterError(f"direction must be +1 or -1, got {self.direction!r}")
        object.__setattr__(self, "direction", int(self.direction))
        object.__setattr__(self, "lane", float(as_float_array("lane", self.lane, ndim=0)))
        if self.position is not None:
            object.__setattr__(self, "position",
                               float(as_float_array("position", self.position, ndim=0)))
        if self.harmonics is not None:
            rows = as_float_array("harmonics", self.harmonics)
            rows = rows.reshape(0, 3) if rows.size == 0 else rows
            if rows.ndim != 2 or rows.shape[1] != 3:
                raise ParameterError(
                    "harmonics must be a sequence of (frequency multiple, dynamic load factor, "
                    f"phase) triples, got shape {rows.shape}")
            check_positive("harmonics frequency multiple", rows[:, 0])
            object.__setattr__(self, "harmonics", tuple(tuple(float(v) for v in r) for r in rows))


@dataclass(frozen=True)
class _Walkers:
    """All pedestrians of a run as arrays (the kernel's view), sorted by time on the deck."""

    arrival: np.ndarray        # t_k [s]
    x_start: np.ndarray        # x at t_k [m]
    velocity: np.ndarray       # signed speed [m/s]
    t_on: np.ndarray           # time the pedestrian steps on the deck [s]
    t_off: np.ndarray          # time the pedestrian steps off (inf for standing) [s]
    lateral: np.ndarray        # y [m], 0..B
    step_frequency: np.ndarray # f_s [Hz]
    body_mass: np.ndarray      # m_h [kg]
    dlf: np.ndarray            # α_c [-], (n, n_components)
    ratio: np.ndarray          # r_c [-], (n, n_components)
    phase: np.ndarray          # θ_c [rad], (n, n_components)
    replay: tuple              # ReplayDraws of a MeasuredForce (record −1: none), one per walker

    @property
    def amplitude(self):
        """W α_c [N], (n, n_components)."""
        return (self.body_mass * STANDARD_GRAVITY)[:, np.newaxis] * self.dlf

    @property
    def omega(self):
        """2π r_c f_s [rad/s], (n, n_components)."""
        return 2.0 * np.pi * self.ratio * self.step_frequency[:, np.newaxis]

    @property
    def size(self):
        return self.arrival.size


def _seed_from(rng):
    """The integer seed of a run: given, drawn from a given generator, or from OS entropy."""
    if rng is None:
        return secrets.randbits(63)
    if isinstance(rng, np.random.Generator):
        return int(rng.integers(0, 2**63))
    if isinstance(rng, (int, np.integer)) and not isinstance(rng, bool):
        if rng < 0:
            raise ParameterError(f"rng must be a non-negative integer seed, got {rng}")
        return int(rng)
    raise ParameterError(
        f"rng must be None, a non-negative int or a numpy.random.Generator, got {type(rng).__name__}")


#: Crowd walkers whose step frequencies, DLFs, phases and masses are drawn in one go (docs:
#: theory, Poisson arrivals). A stream of up to this many is drawn exactly as it always was; a
#: longer one draws block after block of this many, block b > 0 from its own generator spawned
#: from the run's seed, so a run of days holds a block or two at a time and any block can be
#: drawn again alone. The record depends on the seed only, never on how it is chunked.
STREAM_BLOCK = 1 << 16


def _crowd_arrivals(structure, crowd, start, end, rng, profile=None):
    """The arrival times of a crowd's stream over [start, end), in stream order, and how many
    walk forwards (they come first; docs: theory, Poisson arrivals).

    Per direction: the people already on the deck at ``start`` (Poisson(n·share) at uniform
    positions, i.e. arrival times start − U[0, L/v]), then Poisson arrivals on [start, end).
    With a :class:`~crowdvib.models.CrowdProfile` whose density varies, the stream is the
    non-homogeneous one of rate d(t)·B·v (docs: theory, A crowd that changes).
    """
    crossing = structure.length / crowd.walking_speed
    if profile is not None and not profile.is_constant:
        return _profile_arrivals(structure, crowd, profile, start - crossing, start, end, rng)
    arrivals = []
    for share in (crowd.forward_fraction, 1.0 - crowd.forward_fraction):
        on_deck = rng.poisson(crowd.density * structure.width * structure.length * share)
        arrivals.append(start - crossing * rng.uniform(0.0, 1.0, on_deck))
        entering = rng.poisson(crowd.arrival_rate(structure.width) * share * (end - start))
        arrivals.append(np.sort(rng.uniform(start, end, entering)))
    return np.concatenate(arrivals), arrivals[0].size + arrivals[1].size


def _profile_arrivals(structure, crowd, profile, before, start, end, rng):
    """:func:`_crowd_arrivals` of a varying density, by inversion of the cumulative rate: per
    direction, the walkers who entered during the crossing before ``start`` (on the deck at
    ``start``), then those entering on [start, end); the draws in the stationary stream's order.

    N ~ Poisson(B·v·share·∫d) and the times C⁻¹(U) with U uniform over the cumulative density:
    the Poisson stream of rate d(t)·B·v (docs: theory, A crowd that changes).
    """
    rate = structure.width * crowd.walking_speed
    bounds = profile.cumulative(np.array([before, start, end]))
    arrivals = []
    for share in (crowd.forward_fraction, 1.0 - crowd.forward_fraction):
        for low, high in ((bounds[0], bounds[1]), (bounds[1], bounds[2])):
            count = rng.poisson(rate * share * (high - low))
            arrivals.append(profile.inverse_cumulative(np.sort(rng.uniform(low, high, count))))
    return np.concatenate(arrivals), arrivals[0].size + arrivals[1].size


def _crowd_attributes(n, structure, crowd, force, rng):
    """Lateral positions U[0, B], step frequencies N(μ, σ), DLFs and phases, and, when the crowd
    has a body-mass spread, body masses N(m_h, σ_m) of ``n`` walkers, in this order (the masses
    last, so a crowd without spread gives the same stream as before the option existed)."""
    lateral = rng.uniform(0.0, structure.width, n)
    step_frequency = positive_normal(np.full(n, crowd.step_frequency_mean),
                                     crowd.step_frequency_std, rng)
    dlf, phase = force.sample(step_frequency, rng)
    replay = _replay_draws(force, step_frequency, rng)
    if crowd.body_mass_std > 0:
        mass = positive_normal(np.full(n, crowd.body_mass), crowd.body_mass_std, rng)
    else:
        mass = np.full(n, crowd.body_mass)
    return lateral, step_frequency, dlf, phase, mass, replay


def _replay_draws(force, step_frequency, rng):
    """A MeasuredForce's replay draws per walker; none otherwise (record −1, nothing drawn)."""
    if isinstance(force, MeasuredForce):
        return force.sample_replay(step_frequency, rng)
    n = np.asarray(step_frequency).size
    return ReplayDraws(np.full(n, -1, dtype=np.int64), np.zeros(n), np.zeros(n), np.zeros(n),
                       np.zeros(n))


def _table(arrival, x_start, velocity, lateral, step_frequency, body_mass, dlf, ratio, phase,
           replay, width):
    """Walkers' columns as a dict, the force components zero-padded to ``width``."""
    def pad(columns):      # (a crowd's ratios stay one broadcast row when wide enough)
        return columns if columns.shape[1] == width else np.pad(
            columns, ((0, 0), (0, width - columns.shape[1])))
    return {"arrival": arrival, "x_start": x_start, "velocity": velocity, "lateral": lateral,
            "step_frequency": step_frequency, "body_mass": body_mass,
            "dlf": pad(dlf), "ratio": pad(ratio), "phase": pad(phase), "replay": tuple(replay)}


def _time_off(arrival, x_start, velocity, x0, x1):
    """Time on the deck ends: from the arrival at x_start to the far end (never, when standing)."""
    remaining = np.where(velocity > 0, x1 - x_start, x_start - x0)
    speed = np.abs(velocity)
    with np.errstate(divide="ignore"):
        return np.where(speed > 0, arrival + remaining / np.where(speed > 0, speed, 1.0), np.inf)


class _Stream:
    """Everybody of a run in order of arrival, handed out a window at a time (docs: theory,
    Poisson arrivals; issue 28 §3): the crowd's stream, then the explicit pedestrians, then the
    tuned mass dampers (walkers that never walk), ranked by arrival (stable).

    Only the arrival and leaving times and the rank of the whole stream are kept (32 bytes a
    walker); the crowd's other draws are made a :data:`STREAM_BLOCK` at a time when a window
    needs them.
    """

    def __init__(self, structure, crowd, pedestrians, start, end, force, rng, dampers=(),
                 profile=None):
        self.structure, self.crowd, self.force = structure, crowd, force
        x0, x1 = structure.positions[0], structure.positions[-1]
        self.x0, self.x1 = x0, x1
        self.seed_sequence = rng.bit_generator.seed_seq
        self.n_crowd = 0
        self.width = 1
        self._blocks = {}
        crowd_arrival = np.zeros(0)
        if crowd is not None and crowd.density > 0:
            crowd_arrival, self.n_forward = _crowd_arrivals(structure, crowd, start, end, rng,
                                                            profile)
            self.n_crowd = crowd_arrival.size
            self._crowd_arrival = crowd_arrival
            self._state = rng.bit_generator.state             # block 0 can be drawn again
            first = self._attributes(0, rng)                  # the run's generator: as ever
            self.width = first[2].shape[1]
        fixed = []
        if pedestrians:
            arrays = _explicit_arrays(structure, pedestrians, force, rng)
            self.width = max(self.width, arrays[6].shape[1])
            fixed.append(arrays)
        self.n_dampers = len(dampers)
        if dampers:
            for damper in dampers:
                damper.shape_row(structure)                 # raises if off the walkway
            n = len(dampers)
            fixed.append((np.full(n, float(start)), np.array([d.position for d in dampers]),
                          np.zeros(n), np.array([structure.width / 2 if d.lane is None else d.lane
                                                 for d in dampers]),
                          np.ones(n), np.array([d.mass for d in dampers]),
                          np.zeros((n, self.width)), np.ones((n, self.width)),
                          np.zeros((n, self.width)), _replay_draws(None, np.ones(n), None)))
        # The explicit pedestrians and the dampers: one table, kept whole.
        self._fixed = _table(*(np.concatenate([f[i] for f in fixed]) if fixed
                               else np.zeros((0, 1) if i in (6, 7, 8) else 0) for i in range(9)),
                             ReplayDraws(*(np.concatenate([f[9][i] for f in fixed]) if fixed
                                           else _replay_draws(None, np.zeros(0), None)[i]
                                           for i in range(5))), self.width)
        if self.n_crowd:
            self._blocks[0] = self._block_table(0, first)
        self._first_damper = self.n_crowd + self._fixed["arrival"].size - self.n_dampers
        arrival = np.concatenate([crowd_arrival, self._fixed["arrival"]])
        self.order = np.argsort(arrival, kind="stable")
        self.t_on = arrival[self.order]
        # Crowd walkers start at an end: the distance to the other is the length either way.
        self._t_off = np.concatenate([
            crowd_arrival + (x1 - x0) / crowd.walking_speed if self.n_crowd else crowd_arrival,
            _time_off(self._fixed["arrival"], self._fixed["x_start"], self._fixed["velocity"],
                      x0, x1)])

    @property
    def size(self):
        return self.t_on.size

    def t_off(self):
        """The times every walker steps off, in stream (not time) order."""
        return self._t_off

    def _attributes(self, block, rng=None):
        """The crowd's draws for stream positions [block·B, (block + 1)·B); block 0 from the
        run's generator ``rng``, any other from its own."""
        first = block * STREAM_BLOCK
        if rng is None and block == 0:
            rng = np.random.default_rng(self.seed_sequence)
            rng.bit_generator.state = self._state
        elif rng is None:
            child = np.random.SeedSequence(self.seed_sequence.entropy,
                                           spawn_key=self.seed_sequence.spawn_key + (int(block),))
            rng = np.random.default_rng(child)
        return _crowd_attributes(min(STREAM_BLOCK, self.n_crowd - first), self.structure,
                                 self.crowd, self.force, rng)

    def _block_table(self, block, attributes):
        first = block * STREAM_BLOCK
        lateral, fs, dlf, phase, mass, replay = attributes
        forward = np.arange(first, first + fs.size) < self.n_forward
        return _table(self._crowd_arrival[first:first + fs.size],
                      np.where(forward, self.x0, self.x1),
                      np.where(forward, 1, -1) * self.crowd.walking_speed, lateral, fs, mass,
                      dlf, np.broadcast_to(self.force.ratios, dlf.shape), phase, replay,
                      self.width)

    def _draw_block(self, block):
        return self._block_table(block, self._attributes(block))

    def block(self, block):
        """A block of the crowd's columns, drawn again unless it is one of the last three used
        (a window reaches into a forward and a backward one, and at times the next of either)."""
        table = self._blocks.pop(block, None)
        if table is None:
            table = self._draw_block(block)
            if len(self._blocks) >= 3:
                del self._blocks[next(iter(self._blocks))]   # the least recently used
        self._blocks[block] = table
        return table

    def tables(self):
        """Every table of columns once, with its number of people (the rows before the
        dampers): the crowd's blocks, then the rest, for a pass over all."""
        for block in range(-(-self.n_crowd // STREAM_BLOCK)):
            table = self._blocks[block] if block in self._blocks else self._draw_block(block)
            yield table, table["arrival"].size
        yield self._fixed, self._first_damper - self.n_crowd

    def window(self, first, stop):
        """The walkers of ranks [first, stop) as :class:`_Walkers`, and each one's damper
        number (−1 for a pedestrian)."""
        source = self.order[first:stop]
        parts = []
        crowd = np.flatnonzero(source < self.n_crowd)
        for block in np.unique(source[crowd] // STREAM_BLOCK):
            rows = crowd[source[crowd] // STREAM_BLOCK == block]
            parts.append((rows, self.block(block), source[rows] - block * STREAM_BLOCK))
        rows = np.flatnonzero(source >= self.n_crowd)
        parts.append((rows, self._fixed, source[rows] - self.n_crowd))
        columns = {}
        for name in ("arrival", "x_start", "velocity", "lateral", "step_frequency", "body_mass",
                     "dlf", "ratio", "phase"):
            column = np.empty((source.size,) + parts[-1][1][name].shape[1:])
            for rows, table, index in parts:
                column[rows] = table[name][index]
            columns[name] = column
        replay = []
        for i, example in enumerate(self._fixed["replay"]):
            column = np.empty(source.size, dtype=example.dtype)
            for rows, table, index in parts:
                column[rows] = table["replay"][i][index]
            replay.append(column)
        damper = np.where(source >= self._first_damper, source - self._first_damper, -1)
        arrival = columns["arrival"]
        t_off = _time_off(arrival, columns["x_start"], columns["velocity"], self.x0, self.x1)
        return _Walkers(t_on=arrival, t_off=t_off, replay=ReplayDraws(*replay),
                        **columns), damper


def _walkers(structure, crowd, pedestrians, start, end, force, rng):
    """Everybody of a run as one :class:`_Walkers` (the crowd's stream, then the explicit ones)."""
    stream = _Stream(structure, crowd, pedestrians, start, end, force, rng)
    return stream.window(0, stream.size)[0]


def _explicit_arrays(structure, pedestrians, force, rng):
    """Arrays of explicit pedestrians; missing harmonics drawn from ``force`` in list order."""
    x0, x1 = structure.positions[0], structure.positions[-1]
    half_width = structure.width / 2
    arrival, x_start, velocity, lateral, fs, mass, rows = [], [], [], [], [], [], []
    replays = []
    for index, walker in enumerate(pedestrians):
        if not isinstance(walker, Pedestrian):
            raise ParameterError(
                f"pedestrians[{index}] must be a Pedestrian, got {type(walker).__name__}")
        if abs(walker.lane) > half_width:
            raise ParameterError(
                f"pedestrians[{index}].lane must lie within ±width/2 = ±{half_width:g} m of the "
                f"centreline, got {walker.lane:g} m")
        start = (x0 if walker.direction > 0 else x1) if walker.position is None else walker.position
        if not x0 <= start <= x1:
            raise ParameterError(
                f"pedestrians[{index}].position must lie on the walkway [{x0:g}, {x1:g}] m, "
                f"got {start:g} m")
        if walker.harmonics is None:
            dlf, phase = force.sample(np.array([walker.step_frequency]), rng)
            components = np.column_stack([force.ratios, dlf[0], phase[0]])
            replays.append(_replay_draws(force, np.array([walker.step_frequency]), rng))
        else:
            components = np.array(walker.harmonics, dtype=float).reshape(-1, 3)
            replays.append(_replay_draws(None, np.zeros(1), None))
        arrival.append(walker.arrival_time)
        x_start.append(start)
        velocity.append(walker.direction * walker.walking_speed)
        lateral.append(half_width + walker.lane)
        fs.append(walker.step_frequency)
        mass.append(walker.body_mass)
        rows.append(components)
    width = max(1, max(r.shape[0] for r in rows))
    block = np.zeros((len(rows), width, 3))
    block[:, :, 0] = 1.0     # padding: a zero-amplitude component at any harmless multiple
    for i, r in enumerate(rows):
        block[i, :r.shape[0]] = r
    return (np.array(arrival), np.array(x_start), np.array(velocity), np.array(lateral),
            np.array(fs), np.array(mass), block[:, :, 1], block[:, :, 0], block[:, :, 2],
            ReplayDraws(*(np.concatenate([r[i] for r in replays]) for i in range(5))))


def generate_traffic(structure, crowd, duration, *, force=None, rng=None, warm_up=0.0):
    """The pedestrian stream of :func:`simulate` as a list of explicit :class:`Pedestrian`.

    Useful to inspect, edit or replay a crowd: ``simulate(structure, duration=T,
    pedestrians=generate_traffic(structure, crowd, T, rng=s), ...)`` reproduces
    ``simulate(structure, crowd, T, rng=s, ...)`` up to rounding of the lateral positions.

    Parameters
    ----------
    structure : ModalModel
    crowd : Crowd
    duration : float
        Record length [s] after the warm-up.
    force : ZivanovicForce or YoungForce, optional
        Force model for the DLFs and phases (default Živanović 2007).
    rng : None, int or numpy.random.Generator
    warm_up : float
        Simulated time [s] before t = 0 (the deck is populated at t = −warm_up).

    Returns
    -------
    list of Pedestrian
        Sorted by arrival time; every pedestrian carries explicit harmonics.
    """
    _check_structure(structure)
    check_type("crowd", crowd, Crowd).check_stationary("generate_traffic")
    duration, warm_up = check_duration(duration, warm_up)
    force = as_force_model(force, time_domain=True)
    if isinstance(force, MeasuredForce):
        raise ParameterError("force: generate_traffic lists harmonic pedestrians; a MeasuredForce "
                             "replay cannot be written as harmonics (pass it to simulate)")
    walkers = _walkers(structure, crowd, None, -warm_up, duration, force,
                       np.random.default_rng(_seed_from(rng)))
    x0, x1 = structure.positions[0], structure.positions[-1]
    result = []
    for k in range(walkers.size):
        speed = abs(walkers.velocity[k])
        direction = 1 if walkers.velocity[k] >= 0 else -1
        fs = walkers.step_frequency[k]
        harmonics = tuple((float(r), float(a), float(p))
                          for r, a, p in zip(walkers.ratio[k], walkers.dlf[k], walkers.phase[k])
                          if a != 0.0)
        result.append(Pedestrian(walkers.arrival[k], speed, fs, walkers.body_mass[k],
                                 direction=direction,
                                 lane=walkers.lateral[k] - structure.width / 2,
                                 harmonics=harmonics,
                                 position=x0 if direction > 0 else x1))
    return result


def check_duration(duration, warm_up):
    """A run's duration (> 0 s) and warm-up (>= 0 s) as floats, or a ParameterError."""
    if duration is None:
        raise ParameterError("duration must be given (> 0 s), got None")
    duration = float(as_float_array("duration", duration, ndim=0))
    if duration <= 0:
        raise ParameterError(f"duration must be > 0 s, got {duration:g}")
    warm_up = check_non_negative("warm_up", warm_up, unit="s")
    return duration, float(warm_up)


def _check_structure(structure):
    check_type("structure", structure, ModalModel)
