"""Command line: ``crowdvib demo`` and the case-file commands.

The CLI only parses arguments, calls the public API and writes through the file and plotting
helpers. Exit codes: 0 success, 1 a crowdvib error (message on stderr; traceback with
``--verbose``), 2 a usage error.
"""

import argparse
import contextlib
import sys
import time
from pathlib import Path

import numpy as np

from .. import __version__
from .._files import write_json
from ..errors import CrowdvibError
from ..reporting.report import provenance, write_report

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
    parser.add_argument("--spectral", action="store_true",
                        help="make the 'measured' PSD from the spectral model with Welch scatter "
                             "instead of a time-domain simulation (faster; no compiled kernel "
                             "needed)")


def _run_demo(args):
    from ..identification.estimation import estimate_hsi
    from ..models.examples import paper_example
    from ..reporting.plotting import plot_psd_comparison, save_figure
    from ..signals import LowPassFilter, synthetic_welch_psd, welch_psd, welch_segment_count
    from ..response.simulation import simulate
    from ..response.spectral import effective_modal_properties, response_psd

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
    if args.spectral:
        frequency = np.arange(int(sample_rate / 2 * window) + 1) / window   # the Welch grid
        n_windows = welch_segment_count(int(args.duration_s * sample_rate),
                                        int(window * sample_rate))
        expected = response_psd(structure, crowd, frequency, msd=truth,
                                welch_window_length=window)
        measured = synthetic_welch_psd(expected, n_windows, rng=args.seed).band(0.0, 10.0)
        _say(f"  'measured' PSD: spectral model with HSI as a Welch estimate of a "
             f"{args.duration_s:g} s record (T = {window:g} s, {n_windows} windows, seeded "
             "scatter)")
    else:
        started = time.perf_counter()
        # The deck is populated at t = 0; the warm-up lets the 0.5 %-damped mode forget its
        # initial rest (5/(ξω) ≈ 80 s), as physics.md §8.4 discards its first 100 s.
        record = simulate(structure, crowd, args.duration_s, msd=truth,
                          sample_rate=sample_rate, rng=args.seed, warm_up=100.0,
                          progress=_progress_printer("simulated"))
        lowpass = LowPassFilter(cutoff=10.0, order=4, sample_rate=sample_rate)
        measured = welch_psd(record.acceleration, sample_rate, window_length=window,
                             output_names=record.output_names, lowpass=lowpass).band(0.0, 10.0)
        n_windows = measured.n_windows
        _say(f"  'measured' record: time-domain simulation with moving MSD pedestrians, "
             f"{args.duration_s:g} s at {sample_rate:g} Hz ({record.n_pedestrians} pedestrians, "
             f"{time.perf_counter() - started:.1f} s wall); low-pass 10 Hz, Welch T = "
             f"{window:g} s, {n_windows} windows")

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
                          welch_window_length=window, lowpass=measured.lowpass)
    no_hsi = response_psd(structure, crowd, measured.frequency, welch_window_length=window,
                          lowpass=measured.lowpass)
    label = "measured (synthetic)" if args.spectral else "measured (simulated)"
    ax = plot_psd_comparison({label: measured, "fitted MSD": fitted,
                              "no HSI": no_hsi}, band=case.band,
                             title="Paper example: midspan acceleration PSD")
    figure = save_figure(ax, out / "psd_fit.png")
    results = {
        "command": "demo", "crowdvib_version": __version__, "seed": args.seed,
        "case": case.name, "truth": truth.to_dict(), **estimate.to_dict(),
        "occupied_structure": occupied.to_dict(),
        "measured": {"source": measured.source, "duration_s": args.duration_s,
                     "window_length": window, "n_windows": n_windows},
        **provenance(),
    }
    path = write_json(out / "results.json", results)
    _say(f"\n  wrote {path} and {figure}")
    _say(f"  report: {write_report(out)}")
    return 0


# ------------------------------------------------------------------------------ estimate/simulate
def _prepare_out(out, force):
    """A fresh temporary directory beside ``out``; refuses an existing ``out`` without --force."""
    import tempfile

    from ..errors import ParameterError

    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"--out {out} exists and is not a directory")
    if out.is_dir() and any(out.iterdir()) and not force:
        raise ParameterError(f"--out {out} already holds results; use --force to replace them")
    out.parent.mkdir(parents=True, exist_ok=True)
    return Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".part", dir=out.parent))


@contextlib.contextmanager
def _staged_output(out, force):
    """Yield a staging directory that replaces ``out`` only if the block finishes.

    A failed run removes the staging directory and leaves ``out`` as it was, so no half-written
    results ever appear; an existing ``out`` is refused without ``--force``.
    """
    import shutil

    staging = _prepare_out(out, force)
    try:
        yield staging
        _publish(staging, out)
    finally:
        if staging.exists():
            shutil.rmtree(staging, ignore_errors=True)


def _publish(staging, out):
    """Swap the finished staging directory in for ``out``."""
    import os
    import shutil

    out = Path(out)
    old = None
    if out.exists():
        old = out.with_name(f".{out.name}.old-{os.getpid()}")
        os.replace(out, old)
    os.replace(staging, out)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def _versions():
    import platform

    import scipy

    return {"crowdvib": __version__, "numpy": np.__version__, "scipy": scipy.__version__,
            "python": platform.python_version()}


def _warning_texts(caught):
    return [f"{w.category.__name__}: {w.message}" for w in caught]


def _add_estimate_arguments(parser):
    parser.add_argument("case", type=Path, help="case file (TOML) with [measurement] records")
    parser.add_argument("--out", type=Path, required=True, help="output directory")
    parser.add_argument("--force", action="store_true",
                        help="replace an existing output directory")


def _run_estimate(args):
    import warnings

    from ..io.casefile import load_case

    case = load_case(args.case)
    stamp = provenance(case.path)
    with _staged_output(args.out, args.force) as staging:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            results = _estimate_case(case, staging)
        results.update(stamp)
        results["warnings"] = _warning_texts(caught)
        for text in results["warnings"]:
            print(f"crowdvib estimate: warning: {text}", file=sys.stderr)
        write_json(staging / "results.json", results)
        write_report(staging)
    _say(f"  wrote {args.out / 'results.json'}, figures and report.html")
    return 0


def _case_measurement(case):
    """Read a case's records and make its measured PSD → (record, ResponsePSD, low-pass filter).

    The record keeps the outputs to be fitted (``estimation.outputs``, else every channel); the
    PSD is the Welch estimate of ``[measurement]`` after the zero-phase low-pass filter.
    """
    from ..io.casefile import load_measurement
    from ..errors import ParameterError
    from ..signals import LowPassFilter, welch_psd

    spec, est = case.measurement, case.estimation
    record = load_measurement(case)
    outputs = tuple(est.outputs or record.channel_names)
    unknown = [name for name in outputs if name not in case.structure.output_names]
    if unknown:
        raise ParameterError(
            f"{case.path.name}: record channel(s) {unknown} are not outputs of the structure "
            f"{list(case.structure.output_names)}: map them with measurement.channels "
            "(output = \"channel in file\") or list the outputs in estimation.outputs")
    record = record.select(outputs)
    _say(f"  record  {record.n_channels} channel(s) {list(record.channel_names)}, "
         f"{record.duration:g} s at {record.sample_rate:g} Hz")
    lowpass = (None if spec.lowpass_cutoff is None else
               LowPassFilter(spec.lowpass_cutoff, spec.lowpass_order, record.sample_rate))
    measured = welch_psd(record.data, record.sample_rate, window_length=spec.window_length,
                         overlap=spec.overlap, output_names=outputs, lowpass=lowpass)
    return record, measured, lowpass


def _case_crowd(case, record):
    """The crowd the HSI estimate uses → (Crowd, StepFrequencyEstimate or None).

    With ``[estimation.step_frequencies]`` the step-frequency distribution is first fitted on the
    record low-passed at the cut-off, without HSI (the paper's Waalse Krook procedure), and used
    when ``use_fitted``; otherwise the case file's crowd.
    """
    from ..identification.step_frequencies import estimate_step_frequencies
    from ..signals import LowPassFilter, welch_psd

    spec, est = case.measurement, case.estimation
    crowd = case.crowd
    if est.step_frequencies is None:
        return crowd, None
    sf = est.step_frequencies
    low = LowPassFilter(sf.cutoff, spec.lowpass_order, record.sample_rate)
    measured_low = welch_psd(record.data, record.sample_rate, window_length=spec.window_length,
                             overlap=spec.overlap, output_names=record.channel_names,
                             lowpass=low)
    fitted = estimate_step_frequencies(measured_low, case.structure, crowd, cutoff=sf.cutoff,
                                       band=sf.band, starts=sf.starts, bounds=sf.bounds,
                                       outputs=sf.outputs, match_welch=est.match_welch)
    _say(f"  step frequencies below {sf.cutoff:g} Hz: N({fitted.crowd.step_frequency_mean:.3f}, "
         f"{fitted.crowd.step_frequency_std:.3f}) Hz (case file: "
         f"N({crowd.step_frequency_mean:g}, {crowd.step_frequency_std:g}) Hz)")
    return (fitted.crowd if sf.use_fitted else crowd), fitted


def _estimate_case(case, out):
    """The estimate pipeline on a loaded case; figures into ``out``; returns the results dict."""
    from ..identification.estimation import estimate_hsi
    from ..reporting.plotting import plot_psd_comparison, plot_psd_convergence, save_figure
    from ..signals import psd_convergence
    from ..response.spectral import response_psd

    spec, est = case.measurement, case.estimation
    _say(f"crowdvib estimate: {case.name} ({case.path.name})")
    record, measured, lowpass = _case_measurement(case)
    outputs = record.channel_names
    convergence = psd_convergence(record.data, record.sample_rate,
                                  window_length=spec.window_length, band=est.band,
                                  norm=est.convergence_norm, overlap=spec.overlap,
                                  output_names=outputs, lowpass=lowpass)
    last = convergence.error[:, -2] if convergence.error.shape[1] > 1 else convergence.error[:, 0]
    _say(f"  PSD     Welch T = {spec.window_length:g} s, {measured.n_windows} windows; "
         f"convergence error of the last window added ({convergence.norm}-norm over the band): "
         + ", ".join(f"{v:.1%}" for v in last))
    reach = convergence.duration_to_reach(0.10)
    _say("          below 10 % from " + (f"{reach:g} s of record on" if reach is not None
                                         else "no record length (record too short)"))
    crowd, step_result = _case_crowd(case, record)
    free_mass = "mass_ratio" in est.free_parameters
    estimate = estimate_hsi(measured, case.structure, crowd, band=est.band, outputs=outputs,
                            output_weights=est.output_weights, starts=est.starts,
                            bounds=est.bounds, mass_ratio=case.msd.mass_ratio,
                            free_mass_ratio=free_mass, match_welch=est.match_welch)
    found = estimate.msd
    _say(f"  estimate f_h1 = {found.frequency:.3f} Hz, ξ_h1 = {found.damping_ratio:.3f}, "
         f"μ_h1 = {found.mass_ratio:.3f}; J/J_noHSI = {estimate.relative_cost:.3g}")
    if case.expected:
        for key, label in (("frequency", "f_h1"), ("damping_ratio", "ξ_h1")):
            if key in case.expected:
                value = getattr(found, key)
                _say(f"           {label}: expected {case.expected[key]:g}, "
                     f"error {(value - case.expected[key]) / case.expected[key]:+.1%}")
    figures = []
    window = measured.window_length if est.match_welch else None
    fitted = response_psd(case.structure, crowd, measured.frequency, msd=found, outputs=outputs,
                          welch_window_length=window, lowpass=lowpass if est.match_welch else None)
    no_hsi = response_psd(case.structure, crowd, measured.frequency, outputs=outputs,
                          welch_window_length=window,
                          lowpass=lowpass if est.match_welch else None)
    for name in outputs:
        ax = plot_psd_comparison({"measured": measured, "fitted MSD": fitted, "no HSI": no_hsi},
                                 output=name, band=(0.0, max(est.band[1], 2 * est.band[0])),
                                 title=f"{case.name}: {name}")
        ax.axvspan(*est.band, color="tab:green", alpha=0.07, label="band")
        figures.append(save_figure(ax, out / f"psd_{name}.png").name)
    figures.append(save_figure(plot_psd_convergence(convergence, title=f"{case.name}: PSD "
                                                    "convergence"),
                               out / "psd_convergence.png").name)
    hsi = estimate.to_dict()
    diagnostics = {k: v for k, v in hsi.items() if k != "estimate"}
    diagnostics["convergence"] = convergence.to_dict()
    diagnostics["measured_psd"] = {"window_length": measured.window_length,
                                   "n_windows": measured.n_windows,
                                   "lowpass": None if lowpass is None else lowpass.to_dict()}
    if step_result is not None:
        diagnostics["step_frequencies"] = step_result.to_dict()
    return {"command": "estimate", "crowdvib_version": __version__, "versions": _versions(),
            "seed": case.seed, "case": str(case.path), "inputs": case.to_dict(),
            "record": record.to_dict(), "crowd_used": {
                "step_frequency_mean": crowd.step_frequency_mean,
                "step_frequency_std": crowd.step_frequency_std},
            "estimate": hsi["estimate"], "expected": dict(case.expected),
            "diagnostics": diagnostics, "figures": figures}


# ------------------------------------------------------------------------------ map/sensitivity
def _grid(text):
    """``lower:upper:count`` → a linearly spaced grid (argparse type)."""
    try:
        lower, upper, count = text.split(":")
        return np.linspace(float(lower), float(upper), int(count))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected lower:upper:count, got {text!r}") from None


def _add_map_arguments(parser):
    parser.add_argument("case", type=Path, help="case file (TOML) with [measurement] records")
    parser.add_argument("--out", type=Path, required=True, help="output directory")
    parser.add_argument("--force", action="store_true",
                        help="replace an existing output directory")
    parser.add_argument("--frequencies", type=_grid, default=np.linspace(1.0, 6.0, 51),
                        metavar="LOW:HIGH:N", help="grid of f_h1 [Hz] (default 1:6:51, paper)")
    parser.add_argument("--damping-ratios", type=_grid, default=np.linspace(0.1, 0.8, 36),
                        metavar="LOW:HIGH:N",
                        help="grid of ξ_h1 [-] (default 0.1:0.8:36, paper)")


def _estimate_options(case):
    """Keyword arguments of estimate_hsi from a case's [estimation] table."""
    est = case.estimation
    return dict(band=est.band, outputs=est.outputs, output_weights=est.output_weights,
                starts=est.starts, bounds=est.bounds, mass_ratio=case.msd.mass_ratio,
                match_welch=est.match_welch)


def _run_map(args):
    import warnings

    from ..io.casefile import load_case
    from ..identification.estimation import estimate_hsi
    from ..reporting.plotting import plot_objective_map, save_figure
    from ..identification.sensitivity import objective_map

    case = load_case(args.case)
    stamp = provenance(case.path)
    with _staged_output(args.out, args.force) as staging:
        _say(f"crowdvib map: {case.name} ({case.path.name})")
        record, measured, _ = _case_measurement(case)
        crowd, _ = _case_crowd(case, record)
        options = _estimate_options(case)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            estimate = estimate_hsi(measured, case.structure, crowd, **options)
        options.pop("starts")
        options.pop("bounds")
        started = time.perf_counter()
        landscape = objective_map(measured, case.structure, crowd,
                                  frequencies=args.frequencies,
                                  damping_ratios=args.damping_ratios, estimate=estimate,
                                  **options)
        best = landscape.optimum
        _say(f"  {landscape.cost.size} grid points in {time.perf_counter() - started:.1f} s; "
             f"grid minimum f_h1 = {best.frequency:.3f} Hz, ξ_h1 = {best.damping_ratio:.3f}; "
             f"optimiser {estimate.msd.frequency:.3f} Hz, {estimate.msd.damping_ratio:.3f}")
        _say(f"  curvature along f_h1 / along ξ_h1 at the minimum: "
             f"{landscape.curvature_ratio():.3g}")
        ax = plot_objective_map(landscape, search_bounds=estimate.bounds,
                                title=f"{case.name}: objective J(f_h1, ξ_h1)")
        figure = save_figure(ax, staging / "objective_map.png").name
        write_json(staging / "results.json", {
            "command": "map", "crowdvib_version": __version__, "versions": _versions(),
            "seed": case.seed, "case": str(case.path), "inputs": case.to_dict(),
            "estimate": estimate.msd.to_dict(), "expected": dict(case.expected),
            "diagnostics": {k: v for k, v in estimate.to_dict().items() if k != "estimate"},
            "objective_map": landscape.to_dict(),
            "curvature_ratio": landscape.curvature_ratio(),
            "warnings": _warning_texts(caught), "figures": [figure], **stamp})
        write_report(staging)
    _say(f"  wrote {args.out / 'results.json'}, {figure} and report.html")
    return 0


def _add_sensitivity_arguments(parser):
    parser.add_argument("case", type=Path, help="case file (TOML) with [measurement] records")
    parser.add_argument("--out", type=Path, required=True, help="output directory")
    parser.add_argument("--workers", type=int, default=1,
                        help="local worker processes (default 1: in this process)")
    parser.add_argument("--scheduler", metavar="ADDRESS", default=None,
                        help="run on a dask.distributed scheduler, e.g. tcp://127.0.0.1:8786 "
                             "(needs crowdvib[dask])")
    parser.add_argument("--resume", action="store_true",
                        help="continue an interrupted study in --out without recomputing "
                             "finished tasks")
    parser.add_argument("--force", action="store_true",
                        help="start afresh, replacing an existing output directory")
    parser.add_argument("--no-joint", action="store_true",
                        help="only individual errors (skip the 2⁵ joint sign combinations)")
    parser.add_argument("--no-record-length", action="store_true",
                        help="skip re-estimating on shorter parts of the record")


@contextlib.contextmanager
def _executor(workers, scheduler):
    """The executor a study runs on: none (serial), a process pool, or a dask cluster."""
    from ..errors import ParameterError

    if scheduler is not None:
        try:
            from distributed import Client
        except ImportError:
            raise ParameterError("--scheduler needs dask.distributed: pip install "
                                 "'crowdvib[dask]'") from None
        with Client(scheduler) as client:
            yield client.get_executor()
    elif workers > 1:
        import concurrent.futures

        with concurrent.futures.ProcessPoolExecutor(workers) as pool:
            yield pool
    elif workers == 1:
        yield None
    else:
        raise ParameterError(f"--workers must be >= 1, got {workers}")


def _run_sensitivity(args):
    from ..io.casefile import load_case
    from ..errors import ParameterError
    from ..reporting.plotting import plot_estimation_errors, save_figure
    from ..identification.sensitivity import TaskStore, modelling_error_study, record_length_study

    case = load_case(args.case)
    stamp = provenance(case.path)
    out = Path(args.out)
    if out.is_dir() and any(out.iterdir()) and not (args.resume or args.force):
        raise ParameterError(f"--out {out} already holds a study; use --resume to continue it "
                             "or --force to start afresh")
    if args.force and out.is_dir():
        import shutil

        shutil.rmtree(out)
    out.mkdir(parents=True, exist_ok=True)
    _say(f"crowdvib sensitivity: {case.name} ({case.path.name})")
    record, measured, lowpass = _case_measurement(case)
    crowd, _ = _case_crowd(case, record)
    options = _estimate_options(case)
    store = TaskStore(out / "tasks")
    done = len(store.keys())
    if done:
        _say(f"  resuming: {done} finished task(s) found in {store.directory}")
    with _executor(args.workers, args.scheduler) as executor:
        study = modelling_error_study(measured, case.structure, crowd, joint=not args.no_joint,
                                      executor=executor, store=store,
                                      progress=_progress_printer("estimations", unit="tasks"),
                                      **options)
        lengths = None
        if not args.no_record_length:
            options.pop("band")
            lengths = record_length_study(
                record.data, record.sample_rate, case.structure, crowd,
                window_length=case.measurement.window_length, band=case.estimation.band,
                output_names=record.channel_names, lowpass=lowpass, executor=executor,
                store=TaskStore(out / "record_length"), **options)
    _say(f"\n  {'case':34s}{'Δ f_h1 [%]':>12s}{'Δ ξ_h1 [%]':>12s}")
    for row in study.cases:
        if row["kind"] == "individual":
            text = (f"{row['delta_frequency']:12.2f}{row['delta_damping_ratio']:12.2f}"
                    if "error" not in row else "  failed: " + row["error"])
            _say(f"  {row['name']:34s}{text}")
    for level in sorted({c["level"] for c in study.cases if c["kind"] == "joint"}):
        bound = study.bound(level)
        _say(f"  {'joint, level ' + str(level):34s}{bound['frequency']:12.2f}"
             f"{bound['damping_ratio']:12.2f}   (largest |Δ|)")
    summary = study.summary()
    f, xi = summary["frequency"], summary["damping_ratio"]
    _say(f"\n  result: f_h1 = {f['nominal']:.2f} ± {f['bound']:.2f} Hz, "
         f"ξ_h1 = {xi['nominal']:.2f} ± {xi['bound']:.2f}  (nominal ± joint bound)")
    if lengths:
        _say("  record length: " + ", ".join(
            f"{r['duration']:g} s → {r['frequency']:.3f} Hz" for r in lengths if "error" not in r))
    axes = plot_estimation_errors(study, title=f"{case.name}: estimation error Δ")
    figure = save_figure(axes, out / "estimation_errors.png").name
    write_json(out / "results.json", {
        "command": "sensitivity", "crowdvib_version": __version__, "versions": _versions(),
        "seed": case.seed, "case": str(case.path), "inputs": case.to_dict(),
        "estimate": {"frequency": study.nominal["frequency"],
                     "damping_ratio": study.nominal["damping_ratio"],
                     "mass_ratio": study.nominal["mass_ratio"]},
        "expected": dict(case.expected), "sensitivity": study.to_dict(),
        "record_length": lengths, "figures": [figure], **stamp})
    _say(f"  wrote {out / 'results.json'}, {figure} and {write_report(out).name}")
    return 0


def _add_simulate_arguments(parser):
    parser.add_argument("case", type=Path, nargs="?", default=None,
                        help="case file (TOML); default the embedded paper example")
    parser.add_argument("--out", type=Path, required=True, help="output directory")
    parser.add_argument("--force", action="store_true",
                        help="replace an existing output directory")
    parser.add_argument("--duration-s", type=float, default=None,
                        help="record length [s] (default the case's simulation.duration)")
    parser.add_argument("--sample-rate", type=float, default=None,
                        help="simulation sample rate [Hz] (default the case's)")
    parser.add_argument("--seed", type=int, default=None,
                        help="seed of every random draw (default the case's seed)")
    parser.add_argument("--format", default=None,
                        help="comma-separated record formats among csv, npz, mat, mat73, uff "
                             "(default the case's simulation.formats)")
    parser.add_argument("--no-hsi", action="store_true",
                        help="pedestrians as moving forces only (no MSD)")


def _run_simulate(args):
    from ..io.casefile import load_case, paper_example_case
    from ..errors import ParameterError
    from ..reporting.plotting import plot_psd_comparison, plot_time_history, save_figure
    from ..io.records import RECORD_FORMATS, Record, write_record
    from ..signals import resample, welch_psd
    from ..response.simulation import simulate

    case = paper_example_case() if args.case is None else load_case(args.case)
    spec = case.simulation
    formats = spec.formats if args.format is None else tuple(
        f.strip() for f in args.format.split(",") if f.strip())
    for fmt in formats:
        if fmt not in RECORD_FORMATS:
            raise ParameterError(f"--format must list formats among {list(RECORD_FORMATS)}, "
                                 f"got {fmt!r}")
    duration = spec.duration if args.duration_s is None else args.duration_s
    sample_rate = spec.sample_rate if args.sample_rate is None else args.sample_rate
    seed = case.seed if args.seed is None else args.seed
    msd = None if (args.no_hsi or not spec.hsi) else _simulation_msd(case)
    _say(f"crowdvib simulate: {case.name}, {duration:g} s at {sample_rate:g} Hz, "
         f"{'MSD ' + str(msd.to_dict()) if msd else 'no HSI'}")
    with _staged_output(args.out, args.force) as staging:
        started = time.perf_counter()
        simulation = simulate(case.structure, case.crowd, duration, msd=msd,
                              sample_rate=sample_rate, rng=seed, warm_up=spec.warm_up,
                              progress=_progress_printer("simulated"))
        data, rate = simulation.acceleration, sample_rate
        if spec.record_sample_rate is not None:
            data, rate = resample(data, rate, spec.record_sample_rate)
        record = Record(data=data, sample_rate=rate, channel_names=simulation.output_names)
        files = []
        for fmt in formats:
            suffix = "_v73.mat" if fmt == "mat73" else RECORD_FORMATS[fmt][0]
            files.append(write_record(record, staging / f"record{suffix}", format=fmt,
                                      dtype=spec.dtype).name)
        elapsed = time.perf_counter() - started
        window = min(case.measurement.window_length, record.duration)
        psd = welch_psd(record.data, rate, window_length=window,
                        output_names=record.channel_names)
        figure = save_figure(plot_psd_comparison({"simulated (Welch)": psd},
                                                 band=(0.0, min(rate / 2, 12.0)),
                                                 title=f"{case.name}: simulated record"),
                             staging / "psd.png").name
        history = save_figure(plot_time_history(simulation,
                                                title=f"{case.name}: simulated time history"),
                              staging / "time_history.png").name
        results = {"command": "simulate", "crowdvib_version": __version__,
                   "versions": _versions(), "seed": int(simulation.seed),
                   "case": None if case.path is None else str(case.path),
                   "inputs": case.to_dict(), "msd": None if msd is None else msd.to_dict(),
                   "duration": duration, "sample_rate": sample_rate,
                   "record": {**record.to_dict(), "files": files},
                   "rms": dict(zip(record.channel_names, np.sqrt(np.mean(
                       (record.data - record.data.mean(axis=1, keepdims=True)) ** 2,
                       axis=1)).tolist())),
                   "elapsed_s": elapsed, "figures": [figure, history],
                   **provenance(case.path)}
        write_json(staging / "results.json", results)
        write_report(staging)
    _say(f"  wrote {', '.join(files)} and results.json to {args.out} ({elapsed:.1f} s)")
    return 0


def _progress_printer(label, unit="s"):
    """A ``progress(done, total)`` callback drawing a progress bar on stderr.

    On a terminal the bar is redrawn in place with the elapsed and remaining time; in a log
    (not a terminal) a line is written every 10 %.
    """
    shown = [-1]
    started = time.perf_counter()
    terminal = sys.stderr.isatty()

    def progress(done, total):
        fraction = min(done / total, 1.0) if total > 0 else 1.0
        elapsed = time.perf_counter() - started
        left = f"~{elapsed * (1 - fraction) / fraction:.0f} s left" if fraction > 0 else ""
        text = (f"  {label} {done:.0f}/{total:.0f} {unit} "
                f"[{'#' * int(30 * fraction):30s}] {fraction:4.0%}  {elapsed:.0f} s elapsed {left}")
        if terminal:
            end = "\n" if fraction >= 1 else ""
            print("\r" + text, end=end, file=sys.stderr, flush=True)
        elif int(10 * fraction) > shown[0]:
            shown[0] = int(10 * fraction)
            print(text, file=sys.stderr, flush=True)

    return progress


def _simulation_msd(case):
    """The MSD a case simulates with: its [expected] truth if given, else its [hsi] table."""
    from ..models.pedestrian import MSDModel

    expected = case.expected
    if "frequency" in expected and "damping_ratio" in expected:
        return MSDModel(expected["frequency"], expected["damping_ratio"],
                        expected.get("mass_ratio", case.msd.mass_ratio))
    return case.msd


# ------------------------------------------------------------------------------------- report
def _add_report_arguments(parser):
    parser.add_argument("directory", type=Path,
                        help="results directory written by a crowdvib command (holds "
                             "results.json)")


def _run_report(args):
    path = write_report(args.directory)
    _say(f"wrote {path}")
    return 0


# --------------------------------------------------------------------------------------- main
_COMMANDS = {
    "demo": ("estimate the MSD parameters back on the paper's numerical example",
             _add_demo_arguments, _run_demo),
    "estimate": ("estimate the MSD parameters from a case file's measured records",
                 _add_estimate_arguments, _run_estimate),
    "simulate": ("simulate a case (default: the paper example) and write its record",
                 _add_simulate_arguments, _run_simulate),
    "report": ("write report.html, a self-contained HTML report, into a results directory",
               _add_report_arguments, _run_report),
    "map": ("evaluate the objective J(f_h1, ξ_h1) of a case on a grid",
            _add_map_arguments, _run_map),
    "sensitivity": ("estimation error from modelling errors and record length: nominal ± bound",
                    _add_sensitivity_arguments, _run_sensitivity),
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
