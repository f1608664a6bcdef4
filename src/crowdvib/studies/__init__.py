"""Studies that test an identification's answer, run as independent tasks (:mod:`crowdvib.runner`).

``landscape`` (the objective on a grid: :func:`objective_map`), ``modelling_error`` (the
modelling-error and record-length studies), ``parametric`` (the paper's parametric study) and
``monte_carlo`` (seeded simulated records in batches, their statistics), ``season`` (a monitoring
season's records, each estimated, and one MSD for all); ``plots`` draws them.
"""

from .landscape import ObjectiveMap, objective_map
from .modelling_error import (PAPER_ERROR_LEVELS, ErrorCase, SensitivityResult,
                              modelling_error_study, record_length_study)
from .monte_carlo import monte_carlo, record_statistics
from .parametric import ParametricResult, parametric_study
from .season import SeasonResult, season_study, write_synthetic_season

__all__ = ["objective_map", "ObjectiveMap", "modelling_error_study", "ErrorCase",
           "SensitivityResult", "record_length_study", "parametric_study", "ParametricResult",
           "PAPER_ERROR_LEVELS", "monte_carlo", "record_statistics", "season_study",
           "SeasonResult", "write_synthetic_season"]
