"""Figures, all importable from here: spectra, FRFs and time histories in this module, the
studies' figures in :mod:`.study_plots`, what they share in :mod:`.figure_base`.

Every function takes result objects and an optional ``ax``, labels axes with units, returns the
Axes and never calls ``plt.show()``; matplotlib is imported only when a plot is asked for.
"""

from typing import TYPE_CHECKING

import numpy as np

from .figure_base import (_DARK, _LIGHT, FigureAxes, _axes, _in_band, _panels, _positive,
                          figure_bytes, save_figure)
from .study_plots import plot_estimation_errors, plot_objective_map, plot_parametric_ratios

if TYPE_CHECKING:
    from ..signals import ResponsePSD

__all__ = ["FigureAxes", "plot_psd_comparison", "plot_psd_residuals", "plot_psd_convergence", "plot_load_psd",
           "plot_hsi_effect", "plot_frf", "plot_objective_map", "plot_estimation_errors",
           "plot_parametric_ratios", "plot_time_history", "save_figure", "figure_bytes"]


def plot_psd_comparison(curves, *, output=None, band=None, analysis_band=None, logscale=True,
                        ax=None, title=None):
    """Acceleration PSDs of one output on one axes (paper Figs. 3, 12, 17, 20).

    Parameters
    ----------
    curves : dict of str to ResponsePSD
        Legend label → PSD; drawn in order (first: the measurement, as a black line).
    output : str, optional
        Output name (default the first output of the first curve).
    band : (float, float), optional
        Frequency range [Hz] to show.
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
    ax = _axes(ax)
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
        keep = _in_band(row.frequency, band)
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


def plot_psd_residuals(measured: "ResponsePSD", fitted: "ResponsePSD", *,
                       output: str | None = None, band: tuple | None = None, ax=None,
                       title: str | None = None):
    """Relative residuals Ĝ/G − 1 of a fit, with the 95 % band of the Welch scatter.

    For a Welch estimate of ν equivalent degrees of freedom, Ĝ/G ~ χ²_ν/ν: residuals that stay
    within its 2.5–97.5 % quantiles are what the record's length explains
    (docs: theory, Statistical uncertainty of an estimate).

    Parameters
    ----------
    measured, fitted : ResponsePSD
        The measured (Welch) PSD and the fitted model on the same grid.
    output : str, optional
    band : (float, float), optional
    ax : matplotlib.axes.Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    from scipy import stats

    from ..signals.welch import welch_degrees_of_freedom

    ax = _axes(ax)
    name = output or measured.output_names[0]
    data, model = measured.select(name), fitted.select(name)
    keep = _in_band(data.frequency, band) & (model.psd[0] > 0)
    ax.plot(data.frequency[keep], data.psd[0][keep] / model.psd[0][keep] - 1, color="black",
            lw=0.9, label="measured / fitted − 1")
    if measured.n_windows:
        nu = welch_degrees_of_freedom(measured.n_windows)
        low, high = stats.chi2.ppf([0.025, 0.975], nu) / nu - 1
        ax.axhspan(low, high, color="tab:green", alpha=0.15,
                   label=f"95 % Welch scatter (ν = {nu:.0f})")
    ax.axhline(0.0, color="0.4", lw=0.8)
    ax.set_xlabel("Frequency [Hz]")
    ax.set_ylabel("Relative residual [-]")
    if title:
        ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend()
    return ax


def plot_load_psd(frequency, crowd, *, structure=None, force=None, ax=None, title=None):
    """PSD of the crowd's vertical walking load (paper Fig. 2).

    Parameters
    ----------
    frequency : array_like
        Frequencies [Hz], >= 0.
    crowd : Crowd
        Density, step-frequency distribution and body mass.
    structure : ModalModel, optional
        With a structure, the modal load PSD G_F,jj(f) = Ψ_jj s(f) of each mode [N²/Hz] (the
        paper's G_F); without, the crowd-load spectrum per unit influence s(f) [N²/Hz].
    force : ZivanovicForce or YoungForce, optional
        Walking force model (default Živanović 2007).
    ax : matplotlib.axes.Axes, optional
    title : str, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    from ..models.loading import as_force_model

    force = as_force_model(force)
    frequency = np.asarray(frequency, dtype=float)
    ax = _axes(ax)
    if structure is None:
        curves = {"s(f), per unit influence": force.load_spectrum(frequency, crowd)}
        ylabel = "Load PSD s [N²/Hz]"
    else:
        modal = force.modal_load_psd(frequency, crowd, structure)
        curves = {f"mode {j + 1} ({structure.frequencies[j]:g} Hz)": modal[:, j, j]
                  for j in range(structure.n_modes)}
        ylabel = "Modal load PSD $G_F$ [N²/Hz]"
    for (label, values), color in zip(curves.items(), [_DARK, _LIGHT, "0.35", "0.8"] * 8):
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
    """Response PSD without and with HSI, and an enlargement of the dominant peak (paper Fig. 3).

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
    handles = _panels(axes, 1, 2, (10.0, 4.0), width_ratios=(3, 2))
    full, detail = handles.axes
    name = output or without.output_names[0]
    curves = [("without HSI", without.select(name), dict(color=_DARK, lw=1.2)),
              ("with HSI", with_hsi.select(name), dict(color=_LIGHT, lw=1.8))]
    for label, row, style in curves:
        peak = row.peak_frequency()[0]
        keep = _in_band(row.frequency, band)
        full.plot(row.frequency[keep], _positive(row.psd[0][keep]),
                  label=f"{label} (peak {peak:.2f} Hz)", **style)
    top = max(float(np.nanmax(row.psd[0])) for _, row, _ in curves)
    full.set_yscale("log")
    full.set_ylim(top * 1e-8, top * 3)  # eight decades: below is numerical dust
    lower, upper = zoom or _peak_zoom([row.psd[0] for _, row, _ in curves], curves[0][1].frequency)
    full.axvspan(lower, upper, color="tab:blue", alpha=0.08, lw=0)
    for label, row, style in curves:
        keep = _in_band(row.frequency, (lower, upper))
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
    """Accelerance FRF magnitude of the empty and the occupied structure (paper Figs. 9, 18).

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
    ax = _axes(ax)
    name = output or empty.output_names[0]
    source = name if input is None else input
    curves = [("empty", empty, dict(color=_DARK, lw=1.2, ls="--"))]
    if occupied is not None:
        curves.append(("with HSI" if occupied.occupied else "second FRF", occupied,
                       dict(color=_DARK, lw=1.6)))
    for label, result, style in curves:
        keep = _in_band(result.frequency, band)
        magnitude = result.magnitude(name, source)[keep]
        peak = result.frequency[keep][np.argmax(magnitude)]
        ax.plot(result.frequency[keep], _positive(magnitude),
                label=f"{label} (peak {peak:.2f} Hz)", **style)
    ax.set_yscale("log")
    ax.set_xlabel("Frequency [Hz]")
    ax.set_ylabel(f"|H| [{empty.unit}]")
    ax.set_title(title or f"FRF, output {name}, input {source}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return ax


def _running_rms(signal, sample_rate, window, weighting=None):
    """Trailing running RMS over ``window`` seconds (optionally of the W_b-weighted signal);
    NaN until the first window is full."""
    from ..signals.weighting import running_rms, weight_wb

    signal = np.asarray(signal, dtype=float)
    if weighting == "Wb":
        signal = weight_wb(signal, sample_rate)
    n = max(int(round(window * sample_rate)), 1)
    result = np.full(signal.size, np.nan)
    if result.size >= n:
        result[n - 1:] = running_rms(signal, sample_rate, n / sample_rate)
    return result


def plot_time_history(simulation, *, output=None, window=1.0, axes=None, title=None,
                      weighting=None):
    """Simulated acceleration, its running RMS and the number of people on the deck.

    Parameters
    ----------
    simulation : Simulation
        Anything with ``time`` [s], ``acceleration`` (n_outputs, n_samples) [m/s²],
        ``output_names``, ``n_on_deck`` (n_samples,) and ``sample_rate`` [Hz].
    output : str, optional
        Output name (default the first).
    window : float
        Running-RMS window [s] (default 1 s).
    axes : sequence of two matplotlib.axes.Axes, optional
    title : str, optional
    weighting : {None, "Wb"}
        Running RMS of the W_b-weighted acceleration (BS 6841 / ISO 10137,
        :mod:`crowdvib.signals.weighting`) instead of the unweighted one.

    Returns
    -------
    FigureAxes
        ``axes`` = (acceleration with running RMS, people on the deck).
    """
    handles = _panels(axes, 2, 1, (9.0, 5.0), sharex=True, height_ratios=(2, 1))
    top, bottom = handles.axes
    names = tuple(simulation.output_names)
    name = output or names[0]
    if name not in names:
        from ..errors import ParameterError

        raise ParameterError(f"output must be one of {list(names)}, got {name!r}")
    signal = np.asarray(simulation.acceleration)[names.index(name)]
    time = np.asarray(simulation.time)
    if weighting not in (None, "Wb"):
        from ..errors import ParameterError

        raise ParameterError(f"weighting must be None or 'Wb', got {weighting!r}")
    rms = _running_rms(signal, simulation.sample_rate, window, weighting)
    top.plot(time, signal, color=_LIGHT, lw=0.4, label="acceleration")
    peak = np.nanmax(rms) if np.isfinite(rms).any() else np.nan
    label = f"{window:g} s running RMS{' (W_b)' if weighting else ''} (max {peak:.3g} m/s²)"
    top.plot(time, rms, color=_DARK, lw=1.4, label=label)
    top.set_ylabel("Acceleration [m/s²]")
    top.grid(True, alpha=0.3)
    top.legend(loc="upper right", fontsize="small")
    bottom.step(time, simulation.n_on_deck, where="post", color=_DARK, lw=1.0)
    bottom.set_ylabel("People on deck [-]")
    bottom.set_xlabel("Time [s]")
    bottom.set_ylim(bottom=0)
    bottom.grid(True, alpha=0.3)
    top.set_xlim(time[0], time[-1])
    handles.figure.suptitle(title or f"Simulated response at {name}")
    return handles


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
    ax.set_ylim(bottom=0)  # the error is a distance to the converged PSD: 0 is the goal
    ax.set_xlabel("Record length k·T [s]")
    ax.set_ylabel(f"ΔG ({convergence.norm}-norm, {convergence.band[0]:g}–"
                  f"{convergence.band[1]:g} Hz) [%]")
    if title:
        ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend()
    return ax
