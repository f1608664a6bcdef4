"""Figures, all importable from here; each is defined in the layer of the results it draws, so
that a result's ``plot()`` draws without importing this edge layer: spectra in
:mod:`crowdvib.signals.plots`, the forward models' figures in
:mod:`crowdvib.response.frequency_domain.plots` and :mod:`crowdvib.response.time_domain.plots`,
the identification's in :mod:`crowdvib.identification.plots`, the studies' in
:mod:`crowdvib.studies.plots`, what they share in
:mod:`crowdvib._figures`.

Every function takes result objects and an optional ``ax``, labels axes with units, returns the
Axes and never calls ``plt.show()``; matplotlib is imported only when a plot is asked for.
"""

from .._figures import FigureAxes, figure_bytes, save_figure
from ..identification.plots import plot_psd_residuals
from ..studies.plots import (plot_estimation_errors, plot_objective_map, plot_parametric_ratios,
                             plot_season_trends)
from ..response.frequency_domain.plots import plot_frf, plot_hsi_effect, plot_load_psd
from ..response.time_domain.plots import plot_time_history
from ..signals.plots import plot_psd_comparison, plot_psd_convergence

__all__ = ["FigureAxes", "plot_psd_comparison", "plot_psd_residuals", "plot_psd_convergence",
           "plot_load_psd", "plot_hsi_effect", "plot_frf", "plot_objective_map",
           "plot_estimation_errors", "plot_parametric_ratios", "plot_season_trends",
           "plot_time_history", "save_figure", "figure_bytes"]
