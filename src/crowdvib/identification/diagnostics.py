"""Diagnostics of a fitted estimate: bounds, convergence, identifiability, plausibility of the level.

docs: theory, The estimator. The warnings point at the caller of the public estimator.
"""

from __future__ import annotations

import warnings

import numpy as np

from .._plausibility import derived
from ..errors import (BoundWarning, ConvergenceWarning, DataError, IdentifiabilityWarning,
                      PlausibilityWarning)
from ..models.loading import STANDARD_GRAVITY
from ..models.pedestrian import MSDModel

# A parameter within this fraction of its bound's range of the bound counts as on it.
_BOUND_TOLERANCE = 1e-4
#: Measured over modelled band variance beyond which (either way) the level itself is in doubt:
#: at a sound optimum the two agree within the Welch scatter and the modelling errors (a few
#: tens of per cent); a unit or gain mix-up is a factor of ~100 or more.
LEVEL_RATIO_LIMIT = 3.0
#: Measured over modelled band variance that no θ within the bounds brings within this factor
#: of 1 is refused before any fit (issue 35 §2): the right input comes within 3 (at the truth),
#: a unit mix-up is a factor of ~100 (g², 1e6) or a resonance the model does not have.
GROSS_LEVEL_RATIO = 10.0
#: Grid points per parameter of the level check before the fit (log-spaced for f_h1 and ξ_h1).
_LEVEL_GRID = {"frequency": 10, "damping_ratio": 6, "mass_ratio": 3}
#: Unit mix-ups tried when the level is in doubt: factor on the measured PSD → likely cause.
_UNIT_MIXUPS = ((STANDARD_GRAVITY**2, "a record in g read as m/s²"),
                (STANDARD_GRAVITY**-2, "a record in m/s² declared as g"),
                (1e-6, "a record in mm/s² read as m/s²"),
                (1e6, "a record in m/s² declared as mm/s²"))


def _diagnose(best, runs, names, lower, upper, what, hint, stacklevel=3):
    """Active bounds and convergence of the best run (warned about), and the per-start table.

    The warnings point at the caller of the public estimator: ``stacklevel`` frames up from here
    (3 when the public function calls this directly).
    """
    span = upper - lower
    active = tuple(
        f"{name}:{side}" for name, x, lo, hi, width in zip(names, best.x, lower, upper, span)
        for side, hit in (("lower", x - lo <= _BOUND_TOLERANCE * width),
                          ("upper", hi - x <= _BOUND_TOLERANCE * width)) if hit)
    if active:
        warnings.warn(f"{what} ({', '.join(active)}): widen the bounds or {hint}", BoundWarning,
                      stacklevel=stacklevel)
    success = best.status > 0
    if not success:
        warnings.warn(f"least_squares did not converge: {best.message}", ConvergenceWarning,
                      stacklevel=stacklevel)
    table = tuple({"start": [float(v) for v in start], "estimate": [float(v) for v in r.x],
                   "cost": float(2 * r.cost), "n_evaluations": int(n), "status": int(r.status)}
                  for r, start, n in runs)
    return active, success, table


#: |correlation| of two estimated parameters above which the data do not tell them apart.
IDENTIFIABILITY_CORRELATION = 0.99


def _check_identifiability(names, covariance):
    """Warn when two parameters are so correlated that the record cannot separate them."""
    scale = np.sqrt(np.maximum(np.diag(covariance), 1e-300))
    correlation = covariance / np.outer(scale, scale)
    pairs = [f"{names[i]}–{names[j]} {correlation[i, j]:+.3f}"
             for i in range(len(names)) for j in range(i + 1, len(names))
             if abs(correlation[i, j]) > IDENTIFIABILITY_CORRELATION]
    if pairs:
        hint = ("hold mass_ratio fixed (the paper uses 0.95) or fit several records with "
                "different crowds together" if "mass_ratio" in names else "add data")
        warnings.warn(f"the data do not determine {', '.join(names)} separately (correlation "
                      f"{'; '.join(pairs)}, beyond ±{IDENTIFIABILITY_CORRELATION:g}): {hint}",
                      IdentifiabilityWarning, stacklevel=4)


def _check_level(objective, ratio, fit, to_msd):
    """Warn when the measured level disagrees with the fitted model's, naming the likely cause.

    Each unit mix-up of ``_UNIT_MIXUPS`` is tried by fitting the rescaled data again; one that
    makes the level consistent and fits ten times better than the data as given is named in the
    warning (the estimate itself is left as it is: the user must correct the input). ``fit``
    fits the MSD alone at the crowd of ``objective``, the data as given and each rescaling
    alike.
    """
    off = (ratio > LEVEL_RATIO_LIMIT) | (ratio < 1 / LEVEL_RATIO_LIMIT)
    if not off.any():
        return
    base, _ = fit(objective)
    cost = 2 * base.cost
    where = ", ".join(f"{name!r}: {value:.3g}" for name, value, bad in
                      zip(objective.output_names, ratio, off) if bad)
    hint = "check the units, the sensor gain and the channel mapping"
    found = []
    for factor, cause in _UNIT_MIXUPS:
        rescaled = objective.with_level(factor)
        best, _ = fit(rescaled)
        msd = to_msd(best.x)
        ratios = rescaled.level_ratio(msd)
        if np.all((ratios <= LEVEL_RATIO_LIMIT) & (ratios >= 1 / LEVEL_RATIO_LIMIT)):
            found.append((2 * best.cost, cause, msd))
    if found:
        rescaled_cost, cause, msd = min(found, key=lambda item: item[0])
        # Named only when it explains the data: a consistent level AND a fit ten times better
        # (a mere gain error can come within the level limit after a wrong rescaling).
        if rescaled_cost < 0.1 * cost:
            hint = (f"{cause}? Rescaled so, the data fit with a misfit of {rescaled_cost:.3g} "
                    f"instead of {cost:.3g} and give f_h1 = {msd.frequency:.3g} Hz, "
                    f"ξ_h1 = {msd.damping_ratio:.3g}")
    warnings.warn(
        f"the measured PSD level over the band is not the fitted model's (measured/model "
        f"variance {where}; a consistent level lies within a factor {LEVEL_RATIO_LIMIT:g}), so "
        f"the estimate is not to be trusted: {hint}", PlausibilityWarning, stacklevel=4)


def _level_span(objective, names, lower, upper, mass_ratio):
    """(lowest, highest) measured/model band variance per output over no HSI and a coarse grid
    of the MSD within the bounds, at the objective's crowd: what a fit can reach.

    The grid stops as soon as every output has met a ratio within GROSS_LEVEL_RATIO of 1 from
    below and from above (one within it does both): the check cannot refuse it any more, and
    the rest of the grid would only widen a span no one reads (a record in the right units
    stops at no HSI, the first point: 61 model evaluations fewer per estimate, issue 39). A
    record the check refuses never stops early, so its message quotes the whole grid's span."""
    axes = {name: (np.geomspace if name in ("frequency", "damping_ratio") else np.linspace)(
        lo, hi, _LEVEL_GRID[name]) for name, lo, hi in zip(names, lower, upper)}
    with derived():                   # grid points, not the user's values
        msds = [None] + [MSDModel(f, x, mu) for f in axes["frequency"]
                         for x in axes["damping_ratio"]
                         for mu in axes.get("mass_ratio", [mass_ratio])]
    low = high = None
    for msd in msds:
        ratio = objective.level_ratio(msd)
        low = ratio if low is None else np.minimum(low, ratio)
        high = ratio if high is None else np.maximum(high, ratio)
        if np.all((low <= GROSS_LEVEL_RATIO) & (high >= 1 / GROSS_LEVEL_RATIO)):
            break
    return low, high


def _refuse_gross_level(objectives, names, lower, upper, mass_ratio, notes=()):
    """Refuse, before any fit, a measured level that no θ within the bounds explains (DataError).

    The message names the outputs and the measured/model variance the fit could reach, the
    likely cause (a unit mix-up of ``_UNIT_MIXUPS`` that brings the level within
    ``LEVEL_RATIO_LIMIT``, with the variance ratio it would then be, or the structure's
    plausibility ``notes``) and the override. A fit to such data ends on its bounds after
    minutes (issue 35 §2); this check costs a few hundred model evaluations.
    """
    for objective in objectives:
        low, high = _level_span(objective, names, lower, upper, mass_ratio)
        gross = (low > GROSS_LEVEL_RATIO) | (high < 1 / GROSS_LEVEL_RATIO)
        if not gross.any():
            continue
        where = ", ".join(f"{name!r}: {lo:.3g} to {hi:.3g}" for name, lo, hi, bad in
                          zip(objective.output_names, low, high, gross) if bad)
        causes = [f"{cause}? (read so, measured/model would be {low.min() * factor:.3g} to "
                  f"{high.max() * factor:.3g})" for factor, cause in _UNIT_MIXUPS
                  if np.all((low * factor <= LEVEL_RATIO_LIMIT)
                            & (high * factor >= 1 / LEVEL_RATIO_LIMIT))]
        causes += list(notes)
        hint = ("; ".join(causes) if causes else
                "check the units, the sensor gain, the channel mapping and the structure")
        raise DataError(
            f"measured PSD level must be one the model reaches with an MSD within the bounds "
            f"(measured/model variance over the band within a factor {GROSS_LEVEL_RATIO:g} of "
            f"1), got measured/model from {where} (over no HSI and a grid of MSDs within the "
            f"bounds): {hint}. Correct the input, or pass check_level=False (case file: "
            f"estimation.check_level = false) to fit it anyway")
