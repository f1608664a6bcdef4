"""Figures of spectra: PSDs side by side (``ResponsePSD.plot``) and a Welch PSD's convergence.

Every function takes result objects and an optional ``ax``, labels axes with units, returns the
Axes and never calls ``plt.show()``; matplotlib is imported only when a plot is asked for
(:mod:`crowdvib._figures`). All figures are importable from :mod:`crowdvib.reporting.plotting`.
"""

import numpy as np

from .._figures import axes_or_new, in_band

__all__ = ["plot_psd_comparison", "plot_psd_convergence"]


def plot_psd_comparison(curves, *, output=None, band=None, analysis_band=None, logscale=True,
                        ax=None, title=None):
    """Acceleration PSDs of one output on one axes (paper Figures 3, 12, 17 and 20).

    Parameters
    ----------
    curves : dict of str to ResponsePSD
        Legend label → PSD; drawn in order (first: the measurement, as a black line).
    output : str, optional
        Output name (default the first output of the first curve).
    band : (float, float), optional
        Frequency range [Hz] to show. The 0 Hz bin is never drawn: it holds what is left of the
        record's offset, not its vibration, and would set the axis (issue 27 §4).
    analysis_band : (float, float), optional
        The estimator's analysis band [Hz], shaded and named in the legend.
    logscale : bool
        Logarithmic PSD axis.
    ax : matplotlib.axes.Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = axes_or_new(ax)
    if analysis_band is not None:
        low, high = analysis_band
        ax.axvspan(low, high, color="tab:green", alpha=0.07, lw=0,
                   label=f"analysis band {low:g}–{high:g} Hz")
    styles = [dict(color="black", lw=1.0), dict(color="tab:red", lw=1.6, ls="--"),
              dict(color="0.55", lw=1.2), dict(color="tab:blue", lw=1.2, ls=":")]
    unit, top = None, 0.0
    for (label, psd), style in zip(curves.items(), styles * 4):
        name = output or psd.output_names[0]
        row = psd.select(name)
        keep = in_band(row.frequency, band)
        frequency, values = row.frequency[keep], row.psd[0][keep]
        frequency, values = frequency[frequency > 0], values[frequency > 0]
        ax.plot(frequency, np.where(values > 0, values, np.nan) if logscale else values,
                label=label, **style)
        unit = row.unit
        top = max(top, float(np.nanmax(values, initial=0.0)))
    if logscale:
        ax.set_yscale("log")
        if top > 0:  # eight decades show every structural feature; below is numerical dust
            ax.set_ylim(top * 1e-8, top * 3)
    ax.set_xlabel("Frequency [Hz]")
    ax.set_ylabel(f"Acceleration PSD [{unit}]")
    if title:
        ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return ax


def plot_psd_convergence(convergence, *, ax=None, title=None, level=0.10):
    """Convergence error ΔG_kT of a Welch PSD against record length (paper Figure 15).

    Parameters
    ----------
    convergence : PSDConvergence
        From :func:`crowdvib.signals.psd_convergence`.
    ax : matplotlib.axes.Axes, optional
    title : str, optional
    level : float, optional
        A reference level drawn as a dashed line (the paper's 10 %); None for none.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = axes_or_new(ax)
    for name, row in zip(convergence.output_names, convergence.error):
        ax.plot(convergence.duration[:-1], 100 * row[:-1], marker="o", ms=3, label=name)
    if level is not None:
        ax.axhline(100 * level, color="0.5", ls="--", lw=1.0, label=f"{level:.0%}")
    ax.set_ylim(bottom=0)  # the error is a distance to the converged PSD: 0 is the goal
    ax.set_xlabel("Record length k·T [s]")
    ax.set_ylabel(f"ΔG ({convergence.norm}-norm, {convergence.band[0]:g}–"
                  f"{convergence.band[1]:g} Hz) [%]")
    if title:
        ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend()
    return ax
