"""The paper's parametric study (66 structures × 10 error cases, each ±ε) on 1 and 2 local workers.

    python benchmarks/bench_sensitivity.py

Prints the wall time per worker count and the speed-up; asserts nothing.
"""

import time

from crowdvib.studies import parametric_study
from crowdvib.runner import study_executor


def main():
    rows = []
    reference = None
    for workers in (1, 2):
        started = time.perf_counter()
        with study_executor(workers) as executor:       # 1: in this process; 2: dask
            study = parametric_study(executor=executor)
        elapsed = time.perf_counter() - started
        if reference is None:
            reference = study.to_dict()
        same = study.to_dict() == reference
        rows.append((workers, len(study.rows), elapsed, same))
    print(f"{'workers':>7s} {'estimations':>12s} {'wall [s]':>9s} {'speed-up':>9s} "
          f"{'same result':>12s}   target: <= 180 s on 2 workers")
    for workers, count, elapsed, same in rows:
        print(f"{workers:7d} {count:12d} {elapsed:9.1f} {rows[0][2] / elapsed:9.2f} "
              f"{str(same):>12s}")


if __name__ == "__main__":
    main()
