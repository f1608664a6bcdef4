"""crowdvib: crowd-induced vertical footbridge vibrations with human–structure interaction.

Models (ModalModel, Crowd, MSDModel, walking forces), forward models (spectral
``response_psd``; time-domain ``simulate``), measured-data processing (``welch_psd``) and the
inverse problem of Van Nimmen & Van den Broeck (2023): ``estimate_hsi``.
"""

from importlib.metadata import PackageNotFoundError, version

from .errors import (BoundWarning, ConvergenceWarning, CrowdvibError, CrowdvibWarning, DataError,
                     DataWarning, EstimationError, ParameterError, PlausibilityWarning,
                     ResolutionWarning)
from .identification import (HSIEstimate, StepFrequencyEstimate, estimate_hsi,
                             estimate_step_frequencies)
from .io import Case, Record, check_record, load_case, read_modal_model, read_record, write_record
from .models import Crowd, ModalModel, MSDModel, YoungForce, ZivanovicForce
from .response import (FRF, EffectiveModalProperties, Pedestrian, Simulation, SpectralModel,
                       effective_modal_properties, frf, response_psd, simulate)
from .signals import (LowPassFilter, PSDConvergence, ResponsePSD, detrend, psd_convergence,
                      resample, welch_psd)

try:
    __version__ = version("crowdvib")
except PackageNotFoundError:  # running from a source tree that was not installed
    __version__ = "0+unknown"

__all__ = [
    "ModalModel", "Crowd", "MSDModel", "ZivanovicForce", "YoungForce",
    "response_psd", "frf", "effective_modal_properties", "SpectralModel",
    "estimate_hsi", "welch_psd", "LowPassFilter", "simulate", "Pedestrian",
    "ResponsePSD", "FRF", "EffectiveModalProperties", "HSIEstimate", "Simulation",
    "CrowdvibError", "ParameterError", "DataError", "EstimationError",
    "CrowdvibWarning", "BoundWarning", "ConvergenceWarning", "ResolutionWarning",
    "DataWarning", "PlausibilityWarning", "Record", "read_record", "write_record", "check_record", "Case",
    "load_case", "read_modal_model", "estimate_step_frequencies", "StepFrequencyEstimate",
    "psd_convergence", "PSDConvergence", "detrend", "resample",
    "__version__",
]
