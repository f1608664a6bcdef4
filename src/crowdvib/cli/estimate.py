"""``crowdvib estimate``: read, check and filter a case's records and estimate f_h1, ξ_h1.

The work is :func:`crowdvib.runs.run_estimate` (the pipeline: :func:`crowdvib.cases.estimate_case`);
this command parses its arguments and prints.
"""

from pathlib import Path

from .common import add_output_arguments, say, say_verdict, say_warnings


def add_arguments(parser):
    parser.add_argument("case", type=Path, help="case file (TOML) with [measurement] records")
    add_output_arguments(parser)


def run(args):
    from ..runs import run_estimate

    say_warnings("estimate", run_estimate(args.case, args.out, force=args.force, say=say))
    return say_verdict(args.out)
