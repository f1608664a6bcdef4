"""Statistical uncertainty of one Welch PSD's estimate: sandwich covariance, profile intervals.

Both misfits of :mod:`crowdvib.identification.objective` are sums over frequency bins,
S(θ) = Σ_{l,k} ρ_{l,k}(θ), minimised at θ̂. Linearised about the model G = G(θ̂), the score is
g = ∂S/∂θ = Σ_{l,k} q_{l,k} (Ĝ_{l,k} − G_{l,k}) and S(θ) ≈ S(θ̂) + ½ δᵀ H δ with the expected
Hessian H. The estimate's covariance is the sandwich

    Cov(θ̂) = H⁻¹ Var(g) H⁻¹,

with Var(g) from the statistics of Welch ordinates (docs: theory, Correlation of
neighbouring Welch ordinates):
Var(Ĝ_k) = φ_k (2/ν) G_k² — φ_k the dispersion the record's own segments show (1 for a
stationary Gaussian record; :class:`~crowdvib.ResponsePSD`) — and ordinates d bins apart
correlated by ρ(d)
(:func:`crowdvib.signals.welch.welch_bin_correlation`: 0.46 and 0.04 for 50 %-overlapped Hann
segments). The outputs are taken as fully coherent — exact for one output or one mode, and on
the safe (wider) side otherwise. For the likelihood with independent bins this reduces to the
inverse Fisher information; the correlation of neighbouring bins is what makes the plain
curvature overstate the information (by about 1 + 2(ρ(1) + ρ(2)) ≈ 2).

Profile intervals: S is minimised over the other parameters with θ_p = t held, and
c_p (S_p(t) − S(θ̂)) ≤ χ²₁(level) with c_p = 2 (H⁻¹)_pp / Cov_pp, the factor that turns the
curvature of S into the sandwich variance (a calibrated composite-likelihood ratio:
Chandler & Bate 2007). Coverage is checked over seeded synthetic records in the tests.
"""

import numpy as np
from scipy import optimize, stats

from .trust_region import trust_region_fit

__all__ = ["score_variance", "sandwich_covariance", "profile_interval"]


def score_variance(q, spread, degrees_of_freedom, correlation, *, occupancy=None,
                   coherent=True):
    """Var(g) of the score of one record's misfit (module docstring); the sandwich is
    H⁻¹ Var(g) H⁻¹, with Var(g) and H summed over independent records.

    Parameters
    ----------
    q : ndarray, shape (n_outputs, n_bins, n_parameters)
        Score coefficients (:meth:`PSDObjective.score_terms`).
    spread : ndarray, shape (n_outputs, n_bins)
        G(θ̂)·sqrt(φ), in the units of ``q``: the standard deviation of each ordinate over
        sqrt(2/ν), φ its measured dispersion (1 for the χ²_ν of a stationary Gaussian record).
    degrees_of_freedom : float
        ν of the Welch ordinates.
    correlation : array_like
        ρ(0) = 1, ρ(1), … of ordinates 0, 1, … bins apart.
    occupancy : (ndarray, float), optional
        ∂G/∂ln n (shape of ``spread``) and the relative variance of the record's crowd size n:
        a crowd that happened to be larger than its mean shifts every ordinate together.
    coherent : bool
        True: the rows of ``q`` are outputs whose errors share one ε per bin (fully coherent).
        False: the rows are independent score terms (the whitened coordinates of the Wishart
        likelihood, :mod:`crowdvib.identification.wishart`), each correlated across bins by ρ.

    Returns
    -------
    ndarray, shape (n_parameters, n_parameters)
    """
    if coherent:
        terms = np.einsum("lkp,lk->kp", q, spread)[np.newaxis]   # one ε per bin
    else:
        terms = q * spread[..., np.newaxis]                         # one ε per row and bin
    variance = 0.0
    for v in terms:
        variance = variance + v.T @ v
        for lag, rho in enumerate(np.asarray(correlation)[1:], start=1):
            if lag < v.shape[0]:
                cross = v[:-lag].T @ v[lag:]
                variance = variance + rho * (cross + cross.T)
    variance = 2.0 / degrees_of_freedom * variance
    if occupancy is not None:
        gradient, relative_variance = occupancy
        shift = occupancy_shift(q, gradient)
        variance = variance + relative_variance * np.outer(shift, shift)
    return variance


def occupancy_shift(q, gradient):
    """The score's move Σ_{l,k} q_{l,k} ∂G_{l,k}/∂ln n when every ordinate moves with the crowd
    size n (a crowd larger than its mean, or a density stated wrongly)."""
    return np.einsum("lkp,lk->p", q, gradient)


def sandwich_covariance(variance, hessian):
    """H⁻¹ Var(g) H⁻¹ [parameter units²]."""
    inverse = np.linalg.pinv(hessian)
    return inverse @ variance @ inverse


#: The residual that stands in for a non-finite one in a profile's inner fit: far above any
#: residual of a model that fits (normalised residuals are of order 1).
_OFF_MODEL = 1e3


def profile_interval(residuals, estimate, index, lower, upper, covariance, hessian, level):
    """Profile interval of parameter ``index``, calibrated by the sandwich (module docstring).

    Parameters
    ----------
    residuals : callable
        ``residuals(theta)`` → r(θ) with S(θ) = Σ r², for a full parameter vector.
    estimate : ndarray
        θ̂.
    index : int
        The parameter profiled.
    lower, upper : ndarray
        Search bounds of every parameter.
    covariance : ndarray
        From :func:`sandwich_covariance`.
    hessian : ndarray
        Expected Hessian H of S.
    level : float
        Confidence level in (0, 1).

    Returns
    -------
    (low, high), (low_on_bound, high_on_bound)
        The interval, and whether each end stopped at a search bound.
    """
    variance = covariance[index, index]
    inverse = np.linalg.pinv(hessian)
    value = float(estimate[index])
    if not variance > 0 or not inverse[index, index] > 0:
        return (value, value), (False, False)
    factor = 2.0 * inverse[index, index] / variance
    threshold = stats.chi2.ppf(level, 1)
    others = [i for i in range(estimate.size) if i != index]
    r = residuals(estimate)
    best = float(r @ r)
    known = {value: 0.0}
    # The inner fits stop when a step gains less than ``tolerance`` of S: the rise is then
    # known to about 1e-3 of its threshold, which moves an end by some 5e-4 of the half-width,
    # twenty times below the crossing's own precision (brentq's xtol below); at most 1e-4,
    # at least scipy's own 1e-8 (issue 39: a quarter of the inner fits' iterations).
    tolerance = float(np.clip(1e-3 * threshold / max(factor * best, 1e-300), 1e-8, 1e-4))
    # The others' minimum along the profile, t → x(t): each inner fit starts from the
    # quadratic through the three nearest points found so far (at each end's first fit, the
    # line of slope −H_oo⁻¹ H_op, the minimum's motion for a quadratic S, bent as the points
    # found on the other side bend), leaving it a step or two.
    found = {value: estimate[others]}
    slope = (-np.linalg.lstsq(hessian[np.ix_(others, others)], hessian[others, index],
                              rcond=None)[0] if others else np.zeros(0))

    def predicted(t):
        near = sorted(found, key=lambda s: abs(s - t))[:3]
        if not any((s - value) * (t - value) > 0 for s in found):
            # No point on t's side yet (each end's first fit): the quadratic through θ̂ with
            # the minimum's slope there, its curvature fitted to the points found on the
            # other side (none at first: the line). A quadratic through the three nearest,
            # all on the other side, extrapolates their spacing's noise across θ̂.
            d = np.array([s - value for s in found])
            bend = np.array([found[s] - found[value] - slope * (s - value) for s in found])
            curvature = (d ** 2 @ bend) / max(float(np.sum(d ** 4)), 1e-300)
            return found[value] + slope * (t - value) + curvature * (t - value) ** 2
        scale = max(abs(s - value) for s in near)
        return np.array([np.polyval(np.polyfit((np.array(near) - value) / scale, column,
                                               len(near) - 1), (t - value) / scale)
                         for column in np.array([found[s] for s in near]).T])

    def rise(t):
        """c_p (S_p(t) − S(θ̂)), S minimised over the other parameters (each t once)."""
        if t not in known:
            theta = estimate.copy()
            theta[index] = t
            if others:
                last = {}

                def inner(x):
                    # Where the model is not finite (far along a profile of a record that
                    # hardly bounds the parameter, the fitted step frequencies can leave the
                    # band without load), a large finite misfit keeps the fit away; scipy
                    # refuses non-finite residuals. The last point is kept: the fit's first
                    # evaluation is the start, already checked below.
                    key = np.asarray(x, dtype=float).tobytes()
                    if key not in last:
                        theta[others] = x
                        found_r = residuals(theta)
                        last.clear()
                        last[key] = np.where(np.isfinite(found_r), found_r, _OFF_MODEL)
                    return last[key]

                start = np.clip(predicted(t), lower[others], upper[others])
                if np.any(inner(start) == _OFF_MODEL):
                    # The extrapolated start is off the model: start from the nearest point
                    # of the profile found so far instead.
                    start = found[min(found, key=lambda s: abs(s - t))]
                # A parameter that has left the data's reach (a level far off drags ξ to its
                # bound) has a zero Jacobian column; trf's bound scaling then overflows, and its
                # trust-region step divides by zero, in quantities it only compares (numpy 2.5
                # with scipy 1.18 warn; the profile is still the minimum found). Silenced here,
                # where it is understood, and nowhere else. When the overflow reaches trf's SVD
                # (a NaN there: scipy raises), the fit is made again without the scaling.
                with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
                    for scale in ("jac", 1.0):
                        try:
                            fit = trust_region_fit(inner, start, (lower[others], upper[others]),
                                                   x_scale=scale, ftol=tolerance, xtol=1e-6)
                            break
                        except ValueError:
                            if scale != "jac":
                                raise
                theta[others] = found[t] = fit.x
                r = np.where(fit.fun == _OFF_MODEL, np.nan, fit.fun)     # the fit's own r(θ)
            else:
                r = residuals(theta)
            # No finite model at t: beyond every value the data allow (a rise past any level).
            known[t] = (factor * (float(r @ r) - best) if np.all(np.isfinite(r))
                        else _OFF_MODEL ** 2)
        return known[t]

    def excess(t):
        """√rise − √χ²₁(level): the crossing sought, nearly linear in t for a profile close
        to quadratic, so the root finder needs few steps."""
        return np.sqrt(max(rise(t), 0.0)) - np.sqrt(threshold)

    half_width = np.sqrt(threshold * variance)
    xtol = 1e-2 * half_width
    ends, on_bound = [], []
    for side, limit in ((-1, lower[index]), (+1, upper[index])):
        inside, step, end, hit = value, half_width, None, False
        for _ in range(12):      # expand until the threshold is crossed
            trial = value + side * step
            if side * (trial - limit) >= 0:
                trial = float(limit)
            if excess(trial) > 0:
                end = optimize.brentq(_closing(excess, xtol), inside, trial, xtol=xtol)
                break
            if trial == limit:
                end, hit = float(limit), True
                break
            # Next trial where the rise would reach χ² if it grew as (t − θ̂)² from here,
            # 10 % beyond, at least 1.2 and at most 2 times as far.
            growth = np.sqrt(threshold / max(rise(trial), 1e-12 * threshold))
            inside, step = trial, abs(trial - value) * float(np.clip(1.1 * growth, 1.2, 2.0))
        ends.append(float(end if end is not None else inside))
        on_bound.append(hit)
    return (ends[0], ends[1]), tuple(on_bound)


def _closing(excess, xtol):
    """``excess`` for brentq, without the fit of its last step where that step only closes the
    bracket on the point it returns (issue 39: a fifth of a profile's inner fits).

    Once brentq's interpolation has landed next to the root at x₀, its bracket's other end is
    still far; it steps δ = xtol/2 from x₀ towards it (its minimal step) and, the sign changed
    there and |f| larger, returns x₀ itself. The excess is nearly linear in t: from x₀ and the
    nearest point found on the root's other side, its slope s gives f(x₀ + δ) ≈ f(x₀) + s δ.
    When |f(x₀)| ≤ |s δ| / 4 that value has the other sign and at least three times |f(x₀)|,
    and stays so unless the prediction is off by |s δ| / 2: some 2.5e-3 √χ² for the 1 %-of-
    the-half-width xtol, five times the inner fits' precision (their rise to 1e-3 of χ²) and
    far above the excess's curvature over δ. brentq then returns x₀, the point it would have
    returned after the fit: the prediction stands in for it (and is not kept as the profile).
    """
    found = {}

    def closing(t):
        step = 0.5 * xtol
        for x0, f0 in found.items():
            if abs(abs(t - x0) - step) <= 1e-9 * step:
                across = [x for x, f in found.items() if f * f0 < 0]
                if across:
                    x1 = min(across, key=lambda x: abs(x - x0))
                    change = (found[x1] - f0) / (x1 - x0) * (t - x0)
                    if f0 * change < 0 and abs(f0) <= 0.25 * abs(change):
                        return f0 + change
        found[t] = value = excess(t)
        return value

    return closing
