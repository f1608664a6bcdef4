"""What a case file describes, run from Python (issue 26 §1).

Each command of the command line is a call here that returns the objects it computes; the
command only prints them and writes them (results.json, figures, report). A Python user holding
a :class:`~crowdvib.io.casefile.Case` thus gets what the command gets:

- :func:`estimate_case` (``crowdvib estimate``), from :func:`measure_case`, :func:`case_crowd`
  and :func:`case_estimator` (the case's estimator, one
  :class:`~crowdvib.identification.Estimator` every command fits with);
- :func:`map_case` (``crowdvib map``);
- :func:`check_case` (``crowdvib check``);
- :func:`simulate_case` (``crowdvib simulate``);
- :func:`study_case` (``crowdvib sensitivity``), :func:`demo_case` (``crowdvib demo``);
- :func:`identify_ambient` (``crowdvib modes``, on an ambient-test file);
- :func:`season_case` (``crowdvib season``), from :func:`plan_season`;
- :func:`comfort_case` (``crowdvib comfort``).

Each returns an object whose ``to_dict()`` is the command's results.json and whose
``results()`` is that as a :class:`Results`, the object :func:`load_results` reads back from the
file (docs: :doc:`/results`); ``verdict()`` gives the findings the command prints.

:mod:`crowdvib.runs` adds to each its figures and report, written as the command's results
folder (the layer above reporting: results folders need the report).

The names load with their module on first use: the command line imports
:mod:`crowdvib.cases.results` at start-up and the rest only when a command runs.
"""

import importlib

from .results import (DESIGN_TABLES, ESTIMATION_TABLES, SIMULATION_TABLES, CheckResults,
                      DemoResults, EstimateResults, MapResults, ModesResults, Results,
                      SeasonResults, SensitivityResults, SimulateResults, ComfortResults,
                      load_results,
                      results_of, software_versions)
from .schema import KINDS, SCHEMA

#: Public name → the module of this package that defines it.
_MODULES = {
    **dict.fromkeys(("CaseMeasurement", "CaseRecordFit", "CaseEstimate", "CaseMap",
                     "measure_case", "case_crowd", "case_estimator", "estimate_case",
                     "map_case"), "estimate"),
    **dict.fromkeys(("CaseCheck", "check_case", "check_design_table", "design_msd",
                     "verdict_rows", "IntervalCheck", "estimated_msd", "msd_interval", "msd_box",
                     "check_over_interval", "damper_frf"), "design"),
    **dict.fromkeys(("CaseSimulation", "simulation_msd", "simulate_case"), "simulation"),
    **dict.fromkeys(("AmbientModes", "identify_ambient"), "ambient"),
    **dict.fromkeys(("CaseStudy", "study_case", "identified_levels", "STUDY_STORES"), "study"),
    **dict.fromkeys(("CaseDemo", "demo_case"), "demo"),
    **dict.fromkeys(("CaseSeason", "SeasonPlan", "plan_season", "season_case",
                     "season_records"), "season"),
    **dict.fromkeys(("CaseComfort", "comfort_case", "case_traffic", "comfort_dampers",
                     "COMFORT_TABLES"), "comfort"),
    "Finding": "verdict",
}

__all__ = ["DESIGN_TABLES", "ESTIMATION_TABLES", "SIMULATION_TABLES", "software_versions",
           "Results", "EstimateResults", "SensitivityResults", "CheckResults", "ModesResults",
           "SimulateResults", "MapResults", "DemoResults", "SeasonResults", "ComfortResults",
           "load_results",
           "results_of", "SCHEMA", "KINDS", *_MODULES]


def __getattr__(name):
    if name not in _MODULES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f".{_MODULES[name]}", __name__), name)


def __dir__():
    return sorted(__all__)
