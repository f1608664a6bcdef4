"""Figures of the identification: a fit's residuals against the measured PSD, drawn by the
result's ``plot()``.

Every function takes result objects and an optional ``ax`` or ``axes``, returns them and never
calls ``plt.show()``; matplotlib is imported only when a plot is asked for
(:mod:`crowdvib._figures`). All figures are importable from :mod:`crowdvib.reporting.plotting`.
"""

from typing import TYPE_CHECKING

from .._figures import axes_or_new, in_band
from ..signals.welch import welch_degrees_of_freedom

if TYPE_CHECKING:
    from ..signals.spectrum import ResponsePSD

__all__ = ["plot_psd_residuals"]


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

    ax = axes_or_new(ax)
    name = output or measured.output_names[0]
    data, model = measured.select(name), fitted.select(name)
    keep = in_band(data.frequency, band) & (model.psd[0] > 0)
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
