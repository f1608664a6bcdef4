"""Figures of the time-domain simulator: simulated time histories (``Simulation.plot``).

Every function takes result objects and an optional ``ax``, labels axes with units, returns the
Axes and never calls ``plt.show()``; matplotlib is imported only when a plot is asked for
(:mod:`crowdvib._figures`). All figures are importable from :mod:`crowdvib.reporting.plotting`.
"""

import numpy as np

from ..._figures import DARK, LIGHT, panels
from ...errors import ParameterError
from ...signals.weighting import running_rms, weight_wb

__all__ = ["plot_time_history"]


def _running_rms(signal, sample_rate, window, weighting=None):
    """Trailing running RMS over ``window`` seconds (optionally of the W_b-weighted signal);
    NaN until the first window is full."""
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
    handles = panels(axes, 2, 1, (9.0, 5.0), sharex=True, height_ratios=(2, 1))
    top, bottom = handles.axes
    names = tuple(simulation.output_names)
    name = output or names[0]
    if name not in names:
        raise ParameterError(f"output must be one of {list(names)}, got {name!r}")
    signal = np.asarray(simulation.acceleration)[names.index(name)]
    time = np.asarray(simulation.time)
    if weighting not in (None, "Wb"):
        raise ParameterError(f"weighting must be None or 'Wb', got {weighting!r}")
    rms = _running_rms(signal, simulation.sample_rate, window, weighting)
    top.plot(time, signal, color=LIGHT, lw=0.4, label="acceleration")
    peak = np.nanmax(rms) if np.isfinite(rms).any() else np.nan
    label = f"{window:g} s running RMS{' (W_b)' if weighting else ''} (max {peak:.3g} m/s²)"
    top.plot(time, rms, color=DARK, lw=1.4, label=label)
    top.set_ylabel("Acceleration [m/s²]")
    top.grid(True, alpha=0.3)
    top.legend(loc="upper right", fontsize="small")
    bottom.step(time, simulation.n_on_deck, where="post", color=DARK, lw=1.0)
    bottom.set_ylabel("People on deck [-]")
    bottom.set_xlabel("Time [s]")
    bottom.set_ylim(bottom=0)
    bottom.grid(True, alpha=0.3)
    top.set_xlim(time[0], time[-1])
    handles.figure.suptitle(title or f"Simulated response at {name}")
    return handles
