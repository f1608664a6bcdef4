"""crowdvib: crowd-induced vertical footbridge vibrations with human–structure interaction.

Models (ModalModel, Crowd, MSDModel, walking forces), forward models (spectral
``response_psd``; time-domain ``simulate``), measured-data processing (``welch_psd``) and the
inverse problem of Van Nimmen & Van den Broeck (2023): ``estimate_hsi``.
"""

from importlib.metadata import PackageNotFoundError, version

from .crowd import Crowd
from .estimation import estimate_hsi
from .errors import (BoundWarning, ConvergenceWarning, CrowdvibError, CrowdvibWarning, DataError,
                     EstimationError, ParameterError, ResolutionWarning)
from .loading import YoungForce, ZivanovicForce
from .pedestrian import MSDModel
from .results import FRF, EffectiveModalProperties, HSIEstimate, ResponsePSD
from .signals import LowPassFilter, welch_psd
from .spectral import SpectralModel, effective_modal_properties, frf, response_psd
from .structure import ModalModel

try:
    __version__ = version("crowdvib")
except PackageNotFoundError:  # running from a source tree that was not installed
    __version__ = "0+unknown"

__all__ = [
    "ModalModel", "Crowd", "MSDModel", "ZivanovicForce", "YoungForce",
    "response_psd", "frf", "effective_modal_properties", "SpectralModel",
    "estimate_hsi", "welch_psd", "LowPassFilter",
    "ResponsePSD", "FRF", "EffectiveModalProperties", "HSIEstimate",
    "CrowdvibError", "ParameterError", "DataError", "EstimationError",
    "CrowdvibWarning", "BoundWarning", "ConvergenceWarning", "ResolutionWarning",
    "__version__",
]
