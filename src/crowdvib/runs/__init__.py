"""The commands as calls: a case's work written as a results folder (issue 26 §1).

:mod:`crowdvib.cases` computes what a case file describes and returns objects; a run here also
draws their figures and writes the folder a command writes (results.json, figures, report.html,
its manifest), under the rules every command shares (:mod:`crowdvib.runs.folders`). Each
command of the command line is one call here, and prints nothing of its own but the verdict:

- :func:`run_estimate` (``crowdvib estimate``), :func:`run_map` (``crowdvib map``);
- :func:`run_check` (``crowdvib check``), :func:`run_simulate` (``crowdvib simulate``);
- :func:`run_demo` (``crowdvib demo``), :func:`run_sensitivity` (``crowdvib sensitivity``);
- :func:`run_modes` (``crowdvib modes``), :func:`run_season` (``crowdvib season``);
- :func:`run_comfort` (``crowdvib comfort``).

Each takes a ``say`` callable for the lines the command prints (default: none; pass ``print``
to see them) and returns the :class:`~crowdvib.cases.Results` it wrote, the object
:func:`~crowdvib.cases.load_results` reads back; ``results.verdict()`` is the verdict the
command prints.

The names load with their module on first use: the command line imports the folder rules at
start-up and the rest only when a command runs.
"""

import importlib

#: Public name → the module of this package that defines it.
_MODULES = {
    **dict.fromkeys(("case_inputs", "check_clash", "check_output", "prepare_output",
                     "finish_output", "staged_output", "write_results"), "folders"),
    **dict.fromkeys(("run_estimate", "run_map"), "estimate"),
    "run_check": "check", "run_simulate": "simulate", "run_demo": "demo",
    "run_sensitivity": "sensitivity", "run_modes": "modes",
    **dict.fromkeys(("run_season", "SEASON_STORES"), "season"),
    **dict.fromkeys(("run_comfort", "COMFORT_FIGURES"), "comfort"),
}

__all__ = list(_MODULES)


def __getattr__(name):
    if name not in _MODULES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f".{_MODULES[name]}", __name__), name)


def __dir__():
    return sorted(__all__)
