"""Command line: ``crowdvib demo`` and the case-file commands.

The CLI only parses arguments, calls the public API and writes through the file and plotting
helpers. Exit codes: 0 success, 1 a crowdvib error (message on stderr; traceback with
``--verbose``), 2 a usage error.
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from . import __version__
from ._files import write_json
from .errors import CrowdvibError

__all__ = ["main"]


def _say(message=""):
    print(message, flush=True)


# --------------------------------------------------------------------------------------- demo
def _add_demo_arguments(parser):
    parser.add_argument("--out", type=Path, default=Path("crowdvib-demo"),
                        help="output directory (default ./crowdvib-demo; files in it are replaced)")
    parser.add_argument("--seed", type=int, default=20230101,
                        help="seed of every random draw (default 20230101)")
    parser.add_argument("--duration-s", type=float, default=3600.0,
                        help="length of the 'measured' record [s] (default 3600)")


def _run_demo(args):
    from .estimation import estimate_hsi
    from .examples import paper_example
    from .plotting import plot_psd_comparison, save_figure
    from .signals import synthetic_welch_psd, welch_segment_count
    from .spectral import effective_modal_properties, response_psd

    case = paper_example()
    structure, crowd, truth = case.structure, case.crowd, case.msd
    _say("crowdvib demo: the numerical example of Van Nimmen & Van den Broeck (2023)")
    _say(f"  bridge  {structure.name}: f1 = {structure.frequencies[0]:g} Hz, "
         f"ξ1 = {structure.damping_ratios[0]:.1%}, m1 = {structure.modal_masses[0]:.3g} kg")
    _say(f"  crowd   {crowd.density:g} persons/m² ({crowd.density * structure.area:.0f} on deck), "
         f"v = {crowd.walking_speed:.2f} m/s, f_s ~ N({crowd.step_frequency_mean:.2f}, "
         f"{crowd.step_frequency_std:.3f}) Hz, {crowd.body_mass:g} kg")
    _say(f"  truth   MSD f_h1 = {truth.frequency:g} Hz, ξ_h1 = {truth.damping_ratio:g}, "
         f"μ_h1 = {truth.mass_ratio:g}")
    window = case.window_length
    sample_rate = 100.0
    frequency = np.arange(int(sample_rate / 2 * window) + 1) / window   # the Welch grid
    n_windows = welch_segment_count(int(args.duration_s * sample_rate), int(window * sample_rate))
    expected = response_psd(structure, crowd, frequency, msd=truth, welch_window_length=window)
    measured = synthetic_welch_psd(expected, n_windows, rng=args.seed).band(0.0, 10.0)
    _say(f"  'measured' PSD: spectral model with HSI as a Welch estimate of a {args.duration_s:g} s "
         f"record (T = {window:g} s, {n_windows} windows, seeded scatter)")

    started = time.perf_counter()
    estimate = estimate_hsi(measured, structure, crowd, band=case.band)
    elapsed = time.perf_counter() - started
    found = estimate.msd
    _say(f"\n  estimate over {case.band[0]:g}–{case.band[1]:g} Hz, {len(estimate.starts)} starts, "
         f"{estimate.n_evaluations} model evaluations, {elapsed:.2f} s")
    _say(f"  {'':14s}{'truth':>10s}{'estimate':>11s}{'error':>9s}")
    for label, t, e in (("f_h1 [Hz]", truth.frequency, found.frequency),
                        ("ξ_h1 [-]", truth.damping_ratio, found.damping_ratio)):
        _say(f"  {label:14s}{t:10.3f}{e:11.3f}{(e - t) / t:+9.1%}")
    _say(f"  J = {estimate.cost:.3g}; relative to no HSI J/J0 = {estimate.relative_cost:.3g}")
    occupied = effective_modal_properties(structure, crowd, found)
    _say(f"  occupied structure: {occupied.frequencies[0]:.3f} Hz, "
         f"{occupied.damping_ratios[0]:.2%} damping (empty: {structure.frequencies[0]:g} Hz, "
         f"{structure.damping_ratios[0]:.2%})")

    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    fitted = response_psd(structure, crowd, measured.frequency, msd=found,
                          welch_window_length=window)
    no_hsi = response_psd(structure, crowd, measured.frequency, welch_window_length=window)
    ax = plot_psd_comparison({"measured (synthetic)": measured, "fitted MSD": fitted,
                              "no HSI": no_hsi}, band=case.band,
                             title="Paper example: midspan acceleration PSD")
    figure = save_figure(ax, out / "psd_fit.png")
    results = {
        "command": "demo", "crowdvib_version": __version__, "seed": args.seed,
        "case": case.name, "truth": truth.to_dict(), **estimate.to_dict(),
        "occupied_structure": occupied.to_dict(),
        "measured": {"source": measured.source, "duration_s": args.duration_s,
                     "window_length": window, "n_windows": n_windows},
    }
    path = write_json(out / "results.json", results)
    _say(f"\n  wrote {path} and {figure}")
    return 0


# --------------------------------------------------------------------------------------- main
_COMMANDS = {
    "demo": ("estimate the MSD parameters back on the paper's numerical example",
             _add_demo_arguments, _run_demo),
}


def build_parser():
    """The argument parser with one sub-command per entry of ``_COMMANDS``."""
    parser = argparse.ArgumentParser(
        prog="crowdvib",
        description="Crowd-induced footbridge vibrations with human-structure interaction.")
    parser.add_argument("--version", action="version", version=f"crowdvib {__version__}")
    parser.add_argument("--verbose", action="store_true", help="show tracebacks of errors")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, (help_text, add_arguments, _) in _COMMANDS.items():
        sub = commands.add_parser(name, help=help_text, description=help_text)
        sub.add_argument("--verbose", action="store_true", default=argparse.SUPPRESS,
                         help="show tracebacks of errors")
        add_arguments(sub)
    return parser


def main(argv=None):
    """Run the command line; returns the exit code."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_:
        return int(exit_.code or 0)
    try:
        return _COMMANDS[args.command][2](args)
    except CrowdvibError as error:
        if args.verbose:
            raise
        print(f"crowdvib {args.command}: error: {error}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
