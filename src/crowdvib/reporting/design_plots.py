"""Figures of the design checks (``crowdvib check``): utilisation per code and model, the peak
acceleration of every mode, and the FRF of the governing mode without and with the damper."""

import numpy as np

from .._figures import DARK, LIGHT, FigureAxes, panels
from ..design.registry import code_label

__all__ = ["plot_utilisation", "plot_mode_accelerations", "plot_damper_frf", "MODEL_LABELS"]

#: The structural models of a design check as the report and its figures name them.
MODEL_LABELS = {"empty": "no HSI", "added_mass": "added mass", "hsi": "HSI"}
_SHADES = {"empty": "0.75", "added_mass": "0.45", "hsi": "black"}


def plot_utilisation(checks: dict, *, axes: object = None, title: str | None = None) -> FigureAxes:
    """Governing utilisation (largest over the outputs) per code, one bar per structural model.

    Parameters
    ----------
    checks : dict
        Code → :class:`crowdvib.design.DesignCheck`.
    axes : matplotlib.axes.Axes, optional
    title : str, optional

    Returns
    -------
    FigureAxes
    """
    handles = panels(axes, 1, 1, (7.5, 4.0))
    ax = handles.axes[0]
    models = ("empty", "added_mass", "hsi")
    width = 0.8 / len(models)
    for k, model in enumerate(models):
        values = [float(np.max(check.governing_of(model) / check.limit))
                  if model in check.models else np.nan for check in checks.values()]
        ax.bar(np.arange(len(checks)) + (k - 1) * width, values, width, color=_SHADES[model],
               edgecolor=DARK, label=MODEL_LABELS[model])
    ax.axhline(1.0, color=DARK, ls="--", lw=1.0, label="limit")
    ax.set_xticks(np.arange(len(checks)), [_code_label(c) for c in checks.values()])
    ax.set_ylabel("Utilisation a / a_limit [-]")
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize="small")
    ax.set_title(title or "Design checks: governing utilisation")
    return handles


def plot_mode_accelerations(checks: dict, *, axes: object = None,
                            title: str | None = None) -> FigureAxes:
    """Peak acceleration of every mode at the governing output, per code and model.

    Returns
    -------
    FigureAxes
        One panel per code.
    """
    handles = panels(axes, 1, len(checks), (3.6 * len(checks) + 1.0, 3.8), sharey=False)
    for ax, check in zip(handles.axes, checks.values()):
        output = int(np.argmax(check.governing))
        modes = np.arange(1, check.peak_accelerations.shape[-1] + 1)
        for model in check.models:
            index = check.models.index(model)
            ax.plot(modes, check.peak_accelerations[index, output], "o-",
                    color=_SHADES[model], mec=DARK, label=MODEL_LABELS[model])
        ax.axhline(check.limit, color=DARK, ls="--", lw=1.0, label="limit")
        # Modes are whole numbers, the limit and every peak inside the axes from 0 (issue 36
        # §3: one mode was drawn on a continuous axis 0.96–1.04, the limit on the lower edge).
        ax.set_xticks(modes)
        ax.set_xlim(0.5, modes[-1] + 0.5)
        peaks = check.peak_accelerations[:, output]
        top = max(float(check.limit), float(np.nanmax(peaks)) if np.isfinite(peaks).any()
                  else 0.0)
        ax.set_ylim(0.0, 1.15 * top)
        ax.set_xlabel("Mode [-]")
        ax.set_title(f"{_code_label(check)}, {check.output_names[output]}", fontsize="medium")
        ax.grid(True, alpha=0.3)
    handles.axes[0].set_ylabel("Peak acceleration [m/s²]")
    handles.axes[0].legend(fontsize="small")
    handles.figure.suptitle(title or "Peak acceleration per mode")
    return handles


def plot_damper_frf(frf: dict, *, axes: object = None, title: str | None = None) -> FigureAxes:
    """|FRF| of the governing mode at the governing output, without and with the damper, from
    ``frf``, the ``design.frf`` of a check's results.json (:func:`crowdvib.cases.damper_frf`);
    ``axes`` and ``title`` as for :func:`plot_utilisation`."""
    handles = panels(axes, 1, 1, (7.5, 4.0))
    ax = handles.axes[0]
    frequency = np.asarray(frf["frequency"], float)
    ax.plot(frequency, np.asarray(frf["without_damper"], float), color=LIGHT, ls="--",
            label="without the damper")
    ax.plot(frequency, np.asarray(frf["with_damper"], float), color=DARK,
            label="with the damper")
    ax.set_xlabel("Frequency [Hz]")
    ax.set_ylabel("|H| [(m/s²) per unit modal force]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    code = code_label(frf["code"])
    ax.set_title(title or f"Mode {frf['mode']} at {frf['output']}, {frf['model']} "
                 f"({code}, {frf['density']:.3g} persons/m²)")
    return handles


def _code_label(check):
    code = code_label(check.code)
    return code + (f" {check.traffic_class}" if check.traffic_class else "")
