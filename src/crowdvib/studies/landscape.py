"""The objective landscape J(f_h1, ξ_h1) on a grid (paper Figs. 4 and 10): the misfit the estimator
minimises, by default its default (the Whittle deviance), the paper's Eq. (6) on request."""

import os
import time
from dataclasses import dataclass

import numpy as np

from .._validation import as_float_array, check_positive, fields_from_dict
from ..errors import ParameterError
from ..identification.estimator import check_estimator
from ..models.pedestrian import MSDModel
from .plots import plot_objective_map

__all__ = ["ObjectiveMap", "objective_map"]


@dataclass(frozen=True, eq=False)
class ObjectiveMap:
    """J(f_h1, ξ_h1) on a grid (paper Figures 4 and 10).

    Attributes
    ----------
    frequencies : ndarray, shape (n_f,)
        Grid of f_h1 [Hz].
    damping_ratios : ndarray, shape (n_ξ,)
        Grid of ξ_h1 [-].
    cost : ndarray, shape (n_ξ, n_f)
        The objective of the map's method [-]: the Whittle deviance, or J of paper Eq. (6).
    cost_no_hsi : float
        The objective without HSI [-].
    mass_ratio : float
        μ_h1 held fixed [-].
    estimate : MSDModel or None
        The optimiser's solution, when one was given, to mark on the map.
    """

    frequencies: np.ndarray
    damping_ratios: np.ndarray
    cost: np.ndarray
    cost_no_hsi: float
    mass_ratio: float
    estimate: object = None

    @property
    def optimum(self):
        """Grid point of least cost as an :class:`MSDModel`."""
        row, col = np.unravel_index(np.argmin(self.cost), self.cost.shape)
        return MSDModel(float(self.frequencies[col]), float(self.damping_ratios[row]),
                        self.mass_ratio)

    def curvature_ratio(self):
        """How much steeper J is along f_h1 than along ξ_h1 around the grid optimum [-].

        Second differences of J over the relative parameter change, ∂²J/∂(ln f)² divided by
        ∂²J/∂(ln ξ)², at the grid minimum (interior grid points only).
        """
        for name, grid in (("frequencies", self.frequencies),
                           ("damping_ratios", self.damping_ratios)):
            if grid.size < 3:      # a second difference takes 3 points
                raise ParameterError(f"curvature_ratio needs at least 3 grid points along "
                                     f"{name}, the map has {grid.size}")
        row, col = np.unravel_index(np.argmin(self.cost), self.cost.shape)
        row = int(np.clip(row, 1, self.damping_ratios.size - 2))
        col = int(np.clip(col, 1, self.frequencies.size - 2))

        def second(values, grid, i):
            x = np.log(grid[i - 1:i + 2])
            return np.polyfit(x, values[i - 1:i + 2], 2)[0] * 2

        along_f = second(self.cost[row], self.frequencies, col)
        along_xi = second(self.cost[:, col], self.damping_ratios, row)
        return along_f / along_xi

    def plot(self, *, uncertainty=None, search_bounds=None, ax=None, title=None):
        """Draw the map with its optimum (see :func:`crowdvib.reporting.plotting.plot_objective_map`).

        Parameters
        ----------
        uncertainty : SensitivityResult or dict, optional
            A modelling-error study: its nominal ± bound drawn around the optimum.
        search_bounds : dict, optional
            The estimator's bounds, parameter → (lower, upper), drawn as a box.
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (default a new figure).
        title : str, optional
            The axes' title.
        """

        return plot_objective_map(self, uncertainty=uncertainty, search_bounds=search_bounds,
                                  ax=ax, title=title)

    @classmethod
    def from_dict(cls, data):
        """The map of :meth:`to_dict` (``grid_optimum`` is derived, not read).

        Parameters
        ----------
        data : dict
            What :meth:`to_dict` wrote (as read back from JSON).

        Raises
        ------
        DataError
            ``data`` is not a dict or lacks a field.
        """
        found = data.get("estimate") if isinstance(data, dict) else None
        return fields_from_dict(cls, data,
                                estimate=None if found is None else MSDModel.from_dict(found))

    def to_dict(self):
        """JSON-ready dict."""
        optimum = self.optimum
        return {"frequencies": self.frequencies.tolist(),
                "damping_ratios": self.damping_ratios.tolist(), "cost": self.cost.tolist(),
                "cost_no_hsi": self.cost_no_hsi, "mass_ratio": self.mass_ratio,
                "grid_optimum": optimum.to_dict(),
                "estimate": None if self.estimate is None else self.estimate.to_dict()}


def objective_map(measured, structure, crowd, *, frequencies, damping_ratios, estimator,
                  estimate=None, progress=None, max_seconds=None):
    """The objective on a (f_h1, ξ_h1) grid → :class:`ObjectiveMap` (paper Figures 4 and 10).

    The misfit of the estimator's ``method``: by default the one :func:`crowdvib.estimate_hsi`
    minimises by default (the Whittle deviance with the fluctuating crowd), or the paper's J
    of Eq. (6) with ``Estimator(method="least_squares")`` (paper Figures 4 and 10). The crowd
    is held as given: for
    the surface on which an estimate with fitted step frequencies is the minimum, pass the
    crowd it ends with (``HSIEstimate.crowd``), as ``crowdvib map`` does.

    The forward model's θ-independent parts are built once (:class:`~crowdvib.response.frequency_domain.spectral.SpectralModel`),
    so each grid point costs one PSD evaluation vectorised over frequency.

    Parameters
    ----------
    measured, structure, crowd
        As in :func:`crowdvib.estimate_hsi` (a crowd's density a number or a profile).
    estimator : Estimator
        The estimator whose misfit is mapped (:class:`~crowdvib.identification.Estimator`, its
        ``band`` given): its band, outputs, weights, force model, ``match_welch``, method and
        crowd model; μ_h1 is held at its ``mass_ratio``.
    frequencies : array_like
        Grid of f_h1 [Hz], > 0 (the paper: 1–6 Hz).
    damping_ratios : array_like
        Grid of ξ_h1 [-], fractions (the paper: 0.1–0.8).
    estimate : MSDModel or HSIEstimate, optional
        An optimiser's solution to carry along and mark on plots.
    progress : callable, optional
        Called as ``progress(done, total)`` [grid points] after each row of the grid.
    max_seconds : float, optional
        Refuse (:class:`ParameterError`) a grid whose time, estimated from its first point, is
        longer. A grid whose costs would not fit in half the free memory is refused always.

    See Also
    --------
    crowdvib.estimate_hsi : the optimum of the same objective.
    crowdvib.reporting.plotting.plot_objective_map

    References
    ----------
    K. Van Nimmen and P. Van den Broeck, "Using full-scale observations on footbridges to estimate
    the parameters governing human–structure interaction", *Journal of Bridge Engineering* 28(1),
    2023. The objective (Eq. 6) and its landscapes (Figures 4 and 10).

    The theory pages cite them (docs: theory, References).
    """
    frequencies = check_positive("frequencies", as_float_array("frequencies", frequencies, ndim=1),
                                 unit="Hz")
    damping_ratios = as_float_array("damping_ratios", damping_ratios, ndim=1)
    for name, grid in (("frequencies", frequencies), ("damping_ratios", damping_ratios)):
        if grid.size < 1:
            raise ParameterError(f"{name} must hold at least 1 grid point, got {grid.size}")
    for value in damping_ratios:
        MSDModel(damping_ratio=value)          # validates each ξ with the model's own rule
    shape = (damping_ratios.size, frequencies.size)
    _check_memory(shape)
    objective = check_estimator(estimator).objective(measured, structure, crowd)
    mass_ratio = estimator.mass_ratio
    cost = np.empty(shape)
    started = time.perf_counter()
    cost[0, 0] = objective.cost(MSDModel(frequencies[0], damping_ratios[0], mass_ratio))
    _check_time(shape, time.perf_counter() - started, max_seconds)
    for row, xi in enumerate(damping_ratios):
        cost[row, int(row == 0):] = [objective.cost(MSDModel(f, xi, mass_ratio))
                                     for f in frequencies[int(row == 0):]]
        if progress is not None:
            progress((row + 1) * frequencies.size, cost.size)
    if estimate is not None and not isinstance(estimate, MSDModel):
        if not isinstance(getattr(estimate, "msd", None), MSDModel):
            raise ParameterError(f"estimate must be an MSDModel, an HSIEstimate or None, got "
                                 f"{type(estimate).__name__}")
        estimate = estimate.msd
    return ObjectiveMap(frequencies=frequencies, damping_ratios=damping_ratios, cost=cost,
                        cost_no_hsi=objective.cost(None), mass_ratio=mass_ratio,
                        estimate=estimate)


def _grid_text(shape):
    return (f"frequencies × damping_ratios = {shape[1]} × {shape[0]} = {shape[0] * shape[1]} "
            "grid points")


def _check_memory(shape):
    """Refuse a grid whose cost array would take more than half the free memory (Linux)."""
    try:
        free = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):      # not known on this system
        return
    need = 8.0 * shape[0] * shape[1]
    if need > free / 2:
        raise ParameterError(f"{_grid_text(shape)} need {need / 2**30:.3g} GiB for their costs "
                             f"alone, more than half the {free / 2**30:.3g} GiB free: use fewer "
                             "points")


def _check_time(shape, per_point, max_seconds):
    """Refuse a grid that would take longer than ``max_seconds`` at the first point's pace."""
    total = per_point * shape[0] * shape[1]
    if max_seconds is not None and total > max_seconds:
        hours, minutes = divmod(total / 60.0, 60.0)
        raise ParameterError(
            f"{_grid_text(shape)} would take about {int(hours)} h {minutes:.0f} min "
            f"({1e3 * per_point:.2g} ms per point, timed on the first), more than the limit of "
            f"{max_seconds / 60:g} min: use fewer points (or a longer limit)")
