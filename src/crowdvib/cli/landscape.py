"""``crowdvib map``: the objective landscape J(f_h1, ξ_h1) of a case (paper Figs. 4, 10)."""

import argparse
from pathlib import Path

from .common import add_output_arguments, positive_float, progress_printer, say, say_verdict


# ------------------------------------------------------------------------------ map/sensitivity
#: Most points along one axis of a map: far finer than any plot shows, and the grid is made
#: while the arguments are read, before the time a map would take can be estimated.
MAX_AXIS = 100_000


def grid(text):
    """``lower:upper:count`` → a linearly spaced grid of 3 to :data:`MAX_AXIS` points (argparse
    type; the curvature at the map's minimum takes 3 points along each axis)."""
    import numpy as np     # here: crowdvib --help does without numpy

    try:
        lower, upper, count = text.split(":")
        lower, upper, count = float(lower), float(upper), int(count)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected lower:upper:count, got {text!r}") from None
    if not 3 <= count <= MAX_AXIS:
        raise argparse.ArgumentTypeError(f"count must be 3 to {MAX_AXIS} points, got {count} "
                                         f"(in {text!r})")
    return np.linspace(lower, upper, count)


def add_arguments(parser):
    parser.add_argument("case", type=Path, help="case file (TOML) with [measurement] records")
    add_output_arguments(parser)
    parser.add_argument("--frequencies", type=grid, default="1:6:51",
                        metavar="LOW:HIGH:N", help="grid of f_h1 [Hz] (default 1:6:51, paper)")
    parser.add_argument("--damping-ratios", type=grid, default="0.1:0.8:36",
                        metavar="LOW:HIGH:N",
                        help="grid of ξ_h1 [-] (default 0.1:0.8:36, paper)")
    parser.add_argument("--max-minutes", type=positive_float, default=10.0, metavar="MIN",
                        help="refuse a grid that would take longer, timed on its first point "
                             "(default 10)")


def run(args):
    from ..runs import run_map

    # Its warnings are in the verdict, not printed twice.
    run_map(args.case, args.out, frequencies=args.frequencies,
            damping_ratios=args.damping_ratios, max_seconds=60.0 * args.max_minutes,
            force=args.force, say=say, progress=progress_printer)
    return say_verdict(args.out)
