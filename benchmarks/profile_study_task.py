"""Profile one task of a modelling-error study (issue 39): where its CPU time goes.

    python benchmarks/profile_study_task.py [eeklo|paper] [case-name] [--top N] [--warm]

The task is what a worker runs (``crowdvib.studies.modelling_error._estimate_task``) for one
error case of ``crowdvib sensitivity``'s study of the example case (default the Eeklo-like case's
``joint+-+-+@level1``); ``--warm``: started as the study starts it, from the nominal task's optima
(issue 39's warm starts; the nominal task is run first, unprofiled). One thread (set before numpy loads); a first, unprofiled run pays the
numba compilation. Prints the CPU time (``time.process_time``) and the load beside it, then the
top entries of cProfile by own time and by cumulative time.
"""

import os
import sys

for _variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                  "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import cProfile  # noqa: E402
import io  # noqa: E402
import pstats  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from crowdvib.cases import case_crowd, case_estimator, measure_case  # noqa: E402
from crowdvib.io.casefile import load_case  # noqa: E402
from crowdvib.studies import modelling_error as me  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
FILES = {"eeklo": "eeklo_like.toml", "paper": "paper_example.toml"}


def task_of(which, name):
    case = load_case(EXAMPLES / FILES[which])
    measurement = measure_case(case)
    crowd = case_crowd(case, measurement.record)[0]
    # The options tuple exactly as modelling_error_study builds it.
    settings = me._task_options(case_estimator(case))
    cases = {c.name: c for c in me.error_cases()}
    return me._EstimationTask(measurement.psd, case.structure, crowd, cases[name], settings)


def main(argv):
    top = int(argv[argv.index("--top") + 1]) if "--top" in argv else 25
    warm = "--warm" in argv
    argv = [a for a in argv if a != "--warm"]
    argv = [a for i, a in enumerate(argv) if a != "--top" and (i == 0 or argv[i - 1] != "--top")]
    which = argv[0] if argv else "eeklo"
    name = argv[1] if len(argv) > 1 else "joint+-+-+@level1"
    task = task_of(which, name)
    if warm:
        from dataclasses import replace

        starts, limit = me._warm_starts(me._estimate_task(replace(
            task, case=me.ErrorCase("nominal", (), 0, "nominal"))))
        task = replace(task, warm=starts, warm_cost=limit)
    me._estimate_task(task)                                   # numba compiles, caches warm
    cpu = time.process_time()
    result = me._estimate_task(task)
    cpu = time.process_time() - cpu
    print(f"{which} task {name}{' (warm)' if warm else ''}: {cpu:.2f} s CPU, load {os.getloadavg()[0]:.2f} "
          f"on {os.cpu_count()} CPUs; f = {result['frequency']:.5f} Hz, "
          f"ξ = {result['damping_ratio']:.5f}")
    profile = cProfile.Profile(time.process_time)          # CPU, not wall: a shared machine
    profile.enable()
    me._estimate_task(task)
    profile.disable()
    for order in ("tottime", "cumulative"):
        text = io.StringIO()
        pstats.Stats(profile, stream=text).sort_stats(order).print_stats(top)
        print("\n".join(line for line in text.getvalue().splitlines()[4:] if line.strip()))


if __name__ == "__main__":
    main(sys.argv[1:])
