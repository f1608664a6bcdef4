"""Figures of the frequency-domain models: the walking load, the effect of HSI on a response
PSD and FRFs (``FRF.plot``).

Every function takes result objects and an optional ``ax``, labels axes with units, returns the
Axes and never calls ``plt.show()``; matplotlib is imported only when a plot is asked for
(:mod:`crowdvib._figures`). All figures are importable from :mod:`crowdvib.reporting.plotting`.
"""

import numpy as np

from ..._figures import DARK, LIGHT, axes_or_new, in_band, panels, positive_or_nan
from ...models.loading import as_force_model, modal_load_psd

__all__ = ["plot_load_psd", "plot_hsi_effect", "plot_frf"]


def plot_load_psd(frequency, crowd, *, structure=None, force=None, ax=None, title=None):
    """PSD of the crowd's vertical walking load (paper Figure 2).

    Parameters
    ----------
    frequency : array_like
        Frequencies [Hz], >= 0.
    crowd : Crowd
        Density, step-frequency distribution and body mass.
    structure : ModalModel, optional
        With a structure, the modal load PSD G_F,jj(f) = Ψ_jj s(f) of each mode [N²/Hz] (the
        paper's G_F); without, the crowd-load spectrum per unit influence s(f) [N²/Hz].
    force : ZivanovicForce, YoungForce or any models.loading.ForceModel, optional
        Walking force model (default Živanović 2007).
    ax : matplotlib.axes.Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    force = as_force_model(force)
    frequency = np.asarray(frequency, dtype=float)
    ax = axes_or_new(ax)
    if structure is None:
        curves = {"s(f), per unit influence": force.load_spectrum(frequency, crowd)}
        ylabel = "Load PSD s [N²/Hz]"
    else:
        modal = modal_load_psd(force, frequency, crowd, structure)
        curves = {f"mode {j + 1} ({structure.frequencies[j]:g} Hz)": modal[:, j, j]
                  for j in range(structure.n_modes)}
        ylabel = "Modal load PSD $G_F$ [N²/Hz]"
    for (label, values), color in zip(curves.items(), [DARK, LIGHT, "0.35", "0.8"] * 8):
        ax.plot(frequency, values, color=color, lw=1.4, label=label)
    ax.set_xlabel("Frequency [Hz]")
    ax.set_ylabel(ylabel)
    ax.set_xlim(frequency.min(), frequency.max())
    ax.set_ylim(bottom=0)
    ax.set_title(title or f"Walking load, {crowd.density:g} persons/m², $f_s$ ~ "
                 f"N({crowd.step_frequency_mean:g}, {crowd.step_frequency_std:g}) Hz")
    ax.grid(True, alpha=0.3)
    ax.legend()
    return ax


def _peak_zoom(rows, frequency):
    """A frequency window [Hz] around the PSD peaks of ``rows``, wide enough to show both."""
    peaks = [frequency[int(np.nanargmax(row))] for row in rows]
    centre, spread = 0.5 * (min(peaks) + max(peaks)), max(peaks) - min(peaks)
    half = max(0.15 * centre, 1.5 * spread, 2.0 * (frequency[1] - frequency[0]))
    return max(frequency[0], centre - half), min(frequency[-1], centre + half)


def plot_hsi_effect(without, with_hsi, *, output=None, band=None, zoom=None, axes=None,
                    title=None):
    """Response PSD without and with HSI, and an enlargement of the dominant peak (paper Figure 3).

    Parameters
    ----------
    without, with_hsi : ResponsePSD
        Predicted PSDs with the crowd as moving forces only, and with the MSD model.
    output : str, optional
        Output name (default the first output of ``without``).
    band : (float, float), optional
        Frequency range [Hz] of the left panel (default all).
    zoom : (float, float), optional
        Frequency range [Hz] of the enlargement (default around the peaks).
    axes : sequence of two matplotlib.axes.Axes, optional
    title : str, optional

    Returns
    -------
    FigureAxes
        ``axes`` = (full band, log scale; enlargement, linear scale).
    """
    handles = panels(axes, 1, 2, (10.0, 4.0), width_ratios=(3, 2))
    full, detail = handles.axes
    name = output or without.output_names[0]
    curves = [("without HSI", without.select(name), dict(color=DARK, lw=1.2)),
              ("with HSI", with_hsi.select(name), dict(color=LIGHT, lw=1.8))]
    for label, row, style in curves:
        peak = row.peak_frequency()[0]
        keep = in_band(row.frequency, band)
        full.plot(row.frequency[keep], positive_or_nan(row.psd[0][keep]),
                  label=f"{label} (peak {peak:.2f} Hz)", **style)
    top = max(float(np.nanmax(row.psd[0])) for _, row, _ in curves)
    full.set_yscale("log")
    full.set_ylim(top * 1e-8, top * 3)  # eight decades: below is numerical dust
    lower, upper = zoom or _peak_zoom([row.psd[0] for _, row, _ in curves], curves[0][1].frequency)
    full.axvspan(lower, upper, color="tab:blue", alpha=0.08, lw=0)
    for label, row, style in curves:
        keep = in_band(row.frequency, (lower, upper))
        detail.plot(row.frequency[keep], row.psd[0][keep], label=label, **style)
    detail.set_xlim(lower, upper)
    detail.set_ylim(bottom=0)
    unit = curves[0][1].unit
    for ax, sub in ((full, "(a)"), (detail, "(b) enlargement")):
        ax.set_xlabel("Frequency [Hz]")
        ax.set_ylabel(f"Acceleration PSD [{unit}]")
        ax.set_title(sub, loc="left", fontsize="medium")
        ax.grid(True, which="both", alpha=0.3)
    full.legend()
    handles.figure.suptitle(title or f"Response at {name} without and with HSI")
    return handles


def plot_frf(empty, occupied=None, *, output=None, input=None, band=None, ax=None, title=None):
    """Accelerance FRF magnitude of the empty and the occupied structure (paper Figures 9 and 18).

    Parameters
    ----------
    empty : FRF
        From ``crowdvib.frf(structure, f)``.
    occupied : FRF, optional
        From ``crowdvib.frf(structure, f, crowd=crowd, msd=msd)``.
    output : str, optional
        Output point (default the first output of ``empty``).
    input : str, optional
        Input point (default the output: a driving-point FRF).
    band : (float, float), optional
        Frequency range [Hz] to show.
    ax : matplotlib.axes.Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = axes_or_new(ax)
    name = output or empty.output_names[0]
    source = name if input is None else input
    curves = [("empty", empty, dict(color=DARK, lw=1.2, ls="--"))]
    if occupied is not None:
        curves.append(("with HSI" if occupied.occupied else "second FRF", occupied,
                       dict(color=DARK, lw=1.6)))
    for label, result, style in curves:
        keep = in_band(result.frequency, band)
        magnitude = result.magnitude(name, source)[keep]
        peak = result.frequency[keep][np.argmax(magnitude)]
        ax.plot(result.frequency[keep], positive_or_nan(magnitude),
                label=f"{label} (peak {peak:.2f} Hz)", **style)
    ax.set_yscale("log")
    ax.set_xlabel("Frequency [Hz]")
    ax.set_ylabel(f"|H| [{empty.unit}]")
    ax.set_title(title or f"FRF, output {name}, input {source}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return ax
