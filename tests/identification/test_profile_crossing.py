"""The profile interval's root search skips brentq's last fit only where it changes nothing
(issue 39; :func:`crowdvib.identification.uncertainty._closing`)."""

import numpy as np
import pytest
from scipy import optimize

from crowdvib.identification.uncertainty import _closing

THRESHOLD = 3.841458820694124          # χ²₁(0.95)
XTOL = 1e-2 * np.sqrt(THRESHOLD)       # the interval's: 1 % of the half-width √χ²₁ (σ = 1)


def _excess(centre, bend, ripple):
    """√rise − √χ²₁ of a profile whose rise is (t/σ)² bent by a cubic term, σ = 1, about the
    estimate at ``centre``: the nearly linear excess of a profile close to quadratic, with a
    ``ripple`` of amplitude comparable to the skip's margin (a far worse inner fit than the
    profile's) that makes brentq return its closing point or need its value."""
    def excess(t):
        u = t - centre
        return (np.sqrt(u ** 2 * (1 + bend * u)) - np.sqrt(THRESHOLD)
                + ripple * np.sin(300.0 * u))
    return excess


def _searches(bend, ripple):
    """(end, fits) of brentq on the excess itself (the reference) and through ``_closing``,
    and the closing steps ``_closing`` fitted, over ten profiles."""
    rows = []
    for centre in np.linspace(0.0, 0.37, 10):
        excess, plain, calls = _excess(centre, bend, ripple), [], []
        reference = optimize.brentq(lambda t: plain.append(t) or excess(t), centre + 0.5,
                                    centre + 3.0, xtol=XTOL)
        end = optimize.brentq(_closing(lambda t: calls.append(t) or excess(t), XTOL),
                              centre + 0.5, centre + 3.0, xtol=XTOL)
        closing = sum(any(abs(abs(t - s) - XTOL / 2) <= 1e-9 * XTOL for s in calls[:i])
                      for i, t in enumerate(calls))
        rows.append((reference, len(plain), end, len(calls), closing))
    return rows


@pytest.mark.parametrize("bend", [0.02, -0.05])
def test_a_smooth_profile_saves_each_search_its_closing_fit(bend):
    # Reference: scipy's brentq on the excess itself. The end is the same to the bit, one fit
    # fewer in every search.
    for reference, plain, end, calls, closing in _searches(bend, 0.0):
        assert end == reference
        assert (calls, closing) == (plain - 1, 0)


def test_where_the_closing_step_may_matter_it_is_fitted():
    # A ripple of 3e-3 (three times the inner fits' imprecision, about the skip's margin) leaves
    # |f(x₀)| above a quarter of the step's change: every closing step is fitted, and the end
    # is brentq's own on the excess itself.
    for reference, plain, end, calls, closing in _searches(0.02, 3e-3):
        assert end == reference
        assert (calls, closing) == (plain, 1)
