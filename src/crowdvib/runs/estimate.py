"""``crowdvib estimate`` and ``crowdvib map`` as calls: a case's estimate (or objective map)
written as a results folder, with the lines the command prints."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..cases.results import provenance
from ..reporting.text import interval_of, with_interval
from .folders import case_inputs, staged_output, write_results
from .lines import Progress, Say, as_case, caught_warnings, silent, warning_texts
from ..cases import estimate_case
from ..reporting.animation import mode_shape_table
from ..cases import map_case
from ..reporting.plotting import plot_objective_map, save_figure
from .._files import unique_filenames
from ..reporting.plotting import plot_psd_comparison, plot_psd_convergence
from ..reporting.plotting import plot_psd_residuals

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

    from ..cases.results import Results
    from ..io.casefile import Case

__all__ = ["run_estimate", "run_map"]


def run_estimate(case: Case | str | Path, out: str | Path, *, force: bool = False,
                 say: Say = silent) -> Results:
    """What ``crowdvib estimate`` does: :func:`~crowdvib.cases.estimate_case`, its figures,
    results.json and report.html in ``out`` (written whole or not at all).

    Parameters
    ----------
    case : Case, str or pathlib.Path
        From :func:`~crowdvib.io.load_case`, or its file (read here: the warnings of reading it
        are recorded with the run's).
    out : str or pathlib.Path
        The results folder (:func:`~crowdvib.runs.staged_output`'s rules).
    force : bool
        Replace crowdvib's earlier results in ``out``.
    say : callable, optional
        Called with each line the command prints (default: none printed).

    Returns
    -------
    Results
        As written; the run's warnings are recorded in it (``.warnings``), not shown again.
    """

    with caught_warnings() as caught:
        case = as_case(case)
        stamp = provenance(case.path)
        with staged_output(out, force, command="estimate", inputs=case_inputs(case)) as staging:
            fit = estimate_case(case)
            _say_fit(fit, say)
            results = fit.to_dict()
            results["mode_shapes"] = mode_shape_table(case.structure, fit.crowd,   # issue 38
                                                      fit.estimate.msd)
            results["figures"] = (_joint_figures if fit.joint else _figures)(fit, staging)
            results.update(stamp)
            results["warnings"] = warning_texts(caught)
            written = write_results(staging, results)
    say(f"  wrote {Path(out) / 'results.json'}, figures and report.html")
    return written


def run_map(case: Case | str | Path, out: str | Path, *, frequencies: ArrayLike, damping_ratios: ArrayLike,
            max_seconds: float | None = None, force: bool = False, say: Say = silent,
            progress: Progress | None = None) -> Results:
    """What ``crowdvib map`` does: :func:`~crowdvib.cases.map_case`, its figure, results.json and
    report.html in ``out``.

    Parameters
    ----------
    case : Case, str or pathlib.Path
        One ``[measurement]`` (a file is read here, as by :func:`run_estimate`).
    out : str or pathlib.Path
        The results folder (:func:`~crowdvib.runs.staged_output`'s rules).
    frequencies, damping_ratios : array_like
        The grid of f_h1 [Hz] and ξ_h1 [-].
    max_seconds : float, optional
        Refuse a grid estimated to take longer.
    force : bool
        Replace crowdvib's earlier results in ``out``.
    say : callable, optional
        Called with each line the command prints.
    progress : callable, optional
        ``progress(label, unit)`` → the ``progress(done, total)`` callback of the grid [points].

    Returns
    -------
    Results
        As written; the run's warnings are recorded in it, not shown again.
    """

    with caught_warnings() as caught:
        case = as_case(case)
        stamp = provenance(case.path)
        with staged_output(out, force, command="map", inputs=case_inputs(case)) as staging:
            say(f"crowdvib map: {case.name} ({case.path.name})")
            found = map_case(case, frequencies=frequencies, damping_ratios=damping_ratios,
                             progress=None if progress is None else progress("grid", "points"),
                             max_seconds=max_seconds)
            texts = warning_texts(caught)
            say(measurement_line(found.record.measurement))
            _say_crowd(case, found.record.step_frequencies, say)
            landscape, estimate, best = found.landscape, found.estimate, found.landscape.optimum
            say(f"  {landscape.cost.size} grid points in {found.seconds:.1f} s; grid minimum "
                f"f_h1 = {best.frequency:.3f} Hz, ξ_h1 = {best.damping_ratio:.3f}; "
                f"optimiser {estimate.msd.frequency:.3f} Hz, {estimate.msd.damping_ratio:.3f}")
            say(f"  curvature along f_h1 / along ξ_h1 at the minimum: "
                f"{landscape.curvature_ratio():.3g}")
            ax = plot_objective_map(landscape, search_bounds=estimate.bounds,
                                    title=f"{case.name}: objective J(f_h1, ξ_h1)")
            figure = save_figure(ax, staging / "objective_map.png").name
            written = write_results(staging, {**found.to_dict(), "warnings": texts,
                                              "figures": [figure], **stamp})
    say(f"  wrote {Path(out) / 'results.json'}, {figure} and report.html")
    return written


def measurement_line(measurement) -> str:
    """One line on a case's record (:class:`crowdvib.cases.CaseMeasurement`), and one on each
    thing done to its samples as read (a dropout cut or bridged: its notes)."""
    record = measurement.record
    return (f"  record  {record.n_channels} channel(s) {list(record.channel_names)}, "
            f"{record.duration:g} s at {record.sample_rate:g} Hz"
            + "".join(f"\n          {note}" for note in record.notes))


def crowd_line(case, fitted) -> str | None:
    """One line on the step frequencies fitted below the cut-off (None if the case fits none)."""
    if fitted is None:
        return None
    return (f"  step frequencies below {case.estimation.step_frequencies.cutoff:g} Hz: "
            f"N({fitted.crowd.step_frequency_mean:.3f}, {fitted.crowd.step_frequency_std:.3f}) "
            f"Hz (case file: N({case.crowd.step_frequency_mean:g}, "
            f"{case.crowd.step_frequency_std:g}) Hz)")


def _say_crowd(case, fitted, say):
    line = crowd_line(case, fitted)
    if line is not None:
        say(line)


def _say_fit(fit, say):
    """The console lines of an estimate, in the order the pipeline computes them."""
    case = fit.case
    if fit.joint:
        say(f"crowdvib estimate: {case.name} ({case.path.name}), joint fit of "
            f"{len(case.records)} records")
        for part in fit.records:
            say(f"  {part.case.name}: crowd {part.case.stationary_crowd().density:g} P/m²")
            say(measurement_line(part.measurement))
            _say_crowd(part.case, part.step_frequencies, say)
        _say_estimate(fit.estimate, say)
        return
    (part,) = fit.records
    measured, convergence, spec = part.measurement.psd, fit.convergence, case.measurement
    say(f"crowdvib estimate: {case.name} ({case.path.name})")
    say(measurement_line(part.measurement))
    if measured.cross is not None:
        say(f"  likelihood of the {part.measurement.record.n_channels} outputs' cross-spectral "
            "matrix (complex Wishart: coherent outputs count once)")
    last = convergence.error[:, -2] if convergence.error.shape[1] > 1 else convergence.error[:, 0]
    say(f"  PSD     Welch T = {spec.window_length:g} s, {measured.n_windows} windows; "
        f"convergence error of the last window added ({convergence.norm}-norm over the band): "
        + ", ".join(f"{v:.1%}" for v in last))
    reach = convergence.duration_to_reach(0.10)
    say("          below 10 % from " + (f"{reach:g} s of record on" if reach is not None
                                        else "no record length (record too short)"))
    _say_crowd(case, part.step_frequencies, say)
    _say_estimate(fit.estimate, say)
    if fit.estimate.crowd is not None:
        summary = fit.estimate.to_dict()["estimate"]
        say("           step frequencies fitted with the MSD: N(" + ", ".join(
            with_interval(getattr(fit.crowd, key), interval_of(summary, key), "Hz")
            for key in ("step_frequency_mean", "step_frequency_std")) + ")")
    for key, label in (("frequency", "f_h1"), ("damping_ratio", "ξ_h1")):
        if key in case.expected:
            value = getattr(fit.estimate.msd, key)
            say(f"           {label}: expected {case.expected[key]:g}, "
                f"error {(value - case.expected[key]) / case.expected[key]:+.1%}")


#: The MSD's parameters as the console writes them.
_SYMBOLS = {"frequency": "f_h1", "damping_ratio": "ξ_h1", "mass_ratio": "μ_h1"}


def _say_estimate(estimate, say):
    """One line: the estimate with its intervals and the relative misfit."""
    found, summary = estimate.msd, estimate.to_dict()["estimate"]
    say(f"  estimate f_h1 = {with_interval(found.frequency, interval_of(summary, 'frequency'), 'Hz')}"
        f", ξ_h1 = {with_interval(found.damping_ratio, interval_of(summary, 'damping_ratio'))}, "
        f"μ_h1 = {with_interval(found.mass_ratio, interval_of(summary, 'mass_ratio'))}; "
        f"J/J_noHSI = {estimate.relative_cost:.3g}")
    if estimate.density_share:
        say(f"  crowd density ±{estimate.density_uncertainty:.0%} (one s.d.): "
            + ", ".join(f"{_SYMBOLS[name]} {estimate.density_share[name]:.0%} of the interval's "
                        f"variance, {0.1 * estimate.density_sensitivity[name]:+.3g} for a density "
                        "stated 10 % high" for name in _SYMBOLS if name in estimate.density_share))
    for details in estimate.crowd_model_details:
        applied = "on" if details["drift_correction"] else "off"
        say(f"  crowd model: fluctuating, {details['occupancy_nodes']} occupancy nodes, drift "
            f"correction {applied} (κ = {details['spread_parameter']:.2f}, applied up to "
            f"{details['spread_limit']:g})")


def _figures(fit, out):
    """The measured, fitted and no-HSI PSD of each output and the convergence figure."""

    case, est, measured = fit.case, fit.case.estimation, fit.records[0].measurement.psd
    outputs = fit.records[0].measurement.record.channel_names
    # Output names come from the case file: one sanitiser keeps their figures inside `out`.
    names = unique_filenames(outputs, prefix="psd_", suffix=".png",
                             taken=("psd_convergence.png",))
    fitted, no_hsi = fit.model_psds()
    figures = []
    for name in outputs:
        ax = plot_psd_comparison({"measured": measured, "fitted MSD": fitted, "no HSI": no_hsi},
                                 output=name, band=(est.band[0], max(est.band[1], 2 * est.band[0])),
                                 analysis_band=est.band, title=f"{case.name}: {name}")
        figures.append(save_figure(ax, out / names[name]).name)
    figures.append(save_figure(plot_psd_convergence(fit.convergence, title=f"{case.name}: PSD "
                                                    "convergence"),
                               out / "psd_convergence.png").name)
    return figures


def _joint_figures(fit, out):
    """Per record and output of a joint fit: the PSDs and the residuals of the joint fit."""

    case, est = fit.case, fit.case.estimation
    labels = [f"{part.case.name} {name}" for part in fit.records
              for name in part.measurement.record.channel_names]
    names = unique_filenames(labels, prefix="psd_", suffix=".png")
    residual_names = unique_filenames(labels, prefix="residuals_", suffix=".png")
    figures = []
    for part in fit.records:
        measured = part.measurement.psd
        fitted, no_hsi = fit.model_psds(part)
        for name in part.measurement.record.channel_names:
            label = f"{part.case.name} {name}"
            ax = plot_psd_comparison({"measured": measured, "fitted MSD (joint)": fitted,
                                      "no HSI": no_hsi}, output=name,
                                     band=(0.0, max(est.band[1], 2 * est.band[0])),
                                     title=f"{case.name}, {label}")
            ax.axvspan(*est.band, color="tab:green", alpha=0.07, label="band")
            figures.append(save_figure(ax, out / names[label]).name)
            ax = plot_psd_residuals(measured, fitted, output=name, band=est.band,
                                    title=f"{case.name}, {label}: residuals of the joint fit")
            figures.append(save_figure(ax, out / residual_names[label]).name)
    return figures
