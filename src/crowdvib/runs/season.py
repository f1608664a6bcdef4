"""``crowdvib season`` as a call: a monitoring season's records estimated one by one and together,
written in place, task by task, so that an interrupted season resumes where it stopped."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import TYPE_CHECKING

from .._estimators import METHOD_WORDS
from ..cases.results import Results, provenance
from ..errors import CrowdvibError
from .folders import case_inputs, check_clash, finish_output, prepare_output
from .lines import Say, caught_warnings, silent, warning_texts
from .._files import folder_lock
from ..cases import plan_season
from ..io.crowdtable import read_crowd_table
from .._files import write_json
from .._manifest import record_file
from ..reporting.plotting import save_figure
from ..reporting.report import case_template, write_report
from ..runner import TaskStore, study_executor

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    from ..io.casefile import Case

__all__ = ["run_season", "SEASON_STORES"]

#: Task-store subfolder of a season's folder: one file per estimated record or window.
SEASON_STORES = ("tasks",)


def run_season(case: Case, crowd_table: str | Path, out: str | Path, *,
               records: str | Path | Sequence | None = None, workers: int = 1,
               scheduler: str | None = None, hung_after: float = 60.0, joint: bool = True,
               joint_min_density: float = 0.0, batch_size: int | None = None, resume: bool = False, force: bool = False,
               say: Say = silent, progress: Callable[[int, int], None] | None = None) -> Results:
    """What ``crowdvib season`` does: :func:`~crowdvib.cases.season_case`, its table (CSV, and
    Parquet when pyarrow is installed), trend figure, results.json and report.html in ``out``.

    Parameters
    ----------
    case : Case
    crowd_table : str or pathlib.Path
        The crowd table CSV (:func:`crowdvib.io.read_crowd_table`).
    out : str or pathlib.Path
        The results folder, written in place (each finished record kept in ``out/tasks``).
    records : path or sequence of paths, optional
        As :func:`~crowdvib.cases.season_case`.
    workers, scheduler, hung_after
        Where the tasks run (:func:`~crowdvib.runner.study_executor`).
    joint, joint_min_density, batch_size
        As :func:`~crowdvib.cases.season_case`.
    resume, force : bool
        Continue the season in ``out``; replace crowdvib's earlier results in it.
    say : callable, optional
        Called with each line the command prints.
    progress : callable, optional
        ``progress(done, total)`` [records].

    Returns
    -------
    Results
        A :class:`~crowdvib.cases.SeasonResults`; ``to_dataframe()`` is the table.
    """

    # Every input is read and checked (the table, its rows against the records) before anything
    # is written: an input error leaves no results folder to refuse a corrected run.
    table = read_crowd_table(crowd_table)
    say(f"crowdvib season: {case.name} ({case.path.name}), crowd table {table.path.name}")
    try:
        with caught_warnings() as planned:
            plan = plan_season(case, table, records=records)
    except CrowdvibError:
        for found in planned:        # the doubts that led to the error, raised with it
            warnings.warn_explicit(found.message, found.category, found.filename, found.lineno)
        raise
    inputs = [*case_inputs(case), ("the crowd table", table.path)]
    check_clash(out, inputs)
    with folder_lock(out, "season"):
        return _season(plan, Path(out), inputs, list(planned), workers=workers,
                       scheduler=scheduler, hung_after=hung_after, joint=joint,
                       joint_min_density=joint_min_density, batch_size=batch_size,
                       resume=resume, force=force, say=say, progress=progress)


def _season(plan, out, inputs, planned, *, workers, scheduler, hung_after, joint,
            joint_min_density, batch_size, resume, force, say, progress):
    case, table = plan.case, plan.table
    stamp = provenance(case.path)
    prepare_output(out, force=force, resume=resume, inputs=inputs, command="season",
                   stores=SEASON_STORES)
    store = TaskStore(out / "tasks")
    done = len(store.keys())
    if done:
        say(f"  resuming: {done} finished record(s) found in {store.directory}")
    where = (f"on the dask cluster {scheduler}" if scheduler is not None
             else f"on {workers} worker(s)" if workers != 1 else "in this process")
    tasks = sum(payload is not None for _, payload, _ in plan.windows)
    say(f"  {len(table)} row(s) of {table.path.name} on {plan.records} record(s): estimating "
        f"{tasks} row(s) {where}, each with its interval …")
    with caught_warnings() as caught:
        with study_executor(workers, scheduler, timeout_floor=hung_after) as executor:
            found = plan.run(joint=joint, joint_min_density=joint_min_density,
                             executor=executor, store=store, progress=progress,
                             batch_size=batch_size, say=say)
    season = found.season
    _say_season(found, say)
    say("  writing the table, the trend figure and the report …")
    written = []
    for name, write in (("season.csv", season.to_csv), ("season.parquet", season.to_parquet)):
        try:
            write(out / name)
        except ModuleNotFoundError as error:       # Parquet without pyarrow: the CSV is there
            say(f"  not written: {name} ({error})")
            continue
        record_file(out, name, "season")
        written.append(name)
    figure = save_figure(season.plot(title=f"{case.name}: f_h1 and ξ_h1 over the season"),
                         out / "season_trends.png").name
    record_file(out, figure, "season")
    results = {**found.to_dict(), "tables": written, "figures": [figure],
               "warnings": warning_texts(planned + list(caught)), **stamp}
    write_json(out / "results.json", results)
    record_file(out, "results.json", "season")
    report = write_report(out, template=case_template(results))
    finish_output(out, command="season", stores=SEASON_STORES)
    say(f"  wrote {out / 'results.json'}, {', '.join(written)}, {figure} and {report.name}")
    return Results.from_dict(results)


def _say_season(found, say):
    """The table's counts, each record's line, and the joint estimate with its interval."""
    rows = found.season.table()
    states = {state: sum(row["status"] == state for row in rows)
              for state in ("ok", "doubt", "error", "skipped")}
    say(f"  {len(rows)} row(s): " + ", ".join(f"{n} {state}" for state, n in states.items() if n)
        + (f"; {len(found.unmatched)} record(s) not in the crowd table" if found.unmatched
           else ""))
    say(f"  {'record':32s}{'density':>9s}  {'f_h1 [Hz], 95 %':>24s}  {'ξ_h1 [-], 95 %':>24s}")
    for row in rows:
        if row["status"] in ("ok", "doubt"):
            cells = "  ".join(f"{row[k]:8.3f} ({_end(row[k + '_low'])}–{_end(row[k + '_high'])})"
                              for k in ("frequency", "damping_ratio"))
            say(f"  {row['name'][:32]:32s}{row['density']:9.3f}  {cells}"
                + (f"  doubt: {row['warnings']}" if row["status"] == "doubt" else ""))
        else:
            say(f"  {row['name'][:32]:32s}{row['density']:9.3f}  {row['status']}: "
                f"{row['warnings']}")
    joint = found.season.joint
    if joint is not None:
        method = METHOD_WORDS.get(joint.method, joint.method)
        say(f"  joint estimate ({method}), every record with its crowd: " + "; ".join(
            f"{label} = {joint.value(name):.3f} ({_end(low)}–{_end(high)})"
            for name, label in (("frequency", "f_h1"), ("damping_ratio", "ξ_h1"))
            for low, high in [joint.interval(name, 0.95) if joint.covariance is not None
                              else (None, None)]))


def _end(value):
    return "—" if value is None else f"{value:.3f}"
