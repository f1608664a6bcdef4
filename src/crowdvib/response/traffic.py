"""The walkers of a time-domain simulation: who arrives when, how fast, with which force.

A stationary Poisson stream with the deck already populated at the start (docs: theory, Poisson
arrivals), or an explicit list of :class:`Pedestrian`; each walker's step frequency, body mass and
force components are drawn from the crowd's distributions and the force model.
"""

import secrets
from dataclasses import dataclass

import numpy as np

from .._validation import as_float_array, check_non_negative, check_positive, check_type
from ..errors import ParameterError
from ..models.crowd import Crowd
from ..models.loading import STANDARD_GRAVITY, as_force_model, positive_normal
from ..models.measured import MeasuredForce, ReplayDraws
from ..models.structure import ModalModel

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


def _crowd_draws(structure, crowd, start, end, force, rng):
    """Draw the stream of a crowd over [start, end) in a fixed order (docs: theory, Poisson arrivals).

    Per direction: the people already on the deck at ``start`` (Poisson(n·share) at uniform
    positions, i.e. arrival times start − U[0, L/v]), then Poisson arrivals on [start, end).
    Then, for everybody: lateral positions U[0, B], step frequencies N(μ, σ), DLFs and phases,
    and, when the crowd has a body-mass spread, body masses N(m_h, σ_m) (drawn last, so a crowd
    without spread gives the same stream as before the option existed).
    """
    length, width, speed = structure.length, structure.width, crowd.walking_speed
    crossing = length / speed
    arrivals, directions = [], []
    for direction, share in ((1, crowd.forward_fraction), (-1, 1.0 - crowd.forward_fraction)):
        on_deck = rng.poisson(crowd.density * width * length * share)
        arrivals.append(start - crossing * rng.uniform(0.0, 1.0, on_deck))
        entering = rng.poisson(crowd.arrival_rate(width) * share * (end - start))
        arrivals.append(np.sort(rng.uniform(start, end, entering)))
        directions.append(np.full(on_deck + entering, direction))
    arrival = np.concatenate(arrivals)
    direction = np.concatenate(directions)
    lateral = rng.uniform(0.0, width, arrival.size)
    step_frequency = positive_normal(np.full(arrival.size, crowd.step_frequency_mean),
                                     crowd.step_frequency_std, rng)
    dlf, phase = force.sample(step_frequency, rng)
    replay = _replay_draws(force, step_frequency, rng)
    if crowd.body_mass_std > 0:
        mass = positive_normal(np.full(arrival.size, crowd.body_mass), crowd.body_mass_std, rng)
    else:
        mass = np.full(arrival.size, crowd.body_mass)
    return arrival, direction, lateral, step_frequency, dlf, phase, mass, replay


def _replay_draws(force, step_frequency, rng):
    """A MeasuredForce's replay draws per walker; none otherwise (record −1, nothing drawn)."""
    if isinstance(force, MeasuredForce):
        return force.sample_replay(step_frequency, rng)
    n = np.asarray(step_frequency).size
    return ReplayDraws(np.full(n, -1, dtype=np.int64), np.zeros(n), np.zeros(n), np.zeros(n),
                       np.zeros(n))


def _walkers(structure, crowd, pedestrians, start, end, force, rng):
    """Everybody of a run as :class:`_Walkers`; the crowd's stream first, then the explicit ones."""
    x0, x1 = structure.positions[0], structure.positions[-1]
    parts = []
    if crowd is not None and crowd.density > 0:
        arrival, direction, lateral, fs, dlf, phase, mass, replay = _crowd_draws(
            structure, crowd, start, end, force, rng)
        ratios = np.broadcast_to(force.ratios, dlf.shape)
        parts.append((arrival, np.where(direction > 0, x0, x1),
                      direction * crowd.walking_speed, lateral, fs, mass, dlf, ratios, phase,
                      replay))
    if pedestrians:
        parts.append(_explicit_arrays(structure, pedestrians, force, rng))
    if not parts:
        empty = np.zeros(0)
        parts.append((empty,) * 6 + (np.zeros((0, 1)),) * 3 + (_replay_draws(None, empty, None),))
    width = max(p[6].shape[1] for p in parts)
    columns = [np.concatenate([p[i] for p in parts]) for i in range(6)]
    padded = [np.concatenate([np.pad(p[i], ((0, 0), (0, width - p[i].shape[1]))) for p in parts])
              for i in (6, 7, 8)]
    arrival, x_start, velocity, lateral, fs, mass = columns
    dlf, ratios, phase = padded
    replay = ReplayDraws(*(np.concatenate([p[9][i] for p in parts]) for i in range(5)))
    # Time on the deck: from the arrival at x_start to the far end (never, when standing).
    remaining = np.where(velocity > 0, x1 - x_start, x_start - x0)
    speed = np.abs(velocity)
    with np.errstate(divide="ignore"):
        t_off = np.where(speed > 0, arrival + remaining / np.where(speed > 0, speed, 1.0), np.inf)
    order = np.argsort(arrival, kind="stable")
    return _Walkers(arrival=arrival[order], x_start=x_start[order], velocity=velocity[order],
                    t_on=arrival[order], t_off=t_off[order], lateral=lateral[order],
                    step_frequency=fs[order], body_mass=mass[order], dlf=dlf[order],
                    ratio=ratios[order], phase=phase[order],
                    replay=ReplayDraws(*(column[order] for column in replay)))


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
    check_type("crowd", crowd, Crowd)
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


# --- Tuned mass dampers in the simulator (issue 11) -------------------------------------------
# A damper is a walker that never walks: fixed at its position for the whole record, with no
# walking force and its own spring and dashpot (set by the integrator from ``dampers``).

def _with_dampers(structure, walkers, dampers, start):
    """``walkers`` plus one stationary, force-free entry per damper, present from ``start``.

    Returns the new :class:`_Walkers` (sorted by arrival, stable, so the dampers keep their
    order) and the boolean mask of the damper entries.
    """
    if not dampers:
        return walkers, np.zeros(walkers.size, dtype=bool)
    for damper in dampers:
        damper.shape_row(structure)                 # raises if off the walkway
    n, components = len(dampers), walkers.dlf.shape[1]
    extra = {"arrival": np.full(n, float(start)),
             "x_start": np.array([d.position for d in dampers]),
             "velocity": np.zeros(n), "t_on": np.full(n, float(start)), "t_off": np.full(n, np.inf),
             "lateral": np.array([structure.width / 2 if d.lane is None else d.lane
                                  for d in dampers]),
             "step_frequency": np.ones(n), "body_mass": np.array([d.mass for d in dampers]),
             "dlf": np.zeros((n, components)), "ratio": np.ones((n, components)),
             "phase": np.zeros((n, components))}
    merged = {name: np.concatenate([getattr(walkers, name), value])
              for name, value in extra.items()}
    order = np.argsort(merged["arrival"], kind="stable")
    mask = np.concatenate([np.zeros(walkers.size, dtype=bool), np.ones(n, dtype=bool)])
    # A damper replays no measured force (record −1), like a harmonic walker.
    none = _replay_draws(None, np.ones(n), None)
    replay = ReplayDraws(*(np.concatenate(pair)[order] for pair in zip(walkers.replay, none)))
    return (_Walkers(**{name: value[order] for name, value in merged.items()}, replay=replay),
            mask[order])
