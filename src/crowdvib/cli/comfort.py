"""``crowdvib comfort``: a year of comfort of a case's bridge, from a season of monitoring (or a
traffic table) and the identified MSD with its interval (issue 37).

Hours a year in each comfort class (Sétra/HiVoSS CL1–CL4), the probability that a 10-minute
window exceeds a limit and the week's map of the expected class, without HSI, with added mass
and with the identified HSI, each without and with a tuned mass damper. The work is
:func:`crowdvib.runs.run_comfort`; this command parses its arguments and prints.
"""

import argparse
from pathlib import Path

from .common import add_output_arguments, add_workers_argument, say, say_verdict, say_warnings

__all__ = ["add_arguments", "run"]


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("case", type=Path,
                        help="case file (TOML): the bridge, the crowd's other properties, "
                             "optional [comfort] and [traffic] tables")
    source = parser.add_mutually_exclusive_group()
    source.add_argument("--season", type=Path, default=None, metavar="DIR",
                        help="results directory of `crowdvib season`: its windows are the "
                             "traffic (by hour of the week) and its joint estimate the MSD")
    source.add_argument("--traffic", type=Path, default=None, metavar="FILE",
                        help="traffic CSV: columns density,hours_per_year (a design table) or "
                             "hour,density (a daily profile); default the case's [traffic]")
    add_output_arguments(parser)
    parser.add_argument("--msd-from", type=Path, default=None, metavar="DIR",
                        help="results directory of `crowdvib estimate`, `sensitivity` or "
                             "`season`: its MSD and interval (with its modelling bound) for the "
                             "HSI model and its band")
    add_workers_argument(parser)


def run(args: argparse.Namespace) -> int:
    from ..runs import run_comfort

    say_warnings("comfort", run_comfort(args.case, args.out, season=args.season,
                                        traffic=args.traffic, msd_from=args.msd_from,
                                        workers=args.workers, hung_after=args.hung_after,
                                        force=args.force, say=say))
    return say_verdict(args.out)
