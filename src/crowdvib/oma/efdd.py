"""Enhanced frequency domain decomposition (docs: theory, Operational modal analysis, EFDD).

crowdvib's own EFDD [BVA01]_ (pyOMA2's takes the square root of the singular values as the SDOF
bell, which is the spectrum of the amplitude, not of the power, and triples the damping of a
lightly damped mode; see the theory page). Steps:

1. Welch estimate of the output cross-spectral matrix G(f) (Hann window, 50 % overlap);
2. its singular value decomposition at every line: the first singular value s₁(f) and vector
   u₁(f);
3. per mode, the peak of s₁ and the SDOF bell: the contiguous lines around it whose u₁ has a MAC
   >= ``mac_threshold`` with the peak's, and no further than halfway to the neighbouring modes;
4. the bell's inverse FFT: the mode's correlation function, divided by the Hann window's lag
   window (the leakage of the Welch estimate, exact in expectation);
5. the damped frequency from the zero crossings, the decay rate from the logarithm of the
   extrema (between the first and the level ``DECAY_LEVEL``), hence f and ξ;
6. standard deviations by a delete-a-group jackknife over the Welch segments, widened to the
   Student-t quantile of its degrees of freedom.
"""

from __future__ import annotations

import numpy as np
from scipy import stats
from scipy.signal import find_peaks
from scipy.signal.windows import hann

from ..errors import EstimationError
from .modeid import ModeIdentification

__all__ = ["efdd_modes", "default_segment_length", "DECAY_LEVEL", "MAX_LAG_SHARE",
           "PEAK_PROMINENCE", "MAC_THRESHOLD", "N_GROUPS"]

#: The decay is fitted on the correlation's extrema down to this share of its value at lag 0.
DECAY_LEVEL = 0.3
#: ... and at lags up to this share of the segment (the Hann lag window is 0.66 there).
MAX_LAG_SHARE = 0.25
#: Extrema skipped at the start (the bell's truncation shapes the shortest lags).
SKIP_EXTREMA = 1
#: A bell line's first singular vector must have at least this MAC with the peak's.
MAC_THRESHOLD = 0.8
#: Without n_modes, a peak of s₁ is a mode when it stands this many decades above its sides.
PEAK_PROMINENCE = 0.5
#: Search half-width around a given frequency for its peak, as a share of the frequency.
SEARCH_WIDTH = 0.05
#: Jackknife groups of Welch segments (at most).
N_GROUPS = 16
#: Zero padding of the bell before its inverse FFT (time resolution of the correlation).
PAD = 8


def default_segment_length(n_samples: int) -> int:
    """Welch segment: the largest power of two <= n_samples / 16 (>= 256): about 30 segments
    at 50 % overlap, fine enough in frequency for a 30-minute record of a lightly damped mode."""
    return int(max(256, 2 ** int(np.floor(np.log2(max(n_samples / 16, 1))))))


class _Spectra:
    """Windowed segment spectra in the analysis band, summed into G(f) per jackknife group."""

    def __init__(self, data, sample_rate, segment_length, n_groups, band):
        n_samples = data.shape[1]
        self.length = segment_length
        self.sample_rate = sample_rate
        starts = np.arange(0, n_samples - segment_length + 1, segment_length // 2)
        frequency = np.fft.rfftfreq(segment_length, 1 / sample_rate)
        self.lines = np.flatnonzero((frequency >= band[0]) & (frequency <= band[1]))
        self.frequency = frequency[self.lines]
        window = hann(segment_length, sym=False)
        self.segments = []
        for chunk in np.array_split(starts, max(1, starts.size // 8)):
            block = data[:, chunk[:, np.newaxis] + np.arange(segment_length)]
            block = block - block.mean(axis=-1, keepdims=True)
            self.segments.append(np.fft.rfft(block * window, axis=-1)[:, :, self.lines])
        self.segments = np.concatenate(self.segments, axis=1)     # (sensors, segments, lines)
        self.n_segments = starts.size
        self.groups = np.array_split(np.arange(starts.size), min(n_groups, starts.size))
        self.scale = 2 / (sample_rate * np.sum(window**2))
        # lag window of the Hann window: its normalised autocorrelation, on the padded time grid
        lag = np.fft.irfft(np.abs(np.fft.rfft(window, 2 * segment_length)) ** 2)
        lag = lag[:segment_length] / lag[0]
        self.time = np.arange(segment_length * PAD // 2) / (sample_rate * PAD)
        self.lag_window = np.interp(self.time * sample_rate, np.arange(segment_length), lag)

    def matrix(self, lines, leave_out=None):
        """G at the band lines ``lines`` (indices into ``self.frequency``), one group left out."""
        keep = (np.arange(self.n_segments) if leave_out is None else
                np.setdiff1d(np.arange(self.n_segments), self.groups[leave_out]))
        x = self.segments[:, keep][:, :, lines]
        return np.einsum("isf,jsf->fij", x, x.conj()) * (self.scale / keep.size)


def _first_singular(matrix):
    u, s, _ = np.linalg.svd(matrix, hermitian=True)
    return s, u[:, :, 0]


def _mac_rows(rows, reference):
    num = np.abs(rows.conj() @ reference) ** 2
    return num / (np.sum(np.abs(rows) ** 2, axis=1) * np.vdot(reference, reference).real)


def _one_mode(spectra, lines, values, vectors, target, mac_threshold, limits):
    """(f, ξ, shape, (bell start, end) [Hz]) of the mode whose peak is nearest ``target``; the
    bell stays within ``limits`` [Hz] (halfway to the neighbouring modes)."""
    frequency = spectra.frequency[lines]
    near = np.flatnonzero(np.abs(frequency - target) <= SEARCH_WIDTH * target)
    if near.size == 0:
        raise EstimationError(f"no spectral line within {SEARCH_WIDTH:.0%} of {target:g} Hz")
    peak = near[np.argmax(values[near, 0])]
    shape = vectors[peak]
    different = np.flatnonzero((_mac_rows(vectors, shape) < mac_threshold)
                               | (frequency < limits[0]) | (frequency > limits[1]))
    below, above = different[different < peak], different[different > peak]
    low = below[-1] + 1 if below.size else 0                 # the bell: lines low … high − 1
    high = above[0] if above.size else vectors.shape[0]
    bell = np.zeros(spectra.length * PAD // 2 + 1)
    first = spectra.lines[lines[low]]
    bell[first:first + high - low] = values[low:high, 0]
    correlation = np.fft.irfft(bell, n=spectra.length * PAD)[:spectra.time.size]
    usable = spectra.time <= MAX_LAG_SHARE * spectra.length / spectra.sample_rate
    correlation = correlation[usable] / spectra.lag_window[usable]
    correlation = correlation / correlation[0]
    frequency_hz, damping = _decay(spectra.time[usable], correlation,
                                   spectra.time[1] - spectra.time[0], target)
    real = np.real(shape * np.exp(-1j * np.angle(shape[np.argmax(np.abs(shape))])))
    return (frequency_hz, damping, real / real[np.argmax(np.abs(real))],
            (float(frequency[low]), float(frequency[high - 1])))


def _decay(time, correlation, step, target):
    """Natural frequency and damping ratio from a normalised SDOF correlation function."""
    extrema = np.sort(np.concatenate([find_peaks(correlation)[0], find_peaks(-correlation)[0]]))
    before, at, after = correlation[extrema - 1], correlation[extrema], correlation[extrema + 1]
    curvature = before - 2 * at + after
    shift = np.divide(0.5 * (before - after), curvature, out=np.zeros_like(at),
                      where=curvature != 0)
    times = time[extrema] + shift * step
    heights = np.abs(at - 0.25 * (before - after) * shift)
    low = np.flatnonzero(heights < DECAY_LEVEL)
    end = low[0] if low.size else extrema.size
    times, heights = times[SKIP_EXTREMA:end], heights[SKIP_EXTREMA:end]
    if times.size < 4:
        raise EstimationError(f"the correlation function of the mode near {target:g} Hz has "
                              f"{times.size} usable extrema (4 needed): the mode is too heavily "
                              f"damped for EFDD or the bell too narrow")
    rate = -np.polyfit(times, np.log(heights), 1)[0]
    crossing = np.flatnonzero(np.signbit(correlation[:-1]) != np.signbit(correlation[1:]))
    zeros = time[crossing] - correlation[crossing] * step / (correlation[crossing + 1]
                                                              - correlation[crossing])
    zeros = zeros[(zeros >= times[0]) & (zeros <= times[-1])]
    half_period = np.polyfit(np.arange(zeros.size), zeros, 1)[0]
    omega_d = np.pi / half_period
    damping = rate / np.hypot(rate, omega_d)
    if not 0 < damping < 1:
        raise EstimationError(f"the correlation function of the mode near {target:g} Hz does "
                              f"not decay (damping ratio {damping:.3g})")
    return omega_d / (2 * np.pi * np.sqrt(1 - damping**2)), damping


def _peaks(frequency, values, low, high, n_modes):
    """Frequencies of the most prominent peaks of s₁ in [low, high] (docs: theory, EFDD)."""
    level = np.log10(np.maximum(values[:, 0], np.finfo(float).tiny))
    peaks, properties = find_peaks(level, prominence=0.0 if n_modes else PEAK_PROMINENCE)
    inside = (frequency[peaks] >= low) & (frequency[peaks] <= high)
    peaks, prominence = peaks[inside], properties["prominences"][inside]
    ranked = peaks[np.argsort(-prominence, kind="stable")]
    if n_modes is not None:
        if ranked.size < n_modes:
            raise EstimationError(f"only {ranked.size} peak(s) of the first singular value in "
                                  f"the band, n_modes = {n_modes} asked")
        ranked = ranked[:n_modes]
    if ranked.size == 0:
        raise EstimationError(f"no peak of the first singular value stands {PEAK_PROMINENCE} "
                              f"decades above its sides in the band: give n_modes")
    return np.sort(frequency[ranked])


def efdd_modes(data, sample_rate, names, low, high, *, n_modes=None, frequencies=None,
               segment_length=None, mac_threshold=MAC_THRESHOLD, n_groups=N_GROUPS,
               drop_failed=False):
    """EFDD identification of validated signals (docs: theory, Operational modal analysis, EFDD).

    ``frequencies`` seeds the peak search (a cross-check of SSI-cov); else the ``n_modes`` most
    prominent peaks of s₁ in [low, high]. With ``drop_failed`` a mode whose correlation
    function cannot be fitted is left out instead of raising.
    """

    length = default_segment_length(data.shape[1]) if segment_length is None else segment_length
    if 2 * length > data.shape[1]:
        raise EstimationError(f"segment_length {length} leaves fewer than 3 Welch segments in "
                              f"{data.shape[1]} samples")
    nyquist = sample_rate / 2
    spectra = _Spectra(data, sample_rate, length, n_groups,
                       (0.5 * low, min(nyquist, 1.5 * high)))
    all_lines = np.arange(spectra.frequency.size)
    values, vectors = _first_singular(spectra.matrix(all_lines))
    targets = (_peaks(spectra.frequency, values, low, high, n_modes) if frequencies is None
               else np.asarray(frequencies, dtype=float))
    groups = len(spectra.groups)
    widen = stats.t.ppf(0.975, groups - 1) / stats.norm.ppf(0.975)
    rows = []
    middles = np.sqrt(targets[1:] * targets[:-1]) if targets.size > 1 else np.zeros(0)
    edges = np.concatenate([[0.0], np.sort(middles), [np.inf]])
    for target in targets:
        above = np.searchsorted(edges, target)
        limits = (edges[above - 1], edges[above])
        try:
            f, xi, shape, bell = _one_mode(spectra, all_lines, values, vectors, target,
                                           mac_threshold, limits)
            # jackknife over groups, on the lines of the bell and the peak search only
            first = np.searchsorted(spectra.frequency, min(bell[0], f * (1 - SEARCH_WIDTH)))
            last = np.searchsorted(spectra.frequency, max(bell[1], f * (1 + SEARCH_WIDTH)),
                                   side="right")
            lines = all_lines[max(0, first - 1):last + 1]
            replicates = []
            for g in range(groups):
                v, u = _first_singular(spectra.matrix(lines, leave_out=g))
                replicates.append(_one_mode(spectra, lines, v, u, f, mac_threshold,
                                            limits)[:2])
        except EstimationError:
            if not drop_failed:
                raise
            continue
        replicates = np.array(replicates)
        spread = (groups - 1) / groups * np.sum((replicates - replicates.mean(axis=0)) ** 2,
                                                axis=0)
        rows.append((f, xi, widen * np.sqrt(spread[0]), widen * np.sqrt(spread[1]), shape, bell))
    if not rows and not drop_failed:
        raise EstimationError("EFDD identified no mode")
    return ModeIdentification(
        frequencies=np.array([r[0] for r in rows]), damping_ratios=np.array([r[1] for r in rows]),
        frequency_std=np.array([r[2] for r in rows]), damping_std=np.array([r[3] for r in rows]),
        mode_shapes=(np.column_stack([r[4] for r in rows]) if rows
                     else np.zeros((data.shape[0], 0))),
        sensor_names=names, sample_rate=sample_rate, method="efdd",
        poles={"frequency": spectra.frequency, "singular_values": values,
               "bells": [r[5] for r in rows], "targets": targets, "segment_length": length,
               "groups": groups},
        settings={"segment_length": int(length), "mac_threshold": float(mac_threshold),
                  "groups": int(groups), "frequency_band": [float(low), float(high)]})
