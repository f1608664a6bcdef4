"""``crowdvib sensitivity`` as a call: a case's modelling-error study written in place, task by
task, so that an interrupted study resumes where it stopped (paper Figs. 11, 19)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..cases.results import Results, provenance
from .folders import case_inputs, check_clash, finish_output, prepare_output
from .lines import Progress, Say, as_case, recorded_warnings, silent
from .._files import folder_lock
from ..cases import identified_levels
from ..cases.study import STUDY_STORES
from ..runner import TaskStore
from .._files import write_json
from .._manifest import record_file
from ..cases import CaseRecordFit, case_crowd, measure_case, study_case
from ..reporting.plotting import plot_estimation_errors, save_figure
from ..reporting.report import case_template, write_report
from ..runner import study_executor
from .estimate import crowd_line, measurement_line

if TYPE_CHECKING:
    from ..io.casefile import Case

__all__ = ["run_sensitivity", "finished_tasks"]


def run_sensitivity(case: Case | str | Path, out: str | Path, *, workers: int = 1,
                    scheduler: str | None = None, hung_after: float = 60.0,
                    joint: bool = True, record_length: bool = True,
                    modes_from: str | Path | None = None, resume: bool = False,
                    force: bool = False, say: Say = silent, progress: Progress | None = None
                    ) -> Results:
    """What ``crowdvib sensitivity`` does: :func:`~crowdvib.cases.study_case`, its figure,
    results.json and report.html in ``out``.

    ``out`` is written in place under an incomplete manifest, each finished task kept in its
    task store: after an interruption (``KeyboardInterrupt`` propagates; :func:`finished_tasks`
    counts what was kept) the same call with ``resume=True`` computes only the tasks not
    finished, and those whose inputs changed since.

    Parameters
    ----------
    case : Case, str or pathlib.Path
        One ``[measurement]``, or its file (read here: the warnings of reading it are recorded
        with the run's).
    out : str or pathlib.Path
        The results folder (:func:`~crowdvib.runs.prepare_output`'s rules).
    workers, scheduler, hung_after
        Where the tasks run (:func:`~crowdvib.runner.study_executor`: local worker processes,
        1 this one; a dask scheduler's address; the time after which a local task is hung).
    joint, record_length
        As :func:`~crowdvib.cases.study_case`.
    modes_from : str or pathlib.Path, optional
        A results folder of ``crowdvib modes``: error levels from its identified modes
        (:func:`~crowdvib.cases.identified_levels`).
    resume, force : bool
        Continue the study in ``out``; replace crowdvib's earlier results in it.
    say : callable, optional
        Called with each line the command prints.
    progress : callable, optional
        ``progress(label, unit)`` → the ``progress(done, total)`` callback of a stage
        (``"estimations"``, ``"record lengths"``) [tasks].

    Returns
    -------
    Results
        As written, with the run's warnings (:func:`~crowdvib.runs.lines.recorded_warnings`:
        each also shown when it happens).
    """

    with recorded_warnings() as caught:
        case = as_case(case)
        levels = None if modes_from is None else identified_levels(modes_from)
        check_clash(out, case_inputs(case))
        # The study writes `out` in place, task by task: no second run may write it meanwhile.
        with folder_lock(out, "sensitivity"):
            return _study(case, Path(out), levels, modes_from, resume=resume, force=force,
                          workers=workers, scheduler=scheduler, hung_after=hung_after,
                          joint=joint, record_length=record_length, say=say,
                          progress=None if progress is None
                          else (lambda stage: progress(stage, "tasks")), caught=caught)


def finished_tasks(out: str | Path) -> int:
    """How many finished tasks a study's folder keeps (what a resumed run will not repeat)."""

    return sum(len(TaskStore(Path(out) / name).keys()) for name in STUDY_STORES
               if (Path(out) / name).is_dir())


def _study(case, out, levels, modes_from, *, resume, force, workers, scheduler, hung_after,
           joint, record_length, say, progress, caught):
    stamp = provenance(case.path)
    prepare_output(out, force=force, resume=resume, inputs=case_inputs(case),
                   command="sensitivity", stores=STUDY_STORES)
    say(f"crowdvib sensitivity: {case.name} ({case.path.name})")
    if levels is not None:
        say(f"  error levels from {modes_from}: frequencies "
            f"{', '.join(f'{v:.2%}' for v in levels['frequencies'])}, damping ratios "
            f"{', '.join(f'{v:.1%}' for v in levels['damping_ratios'])} (1 and 2 σ of the least "
            "certain identified mode)")
    measurement = measure_case(case)
    say(measurement_line(measurement))
    record = CaseRecordFit(case, measurement, *case_crowd(case, measurement.record))
    if crowd_line(case, record.step_frequencies) is not None:
        say(crowd_line(case, record.step_frequencies))
    store = TaskStore(out / "tasks")
    done = len(store.keys())
    if done:
        say(f"  resuming: {done} finished task(s) found in {store.directory}")
    with study_executor(workers, scheduler, timeout_floor=hung_after) as executor:
        found = study_case(case, record=record, levels=levels, joint=joint,
                           record_length=record_length, executor=executor, directory=out,
                           progress=progress)
    _say_study(found, joint, say)
    axes = plot_estimation_errors(found.study, title=f"{case.name}: estimation error Δ")
    # Each file is listed in the manifest once written: a run that fails on the next one (a
    # full disk) leaves only files crowdvib owns, so --resume may replace them.
    figure = save_figure(axes, out / "estimation_errors.png").name
    record_file(out, figure, "sensitivity")
    results = {**found.to_dict(), "figures": [figure], **stamp,
               "warnings": list(caught)}
    write_json(out / "results.json", results)
    record_file(out, "results.json", "sensitivity")
    report = write_report(out, template=case_template(results))
    finish_output(out, command="sensitivity", stores=STUDY_STORES)
    say(f"  wrote {out / 'results.json'}, {figure} and {report.name}")
    return Results.from_dict(results)


def _say_study(found, joint, say):
    """The study's table, its result (nominal ± bound) and the record's interval beside it."""
    study, lengths = found.study, found.lengths
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
        f"{'joint bound' if joint else 'largest single-error change'})")
    # The record's statistical interval beside the modelling bound, and both together.
    combined = found.combined
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
