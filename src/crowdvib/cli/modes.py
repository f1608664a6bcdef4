"""``crowdvib modes AMBIENT.toml``: the empty bridge's modes from an ambient record (OMA).

The ambient file (TOML, paths relative to it)::

    name = "my footbridge, ambient test"

    [record]                        # read_record: CSV, NPZ, MAT or UFF 58
    file = "ambient.csv"
    channels = ["s1", "s2", "s3"]   # optional: the sensors, in order (default all channels), or
                                    #   a table sensor = "channel in file" (renames them)
    sample_rate = 50.0              # optional: for a CSV without a time column [Hz]
    units = "g"                     # optional: "m/s2" (default) or "g", as in a case file
    time_column = "Time [s]"        # optional: the CSV's time column (format: from the suffix)

    # several setups instead: one [[record]] block per setup (same keys), and
    # identification.reference_channels naming the sensors that stay in place

    [identification]                # identify_modes
    method = "ssi-cov"              # optional: "ssi-cov" (pyOMA2) or "efdd"
    cross_check = true              # optional: run the other method too and compare
    n_modes = 3                     # optional (default every consistently stable mode)
    frequency_band = [1.0, 9.0]     # optional [Hz]
    max_order = 20                  # optional (SSI-cov; default from n_modes: 4 n_modes + 8, or 40)
    block_rows = 50                 # optional (SSI-cov; default from the band's lower end)
    segment_length = 2048           # optional (EFDD, samples)
    reference_channels = ["ref"]    # several setups: the channels every record shares

    [modal_model]                   # optional: the ModalModel to write (OMA gives no masses)
    fe_model = "bridge.uff"         #   an FE export (UFF 15 + 55) whose output_nodes are the
    output_nodes = { s1 = 101 }     #   sensors (identified f, ξ replace the paired FE modes), or
    # modal_masses = [5e4, 4e4]     #   stated masses [kg] with sensor_positions = [...] [m]
    # walkway = [0.0, 50.0]         #   and the walkway's ends [m] (coarse shapes)
    width = 3.0                     #   walkway width [m]

With several setups the sensors are the first record's, then the other records' roving
channels (a name used in several records gets " (setup N)"); ``sensor_positions`` follow that
order. ``--cross-check`` on the command line is ``cross_check = true``.

Writes ``modes.csv`` (f, ξ and their standard deviations per mode), ``mode_shapes.csv`` (at the
sensors), ``cross_check.csv`` (with the cross-check), the stabilisation diagram (SSI-cov) or
singular values (EFDD) per setup and method, ``mode_shapes.png``, the modal-model CSV files
when ``[modal_model]`` is given, ``results.json`` and ``report.html``. Modes the two methods
disagree on are warnings, and so is a stable column of the diagram not among the ``n_modes``
reported. A progress bar shows the identification advancing.
"""

import csv
import sys
import warnings
from pathlib import Path

from .common import (add_output_arguments, progress_printer, say, say_verdict, staged_output,
                     warning_texts, write_results)


def add_arguments(parser):
    parser.add_argument("ambient", type=Path, help="ambient-test file (TOML)")
    parser.add_argument("--cross-check", action="store_true",
                        help="also identify with the other method (EFDD for SSI-cov, and back) "
                             "and compare the modes")
    add_output_arguments(parser)


def _write_csv(path, header, rows):
    with open(path, "w", encoding="utf-8", newline="") as handle:
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(header)
        writer.writerows(rows)


def _figures(modes, staging):
    """Stabilisation diagram / singular values of every setup and method."""
    from ..reporting.plotting import save_figure

    setups = modes.setups or (modes,)
    names = []
    for s, setup in enumerate(setups, start=1):
        suffix = f"_setup{s}" if len(setups) > 1 else ""
        for identification in filter(None, (setup, setup.cross_check and
                                            setup.cross_check.other)):
            stem = "singular_values" if identification.method == "efdd" else "stabilisation"
            if identification.poles:
                names.append(save_figure(identification.plot_stabilisation(),
                                         staging / f"{stem}{suffix}.png").name)
    if modes.n_modes:
        names.append(save_figure(modes.plot_mode_shapes(), staging / "mode_shapes.png").name)
    return names


def _method_words(method, settings):
    """"ssi-cov, 50 block rows, orders up to 20, decimated 2×" from the settings it ran with."""
    if method != "ssi-cov" or "block_rows" not in settings:
        return method
    words = f"{method}, {settings['block_rows']} block rows, orders up to {settings['max_order']}"
    return words + (f", decimated {settings['decimation']}×" if settings["decimation"] > 1
                    else "")


def _cross_check_rows(check):
    def cell(v):
        return "" if v != v else f"{v:.10g}"                      # NaN: not found

    return [[f"mode_{j + 1}", check.method, *(cell(getattr(check, k)[j]) for k in (
        "frequencies", "frequency_std", "damping_ratios", "damping_std", "frequency_difference",
        "damping_difference", "frequency_z", "damping_z", "mac")), str(bool(check.agree[j]))]
            for j in range(check.agree.size)]


def run(args):
    from ..cases.ambient import identify_ambient
    from ..io.modalfiles import write_modal_model

    with staged_output(args.out, args.force, command="modes",
                       inputs=[("the ambient file", args.ambient)]) as staging:
        # Doubtful modes are warnings of the identification: they go to the verdict and report.
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            # The bar is drawn at once: a long SSI-cov run is seen advancing (issue 27 §4).
            found = identify_ambient(args.ambient, cross_check=args.cross_check,
                                     progress=progress_printer("identification", unit="steps"))
        records, options, modes, structure = (found.records, found.options, found.modes,
                                              found.structure)
        say(f"crowdvib modes: {found.name}, {len(records)} setup(s), "
            f"{sum(r.n_channels for r in records)} channel(s), "
            f"{sum(r.duration for r in records):g} s at {records[0].sample_rate:g} Hz "
            f"({_method_words(options['method'], modes.settings)}"
            f"{', cross-checked' if options['cross_check'] else ''})")
        for text in warning_texts(caught):
            print(f"crowdvib modes: warning: {text}", file=sys.stderr)
        _write_csv(staging / "modes.csv", ["mode", "frequency", "frequency_std", "damping_ratio",
                                           "damping_std"],
                   [[f"mode_{j + 1}", *(f"{v[j]:.10g}" for v in (
                       modes.frequencies, modes.frequency_std, modes.damping_ratios,
                       modes.damping_std))] for j in range(modes.n_modes)])
        _write_csv(staging / "mode_shapes.csv",
                   ["sensor"] + [f"mode_{j + 1}" for j in range(modes.n_modes)],
                   [[sensor] + [f"{v:.10g}" for v in row]
                    for sensor, row in zip(modes.sensor_names, modes.mode_shapes)])
        files = ["modes.csv", "mode_shapes.csv"]
        if modes.cross_check is not None:
            _write_csv(staging / "cross_check.csv",
                       ["mode", "method", "frequency", "frequency_std", "damping_ratio",
                        "damping_std", "frequency_difference", "damping_difference",
                        "frequency_z", "damping_z", "mac", "agree"],
                       _cross_check_rows(modes.cross_check))
            files.append("cross_check.csv")
        figures = _figures(modes, staging)
        if structure is not None:
            write_modal_model(structure, staging / "modal_table.csv",
                              staging / "modal_shapes.csv", staging / "output_points.csv")
            files += ["modal_table.csv", "modal_shapes.csv", "output_points.csv"]
        results = {**found.to_dict(), "files": files, "figures": figures,
                   "elapsed_s": found.seconds, "warnings": warning_texts(caught)}
        write_results(staging, results)
    for j in range(modes.n_modes):
        say(f"  mode {j + 1}: f = {modes.frequencies[j]:.4f} ± {modes.frequency_std[j]:.4f} Hz, "
            f"ξ = {modes.damping_ratios[j]:.4f} ± {modes.damping_std[j]:.4f}")
    say(f"  wrote {', '.join(files)} and results.json to {args.out} ({found.seconds:.1f} s)")
    return say_verdict(args.out)
