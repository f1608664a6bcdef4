"""The inverse problem and the trust in its answer.

``estimation`` (f_h1, ξ_h1 from a measured PSD: paper Eq. 5 and 6) and ``step_frequencies`` (the
crowd's N(μ, σ) from the low band); ``landscape`` (the objective on a grid), ``studies``
(modelling-error and record-length studies), ``parametric`` (the paper's parametric study)
and ``monte_carlo`` (seeded simulated records in batches),
run as independent tasks by ``tasks`` on the executor ``engine`` gives (this process or dask);
``oma``: the empty bridge's modes from an ambient record (SSI-cov through pyOMA2, ``efdd``;
``modeid`` the result and the cross-check of two methods, ``multisetup`` several setups merged).
"""

from .engine import study_executor
from .estimation import (DEFAULT_BOUNDS, DEFAULT_STARTS, HSIEstimate, estimate_hsi,
                         estimate_hsi_joint)
from .landscape import ObjectiveMap, objective_map
from .monte_carlo import monte_carlo, record_statistics
from .objective import PSDObjective
from .modeid import ModeCrossCheck
from .oma import ModeIdentification, ambient_response, identify_modes
from .parametric import ParametricResult, parametric_study
from .step_frequencies import (DEFAULT_STEP_FREQUENCY_BOUNDS, StepFrequencyEstimate,
                               estimate_step_frequencies)
from .studies import (PAPER_ERROR_LEVELS, ErrorCase, SensitivityResult, modelling_error_study,
                      record_length_study)
from .tasks import TaskStore, run_tasks

__all__ = ["estimate_hsi", "estimate_hsi_joint", "HSIEstimate", "PSDObjective", "DEFAULT_STARTS",
           "DEFAULT_BOUNDS",
           "estimate_step_frequencies", "StepFrequencyEstimate", "DEFAULT_STEP_FREQUENCY_BOUNDS",
           "objective_map", "ObjectiveMap", "modelling_error_study", "ErrorCase",
           "SensitivityResult", "record_length_study", "parametric_study", "ParametricResult",
           "PAPER_ERROR_LEVELS", "TaskStore", "run_tasks", "study_executor", "monte_carlo",
           "record_statistics", "identify_modes", "ModeIdentification", "ModeCrossCheck",
           "ambient_response"]
