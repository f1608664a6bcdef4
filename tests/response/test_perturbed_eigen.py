"""Eigen-decompositions updated by perturbation for the optimiser's finite-difference columns, and
the occupancy's correlation from its knots (issue 39: the same model at a lower cost)."""

import numpy as np
import pytest

from crowdvib import Crowd, ModalModel, MSDModel
import crowdvib.response.frequency_domain._linalg as linalg
from crowdvib.response.frequency_domain._attached import attachments, reduced_matrices
from crowdvib.response.frequency_domain._modulation import OccupancyPath, modulation_correction
from crowdvib.response.frequency_domain.fluctuation import FluctuatingSpectralModel, occupancy_cumulants
from crowdvib.response.frequency_domain.spectral import _state_matrix

#: scipy's finite-difference step (2-point: √ε relative) in f_h1 and ξ_h1.
STEP = 1.49e-8


def _plate(n_modes=12):
    """A 60 m deck of two lanes with ``n_modes`` modes, twisting ones among them: a crowd
    coupling of full rank, a state matrix of 4 n_modes (above linalg.PERTURBED_ENTRIES)."""
    positions = np.linspace(0.0, 60.0, 121)
    shapes = np.stack([np.stack([np.sin((j // 2 + 1) * np.pi * positions / 60.0)
                                 * (1.0 if j % 2 == 0 or lane == 0 else -1.0)
                                 for j in range(n_modes)], axis=-1) for lane in range(2)])
    return ModalModel(frequencies=1.5 + 0.45 * np.arange(n_modes),
                      damping_ratios=np.full(n_modes, 0.006),
                      modal_masses=np.full(n_modes, 6e4), positions=positions,
                      mode_shapes=shapes, width=3.0, lanes=[0.75, 2.25],
                      output_names=["midspan"], output_shapes=np.ones((1, n_modes)))


def _expansion(poles, vectors, inverse, frequency):
    return np.stack([vectors @ np.diag(1.0 / (2j * np.pi * f - poles)) @ inverse
                     for f in frequency])


@pytest.mark.parametrize("msd", [MSDModel(3.0, 0.3), MSDModel(2.0, 0.05), MSDModel(5.0, 0.6)])
def test_a_finite_difference_column_is_decomposed_as_eig_would(msd):
    # Reference: numpy's eig and inverse of the column's own state matrix. The update's
    # resolvent expansion must match theirs to the eig's own rounding (2e-13 relative, against
    # a change of ~1e-8 that the column differences): the Jacobian is then the one eig gives.
    bridge, crowd = _plate(), Crowd.from_density(0.6)
    frequency = np.linspace(1.0, 8.0, 15)

    def state(model):
        return _state_matrix(*reduced_matrices(bridge, attachments(bridge, crowd, model, ())))[0]

    base = state(msd)
    assert base.size >= linalg.PERTURBED_ENTRIES
    kept = []
    reference = linalg.eigen_decomposition(base, kept)        # by eig, kept
    for moved in (MSDModel(msd.frequency * (1 + STEP), msd.damping_ratio),
                  MSDModel(msd.frequency, msd.damping_ratio + STEP)):
        column = state(moved)
        calls = []
        original = linalg._perturbed

        def counted(*args):
            calls.append(1)
            return original(*args)

        linalg._perturbed, updated = counted, None
        try:
            updated = linalg.eigen_decomposition(column, kept)
        finally:
            linalg._perturbed = original
        assert calls                                          # the update was taken
        poles, vectors = np.linalg.eig(column)
        exact = _expansion(poles, vectors, np.linalg.inv(vectors), frequency)
        change = np.abs(exact - _expansion(*reference, frequency)).max()
        error = np.abs(_expansion(*updated, frequency) - exact).max()
        assert change > 1e-10 * np.abs(exact).max()            # the column moves the model
        assert error <= 2e-13 * np.abs(exact).max()


def test_meeting_poles_are_decomposed_afresh():
    # Two eigenvalues 1e-9 apart and a change of 1e-8: the first-order update's rotation
    # (change over gap, ~10) exceeds linalg._ROTATION and the matrix is decomposed by eig
    # (reference: eig itself, exactly), as where an MSD's two poles meet at ξ_h1 → 1.
    rng = np.random.default_rng(5)
    basis = rng.standard_normal((16, 16))
    values = np.concatenate([[1.0, 1.0 + 1e-9], np.linspace(2.0, 9.0, 14)])
    base = basis @ np.diag(values) @ np.linalg.inv(basis)
    kept = []
    linalg.eigen_decomposition(base, kept)
    column = base + 1e-8 * np.abs(base).max() * rng.standard_normal((16, 16))
    poles, vectors, _ = linalg.eigen_decomposition(column, kept)
    exact, exact_vectors = np.linalg.eig(column)
    np.testing.assert_array_equal(poles, exact)
    np.testing.assert_array_equal(vectors, exact_vectors)


def test_the_drift_correction_of_a_column_is_the_one_eig_gives(paper_bridge, paper_crowd):
    # The tracks of the occupied mode's poles (three nodes × 17 levels of 4 × 4 states) updated
    # for a Jacobian column, against the correction computed afresh: the column's difference
    # quotient within 1e-3 of eig's (measured 5e-6 to 1.3e-4; the correction's own rounding
    # noise, 3e-12 of it for a 4e-16 change of f_h1, makes 3e-5 of a column).
    model = FluctuatingSpectralModel(paper_bridge, paper_crowd, np.arange(121, 361) / 60,
                                     welch_window_length=60.0)
    base = model._base
    grid = base._welch.grid

    def correction(msd, kept):
        return modulation_correction(paper_bridge, base._attached(msd), base._shapes,
                                     model.mode, model.nodes, model.weights, model._path, grid,
                                     kept=kept)

    for f, x in ((3.1, 0.25), (2.0, 0.05), (4.0, 0.6)):
        kept = []
        before = correction(MSDModel(f, x), kept)
        for moved in (MSDModel(f * (1 + STEP), x), MSDModel(f, x + STEP)):
            exact = correction(moved, None)
            change = np.abs(exact - before).max()
            assert change > 1e-9 * np.abs(exact).max()
            assert np.abs(correction(moved, kept) - exact).max() <= 1e-3 * change


def test_correlation_from_its_knots_is_the_station_sum(paper_bridge):
    # ρ is piecewise linear between the lags (x_j − x_i)/v: interpolated from its values
    # there it is the station sum itself (reference: OccupancyPath._correlation) to rounding,
    # at lags on and off the knots, on the walkway and beyond it.
    path = OccupancyPath(paper_bridge, 1.34, 0,
                         variance=occupancy_cumulants(paper_bridge, 0.5, 0, 2)[1],
                         rate_variance=0.01)
    assert path._knots is not None
    lags = np.concatenate([np.random.default_rng(3).uniform(0.0, 50.0, 500),
                           path._knots[0][::7], [0.0, 37.31, 60.0]])
    np.testing.assert_allclose(path.correlation(lags), path._correlation(lags), rtol=0,
                               atol=1e-14)


def test_a_jump_at_the_walkways_end_keeps_the_station_sum():
    # A mode whose φ² does not vanish at an end (a cantilevered deck) makes ρ jump where a
    # walker leaves: no knots, the station sum as before (reference: _correlation itself).
    positions = np.linspace(0.0, 20.0, 41)
    deck = ModalModel(frequencies=[2.0], damping_ratios=[0.01], modal_masses=[1e4],
                      positions=positions, mode_shapes=(positions / 20.0)[:, np.newaxis],
                      width=2.0, output_names=["tip"], output_shapes=[[1.0]])
    path = OccupancyPath(deck, 1.2, 0, variance=0.1, rate_variance=0.01)
    assert path._knots is None
    lags = np.linspace(0.0, 20.0, 57)
    np.testing.assert_array_equal(path.correlation(lags), path._correlation(lags))
