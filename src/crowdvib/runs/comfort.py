"""``crowdvib comfort`` as a call: a year of comfort from a season (or a traffic table) and the
identified MSD, written as a results folder (issue 37)."""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import TYPE_CHECKING

from ..cases.results import provenance
from .folders import case_inputs, staged_output, write_results
from .lines import Say, caught_warnings, silent, warning_texts
from .._manifest import verified_file
from ..cases import comfort_case
from ..cases.comfort import simulate_below
from ..errors import ParameterError
from ..io.casefile import load_case
from ..reporting.animation import mode_shape_table
from ..reporting.reading import read_results
from ..runner import study_executor
from .._figures import save_figure

if TYPE_CHECKING:
    from ..cases.results import Results
    from ..io.casefile import Case

__all__ = ["run_comfort", "COMFORT_FIGURES"]

#: The figures ``crowdvib comfort`` writes: file name → ComfortYear.plot kind.
COMFORT_FIGURES = {"comfort_hours.png": "hours", "comfort_exceedance.png": "exceedance",
                   "comfort_week.png": "week", "comfort_peaks.png": "peaks"}


def run_comfort(case: Case | str | Path, out: str | Path, *, season: str | Path | None = None,
                traffic: str | Path | None = None, msd_from: str | Path | None = None,
                workers: int = 1, hung_after: float = 60.0, force: bool = False,
                say: Say = silent) -> Results:
    """What ``crowdvib comfort`` does: :func:`~crowdvib.cases.comfort_case`, its figures,
    results.json and report.html in ``out``.

    Parameters
    ----------
    case : Case, str or pathlib.Path
        The case, or its file.
    out : str or pathlib.Path
        The results folder (:func:`~crowdvib.runs.staged_output`'s rules).
    season : str or pathlib.Path, optional
        A ``crowdvib season`` results folder: its windows are the traffic, its joint estimate
        the MSD (unless ``msd_from``).
    traffic : str or pathlib.Path, optional
        A traffic CSV instead (``density, hours_per_year`` or ``hour, density``); neither: the
        case's ``[traffic]``.
    msd_from : str or pathlib.Path, optional
        A results folder of ``crowdvib estimate``, ``sensitivity`` or ``season``: its MSD and
        interval. Each results.json read is verified against its folder's manifest first.
    workers, hung_after
        Local worker processes of the windows ``[comfort] simulate_below`` simulates (1: this
        process), and when one counts as hung (:func:`~crowdvib.runner.study_executor`).
    force : bool
        Replace crowdvib's earlier results in ``out``.
    say : callable, optional
        Called with each line the command prints.

    Returns
    -------
    Results
        A :class:`~crowdvib.cases.ComfortResults`, as written.
    """

    if season is not None and traffic is not None:
        raise ParameterError("give --season or --traffic, not both")
    with caught_warnings() as caught:
        case = case if hasattr(case, "comfort") else load_case(case)
        inputs = case_inputs(case)
        read = {}
        for key, folder in (("season", season), ("msd", msd_from)):
            if folder is not None:
                folder = Path(folder)
                read[key] = read_results(verified_file(folder, "results.json",
                                                       f"--{key.replace('msd', 'msd-from')}"))
                inputs.append((f"the {key} results", folder / "results.json"))
        if traffic is not None:
            inputs.append(("the traffic table", Path(traffic)))
        say(f"crowdvib comfort: {case.name}, traffic from "
            f"{season or traffic or 'the case [traffic]'}")
        simulates = simulate_below(case) > 0
        pool = (study_executor(workers, timeout_floor=hung_after) if simulates
                else contextlib.nullcontext(None))
        with staged_output(out, force, command="comfort", inputs=inputs) as staging, \
                pool as executor:
            found = comfort_case(case, season=read.get("season"), traffic=traffic,
                                 msd_results=read.get("msd"),
                                 msd_source=None if msd_from is None
                                 else f"the estimate in {msd_from}", executor=executor)
            figures = _figures(found.year, staging, case.name)
            written = write_results(staging, {
                **found.to_dict(), "figures": figures, **provenance(case.path),
                # the modes swing in the report (issue 38), occupied by the case's crowd
                "mode_shapes": mode_shape_table(case.structure, case.stationary_crowd(), found.msd),
                "warnings": list(dict.fromkeys(warning_texts(caught)))})
    for line in comfort_lines(found.year.to_dict()):
        say("  " + line)
    say(f"  wrote results.json, {', '.join(figures)} and report.html to {out} "
        f"({found.seconds:.1f} s CPU)")
    return written


def comfort_lines(year: dict) -> list[str]:
    """The console's table: hours a year per class and the probability that a window exceeds
    CL1's limit, per model, with the HSI band."""
    settings = year["settings"]
    names = [name for name, _ in settings["classes"]]
    limit = f"{settings['classes'][0][1]:g}"
    lines = [f"{settings['total_hours']:.0f} h a year, output {settings['output']}, window "
             f"{settings['duration']:g} s ({settings['peak_model']} peak)",
             f"{'model':28s} " + " ".join(f"{n + ' [h]':>9s}" for n in names)
             + f"  P(>{limit} m/s²)"]
    for row in year["rows"]:
        label = row["label"] + (" + damper" if row["damper"] else "")
        band = row.get("exceedance_band_hsi") or row.get("exceedance_band_sampling")
        lines.append(f"{label:28s} " + " ".join(f"{row['hours_per_class'][n]:9.0f}"
                                                  for n in names)
                     + f"  {row['exceedance'][limit]:.3f}"
                     + (f" ({band[limit][0]:.3f}–{band[limit][1]:.3f})" if band else ""))
    return lines


def _figures(year, staging, name):
    return [save_figure(year.plot(kind, title=None), staging / file).name
            for file, kind in COMFORT_FIGURES.items()]
