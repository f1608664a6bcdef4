"""What a case file describes, run from Python: the estimate pipeline of ``crowdvib estimate``.

A :class:`~crowdvib.io.casefile.Case` names its records, the structure, the crowd and the
estimator's options; the functions here turn it into the objects ``crowdvib estimate`` computes
(the filtered record, its Welch PSD, the crowd, the :class:`HSIEstimate`), so that a Python user
holding a case gets the same estimate as the command line, bit for bit. The command line only
prints and writes what they return (issue 26 §1).

The pipeline (docs: :ref:`theory-estimator`): read the records → select
the fitted outputs → zero-phase low-pass → Welch PSD → convergence of the PSD with the record
length → step frequencies fitted below a cut-off (optional, the paper's Waalse Krook procedure)
→ estimate of f_h1, ξ_h1 (and μ_h1) with intervals.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from .._version import __version__
from ..errors import ParameterError
from .results import ESTIMATION_TABLES, AsResults, software_versions
from .schema import schema_header
from ..io.casefile import load_measurement
from ..signals import LowPassFilter, welch_psd
from ..identification.step_frequencies import estimate_step_frequencies
from ..identification.estimator import Estimator
from ..signals import psd_convergence
from ..studies.landscape import objective_map
from ..response.frequency_domain.varying import record_model

if TYPE_CHECKING:
    from collections.abc import Callable

    from numpy.typing import ArrayLike

    from ..identification.estimator import Estimator
    from ..identification.result import HSIEstimate
    from ..identification.step_frequencies import StepFrequencyEstimate
    from ..io.casefile import Case
    from ..io.records import Record
    from ..models.crowd import Crowd
    from ..signals.convergence import PSDConvergence
    from ..signals.lowpass import LowPassFilter
    from ..signals.spectrum import ResponsePSD
    from ..studies.landscape import ObjectiveMap


__all__ = ["CaseMeasurement", "CaseRecordFit", "CaseEstimate", "measure_case", "case_crowd",
           "case_estimator", "estimate_case", "CaseMap", "map_case"]


@dataclass(frozen=True)
class CaseMeasurement:
    """A case's record reduced to the fitted outputs, and its measured PSD.

    Attributes
    ----------
    record : Record
        The outputs to be fitted (``estimation.outputs``, else every channel), unfiltered.
    psd : ResponsePSD
        The Welch estimate of ``[measurement]`` after the low-pass filter; with the
        cross-spectra when several outputs are fitted by the likelihood.
    lowpass : LowPassFilter or None
        The zero-phase low-pass filter applied before Welch (None: none).
    """

    record: Record
    psd: ResponsePSD
    lowpass: LowPassFilter | None


@dataclass(frozen=True)
class CaseRecordFit:
    """One record's share of an estimate: its measurement and the crowd it was fitted with.

    Attributes
    ----------
    case : Case
        The case (for a joint fit, the ``[[measurement]]`` block as a case of its own).
    measurement : CaseMeasurement
    crowd : Crowd
        The crowd the estimator was given (the case file's, or the fitted step frequencies),
        its density the case's profile on the record's time when its crowd was counted.
    step_frequencies : StepFrequencyEstimate or None
        The step frequencies fitted below the cut-off, if the case asks for them.
    """

    case: Case
    measurement: CaseMeasurement
    crowd: Crowd
    step_frequencies: StepFrequencyEstimate | None


@dataclass(frozen=True)
class CaseEstimate(AsResults):
    """What ``crowdvib estimate`` computes for a case (:func:`estimate_case`).

    Attributes
    ----------
    case : Case
    records : tuple of CaseRecordFit
        One per record: one for a single ``[measurement]``, one per ``[[measurement]]`` block
        of a joint fit.
    estimate : HSIEstimate
        The MSD with its intervals (``estimate.msd``; a joint fit's is one MSD for all records).
    convergence : PSDConvergence or None
        The PSD's convergence with the record length (single record only).
    """

    case: Case
    records: tuple[CaseRecordFit, ...]
    estimate: HSIEstimate
    convergence: PSDConvergence | None = None

    @property
    def joint(self) -> bool:
        """True for a joint fit of several ``[[measurement]]`` blocks."""
        return bool(self.case.records)

    @property
    def crowd(self):
        """The single record's crowd from the estimate on: the step frequencies fitted with the
        MSD when ``estimation.free_parameters`` frees them, else the crowd the estimator had,
        at one density (a counted crowd's walkers at the case's reference density, as the mode
        shapes and a report's stationary figures take it)."""
        crowd = self.estimate.crowd if self.estimate.crowd is not None else self.records[0].crowd
        if crowd.profile is None:
            return crowd
        return crowd.with_density(self.case.stationary_crowd().density)

    def model_psds(self, part: CaseRecordFit | None = None):
        """The fitted and the no-HSI model PSDs of one record, as the estimator compared them.

        Parameters
        ----------
        part : CaseRecordFit, optional
            The record (default: the single record, with :attr:`crowd`).

        Returns
        -------
        (ResponsePSD, ResponsePSD)
            The model PSD with the estimated MSD, and without HSI.
        """

        crowd = self.crowd if part is None else part.crowd
        part = self.records[0] if part is None else part
        est, measured = self.case.estimation, part.measurement.psd
        model = record_model(self.case.structure, on_record(crowd, part.case), measured.frequency,
                             record_windows=(measured.window_length, measured.n_windows),
                             force=self.case.force,
                             outputs=part.measurement.record.channel_names,
                             welch_window_length=measured.window_length if est.match_welch
                             else None,
                             lowpass=part.measurement.lowpass if est.match_welch else None,
                             crowd_model=est.crowd_model)
        return model.psd(self.estimate.msd), model.psd(None)

    def to_dict(self) -> dict:
        """The results ``crowdvib estimate`` writes to results.json, without its figures and
        provenance (docs: :doc:`/cli`)."""
        case, hsi = self.case, self.estimate.to_dict()
        diagnostics = {k: v for k, v in hsi.items() if k != "estimate"}
        head = {**schema_header("estimate"), "command": "estimate",
                "crowdvib_version": __version__,
                "versions": software_versions(), "seed": case.seed, "case": str(case.path)}
        if self.joint:
            records = [_record_entry(part) for part in self.records]
            diagnostics["records"] = records
            return {**head, "inputs": case.inputs(), "records": records,
                    "estimate": hsi["estimate"], "expected": dict(case.expected),
                    "diagnostics": diagnostics}
        measurement, step = self.records[0].measurement, self.records[0].step_frequencies
        diagnostics["convergence"] = self.convergence.to_dict()
        diagnostics["measured_psd"] = {
            "window_length": measurement.psd.window_length,
            "n_windows": measurement.psd.n_windows,
            "lowpass": None if measurement.lowpass is None else measurement.lowpass.to_dict()}
        if step is not None:
            diagnostics["step_frequencies"] = step.to_dict()
        crowd = self.crowd
        return {**head, "inputs": case.inputs(ESTIMATION_TABLES),
                "record": measurement.record.metadata(), "crowd_used": {
                    "step_frequency_mean": crowd.step_frequency_mean,
                    "step_frequency_std": crowd.step_frequency_std},
                "estimate": hsi["estimate"], "expected": dict(case.expected),
                "diagnostics": diagnostics}


def _record_entry(part: CaseRecordFit) -> dict:
    """One record of a joint fit as results.json lists it."""
    crowd, psd = part.crowd, part.measurement.psd
    return {"name": part.case.name, "record": part.measurement.record.metadata(),
            "crowd_used": {"density": part.case.stationary_crowd().density,
                           "step_frequency_mean": crowd.step_frequency_mean,
                           "step_frequency_std": crowd.step_frequency_std},
            "n_windows": psd.n_windows,
            "step_frequencies": None if part.step_frequencies is None
            else part.step_frequencies.to_dict()}


def measure_case(case) -> CaseMeasurement:
    """Read a case's records, keep the fitted outputs and make their measured PSD.

    Parameters
    ----------
    case : Case
        A loaded case with one ``[measurement]`` (for ``[[measurement]]`` blocks, each of
        ``case.blocks()``).

    Returns
    -------
    CaseMeasurement
        The record of the outputs ``estimation.outputs`` (else every channel), the zero-phase
        low-pass filter of ``measurement.lowpass_cutoff`` (or None) and the Welch PSD of
        ``measurement.window_length`` and ``overlap`` after it (docs:
        :ref:`theory-psd-conventions`).

    Raises
    ------
    ParameterError
        A fitted channel that is no output of the structure.
    """

    spec, est = case.measurement, case.estimation
    record = load_measurement(case)
    outputs = tuple(est.outputs or record.channel_names)
    unknown = [name for name in outputs if name not in case.structure.output_names]
    if unknown:
        raise ParameterError(
            f"{case.path.name}: record channel(s) {unknown} are not outputs of the structure "
            f"{list(case.structure.output_names)}: map them with measurement.channels "
            "(output = \"channel in file\") or list the outputs in estimation.outputs")
    record = record.select(outputs)
    lowpass = (None if spec.lowpass_cutoff is None else
               LowPassFilter(spec.lowpass_cutoff, spec.lowpass_order, record.sample_rate))
    # Several outputs fitted by the likelihood: keep the cross-spectra, so that the estimator
    # uses their complex-Wishart likelihood (docs: theory, The likelihood of several outputs),
    # which weighs coherent outputs once; it takes no output weights.
    cross = est.method == "likelihood" and len(outputs) > 1 and est.output_weights is None
    measured = welch_psd(record.data, record.sample_rate, window_length=spec.window_length,
                         overlap=spec.overlap, output_names=outputs, lowpass=lowpass,
                         cross=cross)
    return CaseMeasurement(record, measured, lowpass)


def case_crowd(case, record):
    """The crowd the HSI estimate of a case uses.

    With ``[estimation.step_frequencies]`` the step-frequency distribution is first fitted on
    the record low-passed at its cut-off, without HSI (the paper's Waalse Krook procedure; docs:
    theory, *Step frequencies from the record*), and used when ``use_fitted``; otherwise the
    case file's crowd. A counted crowd (a profile) keeps its profile, on the record's time
    (:func:`on_record`): every command fits the crowd that was counted.

    Parameters
    ----------
    case : Case
    record : Record
        The fitted outputs (:attr:`CaseMeasurement.record`).

    Returns
    -------
    (Crowd, StepFrequencyEstimate or None)
        The crowd for the estimator, and the step-frequency fit (None without one).
    """

    spec, est = case.measurement, case.estimation
    if est.step_frequencies is None:
        return case.record_crowd(), None
    sf = est.step_frequencies
    low = LowPassFilter(sf.cutoff, spec.lowpass_order, record.sample_rate)
    measured_low = welch_psd(record.data, record.sample_rate, window_length=spec.window_length,
                             overlap=spec.overlap, output_names=record.channel_names,
                             lowpass=low)
    fitted = estimate_step_frequencies(measured_low, case.structure, case.stationary_crowd(),
                                       cutoff=sf.cutoff,
                                       band=sf.band, starts=sf.starts, bounds=sf.bounds,
                                       outputs=sf.outputs, force=case.force,
                                       match_welch=est.match_welch)
    return on_record(fitted.crowd if sf.use_fitted else case.crowd, case), fitted


def on_record(crowd, case):
    """``crowd``'s walkers at the density of ``case``'s record: the case's profile on the
    record's time (:meth:`~crowdvib.io.casefile.Case.record_crowd`) when its crowd was counted,
    else ``crowd`` as it is.

    Parameters
    ----------
    crowd : Crowd
        The walkers (the case file's, or with fitted step frequencies).
    case : Case
        The case (for a joint fit, its ``[[measurement]]`` block as a case).

    Returns
    -------
    Crowd
    """
    profile = case.record_crowd().profile
    return crowd if profile is None else crowd.with_density(profile)


def case_estimator(case: Case) -> Estimator:
    """The estimator of a case: its ``[estimation]`` table as one value.

    Parameters
    ----------
    case : Case
        Its ``[estimation]`` table (the estimator's choices it does not state are filled in by
        :meth:`~crowdvib.io.casespecs.EstimationSpec.resolved` when the case is read), its
        MSD's mass ratio and its walking-force model. The step frequencies are free with the
        MSD when ``free_parameters`` frees them (one record; a joint fit holds each record's
        crowd), μ_h1 when it frees ``mass_ratio``.

    Returns
    -------
    Estimator
        What every command of the case fits with (``crowdvib estimate``, ``map``,
        ``sensitivity``, ``season``); a case file that states nothing gives
        :class:`~crowdvib.identification.Estimator`'s defaults with the paper's band.
    """

    est = case.estimation
    free = est.free_parameters
    return Estimator(
        band=est.band, method=est.method,
        interval=None if est.interval == "none" else est.interval, level=est.level,
        crowd_model=est.crowd_model,
        free_step_frequencies=None if case.records else "step_frequency_mean" in free,
        mass_ratio=case.msd.mass_ratio, free_mass_ratio="mass_ratio" in free,
        bounds=est.bounds, starts=est.starts, outputs=est.outputs,
        output_weights=est.output_weights, force=case.force, match_welch=est.match_welch,
        n_boot=est.n_boot, density_uncertainty=est.density_uncertainty,
        check_level=est.check_level)


def estimate_case(case: Case) -> CaseEstimate:
    """Run ``crowdvib estimate``'s pipeline on a loaded case, without writing anything.

    Parameters
    ----------
    case : Case
        From :func:`~crowdvib.io.load_case`. One ``[measurement]`` is fitted by
        :func:`~crowdvib.identification.estimate_hsi`; several ``[[measurement]]`` blocks by
        one MSD for all (:func:`~crowdvib.identification.estimate_hsi_joint`).

    Returns
    -------
    CaseEstimate
        The records, their PSDs and crowds, the estimate with its intervals and (single
        record) the PSD's convergence; ``to_dict()`` is what results.json holds.

    Examples
    --------
    >>> from crowdvib.io import load_case
    >>> fit = estimate_case(load_case("examples/paper_example.toml"))  # doctest: +SKIP
    >>> fit.estimate.msd.frequency                                     # doctest: +SKIP
    """

    est = case.estimation
    estimator = case_estimator(case)
    parts = []
    for block in case.blocks():
        measurement = measure_case(block)
        crowd, step = case_crowd(block, measurement.record)
        parts.append(CaseRecordFit(block, measurement, crowd, step))
    if case.records:
        estimate = estimator.fit_joint([p.measurement.psd for p in parts], case.structure,
                                       [p.crowd for p in parts], rng=case.seed)
        return CaseEstimate(case, tuple(parts), estimate)
    (part,) = parts
    record, spec = part.measurement.record, case.measurement
    convergence = psd_convergence(record.data, record.sample_rate,
                                  window_length=spec.window_length, band=est.band,
                                  norm=est.convergence_norm, overlap=spec.overlap,
                                  output_names=record.channel_names,
                                  lowpass=part.measurement.lowpass)
    estimate = estimator.replace(outputs=record.channel_names).fit(
        part.measurement.psd, case.structure, part.crowd, rng=case.seed)
    return CaseEstimate(case, (part,), estimate, convergence)



@dataclass(frozen=True)
class CaseMap(AsResults):
    """What ``crowdvib map`` computes for a case (:func:`map_case`).

    Attributes
    ----------
    record : CaseRecordFit
        The record, its PSD and the crowd the map uses.
    estimate : HSIEstimate
        The optimiser's estimate (the case's options, the paper's smeared crowd model).
    landscape : ObjectiveMap
        The objective on the grid, carrying the estimate.
    seconds : float
        Wall-clock time of the grid alone [s].
    """

    record: CaseRecordFit
    estimate: HSIEstimate
    landscape: ObjectiveMap
    seconds: float

    def to_dict(self) -> dict:
        """The results ``crowdvib map`` writes to results.json, without its figures, warnings
        and provenance."""
        case, estimate = self.record.case, self.estimate
        return {**schema_header("map"), "command": "map", "crowdvib_version": __version__,
                "versions": software_versions(), "seed": case.seed, "case": str(case.path),
                "inputs": case.inputs(ESTIMATION_TABLES), "estimate": estimate.msd.to_dict(),
                "expected": dict(case.expected),
                "diagnostics": {k: v for k, v in estimate.to_dict().items() if k != "estimate"},
                "objective_map": self.landscape.to_dict(),
                "curvature_ratio": self.landscape.curvature_ratio()}


def map_case(case: Case, *, frequencies: ArrayLike, damping_ratios: ArrayLike,
             progress: Callable[[int, int], None] | None = None,
             max_seconds: float | None = None) -> CaseMap:
    """Run ``crowdvib map``'s pipeline: a case's estimate and its objective on a grid.

    Parameters
    ----------
    case : Case
        One ``[measurement]`` (the map is of one record's objective).
    frequencies, damping_ratios : array_like
        The grid of f_h1 [Hz] and ξ_h1 [-] (docs: :ref:`theory-objective-map`).
    progress : callable, optional
        ``progress(done, total)`` [grid points], as :func:`~crowdvib.studies.objective_map`.
    max_seconds : float, optional
        Refuse a grid estimated to take longer.

    Returns
    -------
    CaseMap
    """
    import time


    measurement = measure_case(case)
    crowd, step = case_crowd(case, measurement.record)
    estimator = case_estimator(case)
    estimate = estimator.fit(measurement.psd, case.structure, crowd, rng=case.seed)
    started = time.perf_counter()
    # The landscape of the misfit at the crowd the estimate ends with (its fitted step
    # frequencies, when they were free): the surface on which the estimate is the minimum.
    landscape = objective_map(measurement.psd, case.structure,
                              on_record(estimate.crowd or crowd, case),
                              frequencies=frequencies,
                              damping_ratios=damping_ratios, estimate=estimate,
                              estimator=estimator, progress=progress, max_seconds=max_seconds)
    return CaseMap(CaseRecordFit(case, measurement, crowd, step), estimate, landscape,
                   time.perf_counter() - started)
