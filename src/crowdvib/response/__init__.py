"""The forward models: what the bridge does under its crowd, in two families that never import
each other.

:mod:`~crowdvib.response.frequency_domain` (the spectral models: FRFs, occupied modal
properties, the expected acceleration PSD of a smeared, fluctuating or varying crowd) and
:mod:`~crowdvib.response.time_domain` (the Monte Carlo simulator with moving pedestrians, which
checks the spectral models and makes realistic records). Their public names are re-exported
here.
"""

from .frequency_domain import (FRF, EffectiveModalProperties, ExpectedPSDModel,
                               FluctuatingSpectralModel, SpectralModel, VaryingCrowdModel,
                               effective_modal_properties, frf, modal_accelerance, response_psd,
                               varying_response_psd)
from .time_domain import (Pedestrian, Simulation, SimulationPSD, generate_traffic, simulate,
                          simulate_many, simulate_psd)

__all__ = ["SpectralModel", "ExpectedPSDModel", "FluctuatingSpectralModel", "response_psd", "frf",
           "effective_modal_properties", "modal_accelerance", "simulate", "simulate_many",
           "Pedestrian", "generate_traffic", "FRF", "EffectiveModalProperties", "Simulation",
           "simulate_psd", "SimulationPSD", "VaryingCrowdModel", "varying_response_psd"]
