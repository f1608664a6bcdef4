"""``crowdvib check`` as a call: the design checks of a case's ``[design]`` table, without and
with HSI (optionally across an estimate's interval), written as a results folder."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..cases.results import provenance
from .folders import case_inputs, staged_output, write_results
from .lines import Say, caught_warnings, silent, warning_texts
from .._manifest import verified_file
from ..cases import check_case, check_design_table, design_msd, estimated_msd
from ..io.casefile import load_case
from ..cases.results import load_results
from ..reporting.animation import mode_shape_table
from .._figures import save_figure
from ..reporting.design_plots import plot_mode_accelerations, plot_utilisation

if TYPE_CHECKING:
    from ..cases.results import Results
    from ..io.casefile import Case

__all__ = ["run_check"]


def run_check(case: Case | str | Path, out: str | Path, *, msd_from: str | Path | None = None,
              force: bool = False, say: Say = silent) -> Results:
    """What ``crowdvib check`` does: :func:`~crowdvib.cases.check_case`, its figures,
    results.json and report.html in ``out``.

    Parameters
    ----------
    case : Case, str or pathlib.Path
        A case with a ``[design]`` table, or its file (read here, so that the warnings of
        reading it are recorded with the run's: ξ = 0.5 for 0.5 % must not pass a failing bridge
        with "no warnings", issue 24).
    out : str or pathlib.Path
        The results folder (:func:`~crowdvib.runs.staged_output`'s rules).
    msd_from : str or pathlib.Path, optional
        A results folder of ``crowdvib estimate`` (or demo, sensitivity): its estimated MSD
        replaces the case's for the HSI model, and the checks span its interval (issue 27 §3,
        :func:`~crowdvib.cases.check_over_interval`). Its results.json is verified against the
        folder's manifest first (:func:`crowdvib._manifest.verified_file`): one edited since is
        refused, one without a manifest used with an ``UnverifiedWarning``.
    force : bool
        Replace crowdvib's earlier results in ``out``.
    say : callable, optional
        Called with each line the command prints.

    Returns
    -------
    Results
        As written, the run's warnings in it (each once).
    """

    with caught_warnings() as caught:
        case = case if hasattr(case, "design") else load_case(case)
        check_design_table(case)
        msd_from = None if msd_from is None else Path(msd_from)
        estimated = None if msd_from is None else load_results(
            verified_file(msd_from, "results.json", "--msd-from"))
        msd, msd_source = (design_msd(case) if estimated is None
                           else (estimated_msd(case, estimated, source=f"--msd-from {msd_from}"),
                                 f"the estimate in {msd_from}"))
        inputs = case_inputs(case) + ([] if msd_from is None
                                      else [("the MSD results", msd_from / "results.json")])
        say(f"crowdvib check: {case.name}, codes {', '.join(case.design.codes)}, "
            f"{'HSI from ' + msd_source if msd is not None else 'no HSI'}")
        with staged_output(out, force, command="check", inputs=inputs) as staging:
            # The estimate's interval carried into the checks (issue 27 §3): a range, not a point.
            found = check_case(case, msd=msd, msd_source=msd_source, estimate=estimated)
            figures = _figures(found.checks, staging, case.name)
            written = write_results(staging, {
                **found.to_dict(), "figures": figures, **provenance(case.path),
                "mode_shapes": mode_shape_table(case.structure, case.stationary_crowd(), found.msd),
                "warnings": list(dict.fromkeys(warning_texts(caught)))})   # once each
    for line in _table_lines(found.rows):
        say("  " + line)
    if estimated is not None:
        for line in _range_lines(found.spread, msd_from):
            say("  " + line)
    prediction = found.prediction
    if prediction is not None:
        for model, rms, peak in zip(prediction.models, prediction.rms, prediction.expected_peak):
            say(f"  crowd stream, {model}: RMS {_join(rms)} m/s², expected peak over "
                f"{prediction.duration:g} s {_join(peak)} m/s²")
    say(f"  wrote results.json, {', '.join(figures)} and report.html to {out} "
        f"({found.seconds:.1f} s)")
    return written


def _join(values):
    import numpy as np

    return "/".join(f"{v:.3f}" for v in np.atleast_1d(values))


def _range_lines(spread, msd_from):
    """Per code, the HSI utilisation at the estimate, its range over the interval and the
    verdict at the conservative end; one note if the results hold no interval."""
    if spread is None:
        return [f"HSI: the point estimate only ({msd_from}/results.json holds no interval: "
                "estimation.interval = \"none\")"]
    box = spread.interval
    over = (f"the {100 * box['level']:g} % interval of f_h1 and ξ_h1"
            + (" widened by the modelling bound" if "modelling" in box["interval"] else ""))
    lines = [f"HSI over the box of {box['interval']} (f_h1 {box['frequency'][0]:.3g}–{box['frequency'][1]:.3g} Hz, "
             f"ξ_h1 {box['damping_ratio'][0]:.3g}–{box['damping_ratio'][1]:.3g}, "
             f"{spread.grid} × {spread.grid} grid):"]
    for code, row in spread.hsi_range().items():
        lines.append(f"  {code:7s} utilisation {row['utilisation']:.2f} (range {row['low']:.2f}–"
                     f"{row['high']:.2f} over {over}): {row['verdict']}"
                     + ("" if row["monotone"] else
                        "; not monotone over the grid, a finer grid may widen the range"))
    return lines


def _table_lines(rows):
    header = (f"{'code':7s} {'class':5s} {'model':10s} {'output':12s} {'a [m/s²]':>9s} "
              f"{'limit':>6s} {'util.':>6s} {'comfort':>7s}")
    lines = [header]
    for row in rows:
        lines.append(f"{row['code']:7s} {row['traffic_class'] or '-':5s} {row['model']:10s} "
                     f"{row['output'][:12]:12s} {row['governing']:9.3f} {row['limit']:6.2f} "
                     f"{row['utilisation']:6.2f} {row['comfort_class']:>7s}"
                     f"{'' if row['passes'] else '  FAILS'}")
    return lines


def _figures(checks, staging, name):
    return [save_figure(plot_utilisation(checks, title=f"{name}: design checks"),
                        staging / "design_utilisation.png").name,
            save_figure(plot_mode_accelerations(checks, title=f"{name}: peak acceleration per "
                                                "mode"), staging / "design_modes.png").name]
