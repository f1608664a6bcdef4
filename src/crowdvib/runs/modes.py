"""``crowdvib modes`` as a call: the empty bridge's modes from an ambient record (OMA), written as
a results folder.

The ambient file's keys are in the docs (Case files, ambient tests); the identification is
:func:`crowdvib.cases.ambient.identify_ambient`. The folder holds ``modes.csv`` (f, ξ and their
standard deviations per mode), ``mode_shapes.csv`` (at the sensors), ``cross_check.csv`` (with
the cross-check), the stabilisation diagram (SSI-cov) or singular values (EFDD) per setup and
method, ``mode_shapes.png``, the modal-model CSV files when ``[modal_model]`` is given,
``results.json`` and ``report.html``. Modes the two methods disagree on are warnings, and so is
a stable column of the diagram not among the ``n_modes`` reported.
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import TYPE_CHECKING

from .folders import staged_output, write_results
from .lines import Progress, Say, caught_warnings, silent, warning_texts
from ..cases.ambient import identify_ambient
from ..io.modalfiles import write_modal_model
from ..reporting.animation import mode_shape_table
from ..reporting.plotting import save_figure

if TYPE_CHECKING:
    from ..cases.results import Results

__all__ = ["run_modes"]


def run_modes(ambient: str | Path, out: str | Path, *, cross_check: bool = False,
              force: bool = False, say: Say = silent,
              progress: Progress | None = None) -> Results:
    """What ``crowdvib modes`` does: the ambient file's modes, their tables, figures,
    results.json and report.html in ``out`` (written whole or not at all).

    Parameters
    ----------
    ambient : str or pathlib.Path
        The ambient-test file (TOML).
    out : str or pathlib.Path
        The results folder (:func:`~crowdvib.runs.staged_output`'s rules).
    cross_check : bool
        Also identify with the other method (EFDD for SSI-cov, and back) and compare.
    force : bool
        Replace crowdvib's earlier results in ``out``.
    say : callable, optional
        Called with each line the command prints (default: none printed).
    progress : callable, optional
        ``progress(label, unit)`` → the ``progress(done, total)`` callback of the identification.

    Returns
    -------
    Results
        As written; the run's warnings are recorded in it (``.warnings``).
    """

    with staged_output(out, force, command="modes",
                       inputs=[("the ambient file", Path(ambient))]) as staging:
        # Doubtful modes are warnings of the identification: they go to the verdict and report.
        with caught_warnings() as caught:
            # The bar is drawn at once: a long SSI-cov run is seen advancing (issue 27 §4).
            found = identify_ambient(ambient, cross_check=cross_check,
                                     progress=None if progress is None
                                     else progress("identification", unit="steps"))
        records, options, modes, structure = (found.records, found.options, found.modes,
                                              found.structure)
        say(f"crowdvib modes: {found.name}, {len(records)} setup(s), "
            f"{sum(r.n_channels for r in records)} channel(s), "
            f"{sum(r.duration for r in records):g} s at {records[0].sample_rate:g} Hz "
            f"({_method_words(options['method'], modes.settings)}"
            f"{', cross-checked' if options['cross_check'] else ''})")
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
        # The model's shapes beside the identified ones (issue 38).
        shapes = {} if structure is None else {"mode_shapes": mode_shape_table(structure)}
        results = {**found.to_dict(), **shapes, "files": files, "figures": figures,
                   "elapsed_s": found.seconds, "warnings": warning_texts(caught)}
        written = write_results(staging, results)
    for j in range(modes.n_modes):
        say(f"  mode {j + 1}: f = {modes.frequencies[j]:.4f} ± {modes.frequency_std[j]:.4f} Hz, "
            f"ξ = {modes.damping_ratios[j]:.4f} ± {modes.damping_std[j]:.4f}")
    say(f"  wrote {', '.join(files)} and results.json to {out} ({found.seconds:.1f} s)")
    return written


def _write_csv(path, header, rows):
    with open(path, "w", encoding="utf-8", newline="") as handle:
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(header)
        writer.writerows(rows)


def _figures(modes, staging):
    """Stabilisation diagram / singular values of every setup and method."""

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
