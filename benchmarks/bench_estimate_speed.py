"""Time of one estimate with its intervals (issue 12 speed targets), both crowd models.

Paper example: a one-hour Gaussian record with the model's PSD (target < 2 s with profile
intervals). Eeklo-like: the example case's record, 14 modes × 2 outputs (target < 20 s).
Prints wall-clock and CPU seconds per estimate (best of ``repeat``) and the load average: on a
shared machine the CPU time of this process is the fairer figure. Usage: ``python benchmarks/bench_estimate_speed.py [repeat]``.
"""

import os
import sys
import time
import warnings
from pathlib import Path

from crowdvib import BoundWarning, estimate_hsi, response_psd, welch_psd
from crowdvib.cli.estimate import case_measurement, estimate_options
from crowdvib.io.casefile import load_case
from crowdvib.models.examples import paper_example
from crowdvib.signals.synthesis import gaussian_record, record_frequencies

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _paper():
    case = paper_example()
    psd = response_psd(case.structure, case.crowd, record_frequencies(3600.0, 20.0),
                       msd=case.msd).psd
    measured = welch_psd(gaussian_record(psd, 20.0, rng=1), 20.0, window_length=60.0,
                         output_names=["midspan"]).band(0.0, 10.0)
    return measured, case.structure, case.crowd, {"band": case.band}


def _eeklo():
    case = load_case(EXAMPLES / "eeklo_like.toml")
    record, measured, _ = case_measurement(case)
    options = estimate_options(case)
    options = {k: options[k] for k in ("band", "output_weights", "starts", "bounds")}
    return measured, case.structure, case.crowd, dict(options, outputs=record.channel_names)


def main(repeat=2):
    rows = []
    for label, make in (("paper example", _paper), ("eeklo_like (14 modes, 2 outputs)", _eeklo)):
        measured, structure, crowd, options = make()
        for method in ("least_squares", "likelihood"):
            for model in ("smeared", "fluctuating"):
                for interval in ("profile",) + (("bootstrap",) if label == "paper example"
                                                and method == "least_squares" else ()):
                    best, cpu = float("inf"), float("inf")
                    for _ in range(repeat):
                        started, cpu_started = time.perf_counter(), time.process_time()
                        with warnings.catch_warnings():
                            warnings.simplefilter("ignore", BoundWarning)
                            estimate_hsi(measured, structure, crowd, method=method,
                                         crowd_model=model, interval=interval, rng=1, **options)
                        best = min(best, time.perf_counter() - started)
                        cpu = min(cpu, time.process_time() - cpu_started)
                    rows.append((label, method, model, interval, best, cpu))
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"{'case':34s}{'method':15s}{'crowd':13s}{'interval':11s}{'wall [s]':>10s}"
          f"{'CPU [s]':>9s}")
    for label, method, model, interval, seconds, cpu in rows:
        print(f"{label:34s}{method:15s}{model:13s}{interval:11s}{seconds:10.2f}{cpu:9.2f}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 2)
