"""Diagnostics of a fitted estimate: bounds, convergence, identifiability, plausibility of the level.

docs: theory, The estimator. The warnings point at the caller of the public estimator.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..errors import BoundWarning, ConvergenceWarning, IdentifiabilityWarning, PlausibilityWarning
from ..models.loading import STANDARD_GRAVITY

# A parameter within this fraction of its bound's range of the bound counts as on it.
_BOUND_TOLERANCE = 1e-4
#: Measured over modelled band variance beyond which (either way) the level itself is in doubt:
#: at a sound optimum the two agree within the Welch scatter and the modelling errors (a few
#: tens of per cent); a unit or gain mix-up is a factor of ~100 or more.
LEVEL_RATIO_LIMIT = 3.0
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
