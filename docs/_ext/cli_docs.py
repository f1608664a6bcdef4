"""The crowdvib argument parser as the CLI page shows it.

sphinx-argparse prints each default inside an inline literal; a numpy array default (the grids of
``crowdvib map``) prints over several lines and breaks it. Such defaults are shown here in the
command line's own ``start:stop:count`` syntax instead, and ``--workers`` defaults to "the
physical cores" rather than the count of the machine that built the docs.
"""

import argparse

import numpy as np

from crowdvib.cli import build_parser as _build_parser


def _readable_defaults(parser):
    for action in parser._actions:
        if action.dest == "workers":
            # The default is counted at run time; the build machine's count means nothing here.
            action.default = "the physical cores"
        if isinstance(action.default, np.ndarray) and action.default.ndim == 1:
            grid = action.default
            action.default = f"{grid[0]:g}:{grid[-1]:g}:{grid.size}"
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                _readable_defaults(sub)
    return parser


def build_parser():
    """``crowdvib.cli.build_parser()`` with array defaults written as ``start:stop:count``."""
    return _readable_defaults(_build_parser())
