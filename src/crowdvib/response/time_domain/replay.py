"""A stretch of a simulated crossing, frame by frame: what a replay of the record draws (issue 38).

The record (:class:`~crowdvib.response.time_domain.results.Simulation`) holds the accelerations at the
outputs only. A replay needs the deck's modal coordinates and the walkers on the deck as
well: the same run is made again from its seed (:func:`crowdvib.simulate` is bit-identical for
any chunking, so the stretch is the record's own) and stopped at every frame to read the modal
displacements z(t) and the walkers of the stream (arrival time, position at arrival, signed
speed, lateral position, step frequency). Frames are decimated, never the physics: the run
keeps its own time step, only the states kept are fewer.

Public: :func:`crossing_replay` and the :class:`Replay` it returns; :func:`busiest_stretch`
picks the default stretch from the record.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._validation import check_positive
from ...errors import ParameterError
from ._run import Run
from .simulation import _start

__all__ = ["Replay", "crossing_replay", "busiest_stretch", "DEFAULT_REPLAY_LENGTH",
           "DEFAULT_FRAME_RATE"]

#: Seconds of record a replay shows by default (issue 38: "a chosen stretch (default 30 s)").
DEFAULT_REPLAY_LENGTH = 30.0
#: Frames per second kept: a 2 Hz mode drawn with 10 points a cycle moves smoothly, and the
#: page stays light (the deflection of each frame is one number per mode).
DEFAULT_FRAME_RATE = 20.0


@dataclass(frozen=True)
class Replay:
    """A stretch of a simulated record with the deck's motion and its walkers.

    Attributes
    ----------
    time : ndarray, shape (n_frames,)
        Frame times [s] on the record's time axis (t = 0 its first sample).
    modal_displacement : ndarray, shape (n_modes, n_frames)
        Modal coordinates z_j(t) [scaling of the mode shapes × m]: the deflection is
        w(x, y, t) = Σ_j φ_j(x, y) z_j(t).
    arrival, x_start, velocity, lateral, step_frequency : ndarray, shape (n_walkers,)
        The walkers on the deck at some time of the stretch: arrival time t_k [s], position at
        arrival [m], signed speed [m/s], lateral position [m, 0 … width], step frequency [Hz];
        on the deck between ``t_on`` and ``t_off``.
    t_on, t_off : ndarray, shape (n_walkers,)
        When each walker steps on and off the deck [s].
    trace_time : ndarray, shape (n_trace,)
        Sample times [s] of ``acceleration`` (the record's own samples in the stretch).
    acceleration : ndarray, shape (n_outputs, n_trace)
        The record's accelerations at the outputs in the stretch [m/s²].
    output_names : tuple of str
    seed : int
        The run's seed.
    hsi : bool
        The walkers were MSDs.
    msd_displacement : ndarray, shape (n_walkers, n_frames), or None
        With HSI: each walker's MSD body relative to the deck under it, u_k − φ_kᵀ z [m] (NaN
        while off the deck); None for moving forces.
    """

    time: np.ndarray
    modal_displacement: np.ndarray
    arrival: np.ndarray
    x_start: np.ndarray
    velocity: np.ndarray
    lateral: np.ndarray
    step_frequency: np.ndarray
    t_on: np.ndarray
    t_off: np.ndarray
    trace_time: np.ndarray
    acceleration: np.ndarray
    output_names: tuple
    seed: int
    hsi: bool
    msd_displacement: np.ndarray | None = None

    @property
    def n_frames(self) -> int:
        return self.time.size

    def positions(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(walker index, x [m]) of the walkers on the deck at time ``t`` [s]:
        x = x_k + v_k (t − t_k)."""
        on = np.flatnonzero((self.t_on <= t) & (t < self.t_off))
        return on, self.x_start[on] + self.velocity[on] * (t - self.arrival[on])


def busiest_stretch(n_on_deck, sample_rate, length):
    """Start [s] of the ``length`` s of a record with the most walkers on the deck on average
    (the earliest of equals); 0 when the record is not longer.

    Parameters
    ----------
    n_on_deck : array_like of int
        Walkers on the deck per sample (``Simulation.n_on_deck``).
    sample_rate : float
        [Hz].
    length : float
        [s].
    """
    count = np.asarray(n_on_deck, dtype=float)
    width = int(round(length * sample_rate))
    if width >= count.size:
        return 0.0
    running = np.convolve(count, np.ones(width), mode="valid")      # sums of each window
    return float(np.argmax(running)) / sample_rate


def crossing_replay(structure, crowd=None, duration=None, *, start=None,
                    length=DEFAULT_REPLAY_LENGTH, frame_rate=DEFAULT_FRAME_RATE,
                    pedestrians=None, msd=None, force=None, sample_rate=100.0, rng=None,
                    warm_up=0.0, dampers=None, n_on_deck=None) -> Replay:
    """A stretch of the record :func:`crowdvib.simulate` makes with the same arguments, with its
    modal coordinates and walkers frame by frame.

    Parameters
    ----------
    structure, crowd, duration, pedestrians, msd, force, sample_rate, rng, warm_up, dampers
        As for :func:`crowdvib.simulate` (``rng`` a seed: the record's own is replayed).
    start : float, optional
        First time of the stretch [s] (default: :func:`busiest_stretch` of ``n_on_deck``, or
        0 without it).
    length : float
        Seconds shown (cut at the record's end).
    frame_rate : float
        Frames per second kept [Hz]; rounded to a whole number of samples per frame.
    n_on_deck : array_like, optional
        The record's walkers on the deck per sample, to choose the busiest stretch.

    Returns
    -------
    Replay

    Raises
    ------
    ParameterError
        A stretch outside the record, or a frame rate above the sample rate.
    """
    length = check_positive("length", length, unit="s")
    frame_rate = check_positive("frame_rate", frame_rate, unit="Hz")
    run = Run.checked(structure, crowd, duration, pedestrians=pedestrians, msd=msd, force=force,
                      sample_rate=sample_rate, rng=rng, progress=None,
                      include_static_weight=False, chunk_duration=None,
                      record_modal_load=False, warm_up=warm_up, dampers=dampers)
    integrator, _ = _start(run)       # stepped frame by frame below, not chunk by chunk
    seed, sample_rate, n_samples = run.seed, run.sample_rate, run.n_samples
    if frame_rate > sample_rate:
        raise ParameterError(f"frame_rate must not exceed the sample rate {sample_rate:g} Hz, "
                             f"got {frame_rate:g} Hz")
    if start is None:
        start = (0.0 if n_on_deck is None
                 else busiest_stretch(n_on_deck, sample_rate, length))
    first = int(round(start * sample_rate))
    if not 0 <= first < n_samples:
        raise ParameterError(f"start must lie within the record [0, {n_samples / sample_rate:g})"
                             f" s, got {start!r}")
    last = min(n_samples, first + int(round(length * sample_rate)))     # exclusive
    every = max(1, int(round(sample_rate / frame_rate)))
    frames = np.arange(first, last, every)
    substeps = integrator.substeps
    # To the first frame in one call (the state there is the record's: chunking changes no
    # bit), then frame by frame; sample i is the state at step i·substeps.
    integrator.advance((run.warm_up_samples + first) * substeps)
    z = np.empty((structure.n_modes, frames.size))
    trace = np.empty((structure.n_outputs, last - first))
    rows: dict[tuple, tuple] = {}
    relative: dict[tuple, dict] = {}
    for k, sample in enumerate(frames):
        z[:, k] = integrator.z
        _seen(integrator, rows, relative if msd is not None else None, k)
        stop = min(sample + every, last)
        _, count = integrator.advance((stop - sample) * substeps)
        trace[:, sample - first:stop - first] = integrator.acceleration[:, :count]
    walkers = _walker_table(rows)
    moving = None
    if msd is not None:
        moving = np.full((len(rows), frames.size), np.nan)
        for i, key in enumerate(sorted(rows)):
            for k, value in relative[key].items():
                moving[i, k] = value
    return Replay(time=frames / sample_rate, modal_displacement=z, **walkers,
                  trace_time=np.arange(first, last) / sample_rate, acceleration=trace,
                  output_names=tuple(structure.output_names), seed=seed, hsi=msd is not None,
                  msd_displacement=moving)


def _seen(integrator, rows, relative, frame):
    """Add the walkers (not the dampers) on the deck now to ``rows`` (their key → their data)
    and, with ``relative``, their MSD's displacement relative to the deck at ``frame``."""
    w, n = integrator.walkers, integrator.n_active
    # Slot s holds walker row active[s]; u is the body's displacement, φ(t)ᵀz the deck's under
    # it (the kernel's state at the current time).
    body = integrator.u[:n] - integrator.phi_now[:n] @ integrator.z
    for slot, row in enumerate(integrator.active[:n]):
        if integrator.damper.size and integrator.damper[row] >= 0:
            continue
        key = (float(w.arrival[row]), float(w.x_start[row]), float(w.lateral[row]))
        rows.setdefault(key, (float(w.velocity[row]), float(w.step_frequency[row]),
                              float(w.t_on[row]), float(w.t_off[row])))
        if relative is not None:
            relative.setdefault(key, {})[frame] = float(body[slot])


def _walker_table(rows):
    """The walkers seen, by arrival time, as :class:`Replay`'s columns."""
    keys = sorted(rows)
    table = np.array([(*key, *rows[key]) for key in keys], dtype=float).reshape(-1, 7)
    names = ("arrival", "x_start", "lateral", "velocity", "step_frequency", "t_on", "t_off")
    return {name: table[:, i].copy() for i, name in enumerate(names)}
