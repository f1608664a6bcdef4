"""What a case file asks for, table by table, once read and checked: the specifications that
:class:`crowdvib.io.casefile.Case` carries (the parsing is in :mod:`crowdvib.io.casefile`)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

from .._estimators import (DEFAULT_DENSITY_UNCERTAINTY, DEFAULT_JOINT_METHOD, DEFAULT_METHOD,
                           estimator_defaults)

if TYPE_CHECKING:
    from ..models.crowd import Crowd
    from ..models.pedestrian import MSDModel

__all__ = ["MeasurementSpec", "MeasurementBlock", "StepFrequencySpec", "EstimationSpec",
           "SimulationSpec", "DesignSpec"]

@dataclass(frozen=True)
class MeasurementSpec:
    """How measured records are read and processed (the case file's ``[measurement]``).

    Attributes
    ----------
    files : tuple of Path
        Record files (channels of all files are merged; same length and sample rate).
    format : str or None
        Record format (default from each suffix).
    channels : dict or None
        Output name → channel name in the file(s); None keeps the file's names.
    units : str or None
        "m/s2", "g", "mg" or "mm/s2"; None: as stored in the file (a comment, the column
        headers), else m/s².
    sample_rate : float or None
        [Hz] for files without time stamps.
    time_column : str
    time_frame : None, (float, float) or "stationary"
        Part of the record used [s].
    lowpass_cutoff : float or None
        Zero-phase Butterworth low-pass cut-off [Hz] (paper: 10 Hz); None = no filter.
    lowpass_order : int
    resample : float or None
        New sample rate [Hz] (polyphase), applied after the time frame.
    window_length : float
        Welch segment length T [s].
    overlap : float
    detrend : str
        "constant" (paper) or "linear".
    header_row : int or None
        CSV: the line number (from 1) of the header row; None finds it below a logger's
        metadata lines.
    gaps : str or None
        A dropout (empty cells): "cut" keeps the longest stretch without one, "bridge"
        interpolates each up to ``max_gap``; None refuses it (:mod:`crowdvib.io.gaps`).
    max_gap : float
        [s] the longest dropout "bridge" interpolates.
    """

    files: tuple = ()
    format: str = None
    channels: dict = None
    units: str = None
    sample_rate: float = None
    time_column: str = "time"
    time_frame: object = None
    lowpass_cutoff: float = 10.0
    lowpass_order: int = 4
    resample: float = None
    window_length: float = 60.0
    overlap: float = 0.5
    detrend: str = "constant"
    header_row: int = None
    gaps: str = None
    max_gap: float = 0.1


@dataclass(frozen=True)
class MeasurementBlock:
    """One of several ``[[measurement]]`` blocks: a record with its own crowd (joint fit)."""

    name: str
    measurement: MeasurementSpec
    #: Its density a number, or a profile against the record's time (its ``crowd.counts`` or
    #: ``crowd.density_profile``).
    crowd: Crowd
    #: The walkers' reference density [persons/m²] (as :attr:`Case.reference_density`).
    reference_density: float | None = None


@dataclass(frozen=True)
class StepFrequencySpec:
    """The step-frequency fit of ``[estimation.step_frequencies]`` (paper, Waalse Krook)."""

    cutoff: float = 2.3
    band: tuple = None
    starts: tuple = None
    bounds: dict = None
    outputs: tuple = None
    use_fitted: bool = True


@dataclass(frozen=True)
class EstimationSpec:
    """The inverse problem of ``[estimation]`` (paper Eq. 5 and 6)."""

    band: tuple = (0.0, 10.0)
    outputs: tuple = None
    output_weights: tuple = None
    starts: tuple = None
    bounds: dict = None
    free_parameters: tuple = None
    match_welch: bool = True
    convergence_norm: str = "2"
    step_frequencies: StepFrequencySpec = None
    method: str = None
    interval: str = "profile"
    level: float = 0.95
    crowd_model: str = None
    n_boot: int = 200
    #: ``[crowd] density_uncertainty``: read with the crowd, carried by the estimate's intervals.
    density_uncertainty: float = DEFAULT_DENSITY_UNCERTAINTY
    check_level: bool = True

    def resolved(self, joint: bool = False) -> EstimationSpec:
        """The estimator's choices not stated (None) filled in, as :func:`crowdvib.estimate_hsi`
        and :func:`crowdvib.estimate_hsi_joint` fill them (one table, ``crowdvib._estimators``):
        one record gets the likelihood with the fluctuating crowd and its step frequencies
        fitted with the MSD, several records the paper's least squares; least squares keeps the
        paper's smeared crowd and the crowd as given."""
        method = self.method or (DEFAULT_JOINT_METHOD if joint else DEFAULT_METHOD)
        crowd_model, free_steps = estimator_defaults(method, self.crowd_model)
        free = self.free_parameters
        if free is None:
            free = ("frequency", "damping_ratio") + (
                ("step_frequency_mean", "step_frequency_std") if free_steps and not joint
                else ())
        return replace(self, method=method, crowd_model=crowd_model, free_parameters=free)


@dataclass(frozen=True)
class SimulationSpec:
    """Time-domain simulation of ``[simulation]`` (used by ``crowdvib simulate``)."""

    duration: float = 600.0
    sample_rate: float = 100.0
    warm_up: float = 0.0
    hsi: bool = True
    record_sample_rate: float = None
    formats: tuple = ("npz",)
    dtype: str = "float64"


@dataclass(frozen=True)
class DesignSpec:
    """The design checks of ``[design]`` (used by ``crowdvib check``).

    Attributes
    ----------
    codes : tuple of str
        Codes of :func:`crowdvib.design.design_check` to check.
    classes : dict
        Code → traffic class ("TC3", "II", "B", …); a code without one takes ``density``.
    density : float or None
        Crowd density [persons/m²] overriding the classes' (and the checks' only one for codes
        without a class).
    comfort_class : str or None
        Target comfort class of Sétra/HiVoSS (default CL2).
    hsi : bool
        Add the HSI model with ``msd``.
    msd : MSDModel or None
        ``[design.msd]``; None: the case's ``[hsi]``.
    site_factors : dict
        k1…k4 of the UK NA limit (numbers or named choices).
    weighting : str or None
        "Wb": running RMS of W_b-weighted accelerations where computed.
    gamma_figure : str or None
        UK NA: the γ figure of the walkers and joggers, "pd6688-2" (None: the default,
        PD 6688-2:2011 Figure 2) or "na9" (Figure NA.9 as published).
    neq_damping : str or None
        Sétra/HiVoSS/EN 1990: the damping ratio of n_eq, "occupied" (None: the default) or
        "empty"; the report shows both readings either way.
    damper : dict or None
        ``[design.damper]``: mass, frequency, damping_ratio, position[, lane], or mode and
        mass_ratio (tuned with :func:`crowdvib.design.tune_damper`).
    prediction : bool
        Add the stochastic prediction of the case's ``[crowd]`` stream.
    duration : float
        Record length [s] of the prediction's expected peak.
    """

    codes: tuple
    classes: dict = field(default_factory=dict)
    density: float | None = None
    comfort_class: str | None = None
    hsi: bool = True
    msd: MSDModel | None = None
    site_factors: dict = field(default_factory=dict)
    weighting: str | None = None
    gamma_figure: str | None = None
    neq_damping: str | None = None
    damper: dict | None = None
    prediction: bool = True
    duration: float = 600.0
