"""The drift correction against the exact time-varying system it approximates.

The correction (docs: theory, Beyond the quasi-static mixture) describes the occupied mode with
its crowd lumped into one MSD whose mass and load follow the occupancy λ(t); it then takes the
path to be Gaussian about its linear prediction and the pole linear about the mean path. This
study simulates that lumped system itself — the state matrices of the occupied mode at the
occupancy of a real stream of walkers (Poisson arrivals crossing a half sine at speed v, λ(t)
their Σ φ²(x_k(t)) over its mean), white load of intensity λ(t), exact discretisation for λ
constant over each 0.05 s — and prints its PSD of the modal displacement over the frozen
mixture per band of half-power half-widths around the occupied peak (± one standard error over
the hours), against the mixture plus the correction. What differs from the time-domain simulator (one MSD per walker, the Živanović
load) is then the lumping; what differs here is the correction's own approximation.

With ``--gaussian`` the occupancy is instead a stationary Gaussian process with the same
variance and correlation (spectral synthesis; clipped at 0), the correction's own path law, and
the mixture is taken over that Gaussian law (15 Gauss–Hermite nodes): what then remains between
the two columns is the pole's linearisation about the mean path and the single-pole picture.

Usage: ``python accuracy/drift_lumped.py [case] [hours] [seed] [--gaussian]``; cases
``paper`` (0.25 P/m², κ = 0.42), ``light`` (20 m bridge, 48 walkers of 17.5 kg, κ = 0.42) and
``strong`` (20 m bridge, 12 walkers of 70 kg, κ = 1.38).
"""

import sys
import time

import numba
import numpy as np
from scipy.linalg import expm
from scipy.signal import welch

from coupling import case as coupling_case          # the 20 m bridge's cases
from intervals import BRIDGE, paper_crowd           # the paper example's

from crowdvib import MSDModel
from crowdvib.response.frequency_domain._modulation import (OccupancyPath, _OccupiedMode, modulation_correction,
                                           occupancy_rate_variance)
from crowdvib.response.frequency_domain.fluctuation import FluctuatingSpectralModel, occupancy_cumulants

MSD = MSDModel(3.0, 0.30, 0.95)
STEP, OCCUPANCY_STEP, WINDOW = 0.01, 0.05, 200.0          # [s]
BANDS = ((-8, -4), (-4, -2), (-2, -1), (-1, 1), (1, 2), (2, 4), (4, 8))


def case(name):
    """(bridge, crowd): the paper example's at 0.25 P/m², or coupling.py's case A (light,
    κ = 0.42) or D (strong, κ = 1.38)."""
    if name == "paper":
        return BRIDGE, paper_crowd(0.25)
    return coupling_case({"light": "A", "strong": "D"}[name])


@numba.njit(cache=True)
def _occupancy(arrivals, count, step, crossing, length, speed, mean):
    """λ on an even grid: each walker adds sin²(πx/L)/ψ̄ while on the span."""
    occupancy = np.zeros(count)
    for start in arrivals:
        first = max(int(np.ceil(start / step)), 0)
        last = min(int((start + crossing) / step), count - 1)
        for i in range(first, last + 1):
            shape = np.sin(np.pi * speed * (i * step - start) / length)
            occupancy[i] += shape * shape / mean
    return occupancy


@numba.njit(cache=True)
def _response(occupancy, ratio, lowest, spacing, transition, noise_factor, noise, state):
    """x_{n+1} = Φ(λ) x_n + R(λ) ε_n with λ held over ``ratio`` steps → modal displacement."""
    out = np.empty(noise.shape[0])
    for i in range(noise.shape[0]):
        level = int((occupancy[i // ratio] - lowest) / spacing + 0.5)
        state = transition[level] @ state + noise_factor[level] @ noise[i]
        out[i] = state[0]
    return out, state


def _discretised(occupied, levels):
    """Φ = e^{AΔ} and a square root R of the noise covariance ∫ e^{As} b b'/2 e^{A's} ds
    (Van Loan) at each occupancy level: one-sided unit load PSD."""
    state, load = occupied.system(levels)
    size = state.shape[-1]
    transition, factor = np.empty_like(state), np.empty_like(state)
    for k in range(levels.size):
        block = np.zeros((2 * size, 2 * size))
        block[:size, :size] = -state[k]
        block[:size, size:] = 0.5 * load[k] @ load[k].T
        block[size:, size:] = state[k].T
        exponential = expm(block * STEP)
        transition[k] = exponential[size:, size:].T
        covariance = transition[k] @ exponential[:size, size:]
        values, vectors = np.linalg.eigh((covariance + covariance.T) / 2)
        factor[k] = vectors * np.sqrt(np.clip(values, 0.0, None))
    return transition, factor


def _gaussian_occupancy(path, count, rng):
    """A stationary Gaussian λ(t) of mean 1 with σ² ρ(τ) (circulant embedding), clipped at 0."""
    size = 1 << int(np.ceil(np.log2(2 * count)))
    support = int(np.ceil(path.structure.length / path.walking_speed / OCCUPANCY_STEP)) + 2
    correlation = path.variance * path.correlation(np.arange(support) * OCCUPANCY_STEP)
    circulant = np.zeros(size)
    circulant[:support], circulant[size - support + 1:] = correlation, correlation[1:][::-1]
    spectrum = np.maximum(np.fft.rfft(circulant).real, 0.0)
    noise = np.fft.rfft(rng.standard_normal(size))
    return np.maximum(1.0 + np.fft.irfft(noise * np.sqrt(spectrum), size)[:count], 0.0)


def main(name="paper", hours=300, seed=1, gaussian=False):
    bridge, crowd = case(name)
    rng = np.random.default_rng(seed)
    attached = FluctuatingSpectralModel(bridge, crowd, np.arange(0, 10, 0.01))._base._attached(MSD)
    occupied = _OccupiedMode(bridge, attached, 0)
    length, width, density, speed = bridge.length, bridge.width, crowd.density, crowd.walking_speed
    duration, crossing = 3600.0 * hours, length / speed
    variance = occupancy_cumulants(bridge, density, 0, 2)[1]
    path = OccupancyPath(bridge, speed, 0, variance,
                         occupancy_rate_variance(bridge, density, speed, 0))
    count = int(duration / OCCUPANCY_STEP) + 2
    if gaussian:
        occupancy = _gaussian_occupancy(path, count, rng)
    else:
        rate = density * speed * width
        arrivals = np.cumsum(rng.exponential(1 / rate,
                                             int(rate * (duration + crossing) * 1.1) + 100))
        arrivals = arrivals - crossing
        occupancy = _occupancy(arrivals[arrivals < duration], count, OCCUPANCY_STEP, crossing,
                               length, speed, density * width * length / 2)
    levels = np.linspace(0.0, occupancy.max() * 1.001, 600)
    transition, factor = _discretised(occupied, levels)
    ratio, per_hour = int(round(OCCUPANCY_STEP / STEP)), int(3600.0 / STEP)
    started, state, per_hour_psd = time.perf_counter(), np.zeros(transition.shape[-1]), []
    segment = int(WINDOW / STEP)
    for hour in range(hours):
        chunk = occupancy[hour * per_hour // ratio:(hour + 1) * per_hour // ratio + 1]
        out, state = _response(chunk, ratio, levels[0], levels[1] - levels[0], transition,
                               factor, rng.standard_normal((per_hour, state.size)), state)
        frequency, psd = welch(out, fs=1 / STEP, nperseg=segment, noverlap=segment // 2,
                               detrend=False)
        per_hour_psd.append(psd[frequency < 10.0].astype(np.float32))
    frequency = frequency[frequency < 10.0]
    per_hour_psd = np.array(per_hour_psd)
    model = FluctuatingSpectralModel(bridge, crowd, frequency, modulation=False)
    nodes, weights = model.nodes, model.weights
    if gaussian:            # the mixture over the Gaussian law the occupancy now has
        points, weights = np.polynomial.hermite_e.hermegauss(15)
        nodes, weights = np.maximum(1.0 + np.sqrt(variance) * points, 0.01), weights / weights.sum()
    omega = 2j * np.pi * frequency[:, np.newaxis, np.newaxis]

    def frozen(level):
        matrix, load = occupied.system(level)
        size = matrix.shape[-1]
        transfer = np.linalg.solve(omega * np.eye(size) - matrix,
                                   np.broadcast_to(load, (frequency.size, size, 1)))
        return np.abs(transfer[:, 0, 0]) ** 2

    mixture = sum(w * frozen(level) for level, w in zip(nodes, weights))
    correction = modulation_correction(bridge, attached, np.ones((1, 1)), 0, nodes, weights,
                                       path, frequency)[0]
    peak = frequency[np.argmax(np.where(frequency > 1.0, mixture, 0.0))]
    track, _, _, _ = occupied.drifting_poles(np.ones(1))
    half = -track[0, 0].real / (2 * np.pi)
    law = "Gaussian occupancy" if gaussian else "walkers' occupancy"
    print(f"{name}: lumped system, {law}, {hours} h ({time.perf_counter() - started:.0f} s), seed {seed}; "
          f"Var λ {occupancy.var():.4f} (Campbell {variance:.4f}); peak {peak:.3f} Hz, "
          f"half-width {half:.4f} Hz")
    print(f"  {'band [half-widths]':20s}{'lumped/mixture':>22s}{'corrected/mixture':>19s}")
    for low, high in BANDS:
        inside = (frequency >= peak + low * half) & (frequency < peak + high * half)
        ratios = per_hour_psd[:, inside].sum(axis=1) / mixture[inside].sum()
        error = ratios.std(ddof=1) / np.sqrt(hours)     # hours nearly independent (memory ≪ 1 h)
        print(f"  {f'{low:+d} … {high:+d}':20s}{ratios.mean():14.3f} ± {error:.3f}"
              f"{(mixture + correction)[inside].sum() / mixture[inside].sum():19.3f}")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--gaussian"]
    main(args[0] if args else "paper", int(args[1]) if len(args) > 1 else 300,
         int(args[2]) if len(args) > 2 else 1, gaussian="--gaussian" in sys.argv)
