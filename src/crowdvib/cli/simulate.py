"""``crowdvib simulate``: a simulated record of a case, written in the chosen formats."""

import time
from pathlib import Path

from .._files import unique_filenames
from ..cases.results import provenance
from .common import (add_output_arguments, case_inputs, progress_printer, record_formats, say,
                     say_if_compiling, say_verdict, staged_output, write_results)


def add_arguments(parser):
    parser.add_argument("case", type=Path, nargs="?", default=None,
                        help="case file (TOML); default the embedded paper example")
    add_output_arguments(parser)
    parser.add_argument("--duration-s", type=float, default=None,
                        help="record length [s] (default the case's simulation.duration)")
    parser.add_argument("--sample-rate", type=float, default=None,
                        help="simulation sample rate [Hz] (default the case's)")
    parser.add_argument("--seed", type=int, default=None,
                        help="seed of every random draw (default the case's seed)")
    parser.add_argument("--format", type=record_formats, default=None,
                        help="comma-separated record formats among csv, npz, mat, mat73, uff "
                             "(default the case's simulation.formats)")
    parser.add_argument("--no-hsi", action="store_true",
                        help="pedestrians as moving forces only (no MSD)")


def run(args):
    from ..cases.simulation import simulate_case, simulation_msd
    from ..io.casefile import load_case, paper_example_case
    from ..io.records import RECORD_FORMATS, write_record
    from ..reporting.plotting import plot_psd_comparison, plot_time_history, save_figure
    from ..signals import welch_psd

    case = paper_example_case() if args.case is None else load_case(args.case)
    spec = case.simulation
    formats = spec.formats if args.format is None else args.format
    duration = spec.duration if args.duration_s is None else args.duration_s
    sample_rate = spec.sample_rate if args.sample_rate is None else args.sample_rate
    hsi = spec.hsi and not args.no_hsi
    msd = simulation_msd(case) if hsi else None
    pedestrians = ("moving forces only (no HSI)" if msd is None else
                   f"MSD pedestrians f_h1 = {msd.frequency:g} Hz, ξ_h1 = {msd.damping_ratio:g}, "
                   f"μ_h1 = {msd.mass_ratio:g}")
    say(f"crowdvib simulate: {case.name}, {duration:g} s at {sample_rate:g} Hz, {pedestrians}")
    with staged_output(args.out, args.force, command="simulate",
                       inputs=case_inputs(case)) as staging:
        started = time.perf_counter()
        say_if_compiling(case.structure, hsi)
        found = simulate_case(case, duration=duration, sample_rate=sample_rate, seed=args.seed,
                              hsi=hsi, progress=progress_printer(
                                  f"simulated (after {spec.warm_up:g} s warm-up)",
                                  offset=spec.warm_up))
        simulation, record = found.simulation, found.record
        files = []
        for fmt in formats:
            suffix = "_v73.mat" if fmt == "mat73" else RECORD_FORMATS[fmt][0]
            files.append(write_record(record, staging / f"record{suffix}", format=fmt,
                                      dtype=spec.dtype).name)
        elapsed = time.perf_counter() - started
        window = min(case.measurement.window_length, record.duration)
        psd = welch_psd(record.data, record.sample_rate, window_length=window,
                        output_names=record.channel_names)
        # Every output on the PSD figure, named; one time history per output.
        figures = [save_figure(plot_psd_comparison(
            {name: psd.select(name) for name in psd.output_names},
            band=(0.0, min(record.sample_rate / 2, 12.0)),
            title=f"{case.name}: simulated record (Welch PSD)"), staging / "psd.png").name]
        names = unique_filenames(simulation.output_names, prefix="time_history_", suffix=".png",
                                 taken=("psd.png",))
        for name in simulation.output_names:
            figures.append(save_figure(plot_time_history(
                simulation, output=name, title=f"{case.name}: simulated time history at {name}"),
                staging / names[name]).name)
        results = found.to_dict()
        results["record"]["files"] = files
        results.update({"elapsed_s": elapsed, "figures": figures, **provenance(case.path)})
        write_results(staging, results)
    say(f"  wrote {', '.join(files)} and results.json to {args.out} ({elapsed:.1f} s)")
    return say_verdict(args.out)
