"""Bounded trust-region least squares (scipy's ``trf``) without the Jacobian nothing uses.

trf makes the Jacobian at every point it accepts, and only then tests whether the step that led
there ended the fit: at the last point that Jacobian is made for nothing. With finite
differences it costs one evaluation of the residuals per parameter, a third of the evaluations
of a fit started next to its minimum (a profile's inner fits, the refit of an estimate; issue
39). :func:`trust_region_fit` hands trf a Jacobian that applies trf's ftol test to the step just
taken first, and ends the fit there when it holds.

It ends the fit only where trf would have ended it, so the point, the residuals and the status
are trf's own. trf stops when the step lowered the cost F = ½‖r‖² by dF < ftol·F with
ρ = dF / (its model's predicted reduction) > 0.25. Its model is the Gauss–Newton one,
gᵀs + ½‖Js‖², plus ½ sᵀCs with C ⪰ 0 (the Coleman–Li scaling of the bounds), so its ρ is at
least the one computed here without C: the test here is passed only when trf's is. It asks
ρ > 0.3, a margin over rounding. Where it is not passed (trf's ρ may still be > 0.25, or its
xtol or gtol test may hold), the Jacobian is made and trf goes on as it would.

The Jacobian is scipy's forward difference ('2-point', its relative step √ε·max(1, |x|), turned
one-sided inward at a bound), so that the path, and with it the answer, is the one of a plain
``least_squares(method="trf")`` call.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import OptimizeResult, least_squares

#: trf's ratio test (ρ > 0.25), with a margin: the ρ here can only be below trf's.
_RATIO = 0.3
#: scipy's messages for the stops made here (its statuses 2 and 4).
_MESSAGES = {2: "`ftol` termination condition is satisfied.",
             4: "Both `ftol` and `xtol` termination conditions are satisfied."}


class _Ended(Exception):
    """Raised from the Jacobian when the step to its point ended the fit."""

    def __init__(self, x, r, status):
        super().__init__(_MESSAGES[status])
        self.x, self.r, self.status = x, r, status


def forward_jacobian(residuals, x, r, lower, upper):
    """scipy's '2-point' Jacobian of ``residuals`` at ``x`` (r = residuals(x)) within the bounds."""
    sign = np.where(x >= 0, 1.0, -1.0)
    step = np.sqrt(np.finfo(float).eps) * sign * np.maximum(1.0, np.abs(x))
    # scipy's one-sided scheme: a step that leaves the bounds is turned round if it fits the
    # other way, else made a full step to the farther bound
    outside = (x + step < lower) | (x + step > upper)
    below, above = x - lower, upper - x
    fits = np.abs(step) <= np.maximum(below, above)
    step = np.where(outside & fits, -step, step)
    step = np.where(~fits & (above >= below), above, step)
    step = np.where(~fits & (above < below), -below, step)
    # column by column into the transpose, as scipy does: the same memory order makes trf's
    # sums over J (its gradient, its scaling) round the same way
    columns = np.empty((x.size, r.size))
    for i in range(x.size):
        moved = x.copy()
        moved[i] += step[i]
        columns[i] = (residuals(moved) - r) / (moved[i] - x[i])
    return columns.T


def trust_region_fit(residuals, start, bounds, *, ftol=1e-8, xtol=1e-8, x_scale="jac",
                     max_nfev=None, final_jacobian=False):
    """``scipy.optimize.least_squares(method="trf")`` of ``residuals`` from ``start`` within
    ``bounds`` = (lower, upper), its Jacobian by forward differences, ended as trf ends but
    without the Jacobian at its last point (module docstring) → its result: x, fun, cost,
    status, message and nfev (here the calls of ``residuals``, differences included).

    ``final_jacobian``: make that Jacobian all the same (a plain trf call; its result also
    holds ``jac`` and ``active_mask``), for a caller that uses it. The tolerances and
    ``max_nfev`` are scipy's.
    """
    lower, upper = (np.asarray(b, dtype=float) for b in bounds)
    calls, last = [0], {}          # last: the point trf evaluated last (its Jacobian's point)
    accepted = []                  # (x, r, J) at the last point trf accepted

    def counted(x):
        calls[0] += 1
        return np.asarray(residuals(x), dtype=float)

    def evaluate(x):
        key = x.tobytes()
        if key not in last:
            last.clear()
            last[key] = counted(x)
        return last[key]

    def jacobian(x):
        x = np.array(x, dtype=float)
        r = evaluate(x)
        if accepted:
            before, r0, J0 = accepted
            s, cost = x - before, 0.5 * float(r0 @ r0)
            gain = cost - 0.5 * float(r @ r)
            predicted = -(float((J0.T @ r0) @ s) + 0.5 * float(np.sum((J0 @ s) ** 2)))
            if 0 < gain < ftol * cost and predicted > 0 and gain > _RATIO * predicted:
                small = np.linalg.norm(s) < xtol * (xtol + np.linalg.norm(before))
                raise _Ended(x, r, 4 if small else 2)
        J = forward_jacobian(counted, x, r, lower, upper)
        accepted[:] = x, r, J
        return J

    options = dict(method="trf", bounds=(lower, upper), x_scale=x_scale, ftol=ftol, xtol=xtol,
                   max_nfev=max_nfev)
    try:
        result = (least_squares(counted, start, **options) if final_jacobian
                  else least_squares(evaluate, start, jac=jacobian, **options))
    except _Ended as ended:
        result = OptimizeResult(x=ended.x, fun=ended.r, cost=0.5 * float(ended.r @ ended.r),
                                status=ended.status, message=str(ended), success=True)
    result.nfev = calls[0]
    return result
