"""``crowdvib estimate``: read, check and filter a case's records and estimate f_h1, ξ_h1.

The work is :func:`crowdvib.cases.estimate_case`; this command prints it, draws its figures and
writes results.json.
"""

import sys
from pathlib import Path

from .._files import unique_filenames
from ..cases.results import provenance
from ..reporting.text import interval_of, with_interval
from .common import (add_output_arguments, case_inputs, say, say_verdict, staged_output,
                     warning_texts, write_results)


def add_arguments(parser):
    parser.add_argument("case", type=Path, help="case file (TOML) with [measurement] records")
    add_output_arguments(parser)


def run(args):
    import warnings

    from ..cases import estimate_case
    from ..io.casefile import load_case

    case = load_case(args.case)
    stamp = provenance(case.path)
    with staged_output(args.out, args.force, command="estimate",
                       inputs=case_inputs(case)) as staging:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            fit = estimate_case(case)
            _say_fit(fit)
            results = fit.to_dict()
            results["figures"] = (_joint_figures if fit.joint else _figures)(fit, staging)
        results.update(stamp)
        results["warnings"] = warning_texts(caught)
        for text in results["warnings"]:
            print(f"crowdvib estimate: warning: {text}", file=sys.stderr)
        write_results(staging, results)
    say(f"  wrote {args.out / 'results.json'}, figures and report.html")
    return say_verdict(args.out)


def say_measurement(measurement):
    """One line on a case's record (:class:`crowdvib.cases.CaseMeasurement`)."""
    record = measurement.record
    say(f"  record  {record.n_channels} channel(s) {list(record.channel_names)}, "
        f"{record.duration:g} s at {record.sample_rate:g} Hz")


def say_crowd(case, crowd, fitted):
    """One line on the step frequencies fitted below the cut-off, if the case fits them."""
    if fitted is not None:
        say(f"  step frequencies below {case.estimation.step_frequencies.cutoff:g} Hz: "
            f"N({fitted.crowd.step_frequency_mean:.3f}, {fitted.crowd.step_frequency_std:.3f}) "
            f"Hz (case file: N({case.crowd.step_frequency_mean:g}, "
            f"{case.crowd.step_frequency_std:g}) Hz)")


def _say_fit(fit):
    """The console lines of an estimate, in the order the pipeline computes them."""
    case = fit.case
    if fit.joint:
        say(f"crowdvib estimate: {case.name} ({case.path.name}), joint fit of "
            f"{len(case.records)} records")
        for part in fit.records:
            say(f"  {part.case.name}: crowd {part.case.crowd.density:g} P/m²")
            say_measurement(part.measurement)
            say_crowd(part.case, part.crowd, part.step_frequencies)
        _say_estimate(fit.estimate)
        return
    (part,) = fit.records
    measured, convergence, spec = part.measurement.psd, fit.convergence, case.measurement
    say(f"crowdvib estimate: {case.name} ({case.path.name})")
    say_measurement(part.measurement)
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
    say_crowd(case, part.crowd, part.step_frequencies)
    _say_estimate(fit.estimate)
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


def _figures(fit, out):
    """The measured, fitted and no-HSI PSD of each output and the convergence figure."""
    from ..reporting.plotting import plot_psd_comparison, plot_psd_convergence, save_figure

    case, est, measured = fit.case, fit.case.estimation, fit.records[0].measurement.psd
    outputs = fit.records[0].measurement.record.channel_names
    # Output names come from the case file: one sanitiser keeps their figures inside `out`.
    names = unique_filenames(outputs, prefix="psd_", suffix=".png",
                             taken=("psd_convergence.png",))
    fitted, no_hsi = fit.model_psds()
    figures = []
    for name in outputs:
        ax = plot_psd_comparison({"measured": measured, "fitted MSD": fitted, "no HSI": no_hsi},
                                 output=name, band=(0.0, max(est.band[1], 2 * est.band[0])),
                                 analysis_band=est.band, title=f"{case.name}: {name}")
        figures.append(save_figure(ax, out / names[name]).name)
    figures.append(save_figure(plot_psd_convergence(fit.convergence, title=f"{case.name}: PSD "
                                                    "convergence"),
                               out / "psd_convergence.png").name)
    return figures


def _joint_figures(fit, out):
    """Per record and output of a joint fit: the PSDs and the residuals of the joint fit."""
    from ..reporting.plotting import plot_psd_comparison, plot_psd_residuals, save_figure

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


def _say_estimate(estimate):
    """One line: the estimate with its intervals and the relative misfit."""
    found, summary = estimate.msd, estimate.to_dict()["estimate"]
    say(f"  estimate f_h1 = {with_interval(found.frequency, interval_of(summary, 'frequency'), 'Hz')}"
        f", ξ_h1 = {with_interval(found.damping_ratio, interval_of(summary, 'damping_ratio'))}, "
        f"μ_h1 = {with_interval(found.mass_ratio, interval_of(summary, 'mass_ratio'))}; "
        f"J/J_noHSI = {estimate.relative_cost:.3g}")
    for details in estimate.crowd_model_details:
        applied = "on" if details["drift_correction"] else "off"
        say(f"  crowd model: fluctuating, {details['occupancy_nodes']} occupancy nodes, drift "
            f"correction {applied} (κ = {details['spread_parameter']:.2f}, applied up to "
            f"{details['spread_limit']:g})")
