"""One run of the time-domain simulator, checked: the frozen :class:`Run` that :func:`.simulate`,
:func:`.simulate_psd` and the crossing replay hand on to the integrator, instead of fifteen
values one after the other (issue 34 §4).

Every input is checked here, once, in the order the errors have always come in (the seed, the
options of the run, the crowd and its profile, the structure, the force, the duration and the
sample rate), and the run's records and walkers are sized against the memory available before
anything is allocated.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from ..._resources import MEMORY_SHARE as _MEMORY_SHARE, available_memory
from ..._validation import check_positive, check_type
from ...errors import ParameterError
from ...models.crowd import JAM_DENSITY, Crowd
from ...models.damper import as_dampers
from ...models.loading import as_force_model
from ...models.pedestrian import MSDModel
from ...models.profile import CrowdProfile
from .traffic import STREAM_BLOCK, Pedestrian, _check_structure, _seed_from, check_duration

if TYPE_CHECKING:
    from ...models.damper import TunedMassDamper
    from ...models.structure import ModalModel

#: Default simulated seconds per kernel call (progress granularity; results do not depend on it).
DEFAULT_CHUNK_DURATION = 60.0
#: Bytes a walker costs while its block is drawn: its per-component DLF, ratio and phase rows
#: and some twenty scalars, in float64, about three times over for the temporaries of the draws.
_BYTES_PER_WALKER = 3 * 8 * 20
#: Bytes every walker of the record costs for the whole run: its arrival time (twice), time
#: off the deck and rank in the stream (``traffic._Stream``).
_STREAM_BYTES_PER_WALKER = 4 * 8


@dataclasses.dataclass(frozen=True)
class Run:
    """What one simulated record is made of, checked (:meth:`checked`): the integrator is built
    from it (``_integrator.prepare``) and the results read their metadata from it.

    ``crowd`` is the stream's crowd: with a varying ``profile`` at its peak density (what the
    checks of memory and jam density see), with a constant profile that crowd at its density
    (``profile`` then None: the record is bit-identical to that crowd's). ``force`` is the
    time-domain force model (the default one when none was given); ``duration``,
    ``warm_up`` [s] and ``sample_rate`` [Hz] as floats, with the recorded and warm-up samples
    they give; ``keep_record`` False for :func:`.simulate_psd`, which keeps no samples.
    """

    structure: ModalModel
    crowd: Crowd | None
    profile: CrowdProfile | None
    pedestrians: tuple[Pedestrian, ...]
    msd: MSDModel | None
    force: Any
    dampers: tuple[TunedMassDamper, ...]
    duration: float
    warm_up: float
    sample_rate: float
    n_samples: int
    warm_up_samples: int
    seed: int
    progress: Callable[[float, float], None] | None
    chunk_duration: float
    include_static_weight: bool
    record_modal_load: bool
    keep_record: bool

    @classmethod
    def checked(cls, structure, crowd, duration, *, pedestrians, msd, force, sample_rate, rng,
                progress, include_static_weight, chunk_duration, record_modal_load, warm_up,
                dampers, records=1, keep_record=True) -> Run:
        """The run of :func:`.simulate`'s arguments of the same names, each checked (a
        ParameterError naming it otherwise), its memory for ``records`` kept runs too
        (:func:`crowdvib.simulate_many`'s seeds). ``rng`` becomes the run's integer seed."""
        seed = _seed_from(rng)
        if progress is not None and not callable(progress):
            raise ParameterError(
                f"progress must be callable or None, got {type(progress).__name__}")
        chunk_duration = (DEFAULT_CHUNK_DURATION if chunk_duration is None
                          else check_positive("chunk_duration", chunk_duration, unit="s"))
        dampers = as_dampers(dampers)
        crowd, profile = _with_profile(crowd)
        _check_walkers(structure, crowd, pedestrians, msd)
        force = as_force_model(force, time_domain=True)
        duration, warm_up = check_duration(duration, warm_up)
        sample_rate = _check_sample_rate(structure, sample_rate)
        n_samples = int(round(duration * sample_rate))
        if n_samples < 1:
            raise ParameterError(
                f"duration × sample_rate must give at least one sample, got {duration:g} s × "
                f"{sample_rate:g} Hz")
        run = cls(structure=structure, crowd=crowd, profile=profile,
                  pedestrians=tuple(pedestrians) if pedestrians is not None else (),
                  msd=msd, force=force, dampers=dampers, duration=duration, warm_up=warm_up,
                  sample_rate=sample_rate, n_samples=n_samples,
                  warm_up_samples=int(math.ceil(warm_up * sample_rate - 1e-9)), seed=seed,
                  progress=progress, chunk_duration=chunk_duration,
                  include_static_weight=include_static_weight,
                  record_modal_load=record_modal_load, keep_record=keep_record)
        _check_memory(run, records)
        return run


def _with_profile(crowd):
    """The crowd and profile a run uses (:class:`Run`'s ``crowd`` and ``profile``): a crowd
    whose density is a profile runs as its walkers at the profile's peak (the stream's largest
    rate, which sizes the memory check) with the profile drawing the stream; a constant profile
    is the stationary crowd of its density, bit for bit."""
    if not isinstance(crowd, Crowd) or crowd.profile is None:
        return crowd, None
    profile = crowd.profile
    return crowd.with_density(profile.peak), (None if profile.is_constant else profile)


def _check_walkers(structure, crowd, pedestrians, msd):
    """The structure, the crowd (below the jam density), the pedestrians (one of the two at
    least) and the MSD of a run, or a ParameterError."""
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


def _check_sample_rate(structure, sample_rate):
    """``sample_rate`` [Hz] as a float whose Nyquist frequency lies above the highest mode."""
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    highest = float(np.max(structure.frequencies))
    if sample_rate / 2 <= highest:
        raise ParameterError(
            f"sample_rate must put the Nyquist frequency (sample_rate/2) above the highest "
            f"structural mode {highest:g} Hz, got {sample_rate:g} Hz "
            f"(Nyquist {sample_rate / 2:g} Hz)")
    return sample_rate


def _check_memory(run, records=1):
    """Refuse a run whose records and walkers will not fit, before anything is allocated.

    A duration of 1e9 s once took 13 GB over two minutes before numpy gave up (issue 24): the
    sizes are known from the inputs, so the answer can come at once, naming the parameter.
    ``records``: runs whose results are all kept (:func:`crowdvib.simulate_many`'s seeds).
    """
    structure, crowd = run.structure, run.crowd
    n_samples = run.n_samples + run.warm_up_samples
    # The outputs, the modal loads and a row for n_on_deck (a quarter of one, counted whole).
    rows = (structure.n_outputs + (structure.n_modes if run.record_modal_load else 0) + 1
            if run.keep_record else 0)
    walkers = 0.0
    if crowd is not None and crowd.density > 0:
        walkers = (crowd.arrival_rate(structure.width) * (run.duration + run.warm_up)
                   + crowd.density * structure.area)
    components = np.size(run.force.ratios)
    drawn = min(walkers, 3 * STREAM_BLOCK)          # the blocks held at once
    need = records * (8.0 * rows * n_samples + walkers * _STREAM_BYTES_PER_WALKER
                      + drawn * _BYTES_PER_WALKER * (1 + components / 10))
    have = available_memory()
    if need > _MEMORY_SHARE * have:
        batch = "" if records == 1 else f" for {records} seeds"
        raise ParameterError(
            f"duration = {run.duration:g} s at sample_rate = {run.sample_rate:g} Hz{batch} needs "
            f"about {need / 1e9:.3g} GB ({n_samples:.3g} samples × {rows} rows, {walkers:.3g} "
            f"walkers per record), more than half the {have / 1e9:.3g} GB of memory available: "
            "simulate shorter records" + (" (simulate_many runs several)" if records == 1
                                          else " or fewer seeds at a time"))
