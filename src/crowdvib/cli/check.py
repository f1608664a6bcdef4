"""``crowdvib check``: the design checks of a case's ``[design]`` table, without and with HSI.

For every code of ``design.codes`` the case's structure is checked with
:func:`crowdvib.design.design_check` (no HSI, added mass, and HSI with the case's MSD, or the MSD
another run estimated: ``--msd-from``), optionally with a tuned mass damper, and the case's crowd
stream is predicted with :func:`crowdvib.design.predict_response`. The results directory holds
``results.json`` (every check in full and a verdict table), the figures and ``report.html``.
The work is :func:`crowdvib.runs.run_check`; this command parses its arguments and prints.
"""

import argparse
from pathlib import Path

from .common import add_output_arguments, say, say_verdict, say_warnings

__all__ = ["add_arguments", "run"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", type=Path, help="case file (TOML) with a [design] table")
    add_output_arguments(parser)
    parser.add_argument("--msd-from", type=Path, default=None, metavar="RESULTS",
                        help="results directory of `crowdvib estimate` (or demo, sensitivity): "
                             "its estimated MSD replaces the case's for the HSI model")


def run(args: argparse.Namespace) -> int:
    from ..runs import run_check

    say_warnings("check", run_check(args.case, args.out, msd_from=args.msd_from,
                                    force=args.force, say=say))
    return say_verdict(args.out)
