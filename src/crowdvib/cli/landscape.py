"""``crowdvib map``: the objective landscape J(f_h1, ξ_h1) of a case (paper Figs. 4, 10)."""

import argparse
import time
from pathlib import Path

import numpy as np

from .._version import __version__
from .._files import write_json
from ..reporting.report import provenance, write_report
from .common import (ESTIMATION_TABLES, add_output_arguments, case_inputs, positive_float,
                     progress_printer, say, say_verdict, staged_output, versions, warning_texts)
from .estimate import case_crowd, case_measurement, estimate_options


# ------------------------------------------------------------------------------ map/sensitivity
#: Most points along one axis of a map: far finer than any plot shows, and the grid is made
#: while the arguments are read, before the time a map would take can be estimated.
MAX_AXIS = 100_000


def grid(text):
    """``lower:upper:count`` → a linearly spaced grid of 3 to :data:`MAX_AXIS` points (argparse
    type; the curvature at the map's minimum takes 3 points along each axis)."""
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
    parser.add_argument("--frequencies", type=grid, default=np.linspace(1.0, 6.0, 51),
                        metavar="LOW:HIGH:N", help="grid of f_h1 [Hz] (default 1:6:51, paper)")
    parser.add_argument("--damping-ratios", type=grid, default=np.linspace(0.1, 0.8, 36),
                        metavar="LOW:HIGH:N",
                        help="grid of ξ_h1 [-] (default 0.1:0.8:36, paper)")
    parser.add_argument("--max-minutes", type=positive_float, default=10.0, metavar="MIN",
                        help="refuse a grid that would take longer, timed on its first point "
                             "(default 10)")


def run(args):
    import warnings

    from ..identification.estimation import estimate_hsi
    from ..identification.landscape import objective_map
    from ..io.casefile import load_case
    from ..reporting.plotting import plot_objective_map, save_figure

    case = load_case(args.case)
    stamp = provenance(case.path)
    with staged_output(args.out, args.force, command="map",
                       inputs=case_inputs(case)) as staging:
        say(f"crowdvib map: {case.name} ({case.path.name})")
        record, measured, _ = case_measurement(case)
        crowd, _ = case_crowd(case, record)
        options = estimate_options(case)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            estimate = estimate_hsi(measured, case.structure, crowd, **options)
        for key in ("starts", "bounds", "interval", "level", "n_boot", "rng"):
            options.pop(key)
        started = time.perf_counter()
        landscape = objective_map(measured, case.structure, crowd,
                                  frequencies=args.frequencies,
                                  damping_ratios=args.damping_ratios, estimate=estimate,
                                  progress=progress_printer("grid", unit="points"),
                                  max_seconds=60.0 * args.max_minutes, **options)
        best = landscape.optimum
        say(f"  {landscape.cost.size} grid points in {time.perf_counter() - started:.1f} s; "
             f"grid minimum f_h1 = {best.frequency:.3f} Hz, ξ_h1 = {best.damping_ratio:.3f}; "
             f"optimiser {estimate.msd.frequency:.3f} Hz, {estimate.msd.damping_ratio:.3f}")
        say(f"  curvature along f_h1 / along ξ_h1 at the minimum: "
             f"{landscape.curvature_ratio():.3g}")
        ax = plot_objective_map(landscape, search_bounds=estimate.bounds,
                                title=f"{case.name}: objective J(f_h1, ξ_h1)")
        figure = save_figure(ax, staging / "objective_map.png").name
        write_json(staging / "results.json", {
            "command": "map", "crowdvib_version": __version__, "versions": versions(),
            "seed": case.seed, "case": str(case.path), "inputs": case.to_dict(ESTIMATION_TABLES),
            "estimate": estimate.msd.to_dict(), "expected": dict(case.expected),
            "diagnostics": {k: v for k, v in estimate.to_dict().items() if k != "estimate"},
            "objective_map": landscape.to_dict(),
            "curvature_ratio": landscape.curvature_ratio(),
            "warnings": warning_texts(caught), "figures": [figure], **stamp})
        write_report(staging)
    say(f"  wrote {args.out / 'results.json'}, {figure} and report.html")
    say_verdict(args.out)
    return 0
