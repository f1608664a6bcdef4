"""``crowdvib modes AMBIENT.toml``: the empty bridge's modes from an ambient record (OMA).

The work is :func:`crowdvib.runs.run_modes` (the ambient file's keys: the docs, Case files); this
command parses its arguments and prints, with a progress bar for the identification.
"""

from pathlib import Path

from .common import add_output_arguments, progress_printer, say, say_verdict, say_warnings


def add_arguments(parser):
    parser.add_argument("ambient", type=Path, help="ambient-test file (TOML)")
    parser.add_argument("--cross-check", action="store_true",
                        help="also identify with the other method (EFDD for SSI-cov, and back) "
                             "and compare the modes")
    add_output_arguments(parser)


def run(args):
    from ..runs import run_modes

    say_warnings("modes", run_modes(args.ambient, args.out, cross_check=args.cross_check,
                                    force=args.force, say=say, progress=progress_printer))
    return say_verdict(args.out)
