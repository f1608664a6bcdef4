"""Figures. The only module that imports matplotlib, and only when a plot is asked for.

Every function takes result objects and an optional ``ax``, labels axes with units, returns the
Axes and never calls ``plt.show()``.
"""

import numpy as np

__all__ = ["plot_psd_comparison", "plot_psd_convergence"]


def _axes(ax):
    if ax is not None:
        return ax
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    _, ax = plt.subplots(figsize=(7.5, 4.2), layout="constrained")
    return ax


def plot_psd_comparison(curves, *, output=None, band=None, logscale=True, ax=None, title=None):
    """Acceleration PSDs of one output on one axes (paper Figs. 3, 12, 17, 20).

    Parameters
    ----------
    curves : dict of str to ResponsePSD
        Legend label → PSD; drawn in order (first: the measurement, as a black line).
    output : str, optional
        Output name (default the first output of the first curve).
    band : (float, float), optional
        Frequency range [Hz] to show.
    logscale : bool
        Logarithmic PSD axis.
    ax : matplotlib.axes.Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = _axes(ax)
    styles = [dict(color="black", lw=1.0), dict(color="tab:red", lw=1.6, ls="--"),
              dict(color="0.55", lw=1.2), dict(color="tab:blue", lw=1.2, ls=":")]
    unit, top = None, 0.0
    for (label, psd), style in zip(curves.items(), styles * 4):
        name = output or psd.output_names[0]
        row = psd.select(name)
        keep = slice(None) if band is None else (
            (row.frequency >= band[0]) & (row.frequency <= band[1]))
        values = row.psd[0][keep]
        ax.plot(row.frequency[keep], np.where(values > 0, values, np.nan) if logscale else values,
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


def save_figure(ax, path):
    """Write the figure of ``ax`` to ``path`` (format from the suffix) atomically, and close it."""
    import matplotlib.pyplot as plt

    from ._files import atomic_path

    figure = ax.figure
    with atomic_path(path) as temporary:
        figure.savefig(temporary, format=str(path).rsplit(".", 1)[-1], dpi=130)
    plt.close(figure)
    return path


def plot_psd_convergence(convergence, *, ax=None, title=None, level=0.10):
    """Convergence error ΔG_kT of a Welch PSD against record length (paper Fig. 15).

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
    ax = _axes(ax)
    for name, row in zip(convergence.output_names, convergence.error):
        ax.plot(convergence.duration[:-1], 100 * row[:-1], marker="o", ms=3, label=name)
    if level is not None:
        ax.axhline(100 * level, color="0.5", ls="--", lw=1.0, label=f"{level:.0%}")
    ax.set_xlabel("Record length k·T [s]")
    ax.set_ylabel(f"ΔG ({convergence.norm}-norm, {convergence.band[0]:g}–"
                  f"{convergence.band[1]:g} Hz) [%]")
    if title:
        ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend()
    return ax
