"""``crowdvib sensitivity`` of a case on 1 and 2 local workers: wall time, CPU, speed-up (issue 14).

    python benchmarks/bench_study_scaling.py [CASE] [--rounds R] [--workers 1,2] [--no-ceiling]

Runs the command as a user would (a fresh process each time, output to a temporary directory),
the worker counts interleaved over R rounds (default 3), and prints each run and the medians:
wall time, CPU time of the command and its workers (getrusage of the waited-for children), CPU
per estimation task, and the speed-up over one worker. CASE defaults to
examples/eeklo_like.toml. Asserts nothing; the machine's load is printed beside the figures.

The machine's own ceiling is measured in each round too: the case's nominal estimation repeated
in one process, then in two processes at once (forked, no study engine at all). Two cores give
two such processes less than twice the throughput of one when they share more than the cores
(a host's SMT siblings, clock boost, caches); that throughput ratio bounds what any engine can
reach on this work, and the command's speed-up is reported against it.
"""

import contextlib
import io
import multiprocessing
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def run(case, workers):
    """(wall [s], CPU [s], tasks) of one ``crowdvib sensitivity`` run."""
    with tempfile.TemporaryDirectory() as directory:
        out = Path(directory) / "study"
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        started = time.perf_counter()
        subprocess.run([sys.executable, "-m", "crowdvib", "sensitivity", str(case), "--out",
                        str(out), "--workers", str(workers)], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wall = time.perf_counter() - started
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        tasks = sum(len(list((out / name).glob("*.json"))) for name in ("tasks", "record_length"))
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, tasks


def _repeat_estimation(case, repeats, barrier, queue):
    """The case's nominal point estimation ``repeats`` times after ``barrier``: (wall, CPU)."""
    import warnings

    from threadpoolctl import threadpool_limits

    from crowdvib.cases import case_crowd, case_estimator, measure_case
    from crowdvib.identification import estimate_hsi
    from crowdvib.io.casefile import load_case

    case = load_case(case)
    with contextlib.redirect_stdout(io.StringIO()):          # its "record ..." line
        measurement = measure_case(case)
    record, measured = measurement.record, measurement.psd
    crowd, _ = case_crowd(case, record)
    options = case_estimator(case).options(point_only=True)
    with threadpool_limits(limits=1), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        estimate_hsi(measured, case.structure, crowd, interval=None, **options)   # warm-up
        barrier.wait()                           # the loops of both processes start together
        wall, cpu = time.perf_counter(), time.process_time()
        for _ in range(repeats):
            estimate_hsi(measured, case.structure, crowd, interval=None, **options)
        queue.put((time.perf_counter() - wall, time.process_time() - cpu))


def ceiling(case, repeats=24):
    """The machine's ceiling on this work: (throughput of 2 processes over 1, CPU inflation)."""
    context = multiprocessing.get_context("spawn")
    loop = {}
    for processes in (1, 2):
        barrier, queue = context.Barrier(processes), context.Queue()
        workers = [context.Process(target=_repeat_estimation,
                                   args=(case, repeats, barrier, queue))
                   for _ in range(processes)]
        for worker in workers:
            worker.start()
        timings = [queue.get() for _ in workers]
        for worker in workers:
            worker.join()
        loop[processes] = [sum(t[i] for t in timings) / processes for i in (0, 1)]
    # Two processes do twice the work in the time each of their loops takes.
    return 2 * loop[1][0] / loop[2][0], loop[2][1] / loop[1][1] - 1


def main(argv):
    case = Path(argv[0]) if argv and not argv[0].startswith("--") else \
        ROOT / "examples" / "eeklo_like.toml"
    rounds = int(argv[argv.index("--rounds") + 1]) if "--rounds" in argv else 3
    measure_ceiling = "--no-ceiling" not in argv
    counts = ([int(w) for w in argv[argv.index("--workers") + 1].split(",")]
              if "--workers" in argv else [1, 2])
    print(f"crowdvib sensitivity {case.name}: {rounds} interleaved rounds, workers {counts}, "
          f"load {os.getloadavg()[0]:.2f} at start")
    runs = {workers: [] for workers in counts}
    ceilings = []
    for index in range(rounds):
        if measure_ceiling:
            ceilings.append(ceiling(case))
            print(f"  round {index + 1}  machine: 2 processes of estimations at once give "
                  f"{ceilings[-1][0]:.2f}x the throughput of 1 (CPU per estimation "
                  f"{ceilings[-1][1]:+.0%}), load {os.getloadavg()[0]:.2f}", flush=True)
        for workers in counts:
            wall, cpu, tasks = run(case, workers)
            runs[workers].append((wall, cpu, tasks))
            print(f"  round {index + 1}  workers {workers}: wall {wall:6.2f} s, CPU {cpu:6.1f} s "
                  f"({tasks} tasks), load {os.getloadavg()[0]:.2f}", flush=True)
    reference = statistics.median(wall for wall, _, _ in runs[counts[0]])
    print(f"\n{'workers':>7s} {'wall [s]':>9s} {'CPU [s]':>8s} {'CPU/task [s]':>13s} "
          f"{'speed-up':>9s}   (medians; target >= 1.8x on 2 workers)")
    for workers in counts:
        wall = statistics.median(w for w, _, _ in runs[workers])
        cpu = statistics.median(c for _, c, _ in runs[workers])
        tasks = runs[workers][0][2]
        print(f"{workers:7d} {wall:9.2f} {cpu:8.1f} {cpu / tasks:13.3f} "
              f"{reference / wall:9.2f}")
    if len(counts) > 1:       # the runs of one round are minutes apart at most
        paired = [runs[counts[0]][i][0] / runs[counts[-1]][i][0] for i in range(rounds)]
        print(f"speed-up {counts[0]} -> {counts[-1]} workers round by round: "
              + ", ".join(f"{r:.2f}x" for r in paired))
    if ceilings:
        bound = statistics.median(c[0] for c in ceilings)
        print(f"machine ceiling (2 engine-free processes of estimations over 1, median): "
              f"{bound:.2f}x; CPU per estimation {statistics.median(c[1] for c in ceilings):+.0%}"
              " when both cores work")


if __name__ == "__main__":
    main(sys.argv[1:])
