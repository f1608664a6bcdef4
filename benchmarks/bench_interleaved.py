"""Before and after on a noisy machine: two source trees timed in alternation (issue 39).

    python benchmarks/bench_interleaved.py BEFORE_SRC AFTER_SRC [--rounds 8]
                                           [--work estimate|season] [--records 4]

On a shared machine the CPU time of one run moves by ±30 % from one minute to the next, as much
as a change is worth. Here two worker processes, one per source tree (``PYTHONPATH``), are asked
in turn for the same work, round after round, so that both see the same load; the table gives
each tree's minimum and median CPU (``time.process_time``) and the median of the per-round
ratios after/before, with the load average.

``--work estimate``: the paper example's default estimate on its own time-domain record, with
intervals (``bench_estimate_speed``'s issue 33 row). ``--work season``: ``season_case`` on
``--records`` one-hour records (densities 0.2–1.0 persons/m², 100 Hz), CPU per record
(``bench_season``'s table 2). Each worker first does the work once (imports, numba's cache,
the shared caches) and prints the estimates it found, so that a change that moves them shows.
One thread per worker (BLAS and numba). Asserts nothing.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent

WORKER = r'''
import json, os, sys, tempfile, time, warnings
from pathlib import Path
sys.path.insert(0, sys.argv[1])
import numpy as np


def estimate():
    import bench_estimate_speed as bench
    from crowdvib import estimate_hsi
    measured, structure, crowd, options = bench._paper_record()
    found = estimate_hsi(measured, structure, crowd, rng=1, **options)
    return 1, [found.msd.frequency, found.msd.damping_ratio, *found.intervals["frequency"],
               *found.intervals["damping_ratio"]]


def season_work(records):
    from crowdvib import load_case
    from crowdvib.cases import season_case
    from crowdvib.models.examples import paper_example
    from crowdvib.studies.season import write_synthetic_season
    paper = paper_example()
    folder = Path(tempfile.mkdtemp(prefix="crowdvib-interleaved-"))
    table = write_synthetic_season(folder, paper.structure, paper.crowd, paper.msd,
                                   densities=np.linspace(0.2, 1.0, records), duration=3600.0,
                                   sample_rate=100.0, rng=2028)
    case_file = folder / "season.toml"
    case_file.write_text((Path(sys.argv[1]).parent / "examples" / "paper_example.toml").read_text())
    case = load_case(case_file)

    def season():
        rows = season_case(case, table, records=folder, joint=False).season.rows
        return records, [[row.get("frequency"), row.get("damping_ratio")] for row in rows]
    return season


work = estimate if sys.argv[2] == "estimate" else season_work(int(sys.argv[3]))
warnings.simplefilter("ignore")
count, values = work()
print(json.dumps({"ready": values}), flush=True)
for line in sys.stdin:
    cpu = time.process_time()
    count, _ = work()
    print(json.dumps({"cpu": (time.process_time() - cpu) / count}), flush=True)
'''


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before")
    parser.add_argument("after")
    parser.add_argument("--rounds", type=int, default=8)
    parser.add_argument("--work", choices=("estimate", "season"), default="estimate")
    parser.add_argument("--records", type=int, default=4)
    args = parser.parse_args()
    workers = []
    for name, source in (("before", args.before), ("after", args.after)):
        env = dict(os.environ, PYTHONPATH=str(Path(source).resolve()))
        for variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                         "NUMBA_NUM_THREADS"):
            env[variable] = "1"
        workers.append(subprocess.Popen(
            [sys.executable, "-c", WORKER, str(HERE), args.work, str(args.records)],
            env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True))
    for name, worker in zip(("before", "after"), workers):
        print(f"{name}: {json.loads(worker.stdout.readline())['ready']}")
    load = os.getloadavg()[0]
    times = [[], []]
    for _ in range(args.rounds):
        for worker, found in zip(workers, times):
            worker.stdin.write("go\n")
            worker.stdin.flush()
            found.append(json.loads(worker.stdout.readline())["cpu"])
    for worker in workers:
        worker.stdin.close()
        worker.wait()
    unit = "per estimate" if args.work == "estimate" else "per record"
    print(f"\n{args.work}, CPU {unit}, {args.rounds} interleaved rounds, "
          f"load {load:.2f} -> {os.getloadavg()[0]:.2f}")
    print(f"{'tree':8s} {'min':>8s} {'median':>8s}  runs")
    for name, found in zip(("before", "after"), times):
        print(f"{name:8s} {min(found):7.3f}s {statistics.median(found):7.3f}s  "
              + " ".join(f"{t:.2f}" for t in found))
    ratios = [b / a for a, b in zip(*times)]
    print(f"median ratio after/before {statistics.median(ratios):.3f}")


if __name__ == "__main__":
    main()
