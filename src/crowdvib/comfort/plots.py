"""Figures of a year of comfort (:meth:`crowdvib.comfort.ComfortYear.plot`): hours a year per
comfort class as stacked bars per model, the probability that a window exceeds a limit against
the density, and the week's heat map of the expected class. Each takes the year's dict
(:meth:`~crowdvib.comfort.ComfortYear.to_dict`, as results.json holds it)."""

import numpy as np

from .._figures import DARK, FigureAxes, panels
from .measure import peak_cdf

__all__ = ["plot_class_hours", "plot_exceedance", "plot_week", "plot_peaks"]

#: Grays from light (CL1, comfortable) to dark (CL4): legible in a grayscale print.
_CLASS_SHADES = ("0.92", "0.7", "0.45", "0.15")
_LINES = {"empty": ":", "added_mass": "--", "hsi": "-"}
_DAYS = ("Mon", "Tue", "Wed", "Thu", "Fri", "Sat", "Sun")


def _label(row):
    return row["label"] + (" + damper" if row["damper"] else "")


def plot_class_hours(year: dict, *, axes=None, title=None) -> FigureAxes:
    """Hours a year in each comfort class, one stacked bar per model (and damper), with the
    HSI band (or the season's) on each class as an error bar.

    Parameters
    ----------
    year : dict
        :meth:`ComfortYear.to_dict`.
    axes : matplotlib.axes.Axes, optional
    title : str, optional
    """
    handles = panels(axes, 1, 1, (7.5, 4.2))
    ax = handles.axes[0]
    rows = year["rows"]
    names = [name for name, _ in year["settings"]["classes"]]
    positions = np.arange(len(rows))
    bottom = np.zeros(len(rows))
    for k, name in enumerate(names):
        hours = np.array([row["hours_per_class"][name] for row in rows])
        ax.bar(positions, hours, 0.6, bottom=bottom, color=_CLASS_SHADES[k], edgecolor=DARK,
               label=name)
        for i, row in enumerate(rows):
            band = row.get("hours_band_hsi") or row.get("hours_band_sampling")
            if band and hours[i] > 0:
                low, high = band[name]
                top = bottom[i] + hours[i]
                ax.errorbar(i + 0.12 * (k - 1.5), top, yerr=[[max(hours[i] - low, 0)],
                                                             [max(high - hours[i], 0)]],
                            color=DARK, capsize=2, lw=0.8)
        bottom += hours
    ax.set_xticks(positions, [_label(row) for row in rows], rotation=20, ha="right",
                  fontsize="small")
    ax.set_ylabel("Hours a year [h]")
    ax.legend(fontsize="small", loc="lower right")
    ax.grid(True, axis="y", alpha=0.3)
    ax.set_title(title or "Hours a year per comfort class")
    return handles


def plot_exceedance(year: dict, *, limit: float | None = None, axes=None,
                    title=None) -> FigureAxes:
    """Probability that a window's peak exceeds ``limit`` against the crowd density, per model
    (from the response table's laws).

    Parameters
    ----------
    year : dict
    limit : float, optional
        [m/s²] (default CL1's upper bound, 0.5).
    axes, title
    """
    settings = year["settings"]
    limit = settings["classes"][0][1] if limit is None else float(limit)
    handles = panels(axes, 1, 1, (7.5, 4.2))
    ax = handles.axes[0]
    shown = set()
    for row in year["rows"]:
        key = (row["model"], row["damper"])
        if key in shown:
            continue
        shown.add(key)
        cells = [c for c in year["table"] if (c["model"], c["damper"]) == key]
        density = np.array([c["density"] for c in cells])
        exceed = 1 - peak_cdf(limit, np.array([c["rms"] for c in cells]),
                              np.array([c["crossing_rate"] for c in cells]),
                              np.array([c["spread"] for c in cells]), settings["duration"],
                              settings["peak_model"])
        ax.plot(density, exceed, _LINES[row["model"]], marker="o" if row["damper"] else None,
                ms=3, color=DARK if not row["damper"] else "0.5", label=_label(row))
    ax.set_xlabel("Crowd density [persons/m²]")
    ax.set_ylabel(f"P(peak over {settings['duration']:g} s > {limit:g} m/s²)")
    ax.set_ylim(-0.02, 1.02)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    ax.set_title(title or "Probability that a window exceeds the limit")
    return handles


def plot_week(year: dict, *, model: str | None = None, axes=None, title=None) -> FigureAxes:
    """The expected comfort class (1 = CL1 … 4 = CL4) in each hour of the week, without and
    with the dampers (one panel each), for ``model`` (default the identified HSI if present).

    Parameters
    ----------
    year : dict
    model : str, optional
    axes, title
    """
    rows = [row for row in year["rows"] if row.get("week_class") is not None]
    model = model or ("hsi" if any(r["model"] == "hsi" for r in rows) else "empty")
    rows = [row for row in rows if row["model"] == model]
    handles = panels(axes, max(len(rows), 1), 1, (8.0, 2.2 * max(len(rows), 1) + 0.8))
    image = None
    for ax, row in zip(handles.axes, rows):
        values = np.array([np.nan if v is None else v for v in row["week_class"]],
                          float).reshape(7, 24)
        image = ax.imshow(values, aspect="auto", cmap="Greys", vmin=1, vmax=4,
                          interpolation="nearest")
        ax.set_yticks(range(7), _DAYS)
        ax.set_xticks(range(0, 24, 3))
        ax.set_title(_label(row), fontsize="small")
    if rows:
        handles.axes[-1].set_xlabel("Hour of the day")
        bar = handles.figure.colorbar(image, ax=list(handles.axes))
        bar.set_label("Expected class (1 = CL1 … 4 = CL4)")
    else:
        handles.axes[0].text(0.5, 0.5, "the traffic has no hours of the week", ha="center")
    handles.figure.suptitle(title or "Expected comfort class in the week")
    return handles


def plot_peaks(year: dict, *, axes=None, title=None) -> FigureAxes:
    """The window's peak against the crowd density per model (its first tabled quantile as a
    line, up to its last as a shade), with the comfort classes' bounds.

    Parameters
    ----------
    year : dict
    axes, title
    """
    settings = year["settings"]
    handles = panels(axes, 1, 1, (7.5, 4.2))
    ax = handles.axes[0]
    keys = list(dict.fromkeys((row["model"], row["damper"]) for row in year["rows"]))
    labels = {(row["model"], row["damper"]): _label(row) for row in year["rows"]}
    quantiles = settings["quantiles"]
    for model, damper in keys:
        cells = [c for c in year["table"] if (c["model"], c["damper"]) == (model, damper)]
        density = [c["density"] for c in cells]
        peaks = np.array([c["peak"] for c in cells])
        colour = DARK if not damper else "0.5"
        ax.plot(density, peaks[:, 0], _LINES[model], color=colour,
                label=f"{labels[(model, damper)]} ({100 * quantiles[0]:g} %)")
        ax.fill_between(density, peaks[:, 0], peaks[:, -1], color=colour, alpha=0.12, lw=0)
    for name, bound in settings["classes"]:
        if bound is not None:
            ax.axhline(bound, color="0.3", lw=0.7, ls="-.")
            ax.annotate(f"{name} ≤ {bound:g}", (0.0, bound), xycoords=("axes fraction", "data"),
                        fontsize="x-small", va="bottom")
    ax.set_xlabel("Crowd density [persons/m²]")
    ax.set_ylabel(f"Peak over {settings['duration']:g} s [m/s²]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="x-small")
    ax.set_title(title or f"Window peak: {100 * quantiles[0]:g} % (line) to "
                          f"{100 * quantiles[-1]:g} % (shade)")
    return handles
