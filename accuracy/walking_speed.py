"""Where the fluctuating model misses the simulated resonance: the same density at other speeds.

At a fixed density the occupancy law of a Poisson crowd does not depend on the walking speed,
but the occupancy changes faster when the walkers walk faster. Simulated one-hour records of the
paper example at 0.25 P/m² (true MSD, seeds 1…N), mean Welch PSD over the fluctuating model's
expected PSD per band, ± one standard error of the mean (docs: theory, The fluctuating crowd,
Evidence). ``--no-hsi`` simulates without the MSDs (a time-invariant bridge). The standard
error is that of the per-record band ratios (the bins of one record are correlated: their
errors do not add in quadrature). Each band is compared with the fluctuating model with the
walkers' finite crossings (the default) and with the narrow-band load; with HSI, the MSD is then
estimated on the records' mean PSD (the model's own error, free of the estimators' scatter).

    python accuracy/walking_speed.py SPEED [N] [--no-hsi]
    python accuracy/walking_speed.py calibration [N]

``calibration``: the records of ``intervals.py simulated N 0.25`` (Weidmann's speed,
100 s of warm-up; its cache is shared).

With ``CROWDVIB_RECORD_CACHE`` set, the records' Welch PSDs are kept there and reused.
"""

import os
import pickle
import sys
import warnings

import numpy as np

from crowdvib import BoundWarning, Crowd, LowPassFilter, estimate_hsi, simulate, welch_psd
from crowdvib.response import FluctuatingSpectralModel

sys.path.insert(0, os.path.dirname(__file__))
from intervals import (BRIDGE, MSD, mean_psd, paper_crowd,  # noqa: E402
                             simulated_record)

BANDS = ((0.3, 1.0), (1.5, 1.8), (1.8, 1.9), (1.9, 2.05), (2.05, 2.3), (3.5, 6.0))


def record(crowd, seed, msd):
    cache = os.environ.get("CROWDVIB_RECORD_CACHE")
    tag = "" if msd is not None else "_nohsi"
    path = cache and os.path.join(cache, f"v{crowd.walking_speed:g}{tag}_s{seed}.pkl")
    if path and os.path.exists(path):
        with open(path, "rb") as handle:
            return pickle.load(handle)
    # Warm-up: three crossings, so the deck holds its stationary crowd at any speed.
    warm_up = max(100.0, 3 * BRIDGE.length / crowd.walking_speed)
    simulated = simulate(BRIDGE, crowd, 3600.0, msd=msd, rng=seed, warm_up=warm_up,
                         sample_rate=100.0)
    psd = welch_psd(simulated.acceleration, 100.0, window_length=60.0,
                    output_names=simulated.output_names,
                    lowpass=LowPassFilter(10.0, 4, 100.0)).band(0, 10)
    if path:
        with open(path, "wb") as handle:
            pickle.dump(psd, handle)
    return psd


def mean_fit(psds, crowd):
    """Estimates (fluctuating model) on the records' mean Welch PSD: the model's own error."""
    mean = mean_psd(psds)
    for method in ("likelihood", "least_squares"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", BoundWarning)
            estimate = estimate_hsi(mean, BRIDGE, crowd, band=(0.0, 10.0), method=method,
                                    crowd_model="fluctuating")
        print(f"  fitted to the mean PSD, {method:13s}: f_h1 "
              f"{estimate.msd.frequency / MSD.frequency - 1:+.2%}, ξ_h1 "
              f"{estimate.msd.damping_ratio / MSD.damping_ratio - 1:+.2%}")


def band_table(psds, crowd, msd):
    """Mean simulated over model PSD per band, ± one standard error over the records."""
    frequency = psds[0].frequency
    values = np.array([p.psd[0] for p in psds])
    models = {label: FluctuatingSpectralModel(BRIDGE, crowd, frequency, welch_window_length=60.0,
                                              lowpass=psds[0].lowpass,
                                              finite_crossing=crossing).psd_array(msd)[0]
              for label, crossing in (("finite crossings", True), ("narrow-band load", False))}
    print(f"{'band [Hz]':12s}" + "".join(f"{label:>22s}" for label in models))
    for low, high in BANDS:
        k = (frequency >= low) & (frequency < high)
        cells = []
        for model in models.values():
            ratios = values[:, k].sum(axis=1) / model[k].sum()
            error = ratios.std(ddof=1) / np.sqrt(len(ratios))
            cells.append(f"{ratios.mean():.4f} ± {error:.4f}")
        print(f"{low:4.2f}–{high:4.2f}   " + "".join(f"{cell:>22s}" for cell in cells))


def main(speed, n=30, hsi=True):
    base = paper_crowd(0.25)
    crowd = Crowd(density=0.25, walking_speed=speed, step_frequency_mean=base.step_frequency_mean,
                  step_frequency_std=base.step_frequency_std, body_mass=base.body_mass)
    msd = MSD if hsi else None
    psds = [record(crowd, seed, msd) for seed in range(1, n + 1)]
    print(f"0.25 P/m², walking speed {speed:g} m/s, {n} one-hour records, "
          f"{'with' if hsi else 'without'} HSI: mean simulated / fluctuating model")
    band_table(psds, crowd, msd)
    if hsi:
        mean_fit(psds, crowd)


def calibration(n=200):
    crowd = paper_crowd(0.25)
    psds = [simulated_record(crowd, seed) for seed in range(1, n + 1)]
    print(f"0.25 P/m², the {n} one-hour records of intervals.py (seeds 1…{n}), true MSD: "
          "mean simulated / fluctuating model")
    band_table(psds, crowd, MSD)
    mean_fit(psds, crowd)


if __name__ == "__main__" and sys.argv[1:2] == ["calibration"]:
    calibration(*(int(a) for a in sys.argv[2:3]))
elif __name__ == "__main__":
    arguments = [a for a in sys.argv[1:] if a != "--no-hsi"]
    main(float(arguments[0]), int(arguments[1]) if len(arguments) > 1 else 30,
         hsi="--no-hsi" not in sys.argv)
