"""``crowdvib simulate``'s work on a case: a time-domain record of its crowd crossing its
structure, with or without HSI (docs: :ref:`theory-crowd`, :ref:`theory-msd`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from .._version import __version__
from .results import SIMULATION_TABLES, AsResults, software_versions
from .schema import schema_header
from ..models.pedestrian import MSDModel
from ..io.records import Record
from ..response.time_domain.simulation import simulate
from ..signals import resample

if TYPE_CHECKING:
    from collections.abc import Callable

    from ..io.casefile import Case
    from ..io.records import Record
    from ..models.pedestrian import MSDModel
    from ..response.time_domain.results import Simulation


__all__ = ["CaseSimulation", "simulation_msd", "simulate_case"]


@dataclass(frozen=True)
class CaseSimulation(AsResults):
    """What ``crowdvib simulate`` computes for a case (:func:`simulate_case`).

    Attributes
    ----------
    case : Case
    simulation : Simulation
        The simulated response at the structure's outputs.
    record : Record
        Its accelerations as a record (resampled to ``simulation.record_sample_rate`` if set).
    msd : MSDModel or None
        The pedestrians' MSD (None: moving forces only).
    duration, sample_rate : float
        The simulated length [s] and the simulation's sample rate [Hz].
    """

    case: Case
    simulation: Simulation
    record: Record
    msd: MSDModel | None
    duration: float
    sample_rate: float

    def to_dict(self) -> dict:
        """The results ``crowdvib simulate`` writes to results.json, without the record files,
        the run time, figures and provenance."""
        case, msd = self.case, self.msd
        return {**schema_header("simulate"), "command": "simulate",
                "crowdvib_version": __version__,
                "versions": software_versions(), "seed": int(self.simulation.seed),
                "case": None if case.path is None else str(case.path),
                "inputs": case.inputs(SIMULATION_TABLES),
                "msd": None if msd is None else msd.to_dict(),
                "duration": self.duration, "sample_rate": self.sample_rate,
                "record": self.record.metadata(),
                "response": self.simulation.summary(window=1.0)}


def simulation_msd(case):
    """The MSD a case simulates with: its ``[expected]`` truth if given, else its ``[hsi]``.

    Parameters
    ----------
    case : Case
        The case; its ``[expected]`` MSD wins when it gives f_h1 and ξ_h1.

    Returns
    -------
    MSDModel
    """

    expected = case.expected
    if "frequency" in expected and "damping_ratio" in expected:
        return MSDModel(expected["frequency"], expected["damping_ratio"],
                        expected.get("mass_ratio", case.msd.mass_ratio))
    return case.msd


def simulate_case(case: Case, *, duration: float | None = None,
                  sample_rate: float | None = None, seed: int | None = None,
                  hsi: bool | None = None,
                  progress: Callable[[float, float], None] | None = None) -> CaseSimulation:
    """Simulate a case's ``[simulation]``, without writing anything.

    Parameters
    ----------
    case : Case
    duration : float, optional
        Record length [s] (default ``simulation.duration``).
    sample_rate : float, optional
        Simulation sample rate [Hz] (default ``simulation.sample_rate``).
    seed : int, optional
        Seed of every random draw (default the case's seed).
    hsi : bool, optional
        Pedestrians as MSDs (:func:`simulation_msd`) or as moving forces only (default
        ``simulation.hsi``).
    progress : callable, optional
        ``progress(done, total)`` [s of simulated time, warm-up included].

    Returns
    -------
    CaseSimulation
    """

    spec = case.simulation
    duration = spec.duration if duration is None else duration
    sample_rate = spec.sample_rate if sample_rate is None else sample_rate
    seed = case.seed if seed is None else seed
    msd = simulation_msd(case) if (spec.hsi if hsi is None else hsi) else None
    simulation = simulate(case.structure, case.crowd, duration, msd=msd, force=case.force,
                          sample_rate=sample_rate, rng=seed, warm_up=spec.warm_up,
                          progress=progress)
    data, rate = simulation.acceleration, sample_rate
    if spec.record_sample_rate is not None:
        data, rate = resample(data, rate, spec.record_sample_rate)
    record = Record(data=data, sample_rate=rate, channel_names=simulation.output_names)
    return CaseSimulation(case, simulation, record, msd, duration, sample_rate)
