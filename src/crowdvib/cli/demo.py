"""``crowdvib demo``: the paper's numerical example, truth against estimate."""

import time
from pathlib import Path

from .._version import __version__
from .._files import write_json
from ..errors import ParameterError
from ..cases.schema import schema_header
from ..cases.results import provenance
from ..reporting.text import interval_of
from .common import (check_output, progress_printer, say, say_if_compiling, say_verdict,
                     staged_output)


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
    import numpy as np

    from ..identification.estimation import estimate_hsi
    from ..models.examples import paper_example
    from ..signals import LowPassFilter, synthetic_welch_psd, welch_psd, welch_segment_count
    from ..response.simulation import simulate
    from ..response.spectral import effective_modal_properties, response_psd

    case = paper_example()
    # The record must hold one Welch window at least (docs: theory, Welch PSDs, filters and
    # convergence): said in the option's own terms, not as the estimate's "n_windows".
    if not args.duration_s >= case.window_length:
        raise ParameterError(f"--duration-s must be at least one Welch window, "
                             f"T = {case.window_length:g} s, got {args.duration_s:g}")
    check_output(args.out, force=args.force, command="demo")   # refuse before the work
    structure, crowd, truth = case.structure, case.crowd, case.msd
    say("crowdvib demo: the numerical example of Van Nimmen & Van den Broeck (2023)")
    say(f"  bridge  {structure.name}: f1 = {structure.frequencies[0]:g} Hz, "
         f"ξ1 = {structure.damping_ratios[0]:.1%}, m1 = {structure.modal_masses[0]:.3g} kg")
    say(f"  crowd   {crowd.density:g} persons/m² ({crowd.density * structure.area:.0f} on deck), "
         f"v = {crowd.walking_speed:.2f} m/s, f_s ~ N({crowd.step_frequency_mean:.2f}, "
         f"{crowd.step_frequency_std:.3f}) Hz, {crowd.body_mass:g} kg")
    say(f"  truth   MSD f_h1 = {truth.frequency:g} Hz, ξ_h1 = {truth.damping_ratio:g}, "
         f"μ_h1 = {truth.mass_ratio:g}")
    window = case.window_length
    sample_rate = 100.0
    if args.spectral:
        frequency = np.arange(int(sample_rate / 2 * window) + 1) / window   # the Welch grid
        n_windows = welch_segment_count(int(args.duration_s * sample_rate),
                                        int(window * sample_rate))
        expected = response_psd(structure, crowd, frequency, msd=truth,
                                welch_window_length=window)
        measured = synthetic_welch_psd(expected, n_windows, rng=args.seed).band(0.0, 10.0)
        say(f"  'measured' PSD: spectral model with HSI as a Welch estimate of a "
             f"{args.duration_s:g} s record (T = {window:g} s, {n_windows} windows, seeded "
             "scatter)")
    else:
        started = time.perf_counter()
        # The deck is populated at t = 0; the warm-up lets the 0.5 %-damped mode forget its
        # initial rest (5/(ξω) ≈ 80 s), as docs: theory, Time domain against spectral model discards its first 100 s.
        warm_up = 100.0
        say_if_compiling(structure, truth is not None)
        record = simulate(structure, crowd, args.duration_s, msd=truth,
                          sample_rate=sample_rate, rng=args.seed, warm_up=warm_up,
                          progress=progress_printer(f"simulated (after {warm_up:g} s warm-up)",
                                                    offset=warm_up))
        lowpass = LowPassFilter(cutoff=10.0, order=4, sample_rate=sample_rate)
        measured = welch_psd(record.acceleration, sample_rate, window_length=window,
                             output_names=record.output_names, lowpass=lowpass).band(0.0, 10.0)
        n_windows = measured.n_windows
        say(f"  'measured' record: time-domain simulation with moving MSD pedestrians, "
             f"{args.duration_s:g} s at {sample_rate:g} Hz ({record.n_pedestrians} pedestrians, "
             f"{time.perf_counter() - started:.1f} s wall); low-pass 10 Hz, Welch T = "
             f"{window:g} s, {n_windows} windows")

    # The default estimator and the paper's, on the same PSD (docs: theory, Calibration).
    estimates = {}
    for name, title, options in ESTIMATORS:
        started = time.perf_counter()
        estimates[name] = estimate = estimate_hsi(measured, structure, crowd, band=case.band,
                                                  rng=args.seed, **options)
        say(f"\n  {title}: {len(estimate.starts)} fits, {estimate.n_evaluations} model "
            f"evaluations, {time.perf_counter() - started:.2f} s")
        _say_estimate(estimate, truth)
    estimate, paper = estimates["default"], estimates["paper"]
    found = estimate.msd
    occupied = effective_modal_properties(structure, crowd, found)
    say(f"  occupied structure: {occupied.frequencies[0]:.3f} Hz, "
         f"{occupied.damping_ratios[0]:.2%} damping (empty: {structure.frequencies[0]:g} Hz, "
         f"{structure.damping_ratios[0]:.2%})")

    with staged_output(args.out, args.force, command="demo") as staging:
        figure, path = _write_results(args, staging, case, measured, estimate, paper,
                                      occupied, n_windows)
    say(f"\n  wrote {args.out / path.name} and {args.out / figure.name}")
    say(f"  report: {args.out / 'report.html'}")
    return say_verdict(args.out)


#: (key, title, options of estimate_hsi): the default and the paper's least squares.
ESTIMATORS: tuple[tuple[str, str, dict], ...] = (
    ("default", "default estimator: Whittle likelihood, fluctuating crowd, step frequencies "
                "fitted", {}),
    ("paper", "the paper's estimator: least squares (Eq. 6), smeared crowd, crowd as given",
     {"method": "least_squares"}),
)


def _say_estimate(estimate, truth):
    """Truth, estimate, error and interval of f_h1 and ξ_h1, and the misfit, on the console."""
    summary = estimate.to_dict()["estimate"]
    level = f"{100 * estimate.interval_level:g} % interval"
    say(f"  {'':14s}{'truth':>10s}{'estimate':>11s}{'error':>9s}   {level}")
    for label, key in (("f_h1 [Hz]", "frequency"), ("ξ_h1 [-]", "damping_ratio")):
        t, e, ends = getattr(truth, key), getattr(estimate.msd, key), interval_of(summary, key)
        inside = ("" if ends is None else
                  "   truth inside" if ends[0] <= t <= ends[1] else "   truth outside")
        say(f"  {label:14s}{t:10.3f}{e:11.3f}{(e - t) / t:+9.1%}   "
            + ("—" if ends is None else f"{ends[0]:.3f}–{ends[1]:.3f}") + inside)
    misfit = "deviance D" if estimate.method == "likelihood" else "J (paper Eq. 6)"
    say(f"  misfit {misfit} = {estimate.cost:.3g}, relative to no HSI "
        f"{estimate.relative_cost:.3g}")


def _write_results(args, out, case, measured, estimate, paper, occupied, n_windows):
    """The figure, results.json and report.html of the demo into ``out``."""
    from ..reporting.plotting import plot_psd_comparison, save_figure
    from ..reporting.report import write_report
    from ..response.fluctuation import spectral_model

    structure, crowd, truth, window = case.structure, case.crowd, case.msd, case.window_length
    # Each estimate's expected PSD as its estimator modelled it (crowd model, fitted crowd).
    curves = {}
    for key, fit in (("fitted MSD (default)", estimate), ("fitted MSD (paper)", paper)):
        model = spectral_model(structure, fit.crowd or crowd, measured.frequency,
                               welch_window_length=window, lowpass=measured.lowpass,
                               crowd_model=fit.crowd_model)
        curves[key] = model.psd(fit.msd)
    curves["no HSI"] = model.psd(None)
    label = "measured (synthetic)" if args.spectral else "measured (simulated)"
    ax = plot_psd_comparison({label: measured, **curves}, band=case.band, analysis_band=case.band,
                             title="Paper example: midspan acceleration PSD")
    figure = save_figure(ax, out / "psd_fit.png")
    results = {
        **schema_header("demo"), "command": "demo", "crowdvib_version": __version__,
        "seed": args.seed,
        "case": case.name, "truth": truth.to_dict(), **estimate.to_dict(),
        "paper_estimator": paper.to_dict(),
        "occupied_structure": occupied.to_dict(),
        "measured": {"source": measured.source, "duration_s": args.duration_s,
                     "window_length": window, "n_windows": n_windows},
        "figures": [figure.name], **provenance(),
    }
    path = write_json(out / "results.json", results)
    write_report(out)
    return figure, path
