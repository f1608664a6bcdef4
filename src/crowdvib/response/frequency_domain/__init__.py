"""The frequency-domain forward models (docs: theory).

``spectral`` (FRFs, occupied modal properties, the acceleration PSD with HSI of a smeared
crowd), ``fluctuation`` (the expected PSD of a Poisson crowd whose occupancy fluctuates, and
``response_psd``, which makes either model's), ``varying`` (the expected Welch PSD of a record
whose crowd's density changes), ``expected`` (the protocol the three share); their results are
in ``results``, their figures in ``plots``.
"""

from .expected import ExpectedPSDModel
from .fluctuation import FluctuatingSpectralModel, response_psd
from .results import FRF, EffectiveModalProperties
from .spectral import SpectralModel, effective_modal_properties, frf, modal_accelerance
from .varying import VaryingCrowdModel, varying_response_psd

__all__ = ["SpectralModel", "ExpectedPSDModel", "FluctuatingSpectralModel", "response_psd", "frf",
           "effective_modal_properties", "modal_accelerance", "FRF", "EffectiveModalProperties",
           "VaryingCrowdModel", "varying_response_psd"]
