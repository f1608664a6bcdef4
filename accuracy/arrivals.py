"""Fixed-interval arrivals as a control for the fluctuating model's damping bias (issue 25 §1).

At 0.25 P/m² every estimator using the fluctuating-crowd model read ξ_h1 +2 to +5 % high on
crowdvib's own simulated records with Poisson arrivals, also on four-hour records and on the
mean PSD of 200 records. Either the model misdescribes the Poisson crowd's fluctuation, or the
simulator's stream differs from what the model assumes in another detail (the walkers on the
deck at the start, the draw of the DLFs and phases, the step frequencies).

The control: the same simulator, the same bridge, MSD, step frequencies, DLFs and phases, but
pedestrians arriving at fixed intervals 1/λ (a random phase per record; the deck populated at
the same spacing at t = 0). Their occupancy is constant to ±1 walker, so the smeared model is
then the right one: if it reads the truth on these records, the simulator's stream is what the
model assumes and the Poisson bias belongs to the fluctuation (the fluctuating model); if it does
not, the cause is elsewhere in the stream or the physics.

Usage: ``python accuracy/arrivals.py [N] [density] [--workers W]``: N one-hour records
(seeds 1 … N) with fixed-interval arrivals; per record the likelihood and least squares with the
smeared and the fluctuating model at the true crowd (coverage, mean error with its 95 %
interval), then the estimates on the records' mean Welch PSD (the model error alone).
"""

import sys
import time

import numpy as np

from intervals import (BRIDGE, MSD, _table, estimates_of, mean_psd, paper_crowd,
                             print_mean_estimates)
from crowdvib import LowPassFilter, simulate, welch_psd
from crowdvib.runner import study_executor
from crowdvib.response.time_domain.traffic import Pedestrian

ESTIMATORS = [(method, model, False) for model in ("smeared", "fluctuating")
              for method in ("least_squares", "likelihood")]


def fixed_interval_record(crowd, seed, hours=1.0):
    """Welch PSD of a simulated record whose walkers arrive every 1/λ seconds (seeded)."""
    rng = np.random.default_rng(seed)
    crossing = BRIDGE.length / crowd.walking_speed
    headway = 1.0 / crowd.arrival_rate(BRIDGE.width)
    warm_up, duration = 100.0, 3600.0 * hours
    # From one crossing before the start (the deck full at t = 0) to the end of the record.
    arrival = np.arange(-crossing - warm_up + headway * rng.uniform(), duration, headway)
    lanes = rng.uniform(-BRIDGE.width / 2, BRIDGE.width / 2, arrival.size)
    steps = rng.normal(crowd.step_frequency_mean, crowd.step_frequency_std, arrival.size)
    walkers = [Pedestrian(arrival_time=t + warm_up, walking_speed=crowd.walking_speed,
                          step_frequency=f, body_mass=crowd.body_mass, lane=y)
               for t, f, y in zip(arrival, steps, lanes)]
    record = simulate(BRIDGE, None, duration, pedestrians=walkers, msd=MSD, rng=seed,
                      warm_up=warm_up, sample_rate=100.0)
    return welch_psd(record.acceleration, 100.0, window_length=60.0,
                     output_names=record.output_names,
                     lowpass=LowPassFilter(10.0, 4, 100.0)).band(0, 10)


def record_estimates(density, seed):
    """One fixed-interval record: its PSD and, per estimator, ([(value, low, high)], seconds)."""
    crowd = paper_crowd(density)
    measured = fixed_interval_record(crowd, seed)
    found = estimates_of(measured, crowd, ESTIMATORS)
    return measured, found


def main(n=50, density=0.25, workers=1):
    crowd = paper_crowd(density)
    started = time.perf_counter()
    with study_executor(workers) as executor:
        jobs = [(executor.submit(record_estimates, density, seed) if executor
                 else None, seed) for seed in range(1, n + 1)]
        done = [job.result() if job else record_estimates(density, seed) for job, seed in jobs]
    rows = {key: [d[1][key][0] for d in done] for key in ESTIMATORS}
    seconds = {key: sum(d[1][key][1] for d in done) for key in ESTIMATORS}
    print(f"simulated records of 1 h of the paper example at {density:g} P/m², fixed-interval "
          f"arrivals, n = {n}, 95 % profile intervals; {time.perf_counter() - started:.1f} s "
          f"wall on {workers} worker(s)")
    _table(rows, n, seconds)
    mean = mean_psd([d[0] for d in done])
    print(f"\nthe mean Welch PSD of the {n} records")
    print_mean_estimates(mean, crowd, ESTIMATORS)

if __name__ == "__main__":
    workers = int(sys.argv[sys.argv.index("--workers") + 1]) if "--workers" in sys.argv else 1
    args = [a for i, a in enumerate(sys.argv[1:], start=1)
            if a != "--workers" and sys.argv[i - 1] != "--workers"]
    main(int(args[0]) if args else 50, float(args[1]) if len(args) > 1 else 0.25, workers)
