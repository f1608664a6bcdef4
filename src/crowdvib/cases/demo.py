"""``crowdvib demo``'s work: the paper's numerical example, truth against estimate.

A "measured" PSD of the paper's example (Van Nimmen & Van den Broeck 2023) is made with a known
MSD, from a time-domain simulation with moving MSD pedestrians or from the spectral model with
Welch scatter, and the MSD is estimated back with the default estimator and the paper's (docs:
theory, Calibration).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .._version import __version__
from ..errors import ParameterError
from .results import AsResults, software_versions
from .schema import schema_header
from ..identification.estimator import Estimator
from ..models.examples import paper_example
from ..response.frequency_domain.fluctuation import response_psd
from ..response.time_domain.simulation import simulate
from ..response.frequency_domain.spectral import effective_modal_properties
from ..signals import LowPassFilter, synthetic_welch_psd, welch_psd, welch_segment_count
from ..response.frequency_domain.fluctuation import spectral_model

if TYPE_CHECKING:
    from collections.abc import Callable

    from ..models.examples import ExampleCase
    from ..response.frequency_domain.results import EffectiveModalProperties
    from ..response.time_domain.results import Simulation
    from ..signals.spectrum import ResponsePSD

__all__ = ["CaseDemo", "demo_case", "DEMO_ESTIMATORS", "DEMO_SAMPLE_RATE", "DEMO_WARM_UP"]

#: (key, title, choices of the Estimator): the default and the paper's least squares.
DEMO_ESTIMATORS: tuple[tuple[str, str, dict], ...] = (
    ("default", "default estimator: Whittle likelihood, fluctuating crowd, step frequencies "
                "fitted", {}),
    ("paper", "the paper's estimator: least squares (Eq. 6), smeared crowd, crowd as given",
     {"method": "least_squares"}),
)
#: The simulated record's sample rate [Hz].
DEMO_SAMPLE_RATE = 100.0
#: The deck is populated at t = 0; the warm-up lets the 0.5 %-damped mode forget its initial
#: rest (5/(ξω) ≈ 80 s), as docs: theory, Time domain against spectral model discards its first
#: 100 s.
DEMO_WARM_UP = 100.0


@dataclass(frozen=True)
class CaseDemo(AsResults):
    """What ``crowdvib demo`` computes (:func:`demo_case`).

    Attributes
    ----------
    case : ExampleCase
        The paper's example (:func:`~crowdvib.models.examples.paper_example`), truth included.
    measured : ResponsePSD
        The "measured" PSD, 0–10 Hz.
    n_windows : int
        Its number of Welch windows.
    record : Simulation or None
        The simulated record (None: the spectral model made the PSD).
    duration : float
        The record's length [s].
    seed : int
    estimates : dict
        ``"default"`` and ``"paper"`` → :class:`~crowdvib.identification.HSIEstimate`.
    seconds : dict
        Wall-clock time [s] of the record (``"record"``) and of each estimate.
    occupied : ModalProperties
        The occupied structure with the default estimate's MSD.
    """

    case: ExampleCase
    measured: ResponsePSD
    n_windows: int
    record: Simulation | None
    duration: float
    seed: int
    estimates: dict
    seconds: dict
    occupied: EffectiveModalProperties

    def model_psds(self) -> dict:
        """The expected PSD of each estimate as its estimator modelled it (crowd model, fitted
        crowd), and without HSI: label → ResponsePSD, as the demo's figure shows them."""

        structure, crowd, window = self.case.structure, self.case.crowd, self.case.window_length
        curves = {}
        for key in ("default", "paper"):
            fit = self.estimates[key]
            model = spectral_model(structure, fit.crowd or crowd, self.measured.frequency,
                                   welch_window_length=window, lowpass=self.measured.lowpass,
                                   crowd_model=fit.crowd_model)
            curves[f"fitted MSD ({key})"] = model.psd(fit.msd)
        curves["no HSI"] = model.psd(None)
        return curves

    def to_dict(self) -> dict:
        """The results ``crowdvib demo`` writes to results.json, without its figures and
        provenance: the default estimate's as every estimate's (``estimate`` and
        ``diagnostics``), the paper's estimator's under ``paper_estimator``."""
        estimate, paper = self.estimates["default"], self.estimates["paper"].to_dict()
        hsi = estimate.to_dict()
        # The software versions as every other command records them (issue 26 §2: one layout).
        return {**schema_header("demo"), "command": "demo", "crowdvib_version": __version__,
                "versions": software_versions(), "seed": self.seed, "case": self.case.name,
                "truth": self.case.msd.to_dict(), "estimate": hsi.pop("estimate"),
                "diagnostics": hsi, "paper_estimator": paper,
                "occupied_structure": self.occupied.to_dict(),
                "measured": {"source": self.measured.source, "duration_s": self.duration,
                             "window_length": self.case.window_length,
                             "n_windows": self.n_windows}}


def demo_case(*, duration: float = 3600.0, seed: int = 20230101, spectral: bool = False,
              progress: Callable[[float, float], None] | None = None) -> CaseDemo:
    """Run ``crowdvib demo``: make the paper example's "measured" PSD and estimate it back.

    Parameters
    ----------
    duration : float
        Length of the "measured" record [s], at least one Welch window.
    seed : int
        Seed of every random draw.
    spectral : bool
        Make the PSD from the paper's spectral model (the smeared crowd) with Welch scatter
        instead of a time-domain simulation (faster; no compiled kernel needed).
    progress : callable, optional
        ``progress(done, total)`` [s of simulated time, warm-up included].

    Returns
    -------
    CaseDemo

    Raises
    ------
    ParameterError
        ``duration`` shorter than one Welch window.
    """
    import numpy as np


    case = paper_example()
    structure, crowd, truth, window = case.structure, case.crowd, case.msd, case.window_length
    require_demo_duration(duration, window)
    started, rate, record = time.perf_counter(), DEMO_SAMPLE_RATE, None
    if spectral:
        frequency = np.arange(int(rate / 2 * window) + 1) / window   # the Welch grid
        n_windows = welch_segment_count(int(duration * rate), int(window * rate))
        expected = response_psd(structure, crowd, frequency, msd=truth,
                                welch_window_length=window, crowd_model="smeared")
        measured = synthetic_welch_psd(expected, n_windows, rng=seed).band(0.0, 10.0)
    else:
        record = simulate(structure, crowd, duration, msd=truth, sample_rate=rate, rng=seed,
                          warm_up=DEMO_WARM_UP, progress=progress)
        lowpass = LowPassFilter(cutoff=10.0, order=4, sample_rate=rate)
        measured = welch_psd(record.acceleration, rate, window_length=window,
                             output_names=record.output_names, lowpass=lowpass).band(0.0, 10.0)
        n_windows = measured.n_windows
    seconds = {"record": time.perf_counter() - started}
    # The default estimator and the paper's, on the same PSD (docs: theory, Calibration).
    estimates = {}
    for name, _, options in DEMO_ESTIMATORS:
        started = time.perf_counter()
        estimates[name] = Estimator(band=case.band, **options).fit(measured, structure, crowd,
                                                                   rng=seed)
        seconds[name] = time.perf_counter() - started
    occupied = effective_modal_properties(structure, crowd, estimates["default"].msd)
    return CaseDemo(case, measured, n_windows, record, duration, seed, estimates, seconds,
                    occupied)


def require_demo_duration(duration: float, window: float) -> None:
    """Refuse a record shorter than one Welch window of ``window`` s (docs: theory, Welch PSDs,
    filters and convergence), said in the demo's own terms, not as the estimate's
    ``n_windows``."""
    if not duration >= window:
        raise ParameterError(f"--duration-s must be at least one Welch window, "
                             f"T = {window:g} s, got {duration:g}")
