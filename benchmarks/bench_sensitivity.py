"""The studies that re-estimate many times (issue 39): ``crowdvib sensitivity``'s study of an example
case on 1 and 2 local workers, and the paper's parametric study.

    python benchmarks/bench_sensitivity.py [--case eeklo|paper|parametric ...] [--workers 1 2]
                                           [--no-joint] [--compare SRC] [--cold]

``--case eeklo``: the Eeklo-like case's study (modelling errors with the joint cases, 85
estimations, and the record lengths) with the case's estimator (the default: the likelihood
with the fluctuating crowd); ``paper``: the paper example's, the individual cases only
(``--no-joint`` is implied: 21 estimations) unless ``--joint``; ``parametric``: the paper's
parametric study (66 structures × 10 error cases, each ±ε, least squares).

Per case and worker count: the estimations, the CPU time of this process and of its workers
(psutil's, the workers' as last sampled every 0.5 s: the load-independent cost on a shared
machine), the wall time, the speed-up over 1 worker, the load average before and after, and the
joint bounds (ε at the highest level) — the study's result — with the nominal estimate.

``--compare SRC`` first runs this script with ``PYTHONPATH=SRC`` (e.g. the source of a second
worktree at the commit before, ``git worktree add --detach ../crowdvib-before main``) and prints
its table as "before", then this tree's as "after": both on the same machine in one run.
``--cold``: every case from the estimator's own multistart (``warm_start=False``, where the
study has it): the reference the warm-started bounds are compared with. Asserts nothing.

One BLAS/OpenMP/numba thread in this process (a worker gets cores // workers), set before numpy
loads.
"""

import argparse
import os
import subprocess
import sys
import time
import warnings
from pathlib import Path

for _variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                  "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

from bench_season import _peak_rss  # noqa: E402  (this folder: the same CPU accounting)

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
FILES = {"eeklo": "eeklo_like.toml", "paper": "paper_example.toml"}
#: A task is taken as hung after this long [s]: a shared machine's load stretches a task's wall
#: time several-fold, and the default (60 s) then kills tasks that are merely slow.
HUNG_AFTER = 3600.0
TARGETS = {"eeklo": "<= 120 s CPU in all, 1 → 2 workers >= 1.8×", "paper": "<= 20 s CPU",
           "parametric": "<= 180 s wall on 2 workers"}


def _load():
    return os.getloadavg()[0]


def _study(name, workers, joint, cold):
    import inspect

    from crowdvib.runner import study_executor

    if name == "parametric":
        from crowdvib.studies import parametric_study

        with study_executor(workers, timeout_floor=HUNG_AFTER) as executor:
            study = parametric_study(executor=executor)
        return len(study.rows), {}, None
    from crowdvib.cases import study_case
    from crowdvib.io.casefile import load_case
    from crowdvib.studies import modelling_error

    case = load_case(EXAMPLES / FILES[name])
    original = modelling_error.modelling_error_study
    if cold and "warm_start" in inspect.signature(original).parameters:
        def patched(*args, **kwargs):
            return original(*args, warm_start=False, **kwargs)
        modelling_error.modelling_error_study = patched
        import crowdvib.studies as studies
        studies.modelling_error_study = patched
    with study_executor(workers, timeout_floor=HUNG_AFTER) as executor, \
            warnings.catch_warnings():
        warnings.simplefilter("ignore")
        found = study_case(case, joint=joint, executor=executor)
    study = found.study
    count = len(study.cases) + len(found.lengths or ()) + 1     # and the nominal with its interval
    return count, study.bound(), study.nominal


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", nargs="+", default=["eeklo", "paper"],
                        choices=("eeklo", "paper", "parametric"))
    parser.add_argument("--workers", nargs="+", type=int, default=[1, 2])
    parser.add_argument("--joint", action="store_true", help="the paper example's joint cases")
    parser.add_argument("--no-joint", action="store_true", help="no joint cases (Eeklo-like)")
    parser.add_argument("--cold", action="store_true", help="no warm starts (the reference)")
    parser.add_argument("--compare", metavar="SRC", help="first run with PYTHONPATH=SRC")
    parser.add_argument("--label", default="after")
    args = parser.parse_args()
    if args.compare:
        argv = [a for i, a in enumerate(sys.argv[1:])
                if a != "--compare" and (i == 0 or sys.argv[i] != "--compare")]
        env = dict(os.environ, PYTHONPATH=args.compare,
                   NUMBA_CACHE_DIR=os.environ.get("NUMBA_CACHE_DIR", "/tmp/numba") + "-before")
        subprocess.run([sys.executable, __file__, *argv, "--label", f"before ({args.compare})"],
                       env=env, check=True)
    print(f"\n{args.label}{' (cold: no warm starts)' if args.cold else ''}: "
          f"{os.cpu_count()} CPUs")
    print(f"  {'study':11s}{'workers':>8s}{'estim.':>7s}{'CPU [s]':>9s}{'wall [s]':>9s}"
          f"{'speed-up':>9s}{'load':>12s}{'bound f [%]':>12s}{'bound ξ [%]':>12s}"
          f"{'nominal f, ξ':>18s}")
    for name in args.case:
        joint = args.joint if name == "paper" else not args.no_joint
        first = None
        for workers in args.workers:
            load, wall = _load(), time.perf_counter()
            # CPU of this process and of its descendants, the pool's workers as last sampled
            # (they are the fork server's children: getrusage of this process misses them)
            with _peak_rss(every=0.5) as used:
                count, bound, nominal = _study(name, workers, joint, args.cold)
            cpu, wall = used["cpu"], time.perf_counter() - wall
            first = first or wall
            bounds = (f"{bound['frequency']:12.4f}{bound['damping_ratio']:12.4f}" if bound
                      else f"{'':24s}")
            point = (f"{nominal['frequency']:9.4f},{nominal['damping_ratio']:8.4f}" if nominal
                     else "")
            print(f"  {name:11s}{workers:8d}{count:7d}{cpu:9.1f}{wall:9.1f}{first / wall:9.2f}"
                  f"{load:6.2f}→{_load():5.2f}{bounds}{point:>18s}", flush=True)
        print(f"  target ({name}): {TARGETS[name]}")


if __name__ == "__main__":
    main()
