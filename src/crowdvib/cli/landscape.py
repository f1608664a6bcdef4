"""``crowdvib map``: the objective landscape J(f_h1, ξ_h1) of a case (paper Figs. 4, 10)."""

import argparse
from pathlib import Path

from ..cases.results import provenance
from .common import (add_output_arguments, case_inputs, positive_float, progress_printer, say,
                     say_verdict, staged_output, warning_texts, write_results)
from .estimate import say_crowd, say_measurement


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
    import warnings

    from ..cases import map_case
    from ..io.casefile import load_case
    from ..reporting.plotting import plot_objective_map, save_figure

    case = load_case(args.case)
    stamp = provenance(case.path)
    with staged_output(args.out, args.force, command="map",
                       inputs=case_inputs(case)) as staging:
        say(f"crowdvib map: {case.name} ({case.path.name})")
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            found = map_case(case, frequencies=args.frequencies,
                             damping_ratios=args.damping_ratios,
                             progress=progress_printer("grid", unit="points"),
                             max_seconds=60.0 * args.max_minutes)
        say_measurement(found.record.measurement)
        say_crowd(case, found.record.crowd, found.record.step_frequencies)
        landscape, estimate, best = found.landscape, found.estimate, found.landscape.optimum
        say(f"  {landscape.cost.size} grid points in {found.seconds:.1f} s; "
            f"grid minimum f_h1 = {best.frequency:.3f} Hz, ξ_h1 = {best.damping_ratio:.3f}; "
            f"optimiser {estimate.msd.frequency:.3f} Hz, {estimate.msd.damping_ratio:.3f}")
        say(f"  curvature along f_h1 / along ξ_h1 at the minimum: "
            f"{landscape.curvature_ratio():.3g}")
        ax = plot_objective_map(landscape, search_bounds=estimate.bounds,
                                title=f"{case.name}: objective J(f_h1, ξ_h1)")
        figure = save_figure(ax, staging / "objective_map.png").name
        write_results(staging, {**found.to_dict(), "warnings": warning_texts(caught),
                                "figures": [figure], **stamp})
    say(f"  wrote {args.out / 'results.json'}, {figure} and report.html")
    return say_verdict(args.out)
