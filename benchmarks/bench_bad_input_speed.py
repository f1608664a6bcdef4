"""Time to an answer when the input of the default estimator is wrong (issue 35 §2).

The paper example (a one-hour Gaussian record with the model's PSD, Welch T = 60 s) fitted by
``estimate_hsi`` with its defaults (the likelihood, the fluctuating crowd, free step
frequencies, profile intervals): the right input, then each unit mistake of issue 35 §2 (the
measured PSD in g²-for-m/s² (×9.81²) and ×10⁶, the structure's damping ratio 0.5, its natural
frequency in rad/s). Each case runs in a child process limited to ``--cpu-limit`` seconds of
CPU (RLIMIT_CPU): a case that has not answered by then shows ``no answer``. The CPU time of the
child (``resource.getrusage(RUSAGE_CHILDREN)``) is the figure to compare on a shared machine;
the load average is printed beside it. One thread (BLAS and numba).

Usage: ``python benchmarks/bench_bad_input_speed.py [--cpu-limit S] [--src SRC] [case ...]``
(``--src``: the crowdvib source tree to time, default this tree's; e.g. a worktree of an
older commit).
"""

import argparse
import os
import resource
import subprocess
import sys
from pathlib import Path

CASES = ("right input", "PSD x 9.81^2", "PSD x 1e6", "structure xi = 0.5",
         "structure f in rad/s")

_CHILD = r'''
import dataclasses, sys, warnings
import numpy as np
from crowdvib import ModalModel, estimate_hsi, response_psd, welch_psd
from crowdvib.models.examples import paper_example
from crowdvib.signals.synthesis import gaussian_record, record_frequencies

case = paper_example()
psd = response_psd(case.structure, case.crowd, record_frequencies(3600.0, 20.0),
                   msd=case.msd).psd
measured = welch_psd(gaussian_record(psd, 20.0, rng=1), 20.0, window_length=60.0,
                     output_names=["midspan"]).band(0.0, 10.0)

def beam(**changes):
    values = dict(span=50.0, width=3.0, frequency=2.0, damping_ratio=0.005, modal_mass=50e3)
    return ModalModel.simply_supported_beam(**dict(values, **changes))

label = sys.argv[1]
structure = case.structure
if label == "PSD x 9.81^2":
    measured = dataclasses.replace(measured, psd=measured.psd * 9.81 ** 2)
elif label == "PSD x 1e6":
    measured = dataclasses.replace(measured, psd=measured.psd * 1e6)
elif label == "structure xi = 0.5":
    structure = beam(damping_ratio=0.5)
elif label == "structure f in rad/s":
    structure = beam(frequency=2 * np.pi * 2.0)
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    try:
        fit = estimate_hsi(measured, structure, case.crowd, band=case.band, rng=1)
        answer = (f"estimate f_h1 = {fit.msd.frequency:.3g} Hz, xi_h1 = "
                  f"{fit.msd.damping_ratio:.3g}")
    except Exception as exc:
        answer = f"{type(exc).__name__}: {exc}"
notes = [f"{w.category.__name__}: {w.message}" for w in caught
         if "Plausibility" in w.category.__name__]
print(" | ".join([answer] + notes)[:400])
'''


def _one_thread():
    return dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1",
                NUMBA_NUM_THREADS="1")


def run_case(label, cpu_limit, src):
    """(CPU seconds of the child, its answer) for one case."""
    env = _one_thread()
    if src:
        env["PYTHONPATH"] = os.pathsep.join([str(Path(src).resolve()),
                                             env.get("PYTHONPATH", "")])
    before = resource.getrusage(resource.RUSAGE_CHILDREN)

    def limit():
        resource.setrlimit(resource.RLIMIT_CPU, (cpu_limit, cpu_limit + 5))

    done = subprocess.run([sys.executable, "-c", _CHILD, label], env=env, capture_output=True,
                          text=True, preexec_fn=limit)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    answer = done.stdout.strip() or f"no answer (exit {done.returncode}): " \
                                    f"{done.stderr.strip()[-200:]}"
    return cpu, answer


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cases", nargs="*", default=CASES, help=f"among {CASES}")
    parser.add_argument("--cpu-limit", type=int, default=120, help="CPU seconds per case")
    parser.add_argument("--src", default=str(Path(__file__).resolve().parents[1] / "src"),
                        help="the crowdvib source tree to time (default this tree's)")
    args = parser.parse_args()
    rows = [(label, *run_case(label, args.cpu_limit, args.src)) for label in args.cases]
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores, one thread, "
          f"CPU limit {args.cpu_limit} s per case")
    print(f"{'case':24s}{'CPU [s]':>9s}  answer")
    for label, cpu, answer in rows:
        print(f"{label:24s}{cpu:9.1f}  {answer}")


if __name__ == "__main__":
    main()
