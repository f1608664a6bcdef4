"""Time-domain Monte Carlo simulation of a crowd walking over a footbridge (docs: theory, The coupled time-domain model).

Each pedestrian is a moving force on a rigid floor plus, with HSI, a moving mass-spring-damper
(MSD) whose unsprung mass rides on the deck (paper Eq. 1–4; docs: theory, Equations of motion and State-space form). The crowd is a
stationary Poisson stream with the deck already populated at the start (docs: theory, Poisson
arrivals). A run's inputs are checked into one ``_run.Run``; its integrator (``_integrator``)
steps it with the compiled kernel of :mod:`crowdvib.response._kernels` (fixed-step RK4 over
the pedestrians on the deck).

Public: :func:`simulate` (the record); :func:`~crowdvib.response.simulation_psd.simulate_psd`
keeps its Welch PSD and summaries instead, in memory that does not grow with the duration; the
walkers come from :mod:`.traffic`.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _kernels
from ._integrator import kernel_for, prepare
from ._run import Run
from .results import Simulation
from .traffic import Pedestrian

if TYPE_CHECKING:
    from ..._validation import ForceModel, Seed
    from ...models.crowd import Crowd
    from ...models.damper import TunedMassDamper
    from ...models.pedestrian import MSDModel
    from ...models.structure import ModalModel

__all__ = ["simulate"]


def kernel_needs_compiling(structure, hsi):
    """Whether the first run of this kind compiles its kernel (for a while): nothing compiled in
    this process and no numba cache index beside ``_kernels.py`` (``cache=True``) for it."""
    kernel = kernel_for(structure, hsi)
    cache = Path(_kernels.__file__).parent / "__pycache__"
    return not kernel.signatures and not list(cache.glob(f"_kernels.{kernel.__name__}-*.nbi"))



def _start(run):
    """The integrator of ``run`` and its chunks to run (see :func:`_chunks`)."""
    integrator = prepare(run)
    total_steps = (run.warm_up_samples + run.n_samples) * integrator.substeps
    chunk_steps = max(1, int(round(run.chunk_duration * run.sample_rate))) * integrator.substeps
    return integrator, _chunks(integrator, total_steps, chunk_steps, run.progress)


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
             dampers: Sequence[TunedMassDamper] | None = None) -> Simulation:
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
        and phases from ``force``. A crowd whose density is a
        :class:`~crowdvib.models.CrowdProfile` (t = 0 the first recorded sample) enters as a
        non-homogeneous Poisson stream of rate d(t)·B·v, the deck holding at the start whoever
        entered during the crossing before (docs: theory, A crowd that changes). Only the
        stream changes: the same seed gives the same record, and a constant profile the record
        of ``crowd.with_density(d)``.
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
    run = Run.checked(structure, crowd, duration, pedestrians=pedestrians, msd=msd, force=force,
                      sample_rate=sample_rate, rng=rng, progress=progress,
                      include_static_weight=include_static_weight,
                      chunk_duration=chunk_duration, record_modal_load=record_modal_load,
                      warm_up=warm_up, dampers=dampers)
    integrator, chunks = _start(run)
    sample_rate, n_samples = run.sample_rate, run.n_samples
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
        seed=run.seed,
        duration=n_samples / sample_rate,
        modal_load=modal_load,
        time_step=integrator.h,
        n_pedestrians=integrator.stream.size - integrator.n_dampers,
        hsi=msd is not None,
        warm_up=run.warm_up_samples / sample_rate,
    )


#: simulate's options and their defaults (what :func:`checked_run` fills in).
_OPTIONS = {name: parameter.default
            for name, parameter in inspect.signature(simulate).parameters.items()
            if parameter.kind is inspect.Parameter.KEYWORD_ONLY}


def checked_run(structure: ModalModel, crowd: Crowd | None = None,
                duration: float | None = None, *, records: int = 1, **options: Any) -> Run:
    """The checked run ``simulate(structure, crowd, duration, **options)`` makes, its memory
    for ``records`` kept runs (:func:`crowdvib.simulate_many`'s seeds); :func:`simulate`'s
    defaults for the options not given. The integrator is built from it by
    ``_integrator.prepare``."""
    return Run.checked(structure, crowd, duration, records=records, **{**_OPTIONS, **options})
