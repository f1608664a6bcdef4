"""The bounded multistart search shared by the MSD's and the step frequencies' fits: bounds
merged with their defaults, starting points inside them, trust-region least squares from each.

docs: theory, Inverse problem.
"""

from __future__ import annotations

import logging

import numpy as np
from scipy.optimize import least_squares

from .._validation import as_float_array, check_mapping
from ..errors import EstimationError, ParameterError
from ..models.pedestrian import MSD_DAMPING_LIMIT

#: The estimator's logger: its starts are logged under the estimate's name, as before the split.
logger = logging.getLogger("crowdvib.identification.estimation")

#: Starting points (f_h1 [Hz], ξ_h1 [-]) spread over the feasible region
#: (docs: theory, Inverse problem).
DEFAULT_STARTS = ((1.5, 0.6), (5.0, 0.15), (2.2, 0.2), (4.0, 0.7))


def _merge_bounds(bounds, defaults):
    """The default bounds updated by the user's, each checked: 0 < lower < upper."""
    limits = dict(defaults)
    check_mapping("bounds", bounds, "a dict of parameter → (lower, upper)")
    for key, value in (bounds or {}).items():
        if key not in defaults:
            raise ParameterError(f"bounds keys must be among {list(defaults)}, got {key!r}")
        try:
            low, high = (float(v) for v in value)
        except (TypeError, ValueError):
            raise ParameterError(f"bounds[{key!r}] must be a pair (lower, upper), got {value!r}")
        if not 0 < low < high:
            raise ParameterError(f"bounds[{key!r}] must satisfy 0 < lower < upper, got {value!r}")
        if key == "damping_ratio" and high >= MSD_DAMPING_LIMIT:
            raise ParameterError(
                f"bounds['damping_ratio'] must stay below {MSD_DAMPING_LIMIT:g}, the MSD's own "
                f"limit (fractions, not percent), got {value!r}")
        limits[key] = (low, high)
    return limits


#: scipy's own tolerances (ftol = xtol): every fit whose end is the answer.
FINAL_TOLERANCE = 1e-8


def _multistart(residuals, points, lower, upper, *, records=1, tolerance=FINAL_TOLERANCE,
                max_nfev=None):
    """Bounded trust-region least squares from every start → (best result, runs).

    ``runs`` holds (result, start, forward-model evaluations) per start: the calls of
    ``residuals`` times the ``records`` each call evaluates. ``tolerance``: scipy's ftol and
    xtol (its default, 1e-8, unless a fit that refines this one follows); ``max_nfev``: scipy's
    (None: its default, 100 per parameter).
    """
    runs = []
    for start in points:
        calls = [0]

        def counted(theta):
            calls[0] += 1
            return residuals(theta)

        try:
            result = least_squares(counted, start, method="trf", bounds=(lower, upper),
                                   x_scale="jac", ftol=tolerance, xtol=tolerance,
                                   max_nfev=max_nfev)
        except ValueError as exc:  # non-finite residuals
            raise EstimationError(f"objective could not be evaluated from start {start}: {exc}")
        runs.append((result, start, calls[0] * records))
        logger.info("start %s -> %s, J = %.4g", start, result.x, 2 * result.cost)
    best, _, _ = min(runs, key=lambda run: run[0].cost)
    return best, runs


def _starting_points(starts, names, tail, lower, upper):
    """Starting points as arrays strictly inside the bounds (trf needs interior points).

    A start shorter than ``names`` is completed from ``tail`` (name → value: the held μ_h1,
    the crowd's step frequencies), so that (f_h1, ξ_h1) starts serve every parametrisation.
    """
    if starts is None:
        starts = DEFAULT_STARTS
    points = []
    for start in starts:
        start = as_float_array("starts", start, ndim=1)
        if start.size == 3 and tail is not None and "mass_ratio" not in names:
            raise ParameterError(f"starts must hold (f_h1, ξ_h1) with μ_h1 held fixed, got "
                                 f"{start.tolist()}")
        if 2 <= start.size < len(names) and tail is not None:
            start = np.append(start, [tail[name] for name in names[start.size:]])
        if start.size != len(names):
            raise ParameterError(
                f"starts must hold {len(names)} values {names}, got {start.tolist()}")
        margin = 1e-3 * (upper - lower)
        points.append(np.clip(start, lower + margin, upper - margin))
    if not points:
        raise ParameterError("starts must hold at least one starting point")
    return points
