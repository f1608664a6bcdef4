"""OMA accuracy (issue 13): identify_modes on simulated 30-minute ambient records of a 3-mode bridge.

The bridge, the ambient load (independent white-noise modal loads, exact Gaussian synthesis) and
the five walkers are those of tests/unit/test_oma.py (imported from it). Per seed it prints the
relative errors of f_j and ξ_j and the error of ξ_j in units of its reported standard deviation;
then per mode the mean
and largest |error| and the share of seeds whose ±1.96 σ interval covers the truth.
Usage: ``python benchmarks/bench_oma.py [N seeds] [max_order]`` (defaults 8, 24).
"""

import sys
import time
from pathlib import Path

import numpy as np

from crowdvib import identify_modes

# The case of the test: its bridge, ambient load and walkers, imported so the two cannot drift.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "unit"))
from test_oma import DAMPING, FREQUENCIES, SAMPLE_RATE, ambient_record, bridge


def main(n=8, max_order=24):
    structure = bridge()
    rows = []
    print(f"{'seed':>4s} {'s':>5s}  {'f error [%]':>24s}  {'ξ error [%]':>22s}  "
          f"{'ξ error / σ_ξ':>20s}", flush=True)
    for seed in range(1, n + 1):
        started = time.perf_counter()
        modes = identify_modes(ambient_record(structure, seed), SAMPLE_RATE, n_modes=3,
                               frequency_band=(1.0, 9.0), max_order=max_order)
        ef = modes.frequencies / FREQUENCIES - 1
        ex = modes.damping_ratios / DAMPING - 1
        zf = (modes.frequencies - FREQUENCIES) / modes.frequency_std
        zx = (modes.damping_ratios - DAMPING) / modes.damping_std
        rows.append((ef, ex, zf, zx))
        print(f"{seed:4d} {time.perf_counter() - started:5.1f}  "
              f"{' '.join(f'{v:+7.3f}' for v in 100 * ef):>24s}  "
              f"{' '.join(f'{v:+6.1f}' for v in 100 * ex):>22s}  "
              f"{' '.join(f'{v:+6.2f}' for v in zx):>20s}", flush=True)
    ef, ex, zf, zx = (np.array([r[i] for r in rows]) for i in range(4))
    print("\nmode  f_j [Hz]  ξ_j     mean|Δf|  max|Δf|  mean|Δξ|  max|Δξ|  f covered  ξ covered")
    for j in range(3):
        print(f"{j + 1:4d}  {FREQUENCIES[j]:8.2f}  {DAMPING[j]:.3f}  {np.mean(np.abs(ef[:, j])):8.3%}"
              f"  {np.max(np.abs(ef[:, j])):7.3%}  {np.mean(np.abs(ex[:, j])):8.1%}"
              f"  {np.max(np.abs(ex[:, j])):7.1%}  {np.mean(np.abs(zf[:, j]) <= 1.96):9.0%}"
              f"  {np.mean(np.abs(zx[:, j]) <= 1.96):9.0%}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 8,
         int(sys.argv[2]) if len(sys.argv) > 2 else 24)
