"""A season of monitoring at scale (issue 28 §2, §4): per-task overhead, records per minute on the
local pool and on dask, and a synthetic season identified back.

    python benchmarks/bench_season.py [--records N] [--workers 2] [--synthetic M]
                                      [--estimator least_squares|default] [--simulate]
                                      [--keep DIR]
                                      [--skip-dask] [--skip-hours]

Four tables, each with the machine's load beside it (asserts nothing):

1. Per-task overhead: trivial tasks through :func:`crowdvib.runner.run_tasks` on the local pool
   and on a local multi-process dask cluster, one task per dask task (before batching) and in
   the batches the dask executor asks for (after): CPU of this process (client and scheduler)
   and wall time, per task.
2. (a) N one-hour single-channel records at 100 Hz (Gaussian, the paper's example at densities
   0.2–1.0), read, Welch and estimated with intervals by the default estimator through
   ``season_case`` on the local pool: wall time, per record, the extrapolation to 1000 records,
   peak RSS of this process and of the largest worker (sampled every 0.2 s).
3. (b) The same on a local dask cluster of as many single-threaded worker processes: the ratio
   to the pool.
4. (c) A synthetic season: M records of 600 s at 25 Hz every 10 minutes, 06:00–22:30, with
   densities from a daily profile (morning and evening peaks), the crowd table giving counts
   of persons (rounded, as a counter would), estimated back with the paper's least squares
   (``--estimator default``: crowdvib's default), each record and jointly (``--simulate``:
   records of walkers arriving at random instead of Gaussian records of the smeared crowd;
   ``--keep DIR``: keep them and the finished tasks, so that a re-run resumes): per-record
   coverage of the 95 % intervals, by density, and whether the joint interval covers the truth
   (every row, the rows of 0.3 persons/m² and more, and each whole day of 100 records as a
   season of its own).
"""

import argparse
import contextlib
import math
import os
import tempfile
import threading
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _nothing(payload):
    """A task that does nothing: what is left of its time is the executor's."""
    return {"value": payload}


def _warm(payload):
    """Import what a season's task needs (a worker's first task would pay it otherwise)."""
    import crowdvib.cases.season  # noqa: F401
    import crowdvib.identification.estimation  # noqa: F401

    return {"value": payload}


def _load():
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg()) + \
        f" on {os.cpu_count()} CPUs"


@contextlib.contextmanager
def _peak_rss(every=0.2):
    """Sample this process and its descendants; yields a dict filled on exit with the peak RSS
    [MB] of ``self`` and of the largest descendant (``worker``), and ``cpu``, the CPU time [s]
    of all of them during the block (a descendant's as last sampled: the load-independent cost,
    where wall time on a shared machine is not)."""
    import psutil

    peaks, done, cpu = {"self": 0.0, "worker": 0.0}, threading.Event(), {}
    me = psutil.Process()

    def seconds(process):
        times = process.cpu_times()
        return times.user + times.system

    started = seconds(me)
    before = {child.pid: seconds(child) for child in me.children(recursive=True)}

    def sample():
        while True:
            with contextlib.suppress(psutil.Error):
                peaks["self"] = max(peaks["self"], me.memory_info().rss / 2**20)
                for child in me.children(recursive=True):
                    with contextlib.suppress(psutil.Error):
                        peaks["worker"] = max(peaks["worker"], child.memory_info().rss / 2**20)
                        cpu[child.pid] = seconds(child) - before.get(child.pid, 0.0)
            if done.wait(every):
                return

    thread = threading.Thread(target=sample, daemon=True)
    thread.start()
    try:
        yield peaks
    finally:
        done.set()
        thread.join()
        peaks["cpu"] = seconds(me) - started + sum(cpu.values())


@contextlib.contextmanager
def _dask_cluster(workers):
    """A local dask cluster of ``workers`` single-threaded worker processes on loopback."""
    import distributed

    # Each worker's BLAS, OpenMP and numba get its share of the cores, as crowdvib's local
    # workers do (runner.engine): dask leaves them all cores each.
    share = str(max(1, (os.cpu_count() or 1) // workers))
    env = dict.fromkeys(("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                         "NUMBA_NUM_THREADS"), share)
    with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None,
                                  env=env) as cluster:
        yield cluster.scheduler_address


# ------------------------------------------------------------------------------ 1. overhead
def overhead(n_tasks, workers, dask):
    from crowdvib.runner import run_tasks, study_executor

    tasks = [(f"t{i}", i) for i in range(n_tasks)]
    print(f"\n1. Per-task overhead: {n_tasks} tasks that do nothing, {workers} workers "
          f"({_load()})")
    print(f"  {'executor':36s}{'batch':>7s}{'CPU here / task':>17s}{'wall / task':>14s}")
    runs = [("local pool", {"workers": workers}, None)]
    if dask:
        runs += [("dask, one task each (before)", "dask", 1),
                 ("dask, batched (after)", "dask", None)]
    with contextlib.ExitStack() as stack:
        address = stack.enter_context(_dask_cluster(workers)) if dask else None
        for label, where, batch in runs:
            options = {"scheduler": address} if where == "dask" else where
            with study_executor(**options) as executor:
                run_tasks(_nothing, tasks[:4], executor=executor)          # warm up
                size = batch or (executor.batch_size(n_tasks)
                                 if hasattr(executor, "batch_size") else 1)
                cpu, wall = time.process_time(), time.perf_counter()
                run_tasks(_nothing, tasks, executor=executor, batch_size=size)
                cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
            print(f"  {label:36s}{size:7d}{1e3 * cpu / n_tasks:14.2f} ms"
                  f"{1e3 * wall / n_tasks:11.2f} ms")


# ------------------------------------------------------------------------------ 2., 3. hours
def hours(n_records, workers, dask):
    from crowdvib import load_case
    from crowdvib.cases import season_case
    from crowdvib.models.examples import paper_example
    from crowdvib.runner import run_tasks, study_executor
    from crowdvib.studies.season import write_synthetic_season

    paper = paper_example()
    with tempfile.TemporaryDirectory(prefix="crowdvib-season-") as directory:
        folder = Path(directory)
        started = time.perf_counter()
        table = write_synthetic_season(folder, paper.structure, paper.crowd, paper.msd,
                                       densities=np.linspace(0.2, 1.0, n_records),
                                       duration=3600.0, sample_rate=100.0, rng=2028)
        written = time.perf_counter() - started
        size = sum(p.stat().st_size for p in folder.glob("*.npz")) / 2**20
        text = (ROOT / "examples" / "paper_example.toml").read_text(encoding="utf-8")
        (folder / "season.toml").write_text(text, encoding="utf-8")    # the default estimator
        case = load_case(folder / "season.toml")
        print(f"\n2./3. {n_records} one-hour records at 100 Hz ({size:.0f} MB of NPZ, written in "
              f"{written:.1f} s), default estimator ({case.estimation.method}) with profile "
              f"intervals, {workers} workers ({_load()})")
        print(f"  {'executor':14s}{'wall':>9s}{'per record':>12s}{'1000 records':>14s}"
              f"{'CPU / record':>14s}{'peak RSS here':>15s}{'largest worker':>16s}")
        walls = {}
        for label in ("local pool", "dask") if dask else ("local pool",):
            with contextlib.ExitStack() as stack:
                where = ({"scheduler": stack.enter_context(_dask_cluster(workers))}
                         if label == "dask" else {"workers": workers,
                                                  # a loaded machine stretches a task's wall
                                                  # time past the default 60 s
                                                  "timeout_floor": 3600.0})
                executor = stack.enter_context(study_executor(**where))
                run_tasks(_warm, [(f"w{i}", i) for i in range(4 * workers)], executor=executor)
                with _peak_rss() as peaks, warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    started = time.perf_counter()
                    found = season_case(case, table, records=folder, joint=False,
                                        executor=executor)
                    walls[label] = time.perf_counter() - started
            failed = sum(row["status"] == "error" for row in found.season.table())
            per = walls[label] / n_records
            print(f"  {label:14s}{walls[label]:8.1f}s{per:11.2f}s{1000 * per / 60:11.1f} min"
                  f"{peaks['cpu'] / n_records:13.2f}s"
                  f"{peaks['self']:12.0f} MB{peaks['worker']:13.0f} MB"
                  + (f"   {failed} failed" if failed else ""))
        if dask:
            print(f"  dask / local pool: {walls['dask'] / walls['local pool']:.2f}×")


# ------------------------------------------------------------------------------ 4. synthetic
def daily_profile(hour):
    """Persons/m² on the deck at ``hour`` of the day: a base and morning and evening peaks."""
    return (0.08 + 0.55 * np.exp(-((hour - 8.0) / 1.2) ** 2)
            + 0.75 * np.exp(-((hour - 17.5) / 1.8) ** 2))


def synthetic(n_records, workers, estimator, simulate=False, keep=None):
    from crowdvib import load_case
    from crowdvib.cases import season_case
    from crowdvib.models.examples import paper_example
    from crowdvib.runner import study_executor
    from crowdvib.studies.season import write_synthetic_season

    paper = paper_example()
    starts = [6.0 + k / 6.0 for k in range(100)]                     # 06:00 … 22:30
    days = [(day, hour) for day in range(math.ceil(n_records / len(starts)))
            for hour in starts][:n_records]
    densities = [float(daily_profile(hour)) for _, hour in days]
    times = [f"2026-05-{4 + day:02d}T{int(hour):02d}:{round(60 * (hour % 1)):02d}"
             for day, hour in days]
    with (contextlib.nullcontext(keep) if keep else
          tempfile.TemporaryDirectory(prefix="crowdvib-season-")) as directory:
        folder = Path(directory)
        if not (folder / "records").is_dir():          # --keep: records and tasks of a re-run
            write_synthetic_season(folder / "records", paper.structure, paper.crowd, paper.msd,
                                   densities=densities, duration=600.0, sample_rate=25.0,
                                   times=times, rng=17, simulate=simulate)
        area = paper.structure.area
        # A counter gives whole persons: the table's crowd is the count, rounded.
        lines = ["record,count,time"] + [f"record_{i:03d}.npz,{max(round(d * area), 1)},{t}"
                                         for i, (d, t) in enumerate(zip(densities, times), 1)]
        (folder / "crowd.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
        text = (ROOT / "examples" / "paper_example.toml").read_text(encoding="utf-8")
        if estimator == "least_squares":                        # the paper's
            text = text.replace("[estimation]\n", '[estimation]\nmethod = "least_squares"\n')
        (folder / "season.toml").write_text(text, encoding="utf-8")
        case = load_case(folder / "season.toml")
        with study_executor(workers) as executor, warnings.catch_warnings():
            warnings.simplefilter("ignore")
            started = time.perf_counter()
            found = season_case(case, folder / "crowd.csv", records=folder / "records",
                                executor=executor, store=folder / "tasks")
            wall = time.perf_counter() - started
            # The same rows (from the store), the joint estimate of the crowds of 0.3
            # persons/m² and more only.
            dense = season_case(case, folder / "crowd.csv", records=folder / "records",
                                store=folder / "tasks", joint_min_density=0.3).season
            # Each day a season of its own (its rows from the store): as many draws of the
            # joint interval's coverage as there are whole days.
            day_seasons = []
            for day in range(n_records // len(starts)):
                table = folder / f"crowd_day{day + 1}.csv"
                first = 1 + day * len(starts)
                table.write_text("\n".join([lines[0], *lines[first:first + len(starts)]])
                                 + "\n", encoding="utf-8")
                day_seasons.append(season_case(case, table, records=folder / "records",
                                               store=folder / "tasks").season)
    season, truth = found.season, paper.msd
    coverage = season.coverage(truth.to_dict())
    rows = season.table()
    states = [row["status"] for row in rows]
    print(f"\n4. A synthetic season: {n_records} records of 600 s at 25 Hz, densities "
          f"{min(densities):.2f}–{max(densities):.2f} persons/m² from a daily profile, counts "
          f"in the table ({'simulated walkers' if simulate else 'Gaussian, smeared crowd'}); "
          f"the {case.estimation.method} estimator per record and jointly; {wall:.0f} s on "
          f"{workers} workers "
          f"({_load()}); {states.count('ok')} ok, {states.count('doubt')} in doubt (on a "
          f"bound), {states.count('error')} failed")
    bins = ((0.0, 0.15), (0.15, 0.3), (0.3, 0.5), (0.5, 10.0))
    print(f"  {'':6s}{'truth':>7s}{'coverage':>10s}" + "".join(
        f"{f'{low:g}–{high:g}' if high < 10 else f'>= {low:g}':>12s}" for low, high in bins)
        + "   (95 % coverage per record, all and by density [persons/m²])")
    for name, label in (("frequency", "f_h1"), ("damping_ratio", "ξ_h1")):
        value = getattr(truth, name)
        cells = []
        for low, high in bins:
            held = [row[f"{name}_low"] <= value <= row[f"{name}_high"] for row in rows
                    if low <= row["density"] < high and row[f"{name}_low"] is not None]
            cells.append(f"{np.mean(held):6.1%} ({len(held):3d})" if held else "—")
        print(f"  {label:6s}{value:7g}{coverage[name]:10.1%}" + "".join(f"{c:>12s}"
                                                                   for c in cells))
    parts = [(season, "every row"), (dense, "the rows of 0.3 persons/m² and more")] + [
        (day, f"day {number}") for number, day in enumerate(day_seasons, 1)]
    for part, which in parts:
        joint, used = part.joint, sum(row["in_joint"] for row in part.table())
        print(f"  joint estimate of {which} ({used}): " + "; ".join(
            f"{label} {joint.value(name):.4f} (95 %: {low:.4f}–{high:.4f}) "
            f"{'covers' if low <= getattr(truth, name) <= high else 'MISSES'} the truth"
            for name, label in (("frequency", "f_h1"), ("damping_ratio", "ξ_h1"))
            for low, high in [joint.interval(name, 0.95)]))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=50, help="one-hour records (default 50)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--tasks", type=int, default=400, help="trivial tasks (default 400)")
    parser.add_argument("--synthetic", type=int, default=200,
                        help="records of the synthetic season (default 200)")
    parser.add_argument("--estimator", choices=("least_squares", "default"),
                        default="least_squares",
                        help="of each record of the synthetic season (default: the paper's)")
    parser.add_argument("--simulate", action="store_true",
                        help="synthetic records simulated with walkers (the crowd fluctuates) "
                             "instead of Gaussian records of the smeared crowd")
    parser.add_argument("--keep", metavar="DIR",
                        help="keep the synthetic season's records and tasks in DIR (a re-run "
                             "resumes)")
    parser.add_argument("--skip-dask", action="store_true")
    parser.add_argument("--skip-hours", action="store_true")
    args = parser.parse_args()
    dask = not args.skip_dask
    overhead(args.tasks, args.workers, dask)
    if not args.skip_hours:
        hours(args.records, args.workers, dask)
    if args.synthetic:
        synthetic(args.synthetic, args.workers, args.estimator, args.simulate, args.keep)


if __name__ == "__main__":
    main()
