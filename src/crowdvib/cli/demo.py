"""``crowdvib demo``: the paper's numerical example, truth against estimate.

The work is :func:`crowdvib.runs.run_demo` (the pipeline: :func:`crowdvib.cases.demo_case`);
this command parses its arguments and prints.
"""

from pathlib import Path

from .common import progress_printer, say, say_verdict


# --------------------------------------------------------------------------------------- demo
def add_arguments(parser):
    parser.add_argument("--out", type=Path, default=Path("crowdvib-demo"),
                        help="output directory (default ./crowdvib-demo)")
    parser.add_argument("--force", action="store_true",
                        help="replace the results of an earlier crowdvib run in --out")
    parser.add_argument("--seed", type=int, default=20230101,
                        help="seed of every random draw (default 20230101)")
    parser.add_argument("--duration-s", type=float, default=3600.0,
                        help="length of the 'measured' record [s] (default 3600)")
    parser.add_argument("--spectral", action="store_true",
                        help="make the 'measured' PSD from the spectral model with Welch scatter "
                             "instead of a time-domain simulation (faster; no compiled kernel "
                             "needed)")


def run(args):
    from ..runs import run_demo

    run_demo(args.out, duration=args.duration_s, seed=args.seed, spectral=args.spectral,
             force=args.force, say=say, progress=progress_printer)
    return say_verdict(args.out)
