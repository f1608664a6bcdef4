"""The trust-region fit without trf's last Jacobian (issue 39): trf's answer, fewer evaluations.

Reference: ``scipy.optimize.least_squares(method="trf", x_scale="jac")`` itself, on closed-form
residuals (an exponential decay with an offset, the Rosenbrock function, a fit whose optimum
sits on a bound). ``trust_region_fit`` ends only where trf's own ftol test ends it, with trf's
forward-difference Jacobian, so its point and residuals are trf's to the bit (module docstring
of ``crowdvib.identification.trust_region``).
"""

import numpy as np
import pytest
from scipy.optimize import least_squares

from crowdvib.identification.trust_region import forward_jacobian, trust_region_fit

T = np.linspace(0.0, 3.0, 40)
DATA = 2.5 * np.exp(-1.3 * T) + 0.4 + 0.01 * np.sin(17 * T)


def decay(p):
    return p[0] * np.exp(-p[1] * T) + p[2] - DATA


def rosenbrock(p):
    return np.array([10.0 * (p[1] - p[0] ** 2), 1.0 - p[0]])


def counting(function):
    calls = [0]

    def counted(p):
        calls[0] += 1
        return function(p)
    return counted, calls


CASES = [  # (residuals, start, lower, upper, tolerance, whether the fit ends here)
    (decay, (2.4, 1.25, 0.41), (0.1, 0.1, 0.0), (10.0, 5.0, 2.0), 1e-4, True),   # next to it
    (decay, (1.0, 1.0, 1.0), (0.1, 0.1, 0.0), (10.0, 5.0, 2.0), 1e-8, True),
    (decay, (9.99, 0.11, 1.99), (0.1, 0.1, 0.0), (10.0, 5.0, 2.0), 1e-6, True),  # from a corner
    (decay, (2.0, 1.0, 0.1), (0.1, 0.1, 0.0), (10.0, 5.0, 0.3), 1e-8, True),     # on a bound
    # Rosenbrock's residuals vanish at the optimum: trf ends on its gtol test, after the
    # Jacobian, and so does the fit here
    (rosenbrock, (-1.2, 1.0), (-2.0, -2.0), (2.0, 2.0), 1e-8, False),
]


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c[0].__name__}{c[1]}")
def test_the_fit_is_trfs_with_its_last_jacobian_left_out(case):
    function, start, lower, upper, tolerance, ends_here = case
    plain, plain_calls = counting(function)
    expected = least_squares(plain, start, method="trf", bounds=(lower, upper), x_scale="jac",
                             ftol=tolerance, xtol=tolerance)
    counted, calls = counting(function)
    found = trust_region_fit(counted, np.array(start), (np.array(lower), np.array(upper)),
                             ftol=tolerance, xtol=tolerance)
    np.testing.assert_array_equal(found.x, expected.x)
    np.testing.assert_array_equal(found.fun, expected.fun)
    assert found.cost == expected.cost and found.nfev == calls[0]
    assert (found.status in (2, 4)) == ends_here
    if ends_here:
        # ended by the ftol test here: trf's Jacobian at that point (one call per parameter)
        # is all that was left out
        assert calls[0] == plain_calls[0] - len(start)
        assert found.message.startswith(("`ftol`", "Both `ftol`"))
    else:
        assert calls[0] == plain_calls[0] and found.status == expected.status


def test_a_fit_that_uses_the_last_jacobian_keeps_it():
    # final_jacobian: the plain trf call, its Jacobian at the optimum included (the joining
    # multistart's basin test reads it).
    lower, upper = np.array([0.1, 0.1, 0.0]), np.array([10.0, 5.0, 2.0])
    found = trust_region_fit(decay, np.array([2.0, 1.0, 0.5]), (lower, upper),
                             final_jacobian=True)
    expected = least_squares(decay, [2.0, 1.0, 0.5], method="trf", bounds=(lower, upper),
                             x_scale="jac")
    np.testing.assert_array_equal(found.x, expected.x)
    np.testing.assert_array_equal(found.jac, expected.jac)


def test_the_jacobian_is_scipys_forward_difference_inside_the_bounds():
    # Reference: the closed-form derivative of the decay; the step at the upper bound is
    # turned inwards (scipy's one-sided rule), so no evaluation leaves the bounds.
    lower, upper = np.array([0.1, 0.1, 0.0]), np.array([10.0, 5.0, 2.0])
    p = np.array([2.5, 1.3, 2.0])                    # the offset on its upper bound
    seen = []

    def recorded(q):
        seen.append(q.copy())
        return decay(q)

    J = forward_jacobian(recorded, p, decay(p), lower, upper)
    exact = np.stack([np.exp(-p[1] * T), -p[0] * T * np.exp(-p[1] * T), np.ones_like(T)], 1)
    np.testing.assert_allclose(J, exact, rtol=1e-6, atol=1e-7)
    assert all(np.all((q >= lower) & (q <= upper)) for q in seen)
    assert seen[2][2] < p[2]


def test_residuals_not_finite_at_the_start_are_refused_as_scipy_refuses_them():
    with pytest.raises(ValueError, match="not finite"):
        trust_region_fit(lambda p: np.array([np.nan, p[0]]), np.array([1.0]),
                         (np.array([0.0]), np.array([2.0])))
