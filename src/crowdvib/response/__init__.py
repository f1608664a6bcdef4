"""The forward models: what the bridge does under its crowd.

``spectral`` (frequency domain: FRFs, occupied modal properties, the acceleration PSD with HSI),
``fluctuation`` (the expected PSD of a Poisson crowd whose occupancy fluctuates, and
``response_psd``, which makes either model's),
``varying`` (the expected Welch PSD of a record whose crowd's density changes),
``simulation`` (time-domain Monte Carlo with moving pedestrians: a run checked into ``_run``,
stepped by ``_integrator`` with the compiled kernel of ``_kernels``) and ``simulation_psd``
(the Welch PSD of a record too long to keep); their results are in ``results``.
"""

from .batch import simulate_many
from .fluctuation import FluctuatingSpectralModel, response_psd
from .results import FRF, EffectiveModalProperties, Simulation, SimulationPSD
from .simulation import simulate
from .simulation_psd import simulate_psd
from .expected import ExpectedPSDModel
from .spectral import SpectralModel, effective_modal_properties, frf, modal_accelerance
from .traffic import Pedestrian, generate_traffic
from .varying import VaryingCrowdModel, varying_response_psd

__all__ = ["SpectralModel", "ExpectedPSDModel", "FluctuatingSpectralModel", "response_psd", "frf",
           "effective_modal_properties", "modal_accelerance", "simulate", "simulate_many",
           "Pedestrian", "generate_traffic", "FRF", "EffectiveModalProperties", "Simulation",
           "simulate_psd", "SimulationPSD", "VaryingCrowdModel", "varying_response_psd"]
