"""crowdvib: crowd-induced vertical footbridge vibrations with human–structure interaction.

Models (ModalModel, Crowd, MSDModel, walking forces), forward models (spectral
``response_psd``; time-domain ``simulate``), measured-data processing (``welch_psd``) and the
inverse problem of Van Nimmen & Van den Broeck (2023): ``estimate_hsi``.
"""

import importlib
from typing import TYPE_CHECKING

from ._version import __version__

from .errors import (BoundWarning, ConvergenceWarning, CrowdvibError, CrowdvibWarning, DataError,
                     DataWarning, EstimationError, IdentifiabilityWarning, ParameterError,
                     PlausibilityWarning, ResolutionWarning, UnverifiedWarning)

#: Public name → the subpackage that defines it. The subpackages (and scipy and numba behind them)
#: are imported on first use, so that ``crowdvib --help`` and an error message come at once.
_LAZY = {
    **dict.fromkeys(("ModalModel", "Crowd", "MSDModel", "ZivanovicForce", "YoungForce",
                     "MeasuredForce", "ForceModel", "WalkingForce"), "models"),
    **dict.fromkeys(("ResponsePSD", "welch_psd", "LowPassFilter", "psd_convergence",
                     "PSDConvergence", "detrend", "resample", "running_rms", "weight_wb"),
                    "signals"),
    **dict.fromkeys(("response_psd", "frf", "effective_modal_properties", "SpectralModel",
                     "simulate", "simulate_many", "Pedestrian", "FRF", "EffectiveModalProperties", "Simulation",
                     "simulate_psd", "SimulationPSD"),
                    "response"),
    **dict.fromkeys(("estimate_hsi", "estimate_hsi_joint", "HSIEstimate",
                     "estimate_step_frequencies", "StepFrequencyEstimate"), "identification"),
    **dict.fromkeys(("identify_modes", "ModeIdentification"), "oma"),
    **dict.fromkeys(("Record", "read_record", "write_record", "check_record", "Case", "load_case",
                     "read_modal_model"), "io"),
    **dict.fromkeys(("TunedMassDamper", "tune_damper", "design_check", "DesignCheck",
                     "predict_response", "ResponsePrediction"), "design"),
    # What a case file describes, run from Python as the commands run it.
    **dict.fromkeys(("estimate_case", "map_case", "check_case", "simulate_case",
                     "load_results", "Results"), "cases"),
    "modal_accelerance": "response",
    "FluctuatingSpectralModel": "response",
    "CrowdProfile": "models",
    "VaryingCrowdModel": "response",
    "varying_response_psd": "response",
}

__all__ = [
    *_LAZY,
    "CrowdvibError", "ParameterError", "DataError", "EstimationError",
    "CrowdvibWarning", "BoundWarning", "ConvergenceWarning", "ResolutionWarning",
    "DataWarning", "PlausibilityWarning", "IdentifiabilityWarning", "UnverifiedWarning",
    "__version__",
]


def __getattr__(name):
    if name not in _LAZY:
        raise AttributeError(f"module 'crowdvib' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    globals()[name] = value              # later look-ups skip this function
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))


if TYPE_CHECKING:  # the same names, eagerly, for type checkers and IDEs
    # ruff: noqa: F401
    from .identification import (HSIEstimate, StepFrequencyEstimate, estimate_hsi,
                                 estimate_hsi_joint, estimate_step_frequencies)
    from .oma import ModeIdentification, identify_modes
    from .io import (Case, Record, check_record, load_case, read_modal_model, read_record,
                     write_record)
    from .models import (Crowd, ForceModel, MeasuredForce, ModalModel, MSDModel, WalkingForce,
                         YoungForce, ZivanovicForce)
    from .cases import (Results, check_case, estimate_case, load_results, map_case,
                        simulate_case)
    from .response import (FRF, EffectiveModalProperties, Pedestrian, Simulation, SpectralModel,
                           effective_modal_properties, frf, response_psd, simulate,
                           simulate_many, simulate_psd, SimulationPSD)
    from .design import (DesignCheck, ResponsePrediction, TunedMassDamper, design_check,
                         predict_response, tune_damper)
    from .response import FluctuatingSpectralModel, modal_accelerance
    from .models import CrowdProfile
    from .response import VaryingCrowdModel, varying_response_psd
    from .signals import (LowPassFilter, PSDConvergence, ResponsePSD, detrend, psd_convergence,
                          resample, running_rms, weight_wb, welch_psd)
