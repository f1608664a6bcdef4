"""Time of one estimate with its intervals (issue 12 and issue 25 §1 speed targets).

Paper example: a one-hour Gaussian record with the model's PSD. Eeklo-like: the example case's
record, 14 modes × 2 outputs. The paper example's time-domain record (issue 33: 1.2 s of CPU
with the default estimator). Every estimator with profile intervals (and bootstrap for least
squares on the paper example), then the default to be: ``method="likelihood"``,
``crowd_model="fluctuating"``, ``free_step_frequencies=True``, ``interval="profile"``, whose
targets are 2 s of CPU on the paper example and 20 s on the Eeklo-like case, on one core.

One thread (BLAS and numba, set before numpy loads): on a shared machine the CPU time of this
process (``time.process_time``) is the fairer figure; wall time and the load average are
printed beside it, per row (before → after the row's runs). Best of ``repeat``. Usage:
``python benchmarks/bench_estimate_speed.py [repeat] [--default-only] [--skip-eeklo]
[--compare SRC]``; ``--compare SRC`` first runs the same with ``PYTHONPATH=SRC`` (e.g. the
source of a worktree at the commit before) and prints its table as "before", then this tree's
as "after": both on the same machine in one run (issue 39).
"""

import os
import subprocess
import sys
import time
import warnings
from pathlib import Path

# one thread, set before numpy loads (BLAS reads it once)
for _variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                  "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

from crowdvib import BoundWarning, estimate_hsi, response_psd, welch_psd  # noqa: E402
from crowdvib.cases import measure_case  # noqa: E402

try:        # a tree before issue 34 §2 (--compare): the case's options were a dict
    from crowdvib.cases import case_estimator  # noqa: E402

    def _case_options(case):
        return case_estimator(case).options()
except ImportError:
    from crowdvib.cases import estimate_options as _case_options  # noqa: E402
from crowdvib.io.casefile import load_case  # noqa: E402
from crowdvib.models.examples import paper_example  # noqa: E402
from crowdvib.signals.synthesis import gaussian_record, record_frequencies  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
#: The estimator that is to become the default (issue 25), and its CPU targets [s].
DEFAULT = dict(method="likelihood", crowd_model="fluctuating", free_step_frequencies=True,
               interval="profile")
TARGETS = {"paper example": 2.0, "paper example, its record": 1.2,
           "eeklo_like (14 modes, 2 outputs)": 20.0}
#: The default estimator's intervals carry the crowd density's uncertainty (±10 %), whose
#: profiles reach further; the record's own, ``density_uncertainty = 0`` (its case file: the
#: record was simulated at that density), is timed beside it.
DENSITY_UNCERTAINTIES = (0.1, 0.0)


def _paper():
    case = paper_example()
    psd = response_psd(case.structure, case.crowd, record_frequencies(3600.0, 20.0),
                       msd=case.msd, crowd_model="smeared").psd
    measured = welch_psd(gaussian_record(psd, 20.0, rng=1), 20.0, window_length=60.0,
                         output_names=["midspan"]).band(0.0, 10.0)
    return measured, case.structure, case.crowd, {"band": case.band}


def _paper_record():
    """The paper example's time-domain record (examples/paper_example.toml: filtered at 10 Hz)."""
    case = load_case(EXAMPLES / "paper_example.toml")
    measurement = measure_case(case)
    options = _case_options(case)
    options = {k: options[k] for k in ("band", "starts", "bounds")}
    return measurement.psd, case.structure, case.crowd, options


def _eeklo():
    case = load_case(EXAMPLES / "eeklo_like.toml")
    measurement = measure_case(case)
    record, measured = measurement.record, measurement.psd
    options = _case_options(case)
    options = {k: options[k] for k in ("band", "output_weights", "starts", "bounds")}
    return measured, case.structure, case.crowd, dict(options, outputs=record.channel_names)


def _settings(label, default_only):
    """(method, crowd model, interval, free step frequencies) to time on a case."""
    rows = [] if default_only or label == "paper example, its record" else [
        (method, model, interval, False)
        for method in ("least_squares", "likelihood") for model in ("smeared", "fluctuating")
        for interval in ("profile",) + (("bootstrap",) if label == "paper example"
                                        and method == "least_squares" else ())]
    return rows + [(DEFAULT["method"], DEFAULT["crowd_model"], DEFAULT["interval"], True)]


def timed(measured, structure, crowd, options, repeat, **settings):
    """Best wall-clock and CPU seconds of ``repeat`` estimates."""
    best, cpu = float("inf"), float("inf")
    for _ in range(repeat):
        started, cpu_started = time.perf_counter(), time.process_time()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", BoundWarning)
            estimate_hsi(measured, structure, crowd, rng=1, **settings, **options)
        best = min(best, time.perf_counter() - started)
        cpu = min(cpu, time.process_time() - cpu_started)
    return best, cpu


def main(repeat=2, default_only=False, skip_eeklo=False, label="after"):
    rows = []
    for case, make in (("paper example", _paper), ("paper example, its record", _paper_record),
                       ("eeklo_like (14 modes, 2 outputs)", _eeklo))[:2 if skip_eeklo else 3]:
        measured, structure, crowd, options = make()
        for method, model, interval, free in _settings(case, default_only):
            for u in DENSITY_UNCERTAINTIES if free else (0.0,):
                load = os.getloadavg()[0]
                seconds, cpu = timed(measured, structure, crowd, options, repeat, method=method,
                                     crowd_model=model, interval=interval,
                                     free_step_frequencies=free, density_uncertainty=u)
                rows.append((case, method, model, interval, free, u, seconds, cpu,
                             f"{load:5.1f}→{os.getloadavg()[0]:4.1f}"))
    print(f"\n{label}: {os.cpu_count()} cores, one thread, best of {repeat}")
    print(f"{'case':34s}{'method':15s}{'crowd':13s}{'interval':11s}{'steps':7s}{'u_rho':>6s}"
          f"{'CPU [s]':>9s}{'wall [s]':>10s}{'load':>12s}{'target':>8s}")
    for case, method, model, interval, free, u, seconds, cpu, load in rows:
        target = f"{TARGETS[case]:8.1f}" if free else ""
        print(f"{case:34s}{method:15s}{model:13s}{interval:11s}"
              f"{'free' if free else 'fixed':7s}{u:6.2f}{cpu:9.2f}{seconds:10.2f}{load:>12s}"
              f"{target}", flush=True)


if __name__ == "__main__":
    if "--compare" in sys.argv:
        where = sys.argv.index("--compare")
        source, rest = sys.argv[where + 1], sys.argv[1:where] + sys.argv[where + 2:]
        subprocess.run([sys.executable, __file__, *rest, "--label", f"before ({source})"],
                       env=dict(os.environ, PYTHONPATH=source), check=True)
    else:
        rest = sys.argv[1:]
    name = rest[rest.index("--label") + 1] if "--label" in rest else "after"
    arguments = [a for i, a in enumerate(rest)
                 if not a.startswith("--") and (i == 0 or rest[i - 1] != "--label")]
    main(int(arguments[0]) if arguments else 2, "--default-only" in rest, "--skip-eeklo" in rest,
         name)
