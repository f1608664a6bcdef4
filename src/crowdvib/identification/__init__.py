"""The inverse problem and the trust in its answer.

``estimation`` (f_h1, ξ_h1 from a measured PSD: paper Eq. 5 and 6) and ``step_frequencies`` (the
crowd's N(μ, σ) from the low band); ``sensitivity`` (objective landscape and modelling-error
studies), run as independent tasks by ``tasks`` on any executor.
"""

from .estimation import DEFAULT_BOUNDS, DEFAULT_STARTS, HSIEstimate, estimate_hsi
from .objective import PSDObjective
from .sensitivity import (PAPER_ERROR_LEVELS, ErrorCase, ObjectiveMap, SensitivityResult,
                          modelling_error_study, objective_map, parametric_study,
                          record_length_study)
from .step_frequencies import (DEFAULT_STEP_FREQUENCY_BOUNDS, StepFrequencyEstimate,
                               estimate_step_frequencies)
from .tasks import TaskStore, run_tasks

__all__ = ["estimate_hsi", "HSIEstimate", "PSDObjective", "DEFAULT_STARTS", "DEFAULT_BOUNDS",
           "estimate_step_frequencies", "StepFrequencyEstimate", "DEFAULT_STEP_FREQUENCY_BOUNDS",
           "objective_map", "ObjectiveMap", "modelling_error_study", "ErrorCase",
           "SensitivityResult", "record_length_study", "parametric_study", "PAPER_ERROR_LEVELS",
           "TaskStore", "run_tasks"]
