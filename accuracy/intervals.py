"""Calibration of the 95 % intervals (issue 12): coverage, bias and scatter over seeded records.

Two kinds of record of the paper's numerical example (truth f_h1 = 3.0 Hz, ξ_h1 = 0.30):

* ``gaussian`` — Gaussian records with the spectral model's PSD (exact Welch statistics of a
  stationary crowd; what the intervals are built for);
* ``simulated`` — one-hour time-domain simulations with moving MSD pedestrians (Poisson arrivals:
  the occupancy fluctuates, which the smeared spectral model does not describe).

Both estimators (paper least squares, Whittle likelihood), each with the smeared and the
fluctuating crowd model of the expected PSD, are run on the same records. Prints a table:
coverage of the truth by the 95 % profile interval per parameter, mean error with its 95 %
interval, the standard deviation per record and the mean interval width, plus time per
estimate. Usage: ``python accuracy/intervals.py [gaussian|simulated] [N] [density]
[paper|fluctuating|fluctuating-likelihood|fluctuating-least-squares|free|likelihood|least_squares]
[--workers W] [--hours H] [--step-error E] [--density-error E]`` (``default``: the paper's
least squares and the likelihood with the fluctuating model and fitted step frequencies;
``paper``: both estimators with both crowd models; ``fluctuating``:
both with the fluctuating model, ``fluctuating-likelihood`` and ``fluctuating-least-squares``
one of them; ``free``:
the likelihood with the step-frequency distribution fitted too; the last two: one estimator
with the smeared model; records run on W local workers,
default 1; simulated records of H hours, default 1: a bias that shrinks as 1/H is the
estimator's finite-sample bias, one that stays is a model error)
(density in persons/m², default the paper's 0.5; walking speed from Weidmann's relation;
``--step-error`` and ``--density-error``: relative errors in the crowd the estimator is told,
the records being made with the true one).
``python accuracy/intervals.py mean [N] [density] [--hours H]`` estimates on the mean
Welch PSD of the N simulated records (model error against finite-sample bias).
``python accuracy/intervals.py bootstrap [N] [density] [n_boot] [first]`` checks the
parametric bootstrap of least squares (percentile intervals, smeared model) on N Gaussian records
(seeds from ``first``).
With the environment variable ``CROWDVIB_RECORD_CACHE`` set to a directory, the simulated
records' Welch PSDs are kept there (one pickle per density and seed) and reused.
"""

import dataclasses
import os
import pickle
import sys
import time
import warnings

import numpy as np

from crowdvib import (BoundWarning, Crowd, LowPassFilter, ModalModel, MSDModel, estimate_hsi,
                      response_psd, simulate, welch_psd)
from crowdvib.runner import study_executor
from crowdvib.signals.synthesis import gaussian_record, record_frequencies

TRUTH = {"frequency": 3.0, "damping_ratio": 0.30}
BRIDGE = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
CROWD = Crowd(density=0.5, walking_speed=1.30, step_frequency_mean=1.89,
              step_frequency_std=0.175, body_mass=70.0)


def paper_crowd(density):
    """The paper's crowd at another density (speed and step frequency from their relations)."""
    if density == 0.5:
        return CROWD
    return Crowd.from_density(density, body_mass=70.0)
MSD = MSDModel(TRUTH["frequency"], TRUTH["damping_ratio"], 0.95)


def gaussian_record_psd(crowd, seed):
    """Welch PSD of one Gaussian hour with the spectral model's PSD (seeded)."""
    frequency = record_frequencies(3600.0, 20.0)
    psd = response_psd(BRIDGE, crowd, frequency, msd=MSD, crowd_model="smeared").psd
    record = gaussian_record(psd, 20.0, rng=seed)
    return welch_psd(record, 20.0, window_length=60.0, output_names=["midspan"]).band(0, 10)


def gaussian_records(n, crowd, first=0):
    for seed in range(first, first + n):
        yield gaussian_record_psd(crowd, seed)


def simulated_record(crowd, seed, hours=1.0):
    """Welch PSD of a simulated record of ``hours`` (seeded), from the cache directory when
    there is one."""
    cache = os.environ.get("CROWDVIB_RECORD_CACHE")
    tag = "" if hours == 1.0 else f"_h{hours:g}"
    path = cache and os.path.join(cache, f"d{crowd.density:g}{tag}_s{seed}.pkl")
    if path and os.path.exists(path):
        with open(path, "rb") as handle:
            return pickle.load(handle)
    record = simulate(BRIDGE, crowd, 3600.0 * hours, msd=MSD, rng=seed, warm_up=100.0,
                      sample_rate=100.0)
    psd = welch_psd(record.acceleration, 100.0, window_length=60.0,
                    output_names=record.output_names,
                    lowpass=LowPassFilter(10.0, 4, 100.0)).band(0, 10)
    if path:
        with open(path + ".tmp", "wb") as handle:
            pickle.dump(psd, handle)
        os.replace(path + ".tmp", path)
    return psd


def bootstrap(n=200, density=0.5, n_boot=100, first=0):
    """Coverage of the least-squares percentile intervals on n Gaussian records (seeds
    ``first`` … ``first + n − 1``, so that shards can run side by side)."""
    crowd = paper_crowd(density)
    found, started = [], time.perf_counter()
    for seed, measured in enumerate(gaussian_records(n, crowd, first), start=first):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", BoundWarning)
            estimate = estimate_hsi(measured, BRIDGE, crowd, band=(0.0, 10.0),
                                    interval="bootstrap", n_boot=n_boot, rng=10_000 + seed)
        found.append([(getattr(estimate.msd, name), *estimate.interval(name))
                      for name in TRUTH])
        print("record", seed, found[-1], flush=True)
    print(f"gaussian records of the paper example at {density:g} P/m², n = {n}, least squares, "
          f"95 % parametric-bootstrap percentile intervals of {n_boot} replicates")
    key = ("least_squares", "bootstrap", False)
    _table({key: found}, n, {key: time.perf_counter() - started})


def _table(rows, n, seconds):
    print(f"{'method':14s}{'crowd':17s}{'parameter':15s}{'coverage':>9s}{'mean error':>24s}"
          f"{'std/record':>12s}{'mean width':>12s}{'s/estimate':>11s}")
    for key, found in rows.items():
        method, model, free = key
        label = model + (" +f_s" if free else "")
        found = np.array(found)                     # (n, parameters, (value, low, high))
        for p, (name, truth) in enumerate(TRUTH.items()):
            value, low, high = found[:, p, 0], found[:, p, 1], found[:, p, 2]
            covered = np.mean((low <= truth) & (truth <= high))
            error = value / truth - 1
            half = 1.96 * error.std(ddof=1) / np.sqrt(n)
            print(f"{method:14s}{label:17s}{name:15s}{covered:9.1%}"
                  f"{f'{error.mean():+.2%} [{error.mean() - half:+.2%}, {error.mean() + half:+.2%}]':>24s}"
                  f"{error.std(ddof=1):12.2%}{np.mean(high - low) / truth:12.2%}"
                  f"{seconds[key] / n:11.2f}")


#: The estimators compared: (method, crowd model, step frequencies fitted too).
ESTIMATORS = {"paper": [(method, model, False) for model in ("smeared", "fluctuating")
                        for method in ("least_squares", "likelihood")],
              "free": [("likelihood", "fluctuating", True)],
              "fluctuating": [(method, "fluctuating", False)
                              for method in ("least_squares", "likelihood")],
              "fluctuating-likelihood": [("likelihood", "fluctuating", False)],
              "fluctuating-least-squares": [("least_squares", "fluctuating", False)],
              # One estimator alone (the timing of a 200-record calibration study).
              # Which should be the default (issue 25): the paper's estimator and the likelihood
              # with the fluctuating model and the step frequencies fitted.
              "default": [("least_squares", "smeared", False),
                          ("likelihood", "fluctuating", True)],
              "likelihood": [("likelihood", "smeared", False)],
              "least_squares": [("least_squares", "smeared", False)]}


def given_crowd(crowd, step_error=0.0, density_error=0.0):
    """The crowd as a user with relative errors in the mean step frequency and the density
    would describe it to the estimator (the record is made with the true ``crowd``)."""
    return dataclasses.replace(crowd, density=crowd.density * (1 + density_error),
                               step_frequency_mean=crowd.step_frequency_mean * (1 + step_error))


def record_estimates(kind, density, seed, estimators, hours=1.0, errors=(0.0, 0.0)):
    """One record's estimates by every estimator: key → ([(value, low, high) per parameter],
    seconds), the estimator given the crowd with relative ``errors`` (mean step frequency,
    density). A module-level task, so that records run on the study workers."""
    crowd = paper_crowd(density)
    measured = (gaussian_record_psd(crowd, seed) if kind == "gaussian"
                else simulated_record(crowd, seed, hours))
    return estimates_of(measured, given_crowd(crowd, *errors), ESTIMATORS[estimators])


def estimates_of(measured, crowd, estimators):
    """Each estimator's ([(value, low, high) per parameter], seconds) on one measured PSD."""
    found = {}
    for method, model, free in estimators:
        started = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", BoundWarning)
            estimate = estimate_hsi(measured, BRIDGE, crowd, band=(0.0, 10.0), method=method,
                                    crowd_model=model, free_step_frequencies=free)
        found[method, model, free] = ([(getattr(estimate.msd, name), *estimate.interval(name))
                                       for name in TRUTH], time.perf_counter() - started)
    return found


def main(kind="gaussian", n=40, density=0.5, estimators="paper", workers=1, hours=1.0,
         errors=(0.0, 0.0)):
    # Seeds: 0 … n−1 for Gaussian records, 1 … n for simulated ones (as the caches hold them).
    seeds = range(n) if kind == "gaussian" else range(1, n + 1)
    started = time.perf_counter()
    with study_executor(workers) as executor:
        mapper = map if executor is None else executor.map
        per_record = list(mapper(record_estimates, *zip(*[(kind, density, seed, estimators,
                                                            hours, errors) for seed in seeds])))
    wall = time.perf_counter() - started
    rows = {key: [found[key][0] for found in per_record] for key in ESTIMATORS[estimators]}
    seconds = {key: sum(found[key][1] for found in per_record) for key in rows}
    length = "" if kind == "gaussian" else f" of {hours:g} h"
    print(f"{kind} records{length} of the paper example at {density:g} P/m², n = {n}, "
          f"95 % profile intervals; {wall:.1f} s wall on {workers} worker(s)"
          + (f"; the estimator told a mean step frequency {errors[0]:+.0%} and a density "
             f"{errors[1]:+.0%} off" if any(errors) else ""))
    _table(rows, n, seconds)
    cache = os.environ.get("CROWDVIB_RECORD_CACHE")
    if cache:   # the estimates themselves, for other summaries of the same records
        name = f"estimates_{kind}_d{density:g}_h{hours:g}_n{n}_{estimators}.pkl"
        with open(os.path.join(cache, name), "wb") as handle:
            pickle.dump({key: np.array(found) for key, found in rows.items()}, handle)


def mean_psd(records):
    """The records' mean Welch PSD as one record of all their windows (its scatter N times
    smaller): what an estimate reads there is the model's error, not finite-sample bias."""
    return dataclasses.replace(records[0], psd=np.mean([r.psd for r in records], axis=0),
                               n_windows=sum(r.n_windows for r in records), dispersion=None)


def mean_record(n=200, density=0.25, hours=1.0):
    """Estimates on the mean Welch PSD of the n simulated records (seeds 1 … n)."""
    crowd = paper_crowd(density)
    mean = mean_psd([simulated_record(crowd, seed, hours) for seed in range(1, n + 1)])
    print(f"the mean Welch PSD of {n} simulated records of {hours:g} h at {density:g} P/m²")
    print_mean_estimates(mean, crowd, ESTIMATORS["paper"])


def print_mean_estimates(mean, crowd, estimators):
    """Each estimator's relative error on a mean PSD, one line each."""
    for method, model, free in estimators:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", BoundWarning)
            estimate = estimate_hsi(mean, BRIDGE, crowd, band=(0.0, 10.0), method=method,
                                    crowd_model=model, free_step_frequencies=free)
        print(f"{method:14s}{model:13s}" + "".join(
            f"  {name} {getattr(estimate.msd, name) / truth - 1:+.2%}"
            for name, truth in TRUTH.items()))


if __name__ == "__main__":
    options = {"--workers": 1, "--hours": 1.0, "--step-error": 0.0, "--density-error": 0.0}
    for flag, default in options.items():
        if flag in sys.argv:
            options[flag] = type(default)(sys.argv[sys.argv.index(flag) + 1])
    args = [a for i, a in enumerate(sys.argv[1:], start=1)
            if a not in options and sys.argv[i - 1] not in options]

if __name__ == "__main__" and args[:1] == ["mean"]:
    mean_record(*(f(a) for f, a in zip((int, float), args[1:])), hours=options["--hours"])
elif __name__ == "__main__" and args[:1] == ["bootstrap"]:
    bootstrap(*(f(a) for f, a in zip((int, float, int, int), args[1:])))
elif __name__ == "__main__":
    main(args[0] if len(args) > 0 else "gaussian",
         int(args[1]) if len(args) > 1 else 40,
         float(args[2]) if len(args) > 2 else 0.5,
         args[3] if len(args) > 3 else "paper", options["--workers"], options["--hours"],
         (options["--step-error"], options["--density-error"]))
