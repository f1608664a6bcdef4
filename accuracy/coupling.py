"""Where the drift correction of the fluctuating crowd model holds: a light 20 m × 2 m bridge.

The correction (docs: theory, Beyond the quasi-static mixture) was checked on the paper's bridge,
where κ — the occupied resonance's shift over one standard deviation of the occupancy, in
half-power half-widths — is about 0.4 at every density. This study simulates a 20 m bridge
(2 Hz, 0.5 %, walkers at 1.3 m/s, step frequencies N(1.95, 0.175) Hz, truth 3 Hz / 0.30 / 0.95)
with crowds and modal masses that set κ from 0.42 to 1.96, and prints, per case, the mean Welch
PSD of N seeded three-hour records over the mixture in bands around the occupied peak (± one
standard error over the records) against the correction's prediction, then the likelihood and
least squares fitted to that mean PSD with and without the correction (model error alone: the
finite-sample scatter is divided by √N).

Usage: ``python accuracy/coupling.py [N] [case …]`` (default 60 records, every case;
cases ``A`` … ``E`` as in CASES). With ``CROWDVIB_RECORD_CACHE`` set to a directory the records'
Welch PSDs are kept there and reused.
"""

import dataclasses
import os
import pickle
import sys
import time
import warnings

import numpy as np

from crowdvib import BoundWarning, Crowd, ModalModel, MSDModel, estimate_hsi, simulate, welch_psd
from crowdvib.response.frequency_domain.fluctuation import FluctuatingSpectralModel

TRUTH = MSDModel(3.0, 0.30, 0.95)
#: name → (modal mass [kg], density [P/m²], body mass [kg]); κ from 0.42 to 1.96.
CASES = {"A": (12600.0, 1.2, 17.5), "B": (16800.0, 1.2, 70.0), "C": (4200.0, 0.6, 35.0),
         "D": (4200.0, 0.3, 70.0), "E": (4200.0, 0.15, 140.0)}
#: Bands around the occupied peak, in units of 0.02 Hz.
BANDS = ((-6, -3), (-3, -1), (-1, 1), (1, 3), (3, 6))
HOURS = 3.0


def case(name):
    modal_mass, density, body_mass = CASES[name]
    bridge = ModalModel.simply_supported_beam(20.0, 2.0, 2.0, 0.005, modal_mass)
    crowd = Crowd(density=density, walking_speed=1.3, step_frequency_mean=1.95,
                  step_frequency_std=0.175, body_mass=body_mass)
    return bridge, crowd


def record(name, seed):
    """Welch PSD of one seeded three-hour record of case ``name`` (cached when asked)."""
    cache = os.environ.get("CROWDVIB_RECORD_CACHE")
    path = cache and os.path.join(cache, f"coupling{name}_s{seed}.pkl")
    if path and os.path.exists(path):
        with open(path, "rb") as handle:
            return pickle.load(handle)
    bridge, crowd = case(name)
    simulated = simulate(bridge, crowd, 3600.0 * HOURS, msd=TRUTH, rng=seed, warm_up=60.0,
                         sample_rate=50.0)
    psd = welch_psd(simulated.acceleration, 50.0, window_length=60.0,
                    output_names=simulated.output_names).band(0.0, 10.0)
    if path:
        with open(path + ".tmp", "wb") as handle:
            pickle.dump(psd, handle)
        os.replace(path + ".tmp", path)
    return psd


def study(name, n):
    bridge, crowd = case(name)
    started = time.perf_counter()
    records = [record(name, seed) for seed in range(1, n + 1)]
    frequency = records[0].frequency
    options = dict(welch_window_length=records[0].window_length, lowpass=records[0].lowpass)
    mixture = FluctuatingSpectralModel(bridge, crowd, frequency, modulation=False, **options)
    corrected = FluctuatingSpectralModel(bridge, crowd, frequency, modulation=True, **options)
    plain, with_correction = mixture.psd_array(TRUTH)[0], corrected.psd_array(TRUTH)[0]
    peak = frequency[np.argmax(np.where(frequency > 1.0, plain, 0.0))]
    print(f"case {name}: modal mass {bridge.modal_masses[0]:g} kg, {crowd.density:g} P/m² of "
          f"{crowd.body_mass:g} kg ({crowd.density * 40:g} walkers), κ = "
          f"{corrected.spread_parameter:.2f}, ε = {corrected.modulation_parameter:.2f}; {n} "
          f"records of {HOURS:g} h ({time.perf_counter() - started:.0f} s); peak {peak:.3f} Hz")
    ratios = np.array([r.psd[0] / plain for r in records])
    print(f"  {'band [0.02 Hz]':16s}{'records/mixture':>20s}{'correction':>12s}")
    for low, high in BANDS:
        inside = (frequency >= peak + 0.02 * low) & (frequency < peak + 0.02 * high)
        per = ratios[:, inside].mean(axis=1)
        print(f"  {f'{low:+d} … {high:+d}':16s}{per.mean():11.3f} ± {per.std(ddof=1) / np.sqrt(n):.3f}"
              f"{with_correction[inside].sum() / plain[inside].sum():12.3f}")
    mean = dataclasses.replace(records[0], psd=np.mean([r.psd for r in records], axis=0),
                               n_windows=sum(r.n_windows for r in records), dispersion=None)
    build = FluctuatingSpectralModel.__init__
    for modulation in (False, True):
        # estimate_hsi builds its own model: the switch is set on the class for this fit.
        def switched(self, *args, **kwargs):
            build(self, *args, **dict(kwargs, modulation=modulation))

        FluctuatingSpectralModel.__init__ = switched
        try:
            line = f"  {'with' if modulation else 'without'} correction:"
            for method in ("likelihood", "least_squares"):
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", BoundWarning)
                    found = estimate_hsi(mean, bridge, crowd, band=(0.0, 6.0), method=method,
                                         crowd_model="fluctuating", interval=None)
                line += (f"  {method} f_h1 {found.msd.frequency / 3.0 - 1:+.2%} ξ_h1 "
                         f"{found.msd.damping_ratio / 0.30 - 1:+.2%}")
        finally:
            FluctuatingSpectralModel.__init__ = build
        print(line, flush=True)


def main(n=60, names=tuple(CASES)):
    for name in names:
        study(name, n)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 60, tuple(sys.argv[2:]) or tuple(CASES))
