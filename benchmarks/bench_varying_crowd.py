"""A crowd that changes within a record (issue 28 §1): what the profile costs the simulator, and
what it changes in the estimate.

    python benchmarks/bench_varying_crowd.py [--duration 3600] [--seeds 5] [--method least_squares]

1. ``simulate`` of the paper's bridge with HSI at 100 Hz for ``--duration`` seconds: a density
   ramp 0.2 → 1.0 P/m² against the stationary crowd at its mean 0.6 P/m² (the same number of
   walkers on average), best of three; only the stream differs (docs: theory, A crowd that
   changes).
2. The ramp's records (50 Hz, 60 s Welch windows, band 0.5–10 Hz) estimated with the profile and
   with the mean density: f_h1 and ξ_h1 with their 95 % profile intervals per seed, whether the
   intervals hold the truth (3 Hz, 0.30), and the time per estimate.

Prints two tables; asserts nothing. Say the machine's load with the figures.
"""

import argparse
import time
import warnings

from crowdvib import (Crowd, CrowdProfile, ModalModel, MSDModel, estimate_hsi, simulate,
                      welch_psd)

TRUTH = MSDModel()


def _best_of(run, repeat=3):
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        run()
        times.append(time.perf_counter() - started)
    return min(times)


def simulation_speed(bridge, walkers, profile, duration):
    simulate(bridge, walkers, 10.0, msd=TRUTH, rng=0)          # compile outside the timing
    rows = []
    for label, crowd in (("stationary 0.6 P/m²", walkers),
                         ("ramp 0.2 → 1.0 P/m²", walkers.with_density(profile))):
        seconds = _best_of(lambda: simulate(bridge, crowd, duration, msd=TRUTH, rng=1))
        walkers_run = simulate(bridge, crowd, duration, msd=TRUTH, rng=1).n_pedestrians
        rows.append((label, seconds, walkers_run))
    print(f"simulate, paper bridge with HSI, {duration:g} s at 100 Hz (best of 3)")
    print(f"{'crowd':22s} {'time [s]':>9s} {'walkers':>8s} {'µs/walker':>10s}")
    for label, seconds, count in rows:
        print(f"{label:22s} {seconds:9.2f} {count:8d} {1e6 * seconds / count:10.1f}")
    print(f"profile / stationary: {rows[1][1] / rows[0][1]:.2f}\n")


def estimates(bridge, walkers, profile, duration, seeds, method):
    print(f"ramp records of {duration:g} s, 50 Hz, T = 60 s, band 0.5–10 Hz, method {method}; "
          f"truth f_h1 = {TRUTH.frequency:g} Hz, ξ_h1 = {TRUTH.damping_ratio:g}")
    print(f"{'seed':>4s} {'crowd model':12s} {'f_h1 [Hz] (95 %)':>26s} {'ξ_h1 (95 %)':>26s} "
          f"{'holds':>6s} {'time [s]':>8s}")
    held = {"profile": 0, "mean density": 0}
    for seed in range(seeds):
        record = simulate(bridge, walkers.with_density(profile), duration, msd=TRUTH, rng=seed,
                          sample_rate=50.0, warm_up=60.0)
        measured = welch_psd(record.acceleration, 50.0, window_length=60.0,
                             output_names=record.output_names)
        for label, crowd in (("profile", walkers.with_density(profile)),
                             ("mean density", walkers)):
            started = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                fit = estimate_hsi(measured, bridge, crowd, band=(0.5, 10.0), method=method)
            seconds = time.perf_counter() - started
            (f_low, f_high), (x_low, x_high) = (fit.intervals["frequency"],
                                                fit.intervals["damping_ratio"])
            holds = (f_low < TRUTH.frequency < f_high) and (x_low < TRUTH.damping_ratio < x_high)
            held[label] += holds
            print(f"{seed:4d} {label:12s} {fit.msd.frequency:7.3f} [{f_low:6.3f}, {f_high:6.3f}]"
                  f"   {fit.msd.damping_ratio:7.3f} [{x_low:6.3f}, {x_high:6.3f}]"
                  f" {'yes' if holds else 'no':>6s} {seconds:8.1f}")
    for label, count in held.items():
        print(f"{label}: both intervals hold the truth in {count} of {seeds}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=3600.0)
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--method", default="least_squares",
                        choices=("least_squares", "likelihood"))
    args = parser.parse_args()
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    walkers = Crowd.from_density(0.6)
    profile = CrowdProfile([0.0, args.duration], [0.2, 1.0])
    simulation_speed(bridge, walkers, profile, args.duration)
    estimates(bridge, walkers, profile, args.duration, args.seeds, args.method)


if __name__ == "__main__":
    main()
