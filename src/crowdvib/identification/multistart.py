"""The bounded multistart search shared by the MSD's and the step frequencies' fits: bounds
merged with their defaults, starting points inside them, trust-region least squares from each.

docs: theory, Inverse problem.
"""

from __future__ import annotations

import logging

import numpy as np
from scipy.optimize import OptimizeResult

from .._validation import as_float_array, check_mapping
from ..errors import EstimationError, ParameterError
from ..models.pedestrian import MSD_DAMPING_LIMIT
from .trust_region import trust_region_fit

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
#: A start of a fit that only prepares another (``join``) stops where it has reached the basin of
#: an optimum an earlier start found: within this fraction of every parameter's search range of
#: it, with its cost as that optimum's Gauss–Newton model predicts it, within this fraction of
#: the predicted rise (the objective is quadratic about the optimum there, so the trust-region
#: steps from here lead to it). On the paper example's records the default starts reach it a
#: step or two before their own convergence (issue 39).
JOIN_BOX, JOIN_AGREEMENT = 0.01, 0.25
#: The status of a start stopped so (scipy's own are −2 … 4).
JOINED = 5


class _Joined(Exception):
    """Raised from the residuals when an evaluation lies in an earlier optimum's basin."""

    def __init__(self, result):
        super().__init__(result.message)
        self.result = result


def _multistart(residuals, points, lower, upper, *, records=1, tolerance=FINAL_TOLERANCE,
                max_nfev=None, join=False):
    """Bounded trust-region least squares from every start → (best result, runs).

    ``runs`` holds (result, start, forward-model evaluations) per start: the calls of
    ``residuals`` times the ``records`` each call evaluates. ``tolerance``: scipy's ftol and
    xtol (its default, 1e-8, unless a fit that refines this one follows); ``max_nfev``: scipy's
    (None: its default, 100 per parameter). ``join``: a start stops once it is in the basin of
    an earlier start's optimum (:data:`JOIN_BOX`; its result then has status :data:`JOINED`
    and is not a candidate for the best): for a fit whose end only starts another, which
    would find the same optimum again to its own tolerance.
    """
    runs, optima = [], []
    for number, start in enumerate(points, 1):
        calls = [0]

        def counted(theta):
            calls[0] += 1
            r = residuals(theta)
            for earlier, optimum in optima:
                if _in_basin(theta, r, optimum, upper - lower):
                    raise _Joined(OptimizeResult(
                        x=np.array(theta, dtype=float), cost=0.5 * float(r @ r), fun=r,
                        status=JOINED, message=f"in the basin of start {earlier}'s optimum"))
            return r

        try:
            # A joining fit keeps trf's Jacobian at its optimum: the later starts' basin test
            # uses it.
            result = trust_region_fit(counted, start, (lower, upper), ftol=tolerance,
                                      xtol=tolerance, max_nfev=max_nfev, final_jacobian=join)
        except _Joined as joined:
            result = joined.result
        except ValueError as exc:  # non-finite residuals
            raise EstimationError(f"objective could not be evaluated from start {start}: {exc}")
        runs.append((result, start, calls[0] * records))
        # Only an optimum inside the box has the quadratic basin the test relies on: on a
        # bound the cost still falls outwards, and the Gauss–Newton model misses that slope.
        if join and result.status != JOINED and not np.any(result.active_mask):
            optima.append((number, result))
        logger.info("start %s -> %s, J = %.4g", start, result.x, 2 * result.cost)
    best, _, _ = min((run for run in runs if run[0].status != JOINED),
                     key=lambda run: run[0].cost)
    return best, runs


def _in_basin(theta, r, optimum, span):
    """Whether θ with residuals r lies in the basin of ``optimum`` (a scipy result): within
    :data:`JOIN_BOX` of it and its cost rise as the Gauss–Newton model ½ dᵀJᵀJd predicts."""
    step = np.asarray(theta, dtype=float) - optimum.x
    if np.any(np.abs(step) > JOIN_BOX * span) or not np.all(np.isfinite(r)):
        return False
    predicted = 0.5 * float(np.sum((optimum.jac @ step) ** 2))
    rise = 0.5 * float(r @ r) - optimum.cost
    # the optimum is one to its fit's tolerance: rounding of the costs allowed beside
    return abs(rise - predicted) <= JOIN_AGREEMENT * predicted + 1e-9 * (1.0 + optimum.cost)


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
