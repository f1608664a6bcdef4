"""``crowdvib sensitivity``: modelling errors and record length → nominal ± bound (paper Figs. 11, 19)."""

import contextlib
from pathlib import Path


from .. import __version__
from .._files import write_json
from ..reporting.report import provenance, write_report
from .common import case_inputs, finish_output, prepare_output, progress_printer, say, versions
from .estimate import case_crowd, case_measurement, estimate_options


#: Task-store subdirectories of --out (files a resumable study writes while it runs).
_STORES = ("tasks", "record_length")


def add_arguments(parser):
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


def run(args):
    from ..io.casefile import load_case
    from ..reporting.plotting import plot_estimation_errors, save_figure
    from ..identification.sensitivity import TaskStore, modelling_error_study, record_length_study

    case = load_case(args.case)
    stamp = provenance(case.path)
    out = prepare_output(args.out, force=args.force, resume=args.resume,
                         inputs=case_inputs(case), command="sensitivity", stores=_STORES)
    say(f"crowdvib sensitivity: {case.name} ({case.path.name})")
    record, measured, lowpass = case_measurement(case)
    crowd, _ = case_crowd(case, record)
    options = estimate_options(case)
    for key in ("method", "interval", "level"):
        options.pop(key)
    store = TaskStore(out / "tasks")
    done = len(store.keys())
    if done:
        say(f"  resuming: {done} finished task(s) found in {store.directory}")
    with _executor(args.workers, args.scheduler) as executor:
        study = modelling_error_study(measured, case.structure, crowd, joint=not args.no_joint,
                                      executor=executor, store=store,
                                      progress=progress_printer("estimations", unit="tasks"),
                                      **options)
        lengths = None
        if not args.no_record_length:
            options.pop("band")
            lengths = record_length_study(
                record.data, record.sample_rate, case.structure, crowd,
                window_length=case.measurement.window_length, band=case.estimation.band,
                output_names=record.channel_names, lowpass=lowpass, executor=executor,
                store=TaskStore(out / "record_length"), **options)
    say(f"\n  {'case':34s}{'Δ f_h1 [%]':>12s}{'Δ ξ_h1 [%]':>12s}")
    for row in study.cases:
        if row["kind"] == "individual":
            text = (f"{row['delta_frequency']:12.2f}{row['delta_damping_ratio']:12.2f}"
                    if "error" not in row else "  failed: " + row["error"])
            say(f"  {row['name']:34s}{text}")
    for level in sorted({c["level"] for c in study.cases if c["kind"] == "joint"}):
        bound = study.bound(level)
        say(f"  {'joint, level ' + str(level):34s}{bound['frequency']:12.2f}"
             f"{bound['damping_ratio']:12.2f}   (largest |Δ|)")
    summary = study.summary()
    f, xi = summary["frequency"], summary["damping_ratio"]
    say(f"\n  result: f_h1 = {f['nominal']:.2f} ± {f['bound']:.2f} Hz, "
         f"ξ_h1 = {xi['nominal']:.2f} ± {xi['bound']:.2f}  (nominal ± joint bound)")
    if lengths:
        say("  record length: " + ", ".join(
            f"{r['duration']:g} s → {r['frequency']:.3f} Hz" for r in lengths if "error" not in r))
    axes = plot_estimation_errors(study, title=f"{case.name}: estimation error Δ")
    figure = save_figure(axes, out / "estimation_errors.png").name
    write_json(out / "results.json", {
        "command": "sensitivity", "crowdvib_version": __version__, "versions": versions(),
        "seed": case.seed, "case": str(case.path), "inputs": case.to_dict(),
        "estimate": {"frequency": study.nominal["frequency"],
                     "damping_ratio": study.nominal["damping_ratio"],
                     "mass_ratio": study.nominal["mass_ratio"]},
        "expected": dict(case.expected), "sensitivity": study.to_dict(),
        "record_length": lengths, "figures": [figure], **stamp})
    report = write_report(out)
    finish_output(out, command="sensitivity", stores=_STORES)
    say(f"  wrote {out / 'results.json'}, {figure} and {report.name}")
    return 0
