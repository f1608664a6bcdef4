"""The simulator's modal load against the spectral model's, around the paper example's resonance.

The spectral model's load on a mode is Ψ s∗K: the crowd influence times the narrow-band
Živanović load spectrum smoothed by the finite-crossing kernel (docs: theory, Modal load PSD of a
Poisson crowd; Finite crossings). The time-domain simulator builds the same load walker by walker
(drawn step frequency, DLFs, phase and body mass, moving along the mode shape). This study runs
the simulator without HSI for N seeded hours, records the modal load, and prints its Welch PSD
over the model's per frequency band (± one standard error over the hours): a tilt across the
occupied resonance would move an estimate of f_h1.

Usage: ``python accuracy/modal_load.py [density] [hours]`` (defaults 0.5 P/m², 100 h).
"""

import sys
import time

import numpy as np
from scipy.signal import welch

from intervals import BRIDGE, paper_crowd     # the calibration's bridge and crowds

from crowdvib import simulate
from crowdvib.models.loading import as_force_model
from crowdvib.response.frequency_domain._crossing import crossing_spread, smoothed_load_spectrum

BANDS = ((1.5, 1.7), (1.7, 1.8), (1.8, 1.85), (1.85, 1.9), (1.9, 1.95), (1.95, 2.0), (2.0, 2.05),
         (2.05, 2.1), (2.1, 2.2), (2.2, 2.4))
SAMPLE_RATE, WINDOW = 20.0, 60.0


def main(density=0.5, hours=100):
    crowd = paper_crowd(density)
    started, per_hour = time.perf_counter(), []
    for seed in range(1, hours + 1):
        record = simulate(BRIDGE, crowd, 3600.0, msd=None, rng=1000 + seed, warm_up=100.0,
                          sample_rate=SAMPLE_RATE, record_modal_load=True)
        frequency, psd = welch(record.modal_load[0], fs=SAMPLE_RATE,
                               nperseg=int(WINDOW * SAMPLE_RATE),
                               noverlap=int(WINDOW * SAMPLE_RATE / 2), detrend=False)
        per_hour.append(psd)
    per_hour = np.array(per_hour)
    psi = BRIDGE.influence_matrix(crowd.density)[0, 0]
    spread = crossing_spread(BRIDGE, crowd.walking_speed, 0)
    force = as_force_model(None)
    model = psi * smoothed_load_spectrum(force, frequency, crowd, spread)
    narrow = psi * force.load_spectrum(frequency, crowd)
    print(f"{density:g} P/m² (step frequencies N({crowd.step_frequency_mean:g}, "
          f"{crowd.step_frequency_std:g}) Hz, {crowd.walking_speed:g} m/s), crossing spread "
          f"{spread:.4f} Hz; {hours} simulated hours without HSI "
          f"({time.perf_counter() - started:.0f} s)")
    print(f"  {'band [Hz]':12s}{'simulated/model':>22s}{'narrow-band/model':>19s}")
    for low, high in BANDS:
        inside = (frequency >= low) & (frequency < high)
        ratios = per_hour[:, inside].sum(axis=1) / model[inside].sum()
        print(f"  {f'{low:.2f}–{high:.2f}':12s}{ratios.mean():14.3f} ± "
              f"{ratios.std(ddof=1) / np.sqrt(hours):.3f}"
              f"{narrow[inside].sum() / model[inside].sum():19.3f}")


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 0.5,
         int(sys.argv[2]) if len(sys.argv) > 2 else 100)
