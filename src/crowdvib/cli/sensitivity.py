"""``crowdvib sensitivity``: modelling errors and record length → nominal ± bound (paper Figs. 11, 19)."""

import contextlib
import sys
import warnings
from pathlib import Path

from .._version import __version__
from .._files import folder_lock, require_file, write_json
from .._manifest import record_file
from ..cases.schema import schema_header
from ..cases.results import provenance
from .common import (ESTIMATION_TABLES, add_workers_argument, case_inputs, check_clash,
                     close_progress, dask_address, finish_output, prepare_output,
                     progress_printer, say, say_verdict, versions)
from .estimate import say_crowd, say_measurement


#: Task-store subdirectories of --out (files a resumable study writes while it runs).
_STORES = ("tasks", "record_length")


def add_arguments(parser):
    parser.add_argument("case", type=Path, help="case file (TOML) with [measurement] records")
    parser.add_argument("--out", type=Path, required=True, help="output directory")
    add_workers_argument(parser)
    parser.add_argument("--scheduler", type=dask_address, metavar="ADDRESS", default=None,
                        help="run on a dask.distributed scheduler, e.g. tcp://127.0.0.1:8786 "
                             "(needs crowdvib[dask])")
    parser.add_argument("--resume", action="store_true",
                        help="continue an interrupted study in --out without recomputing "
                             "finished tasks; tasks whose inputs (case values, record, options) "
                             "changed since are recomputed, and the command says how many")
    parser.add_argument("--force", action="store_true",
                        help="start afresh, replacing an existing output directory")
    parser.add_argument("--no-joint", action="store_true",
                        help="only individual errors (skip the 2⁵ joint sign combinations)")
    parser.add_argument("--no-record-length", action="store_true",
                        help="skip re-estimating on shorter parts of the record")
    parser.add_argument("--modes-from", type=Path, metavar="DIR", default=None,
                        help="results directory of `crowdvib modes`: the frequency and damping "
                             "error levels become 1 and 2 relative standard deviations of the "
                             "least certain identified mode (instead of 1/5 %% and 10/30 %%)")


def _resume_command(args):
    """The command line that resumes this study, as the user would type it."""
    import shlex

    words = ["crowdvib", "sensitivity", str(args.case), "--out", str(args.out)]
    if args.scheduler is not None:
        words += ["--scheduler", args.scheduler]
    elif args.workers != 1:     # the results do not depend on it; said as given
        words += ["--workers", str(args.workers)]
    words += [flag for flag, given in (("--no-joint", args.no_joint),
                                       ("--no-record-length", args.no_record_length)) if given]
    if args.modes_from is not None:
        words += ["--modes-from", str(args.modes_from)]
    return shlex.join(words + ["--resume"])


def _identified_levels(directory):
    """Error levels from the results.json of ``crowdvib modes`` in ``directory``."""
    import json

    from ..errors import DataError
    from ..oma.identify import identified_error_levels

    path = require_file(Path(directory) / "results.json", "crowdvib modes results")
    try:
        results = json.loads(path.read_text(encoding="utf-8"))
        modes = results["modes"] if results.get("command") == "modes" else None
        columns = {key: [float(mode[key]) for mode in modes] for key in
                   ("frequency", "frequency_std", "damping_ratio", "damping_std")}
    except (ValueError, KeyError, TypeError, UnicodeDecodeError) as exc:
        raise DataError(f"{path}: is not the results.json of `crowdvib modes` (a 'modes' list "
                        f"with frequency, frequency_std, damping_ratio, damping_std): "
                        f"{type(exc).__name__}: {exc}") from None
    return identified_error_levels(columns["frequency"], columns["frequency_std"],
                                   columns["damping_ratio"], columns["damping_std"])


@contextlib.contextmanager
def _warnings_as_lines():
    """Print each crowdvib warning as one line on stderr when it happens (a damaged task file,
    inputs changed since the study began), not as a Python warning with a source line."""
    from ..errors import CrowdvibWarning

    with warnings.catch_warnings():
        others = warnings.showwarning

        def show(message, category, *rest):
            if not issubclass(category, CrowdvibWarning):
                return others(message, category, *rest)
            print(f"crowdvib sensitivity: warning: {message}", file=sys.stderr, flush=True)

        warnings.simplefilter("always", CrowdvibWarning)
        warnings.showwarning = show
        yield


def _estimate_with_warnings(measured, structure, crowd, options):
    """The record's estimate and the crowdvib warnings it gave ``(category, message)``, for
    this process to show (a worker's warnings would not reach the user)."""
    from ..errors import CrowdvibWarning
    from ..identification import estimate_hsi

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", CrowdvibWarning)
        estimate = estimate_hsi(measured, structure, crowd, **options)
    return estimate, [(w.category, str(w.message)) for w in caught
                      if issubclass(w.category, CrowdvibWarning)]


def run(args):
    from ..io.casefile import load_case

    case = load_case(args.case)
    levels = None if args.modes_from is None else _identified_levels(args.modes_from)
    check_clash(args.out, case_inputs(case))
    # The study writes --out in place, task by task: no second run may write it meanwhile.
    with folder_lock(args.out, "sensitivity"):
        return _study(args, case, levels)


def _study(args, case, levels):
    from ..cases import case_crowd, estimate_options, measure_case
    from ..reporting.plotting import plot_estimation_errors, save_figure
    from ..reporting.report import write_report
    from ..runner import TaskStore, study_executor
    from ..studies import modelling_error_study, record_length_study

    stamp = provenance(case.path)
    out = prepare_output(args.out, force=args.force, resume=args.resume,
                         inputs=case_inputs(case), command="sensitivity", stores=_STORES)
    say(f"crowdvib sensitivity: {case.name} ({case.path.name})")
    if levels is not None:
        say(f"  error levels from {args.modes_from}: frequencies "
            f"{', '.join(f'{v:.2%}' for v in levels['frequencies'])}, damping ratios "
            f"{', '.join(f'{v:.1%}' for v in levels['damping_ratios'])} (1 and 2 σ of the least "
            "certain identified mode)")
    measurement = measure_case(case)
    say_measurement(measurement)
    record, measured, lowpass = measurement.record, measurement.psd, measurement.lowpass
    crowd, fitted = case_crowd(case, record)
    say_crowd(case, crowd, fitted)
    options = estimate_options(case, point_only=True)    # the study compares point estimates
    store = TaskStore(out / "tasks")
    done = len(store.keys())
    if done:
        say(f"  resuming: {done} finished task(s) found in {store.directory}")
    try:
        with _warnings_as_lines(), study_executor(args.workers, args.scheduler,
                                                   timeout_floor=args.hung_after) as executor:
            # The record's own estimate with its interval, beside the studies on a worker (it
            # was the longest step left in this process, measured in issue 14).
            record_estimate = (measured, case.structure, crowd, estimate_options(case))
            pending = (executor.submit(_estimate_with_warnings, *record_estimate)
                       if executor is not None else None)
            study = modelling_error_study(
                measured, case.structure, crowd, levels=levels, joint=not args.no_joint,
                executor=executor, store=store,
                progress=progress_printer("estimations", unit="tasks"), **options)
            lengths = None
            if not args.no_record_length:
                options.pop("band")
                lengths = record_length_study(
                    record.data, record.sample_rate, case.structure, crowd,
                    window_length=case.measurement.window_length, band=case.estimation.band,
                    output_names=record.channel_names, lowpass=lowpass, executor=executor,
                    store=TaskStore(out / "record_length"),
                    progress=progress_printer("record lengths", unit="tasks"), **options)
            nominal, caught = (pending.result() if pending is not None
                               else _estimate_with_warnings(*record_estimate))
            for category, message in caught:
                warnings.warn(message, category, stacklevel=1)
    except KeyboardInterrupt:
        # Every finished task is already on disk; the cluster is closed by now.
        kept = sum(len(TaskStore(out / name).keys()) for name in ("tasks", "record_length")
                   if (out / name).is_dir())
        close_progress()
        print(f"crowdvib sensitivity: interrupted, {kept} finished task(s) kept in {out}; "
              f"resume with: {_resume_command(args)}", file=sys.stderr, flush=True)
        return 130
    say(f"\n  {'case':34s}{'Δ f_h1 [%]':>12s}{'Δ ξ_h1 [%]':>12s}")
    for row in study.cases:
        if row["kind"] == "individual":
            text = (f"{row['delta_frequency']:12.2f}{row['delta_damping_ratio']:12.2f}"
                    if "error" not in row else "  failed: " + row["error"])
            say(f"  {row.get('label', row['name']):34s}{text}")
    for level in sorted({c["level"] for c in study.cases if c["kind"] == "joint"}):
        bound = study.bound(level)
        say(f"  {'joint, level ' + str(level + 1):34s}{bound['frequency']:12.2f}"
             f"{bound['damping_ratio']:12.2f}   (largest |Δ|)")
    summary = study.summary()
    f, xi = summary["frequency"], summary["damping_ratio"]
    say(f"\n  result: f_h1 = {f['nominal']:.2f} ± {f['bound']:.2f} Hz, "
         f"ξ_h1 = {xi['nominal']:.2f} ± {xi['bound']:.2f}  (nominal ± "
         f"{'largest single-error change' if args.no_joint else 'joint bound'})")
    # The record's statistical interval beside the modelling bound, and both together.
    combined = study.combined(nominal) if nominal.covariance is not None else None
    for name, label, unit in (("frequency", "f_h1", " Hz"), ("damping_ratio", "ξ_h1", "")):
        if combined:
            row = combined[name]
            say(f"  {label}: {100 * row['level']:g} % interval {row['interval'][0]:.3g}–"
                f"{row['interval'][1]:.3g}{unit}, modelling ± {row['bound']:.2g}{unit}, "
                f"together {row['combined'][0]:.3g}–{row['combined'][1]:.3g}{unit} "
                "(interval widened by the bound)")
    if lengths:
        say("  record length: " + ", ".join(
            f"{r['duration']:g} s → {r['frequency']:.3f} Hz" for r in lengths if "error" not in r))
    axes = plot_estimation_errors(study, title=f"{case.name}: estimation error Δ")
    # Each file is listed in the manifest once written: a run that fails on the next one (a
    # full disk) leaves only files crowdvib owns, so --resume may replace them.
    figure = save_figure(axes, out / "estimation_errors.png").name
    record_file(out, figure, "sensitivity")
    write_json(out / "results.json", {
        **schema_header("sensitivity"), "command": "sensitivity",
        "crowdvib_version": __version__, "versions": versions(),
        "seed": case.seed, "case": str(case.path), "inputs": case.to_dict(ESTIMATION_TABLES),
        "estimate": {"frequency": study.nominal["frequency"],
                     "damping_ratio": study.nominal["damping_ratio"],
                     "mass_ratio": study.nominal["mass_ratio"],
                     **{key: value for key, value in nominal.to_dict()["estimate"].items()
                        if key in ("interval", "standard_error")}},
        "combined": combined,
        "expected": dict(case.expected), "sensitivity": study.to_dict(),
        "record_length": lengths, "figures": [figure], **stamp})
    record_file(out, "results.json", "sensitivity")
    report = write_report(out)
    finish_output(out, command="sensitivity", stores=_STORES)
    say(f"  wrote {out / 'results.json'}, {figure} and {report.name}")
    return say_verdict(out)
