"""Calibration of the crowd density's uncertainty in the intervals (issue 33 §4).

One-hour records of the paper's numerical example simulated by crowdvib's time-domain model
(truth f_h1 = 3.0 Hz, ξ_h1 = 0.30, 0.5 P/m²) are estimated by the default estimator told a
density 10 % low, right and 10 % high, each with the density taken as exact
(``density_uncertainty=0``) and with a stated relative standard uncertainty of 10 %. Prints,
per case and parameter: the coverage of the truth by the 95 % intervals, the mean relative
error with its 95 % interval, the mean interval width, and the share of the variance that the
density makes. docs: theory, The crowd density's uncertainty, quotes the table.

Usage: ``python accuracy/density_uncertainty.py [N] [--workers W] [--uncertainty U]
[--density D]`` (N records, seeds 1 … N, default 60; W local workers, default 1). With
``CROWDVIB_RECORD_CACHE`` set to a folder, the records' Welch PSDs are kept there and reused
(shared with ``accuracy/intervals.py``).
"""

import os
import pickle
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from intervals import BRIDGE, TRUTH, given_crowd, paper_crowd, simulated_record  # noqa: E402

from crowdvib import BoundWarning, estimate_hsi  # noqa: E402
from crowdvib.runner import study_executor  # noqa: E402

#: The density the estimator is told, relative to the record's.
ERRORS = (-0.1, 0.0, 0.1)


def record_rows(seed, density, uncertainty):
    """One record: (error, stated uncertainty) → ([(value, low, high, share) per parameter],
    CPU seconds)."""
    cache = os.environ.get("CROWDVIB_RECORD_CACHE")
    path = cache and os.path.join(cache, f"density_rows_d{density:g}_u{uncertainty:g}_s{seed}.pkl")
    if path and os.path.exists(path):
        with open(path, "rb") as handle:
            return pickle.load(handle)
    crowd = paper_crowd(density)
    measured = simulated_record(crowd, seed)
    rows = {}
    for error in ERRORS:
        for stated in (0.0, uncertainty):
            started = time.process_time()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", BoundWarning)
                estimate = estimate_hsi(measured, BRIDGE, given_crowd(crowd, 0.0, error),
                                        band=(0.0, 10.0), density_uncertainty=stated)
            rows[error, stated] = ([(getattr(estimate.msd, name), *estimate.interval(name),
                                     estimate.density_share.get(name, 0.0)) for name in TRUTH],
                                   time.process_time() - started)
    if path:
        with open(path + ".tmp", "wb") as handle:
            pickle.dump(rows, handle)
        os.replace(path + ".tmp", path)
    return rows


def main(n=60, workers=1, uncertainty=0.1, density=0.5):
    started = time.perf_counter()
    with study_executor(workers) as executor:
        mapper = map if executor is None else executor.map
        per_record = []
        for rows in mapper(record_rows, range(1, n + 1), [density] * n, [uncertainty] * n):
            per_record.append(rows)
            print(f"record {len(per_record)} of {n}", file=sys.stderr, flush=True)
    wall = time.perf_counter() - started
    print(f"simulated one-hour records of the paper example at {density:g} P/m², n = {n}, "
          f"default estimator, 95 % profile intervals; {wall:.0f} s wall on {workers} worker(s)")
    print(f"{'density told':>13s}{'stated u':>10s}{'parameter':>15s}{'coverage':>10s}"
          f"{'mean error':>26s}{'mean width':>12s}{'density share':>15s}{'CPU s':>8s}")
    for key in per_record[0]:
        found = np.array([record[key][0] for record in per_record])   # (n, parameter, 4)
        seconds = np.mean([record[key][1] for record in per_record])
        for p, (name, truth) in enumerate(TRUTH.items()):
            value, low, high, share = found[:, p].T
            covered = np.mean((low <= truth) & (truth <= high))
            error = value / truth - 1
            half = 1.96 * error.std(ddof=1) / np.sqrt(n)
            print(f"{key[0]:+13.0%}{key[1]:10.2f}{name:>15s}{covered:10.1%}"
                  f"{f'{error.mean():+.1%} [{error.mean() - half:+.1%}, {error.mean() + half:+.1%}]':>26s}"
                  f"{np.mean(high - low) / truth:12.1%}{np.mean(share):15.0%}{seconds:8.1f}")


if __name__ == "__main__":
    options = {"--workers": 1, "--uncertainty": 0.1, "--density": 0.5}
    for flag, default in options.items():
        if flag in sys.argv:
            options[flag] = type(default)(sys.argv[sys.argv.index(flag) + 1])
    args = [a for i, a in enumerate(sys.argv[1:], start=1)
            if a not in options and sys.argv[i - 1] not in options]
    main(int(args[0]) if args else 60, options["--workers"], options["--uncertainty"],
         options["--density"])
