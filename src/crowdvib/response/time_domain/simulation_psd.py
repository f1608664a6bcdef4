"""The Welch PSD of a simulated record too long to keep (issue 28 §3): :func:`simulate_psd`.

The record of :func:`.simulate` is run a chunk at a time and each Welch segment's periodogram is
added as soon as its samples are in (:class:`_WelchSums`), so memory does not grow with the
duration.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..._validation import check_positive
from ...errors import ParameterError
from ...signals.spectrum import ResponsePSD
from ...signals.welch import DISPERSION_LAGS, dispersion_ratio, segment_periodograms
from ._run import Run
from .results import SimulationPSD
from .simulation import _start

if TYPE_CHECKING:
    from ..._validation import ForceModel, Seed
    from ...models.crowd import Crowd
    from ...models.damper import TunedMassDamper
    from ...models.pedestrian import MSDModel
    from ...models.structure import ModalModel
    from .traffic import Pedestrian

__all__ = ["simulate_psd"]


class _WelchSums:
    """A Welch average taken chunk by chunk: the segments of ``welch_psd`` (Hann, constant
    detrend, density scaling, a step of T − ⌊T·overlap⌋ samples from the first sample), each
    periodogram added once the samples it covers have arrived; only the samples of the segment
    not yet complete are held.

    The dispersion of ``welch_psd`` from running sums: Σ P_i, Σ P_i², Σ P_i P_(i+l) for the
    lags l <= DISPERSION_LAGS, and the first and last L periodograms, which give the sums of
    the centred products Σ (P_i − m)(P_(i+l) − m) once the mean m is known.
    """

    def __init__(self, n_outputs, sample_rate, segment, overlap):
        self.sample_rate, self.segment = sample_rate, segment
        self.overlap = overlap
        self.step = segment - int(segment * overlap)
        self.held = np.zeros((n_outputs, 0))
        self.total = self.squares = 0.0
        self.lagged = [0.0] * DISPERSION_LAGS
        self.first = self.last = None
        self.count = 0
        self.frequency = None

    def _add_periodograms(self, periodograms):
        self.total = self.total + periodograms.sum(axis=-1)
        self.squares = self.squares + np.sum(periodograms**2, axis=-1)
        recent = (periodograms if self.last is None
                  else np.concatenate([self.last, periodograms], axis=-1))
        new = periodograms.shape[-1]
        for lag in range(1, DISPERSION_LAGS + 1):
            if recent.shape[-1] > lag:
                later = recent[..., max(lag, recent.shape[-1] - new):]
                earlier = recent[..., max(lag, recent.shape[-1] - new) - lag:-lag]
                self.lagged[lag - 1] = self.lagged[lag - 1] + np.sum(later * earlier, axis=-1)
        self.last = recent[..., -DISPERSION_LAGS:]
        self.first = recent[..., :DISPERSION_LAGS] if self.first is None or (
            self.first.shape[-1] < DISPERSION_LAGS) else self.first

    def dispersion(self):
        """``welch_psd``'s dispersion of the segments added (None below 8 segments)."""
        k = self.count
        if k < 8:
            return None
        mean = self.total / k
        variance = self.squares / k - mean**2
        for lag in range(1, min(DISPERSION_LAGS, k - 1) + 1):
            before = self.total - self.last[..., -lag:].sum(axis=-1)     # P_0 … P_(k-1-l)
            after = self.total - self.first[..., :lag].sum(axis=-1)      # P_l … P_(k-1)
            centred = self.lagged[lag - 1] - mean * (before + after) + (k - lag) * mean**2
            variance = variance + 2 * (1 - lag / k) * centred / k
        return dispersion_ratio(variance, mean, k, self.overlap)

    def add(self, samples):
        data = np.concatenate([self.held, samples], axis=1)
        complete = (data.shape[1] - self.segment) // self.step + 1 if (
            data.shape[1] >= self.segment) else 0
        if complete:
            used = (complete - 1) * self.step + self.segment
            self.frequency, periodograms = segment_periodograms(
                data[:, :used], self.sample_rate, self.segment, self.overlap)
            self._add_periodograms(periodograms)
            self.count += complete
        self.held = data[:, complete * self.step:]


def simulate_psd(structure: ModalModel, crowd: Crowd | None = None,
                 duration: float | None = None, *, window_length: float, overlap: float = 0.5,
                 pedestrians: Sequence[Pedestrian] | None = None, msd: MSDModel | None = None,
                 force: ForceModel | None = None, sample_rate: float = 100.0, rng: Seed = None,
                 progress: Callable[[float, float], None] | None = None,
                 include_static_weight: bool = False, chunk_duration: float | None = None,
                 warm_up: float = 0.0,
                 dampers: Sequence[TunedMassDamper] | None = None) -> SimulationPSD:
    """The Welch PSD and summaries of the record :func:`simulate` would return, without the
    record: memory does not grow with ``duration`` beyond 32 bytes a pedestrian (issue 28 §3;
    a month of the paper example fits in well under 1 GB).

    The samples are run a chunk at a time and each Welch segment's periodogram is added as soon
    as its samples are in: the PSD equals ``welch_psd(simulate(...).acceleration, ...)`` of the
    same seed and options to round-off (the segments are summed in another order). Every
    parameter but ``window_length`` and ``overlap`` is :func:`simulate`'s.

    Parameters
    ----------
    structure, crowd, duration, pedestrians, msd, force, sample_rate, rng, progress
        As for :func:`simulate`.
    include_static_weight, chunk_duration, warm_up, dampers
        As for :func:`simulate`.
    window_length : float
        Welch segment length T [s] (Hann window, constant detrend, as
        :func:`crowdvib.welch_psd`).
    overlap : float
        Overlap of consecutive segments, fraction of T, in [0, 1).

    Returns
    -------
    SimulationPSD
        The PSD (``ResponsePSD``, ``source="welch"``, with the segments' dispersion as
        ``welch_psd`` measures it) with the RMS and peak |a| per output, the people on the deck
        and the run's metadata.

    See Also
    --------
    crowdvib.simulate : the record itself.
    crowdvib.welch_psd : the same PSD of a kept record.

    Notes
    -----
    No low-pass: ``welch_psd``'s filter is zero-phase (forward and backward over the whole
    record), which cannot be applied a chunk at a time. A model compared with this PSD should
    be taken unfiltered; filter a record of :func:`simulate` where the filter matters.

    References
    ----------
    K. Van Nimmen and P. Van den Broeck, "Using full-scale observations on footbridges to estimate
    the parameters governing human–structure interaction", *Journal of Bridge Engineering* 28(1),
    2023. The coupled equations of motion (Eq. 1–4).

    P. D. Welch, "The use of fast Fourier transform for the estimation of power spectra: a method
    based on time averaging over short, modified periodograms", *IEEE Transactions on Audio and
    Electroacoustics* 15(2):70–73, 1967. The averaged periodograms.

    The theory pages cite them (docs: theory, References).

    Examples
    --------
    >>> from crowdvib import Crowd, MSDModel, ModalModel, simulate_psd
    >>> bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    >>> result = simulate_psd(bridge, Crowd.from_density(0.5), 120.0, msd=MSDModel(), rng=1,
    ...                       window_length=20.0)
    >>> result.psd.n_windows
    11
    """
    window_length = check_positive("window_length", window_length, unit="s")
    if not 0.0 <= overlap < 1.0:
        raise ParameterError(f"overlap must lie in [0, 1), got {overlap!r}")
    run = Run.checked(structure, crowd, duration, pedestrians=pedestrians, msd=msd, force=force,
                      sample_rate=sample_rate, rng=rng, progress=progress,
                      include_static_weight=include_static_weight,
                      chunk_duration=chunk_duration, record_modal_load=False, warm_up=warm_up,
                      dampers=dampers, keep_record=False)
    integrator, chunks = _start(run)
    sample_rate, n_samples = run.sample_rate, run.n_samples
    segment = int(round(window_length * sample_rate))
    if segment < 8:
        raise ParameterError(
            f"window_length × sample_rate must give at least 8 samples, got {segment}")
    if n_samples < segment:
        raise ParameterError(
            f"duration must hold one window: {n_samples / sample_rate:g} s is shorter than "
            f"window_length = {window_length:g} s")
    welch = _WelchSums(structure.n_outputs, sample_rate, segment, overlap)
    squares = np.zeros(structure.n_outputs)
    peak = np.zeros(structure.n_outputs)
    people, most = 0, 0
    for _, count in chunks:
        samples = integrator.acceleration[:, :count]
        welch.add(samples)
        squares += np.sum(samples**2, axis=1)
        peak = np.maximum(peak, np.max(np.abs(samples), axis=1, initial=0.0))
        on_deck = integrator.n_on_deck[:count] - integrator.n_dampers
        people += int(on_deck.sum())
        most = max(most, int(on_deck.max(initial=0)))
    psd = ResponsePSD(frequency=welch.frequency, psd=welch.total / welch.count,
                      output_names=structure.output_names, window_length=segment / sample_rate,
                      n_windows=welch.count, source="welch", dispersion=welch.dispersion())
    return SimulationPSD(
        psd=psd, rms=np.sqrt(squares / n_samples), peak=peak, sample_rate=sample_rate,
        seed=run.seed, duration=n_samples / sample_rate, time_step=integrator.h,
        n_pedestrians=integrator.stream.size - integrator.n_dampers,
        mean_on_deck=people / n_samples, max_on_deck=most, hsi=msd is not None,
        warm_up=run.warm_up_samples / sample_rate)
