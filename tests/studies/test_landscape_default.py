"""Landscapes are of the objective the estimate minimises unless asked otherwise (issue 33 §3):
objective_map and PSDObjective take their defaults from the estimator's table."""

import inspect

import numpy as np
import pytest

from crowdvib import estimate_hsi, response_psd
from crowdvib.identification import Estimator, PSDObjective
from crowdvib.studies import objective_map


def _default(function, name):
    return inspect.signature(function).parameters[name].default


def test_the_landscapes_default_to_the_estimators_objective():
    # Reference: estimate_hsi's default method; the crowd model is resolved from it by the same
    # table (None → the method's own), so objective_map and PSDObjective must state None.
    method = _default(estimate_hsi, "method")
    assert method == "likelihood"
    for function in (Estimator, PSDObjective):
        assert _default(function, "method") == method, function.__name__
        assert _default(function, "crowd_model") is None, function.__name__
    # objective_map maps the misfit of the Estimator it is given: it has no choice of its own.
    assert "method" not in inspect.signature(objective_map).parameters


@pytest.fixture
def fluctuating_psd(paper_bridge, paper_crowd, paper_msd, welch_grid):
    """The paper's example as a noise-free Welch expectation (T = 60 s), response_psd's default
    (the fluctuating crowd)."""
    measured = response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd,
                            welch_window_length=60.0)
    return paper_bridge, paper_crowd, paper_msd, measured


def test_default_landscape_is_zero_at_the_truth_of_the_default_psd(fluctuating_psd):
    # Reference: the Whittle deviance x − 1 − ln x vanishes where the model equals the data
    # (x = 1), i.e. at the MSD that made the noise-free PSD, and is positive elsewhere; the
    # paper's least squares with the smeared crowd does not vanish there.
    bridge, crowd, truth, measured = fluctuating_psd
    grid = dict(frequencies=[2.9, 3.0, 3.1], damping_ratios=[0.25, 0.30, 0.35])
    default = Estimator(band=(0.0, 10.0))
    landscape = objective_map(measured, bridge, crowd, **grid, estimator=default)
    assert landscape.cost[1, 1] == pytest.approx(0.0, abs=1e-12)
    assert np.all(np.delete(landscape.cost.ravel(), 4) > 1e-6)
    squares = objective_map(measured, bridge, crowd, **grid,
                            estimator=default.replace(method="least_squares"))
    assert squares.cost[1, 1] > 1e-6
