"""``crowdvib sensitivity`` of a case on 1 and 2 local workers: wall time, CPU, speed-up (issue 14).

    python benchmarks/bench_study_scaling.py [CASE] [--rounds R] [--workers 1,2]

Runs the command as a user would (a fresh process each time, output to a temporary directory),
the worker counts interleaved over R rounds (default 3), and prints each run and the medians:
wall time, CPU time of the command and its workers (getrusage of the waited-for children), CPU
per estimation task, and the speed-up over one worker. CASE defaults to
examples/eeklo_like.toml. Asserts nothing; the machine's load is printed beside the figures.
"""

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


def main(argv):
    case = Path(argv[0]) if argv and not argv[0].startswith("--") else \
        ROOT / "examples" / "eeklo_like.toml"
    rounds = int(argv[argv.index("--rounds") + 1]) if "--rounds" in argv else 3
    counts = ([int(w) for w in argv[argv.index("--workers") + 1].split(",")]
              if "--workers" in argv else [1, 2])
    print(f"crowdvib sensitivity {case.name}: {rounds} interleaved rounds, workers {counts}, "
          f"load {os.getloadavg()[0]:.2f} at start")
    runs = {workers: [] for workers in counts}
    for index in range(rounds):
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


if __name__ == "__main__":
    main(sys.argv[1:])
