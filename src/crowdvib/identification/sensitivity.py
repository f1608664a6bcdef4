"""Trust in the estimate, in one import: landscape, modelling-error, record-length and parametric
studies (paper Figs. 4–6, 10, 11, 19), and the task runner they share.

The code lives in :mod:`.landscape`, :mod:`.studies`, :mod:`.parametric`, :mod:`.tasks` and
:mod:`.engine`; this module gathers their public names under the name they were first published.
"""

from .engine import study_executor
from .landscape import ObjectiveMap, objective_map
from .parametric import PARAMETRIC_ERROR_LEVELS, ParametricResult, parametric_study
from .studies import (PAPER_ERROR_LEVELS, ErrorCase, SensitivityResult, error_cases,
                      modelling_error_study, record_length_study)
from .tasks import TaskStore, run_tasks

__all__ = ["ObjectiveMap", "objective_map", "ErrorCase", "SensitivityResult", "error_cases",
           "modelling_error_study", "parametric_study", "ParametricResult", "TaskStore",
           "run_tasks", "study_executor", "record_length_study", "PAPER_ERROR_LEVELS",
           "PARAMETRIC_ERROR_LEVELS"]
