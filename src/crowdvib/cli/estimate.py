"""``crowdvib estimate``: read, check and filter a case's records and estimate f_h1, ξ_h1."""

import sys
from pathlib import Path

from .._version import __version__
from .._files import unique_filenames, write_json
from ..reporting.report import provenance, write_report
from ..reporting.text import interval_of, with_interval
from .common import (ESTIMATION_TABLES, add_output_arguments, case_inputs, say, say_verdict,
                     staged_output, versions, warning_texts)


def add_arguments(parser):
    parser.add_argument("case", type=Path, help="case file (TOML) with [measurement] records")
    add_output_arguments(parser)


def run(args):
    import warnings

    from ..io.casefile import load_case

    case = load_case(args.case)
    stamp = provenance(case.path)
    with staged_output(args.out, args.force, command="estimate",
                       inputs=case_inputs(case)) as staging:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            results = _estimate_case(case, staging)
        results.update(stamp)
        results["warnings"] = warning_texts(caught)
        for text in results["warnings"]:
            print(f"crowdvib estimate: warning: {text}", file=sys.stderr)
        write_json(staging / "results.json", results)
        write_report(staging)
    say(f"  wrote {args.out / 'results.json'}, figures and report.html")
    say_verdict(args.out)
    return 0


def case_measurement(case):
    """Read a case's records and make its measured PSD → (record, ResponsePSD, low-pass filter).

    The record keeps the outputs to be fitted (``estimation.outputs``, else every channel); the
    PSD is the Welch estimate of ``[measurement]`` after the zero-phase low-pass filter.
    """
    from ..errors import ParameterError
    from ..io.casefile import load_measurement
    from ..signals import LowPassFilter, welch_psd

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
    say(f"  record  {record.n_channels} channel(s) {list(record.channel_names)}, "
         f"{record.duration:g} s at {record.sample_rate:g} Hz")
    lowpass = (None if spec.lowpass_cutoff is None else
               LowPassFilter(spec.lowpass_cutoff, spec.lowpass_order, record.sample_rate))
    # Several outputs fitted by the likelihood: keep the cross-spectra, so that the estimator
    # uses their complex-Wishart likelihood (docs: theory, The likelihood of several outputs),
    # which weighs coherent outputs once; it takes no output weights.
    cross = est.method == "likelihood" and len(outputs) > 1 and est.output_weights is None
    measured = welch_psd(record.data, record.sample_rate, window_length=spec.window_length,
                         overlap=spec.overlap, output_names=outputs, lowpass=lowpass,
                         cross=cross)
    return record, measured, lowpass


def case_crowd(case, record):
    """The crowd the HSI estimate uses → (Crowd, StepFrequencyEstimate or None).

    With ``[estimation.step_frequencies]`` the step-frequency distribution is first fitted on the
    record low-passed at the cut-off, without HSI (the paper's Waalse Krook procedure), and used
    when ``use_fitted``; otherwise the case file's crowd.
    """
    from ..identification.step_frequencies import estimate_step_frequencies
    from ..signals import LowPassFilter, welch_psd

    spec, est = case.measurement, case.estimation
    crowd = case.crowd
    if est.step_frequencies is None:
        return crowd, None
    sf = est.step_frequencies
    low = LowPassFilter(sf.cutoff, spec.lowpass_order, record.sample_rate)
    measured_low = welch_psd(record.data, record.sample_rate, window_length=spec.window_length,
                             overlap=spec.overlap, output_names=record.channel_names,
                             lowpass=low)
    fitted = estimate_step_frequencies(measured_low, case.structure, crowd, cutoff=sf.cutoff,
                                       band=sf.band, starts=sf.starts, bounds=sf.bounds,
                                       outputs=sf.outputs, match_welch=est.match_welch)
    say(f"  step frequencies below {sf.cutoff:g} Hz: N({fitted.crowd.step_frequency_mean:.3f}, "
         f"{fitted.crowd.step_frequency_std:.3f}) Hz (case file: "
         f"N({crowd.step_frequency_mean:g}, {crowd.step_frequency_std:g}) Hz)")
    return (fitted.crowd if sf.use_fitted else crowd), fitted


def _estimate_case(case, out):
    """The estimate pipeline on a loaded case; figures into ``out``; returns the results dict."""
    from ..identification.estimation import estimate_hsi
    from ..reporting.plotting import plot_psd_comparison, plot_psd_convergence, save_figure
    from ..signals import psd_convergence

    spec, est = case.measurement, case.estimation
    if case.records:
        return _estimate_joint(case, out)
    say(f"crowdvib estimate: {case.name} ({case.path.name})")
    record, measured, lowpass = case_measurement(case)
    outputs = record.channel_names
    if measured.cross is not None:
        say(f"  likelihood of the {len(outputs)} outputs' cross-spectral matrix (complex "
            "Wishart: coherent outputs count once)")
    convergence = psd_convergence(record.data, record.sample_rate,
                                  window_length=spec.window_length, band=est.band,
                                  norm=est.convergence_norm, overlap=spec.overlap,
                                  output_names=outputs, lowpass=lowpass)
    last = convergence.error[:, -2] if convergence.error.shape[1] > 1 else convergence.error[:, 0]
    say(f"  PSD     Welch T = {spec.window_length:g} s, {measured.n_windows} windows; "
         f"convergence error of the last window added ({convergence.norm}-norm over the band): "
         + ", ".join(f"{v:.1%}" for v in last))
    reach = convergence.duration_to_reach(0.10)
    say("          below 10 % from " + (f"{reach:g} s of record on" if reach is not None
                                         else "no record length (record too short)"))
    crowd, step_result = case_crowd(case, record)
    free_mass = "mass_ratio" in est.free_parameters
    options = dict(estimate_options(case), **estimate_extras(case), outputs=outputs)
    estimate = estimate_hsi(measured, case.structure, crowd, free_mass_ratio=free_mass,
                            free_step_frequencies="step_frequency_mean" in est.free_parameters,
                            **options)
    found = estimate.msd
    _say_estimate(estimate)
    if estimate.crowd is not None:
        crowd = estimate.crowd              # the fitted step frequencies from here on
        summary = estimate.to_dict()["estimate"]
        say("           step frequencies fitted with the MSD: N(" + ", ".join(
            with_interval(getattr(crowd, key), interval_of(summary, key), "Hz")
            for key in ("step_frequency_mean", "step_frequency_std")) + ")")
    if case.expected:
        for key, label in (("frequency", "f_h1"), ("damping_ratio", "ξ_h1")):
            if key in case.expected:
                value = getattr(found, key)
                say(f"           {label}: expected {case.expected[key]:g}, "
                     f"error {(value - case.expected[key]) / case.expected[key]:+.1%}")
    # Output names come from the case file: one sanitiser keeps their figures inside `out`.
    names = unique_filenames(outputs, prefix="psd_", suffix=".png",
                             taken=("psd_convergence.png",))
    figures = []
    fitted, no_hsi = _fitted_and_no_hsi(case, crowd, measured, lowpass, found, outputs)
    for name in outputs:
        ax = plot_psd_comparison({"measured": measured, "fitted MSD": fitted, "no HSI": no_hsi},
                                 output=name, band=(0.0, max(est.band[1], 2 * est.band[0])),
                                 analysis_band=est.band, title=f"{case.name}: {name}")
        figures.append(save_figure(ax, out / names[name]).name)
    figures.append(save_figure(plot_psd_convergence(convergence, title=f"{case.name}: PSD "
                                                    "convergence"),
                               out / "psd_convergence.png").name)
    hsi = estimate.to_dict()
    diagnostics = {k: v for k, v in hsi.items() if k != "estimate"}
    diagnostics["convergence"] = convergence.to_dict()
    diagnostics["measured_psd"] = {"window_length": measured.window_length,
                                   "n_windows": measured.n_windows,
                                   "lowpass": None if lowpass is None else lowpass.to_dict()}
    if step_result is not None:
        diagnostics["step_frequencies"] = step_result.to_dict()
    return {"command": "estimate", "crowdvib_version": __version__, "versions": versions(),
            "seed": case.seed, "case": str(case.path), "inputs": case.to_dict(ESTIMATION_TABLES),
            "record": record.to_dict(), "crowd_used": {
                "step_frequency_mean": crowd.step_frequency_mean,
                "step_frequency_std": crowd.step_frequency_std},
            "estimate": hsi["estimate"], "expected": dict(case.expected),
            "diagnostics": diagnostics, "figures": figures}


def _estimate_joint(case, out):
    """Several ``[[measurement]]`` blocks, one MSD (estimate_hsi_joint); figures per record."""
    from ..identification.estimation import estimate_hsi_joint
    from ..reporting.plotting import plot_psd_comparison, plot_psd_residuals, save_figure

    est = case.estimation
    say(f"crowdvib estimate: {case.name} ({case.path.name}), joint fit of "
        f"{len(case.records)} records")
    parts = []
    for block in case.blocks():
        say(f"  {block.name}: crowd {block.crowd.density:g} P/m²")
        record, measured, lowpass = case_measurement(block)
        crowd, step_result = case_crowd(block, record)
        parts.append((block, record, measured, lowpass, crowd, step_result))
    options = dict(estimate_options(case), **estimate_extras(case), outputs=est.outputs)
    estimate = estimate_hsi_joint([p[2] for p in parts], case.structure, [p[4] for p in parts],
                                  free_mass_ratio="mass_ratio" in est.free_parameters,
                                  **options)
    found = estimate.msd
    _say_estimate(estimate)
    labels = [f"{block.name} {name}" for block, record, *_ in parts
              for name in record.channel_names]
    names = unique_filenames(labels, prefix="psd_", suffix=".png")
    residual_names = unique_filenames(labels, prefix="residuals_", suffix=".png")
    figures, records = [], []
    for block, record, measured, lowpass, crowd, step_result in parts:
        models = _fitted_and_no_hsi(case, crowd, measured, lowpass, found, record.channel_names)
        for name in record.channel_names:
            label = f"{block.name} {name}"
            ax = plot_psd_comparison({"measured": measured, "fitted MSD (joint)": models[0],
                                      "no HSI": models[1]}, output=name,
                                     band=(0.0, max(est.band[1], 2 * est.band[0])),
                                     title=f"{case.name}, {label}")
            ax.axvspan(*est.band, color="tab:green", alpha=0.07, label="band")
            figures.append(save_figure(ax, out / names[label]).name)
            ax = plot_psd_residuals(measured, models[0], output=name, band=est.band,
                                    title=f"{case.name}, {label}: residuals of the joint fit")
            figures.append(save_figure(ax, out / residual_names[label]).name)
        records.append({"name": block.name, "record": record.to_dict(),
                        "crowd_used": {"density": crowd.density,
                                       "step_frequency_mean": crowd.step_frequency_mean,
                                       "step_frequency_std": crowd.step_frequency_std},
                        "n_windows": measured.n_windows,
                        "step_frequencies": None if step_result is None
                        else step_result.to_dict()})
    hsi = estimate.to_dict()
    diagnostics = {k: v for k, v in hsi.items() if k != "estimate"}
    diagnostics["records"] = records
    return {"command": "estimate", "crowdvib_version": __version__, "versions": versions(),
            "seed": case.seed, "case": str(case.path), "inputs": case.to_dict(),
            "records": records, "estimate": hsi["estimate"], "expected": dict(case.expected),
            "diagnostics": diagnostics, "figures": figures}


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


def _fitted_and_no_hsi(case, crowd, measured, lowpass, msd, outputs):
    """The fitted and the no-HSI model PSDs as the estimator compared them."""
    from ..response.fluctuation import spectral_model

    est = case.estimation
    window = measured.window_length if est.match_welch else None
    model = spectral_model(case.structure, crowd, measured.frequency, outputs=outputs,
                           welch_window_length=window,
                           lowpass=lowpass if est.match_welch else None,
                           crowd_model=est.crowd_model)
    return model.psd(msd), model.psd(None)


def estimate_options(case):
    """Keyword arguments of estimate_hsi from a case's [estimation] table."""
    est = case.estimation
    return dict(band=est.band, outputs=est.outputs, output_weights=est.output_weights,
                starts=est.starts, bounds=est.bounds, mass_ratio=case.msd.mass_ratio,
                match_welch=est.match_welch, method=est.method,
                interval=None if est.interval == "none" else est.interval, level=est.level,
                n_boot=est.n_boot, rng=case.seed)


def estimate_extras(case):
    """The [estimation] option only ``crowdvib estimate`` uses: the crowd model of the expected
    PSD (the studies, map and sensitivity, compare with the paper's smeared model)."""
    return dict(crowd_model=case.estimation.crowd_model)
