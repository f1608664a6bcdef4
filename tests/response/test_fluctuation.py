"""The fluctuating-crowd model of the expected PSD (docs: theory, The fluctuating crowd)."""

import os
from math import comb

import numpy as np
import pytest

from crowdvib import Crowd, ModalModel, ParameterError
from crowdvib.response.frequency_domain.fluctuation import (FluctuatingSpectralModel, occupancy_cumulants,
                                           occupancy_quadrature, spectral_model)
from crowdvib.response.frequency_domain.spectral import SpectralModel


def test_occupancy_cumulants_of_a_sine_mode_are_campbells(paper_bridge):
    # Closed form (docs: theory, The occupancy of a mode): κ_r(λ) = n C(2r, r) 4^-r / (n/2)^r
    # for a sine mode over the full deck, n = d L B walkers on average.
    density = 0.25
    n = density * 50.0 * 3.0
    expected = [n * comb(2 * r, r) / 4**r / (n / 2) ** r for r in range(1, 5)]
    found = occupancy_cumulants(paper_bridge, density, 0, order=4)
    np.testing.assert_allclose(found, expected, rtol=2e-3)
    assert found[1] == pytest.approx(3 / (2 * n), rel=2e-3)


def test_quadrature_matches_a_monte_carlo_compound_poisson_occupancy(paper_bridge, rng):
    # Independent reference: draw the occupancy directly, Poisson(n) walkers at uniform positions
    # on the sine mode, λ = Σ sin²(π x/L) / (n/2); compare E[g(λ)] for a resonance-like g.
    crowd = Crowd.from_density(0.25)
    n = 0.25 * 150.0
    counts = rng.poisson(n, 200_000)
    positions = rng.uniform(0.0, 1.0, counts.sum())
    owner = np.repeat(np.arange(counts.size), counts)
    occupancy = np.bincount(owner, np.sin(np.pi * positions) ** 2, counts.size) / (n / 2)
    nodes, weights = occupancy_quadrature(paper_bridge, crowd, 0, n_nodes=3)

    def response(lam):   # λ |H|² of an oscillator whose frequency falls with the added mass
        return lam / ((1 - 1.0 / (1 + 0.03 * lam)) ** 2 + 0.01**2)

    monte_carlo = response(occupancy).mean()
    error = response(occupancy).std() / np.sqrt(occupancy.size)
    assert weights @ response(nodes) == pytest.approx(monte_carlo, abs=4 * error)
    assert weights.sum() == pytest.approx(1.0)
    assert weights @ nodes == pytest.approx(1.0, abs=1e-9)
    assert np.all(nodes > 0)


def test_gauss_rule_of_a_normal_law_is_gauss_hermite():
    # A finely discretised standard normal must give Gauss–Hermite: nodes 0, ±√3, weights
    # 2/3, 1/6 (Abramowitz & Stegun 25.4.46).
    from crowdvib.response.frequency_domain import fluctuation

    grid = np.linspace(-12, 12, 20001)
    nodes, weights = fluctuation._gauss_rule(grid, np.exp(-grid**2 / 2) / np.sum(
        np.exp(-grid**2 / 2)), 3)
    np.testing.assert_allclose(nodes, [-np.sqrt(3), 0, np.sqrt(3)], atol=1e-9)
    np.testing.assert_allclose(weights, [1 / 6, 2 / 3, 1 / 6], atol=1e-9)


def test_one_node_is_the_smeared_model(paper_bridge, paper_crowd, paper_msd, welch_grid):
    smeared = SpectralModel(paper_bridge, paper_crowd, welch_grid, welch_window_length=60.0)
    single = FluctuatingSpectralModel(paper_bridge, paper_crowd, welch_grid, n_nodes=1,
                                      welch_window_length=60.0, finite_crossing=False)
    np.testing.assert_array_equal(single.psd_array(paper_msd), smeared.psd_array(paper_msd))


def test_fluctuation_widens_the_resonance_and_keeps_the_mean_load(paper_bridge, paper_msd):
    # Without HSI the load is linear in λ, so the mixture equals the smeared PSD (E[λ] = 1);
    # with HSI the occupied frequency moves with λ and the mixture has a lower, wider peak
    # (the load's finite crossings left out here: tests/response/test_crossing.py).
    crowd = Crowd.from_density(0.25)
    grid = np.linspace(1.5, 2.5, 2001)
    smeared = SpectralModel(paper_bridge, crowd, grid)
    mixed = FluctuatingSpectralModel(paper_bridge, crowd, grid, finite_crossing=False)
    np.testing.assert_allclose(mixed.psd_array(None), smeared.psd_array(None), rtol=1e-9)
    a, b = smeared.psd_array(paper_msd)[0], mixed.psd_array(paper_msd)[0]
    assert b.max() < 0.95 * a.max()
    assert np.trapezoid(b, grid) == pytest.approx(np.trapezoid(a, grid), rel=0.02)


def test_dominant_mode_of_a_two_mode_bridge(paper_crowd, welch_grid):
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3, n_modes=2)
    model = FluctuatingSpectralModel(bridge, paper_crowd, welch_grid[welch_grid <= 4.0])
    assert model.mode == 0     # mode 2 (8 Hz) lies outside the grid


def test_unknown_crowd_model_is_refused(paper_bridge, paper_crowd, welch_grid):
    with pytest.raises(ParameterError, match="crowd_model must be one of"):
        spectral_model(paper_bridge, paper_crowd, welch_grid, crowd_model="frozen")
    with pytest.raises(ParameterError, match="n_nodes must be an integer"):
        FluctuatingSpectralModel(paper_bridge, paper_crowd, welch_grid, n_nodes=0)


def test_occupancy_law_has_campbells_mean_and_variance(paper_bridge):
    # The FFT-inverted characteristic function against the cumulants κ_1 = 1, κ_2 = 3/(2n).
    from crowdvib.response.frequency_domain.fluctuation import occupancy_law

    values, probabilities = occupancy_law(paper_bridge, 0.25, 0)
    assert probabilities @ values == pytest.approx(1.0, abs=1e-9)
    assert probabilities @ (values - 1) ** 2 == pytest.approx(3 / (2 * 37.5), rel=1e-6)


def test_node_count_follows_the_spread_of_the_occupied_frequency(paper_bridge, paper_msd):
    # Paper example: the occupied frequency moves by less than the resonance width over the
    # occupancy's spread, 3 nodes do. A 20 m bridge whose 12 walkers carry 10 % of the modal
    # mass needs more; the chosen rule must agree with a 40-node rule (the reference) within
    # the 0.5 % of the peak it was chosen for (plus the reference's own small error).
    crowd = Crowd(density=0.3, walking_speed=1.3, step_frequency_mean=1.95,
                  step_frequency_std=0.175, body_mass=70.0)
    grid = np.arange(361) / 60.0
    assert FluctuatingSpectralModel(paper_bridge, Crowd.from_density(0.25), np.arange(601) / 60,
                                    welch_window_length=60.0).nodes.size == 3
    small = ModalModel.simply_supported_beam(20.0, 2.0, 2.0, 0.005, 4200.0)
    # The mixture's rule (this bridge's occupancy is too fast for the slow-modulation term).
    chosen = FluctuatingSpectralModel(small, crowd, grid, welch_window_length=60.0,
                                      modulation=False)
    reference = FluctuatingSpectralModel(small, crowd, grid, welch_window_length=60.0,
                                         n_nodes=40, modulation=False)
    assert chosen.nodes.size > 3
    a, b = chosen.psd_array(paper_msd)[0], reference.psd_array(paper_msd)[0]
    assert np.abs(a - b).max() < 0.01 * b.max()


def test_occupancy_law_is_the_direct_inversion(paper_bridge):
    # The exponent is taken for t ≥ 0 and conjugated for t < 0 (ψ real), its exponentials as
    # products of √(n/2) × √(n/2) blocks (issue 39), which only rearranges the arithmetic: the
    # direct inversion of Campbell's characteristic function over the whole FFT grid (the
    # computation of commit 0e6e805) to 1e-15.
    from crowdvib.response.frequency_domain.fluctuation import _LAW_POINTS, occupancy_law
    for density in (0.25, 1.0):
        values, probabilities = occupancy_law(paper_bridge, density, 0)
        area = density * paper_bridge._area_weights.ravel()
        share = (paper_bridge.mode_shapes[..., 0] ** 2).ravel()
        share = share / np.sum(area * share)
        t = 2 * np.pi * np.fft.fftfreq(_LAW_POINTS, values[1])
        direct = np.maximum(np.fft.fft(np.exp((np.exp(1j * np.outer(t, share)) - 1.0) @ area)
                                       ).real / _LAW_POINTS, 0.0)
        np.testing.assert_allclose(probabilities, direct / direct.sum(), rtol=0, atol=1e-15)
        assert probabilities.max() > 1e-4


def test_one_mode_crowd_factor_is_the_eigen_decompositions():
    # psd_factor skips eigh for a 1 × 1 Ψ (the fluctuating estimate asks thousands of times):
    # the same B with Ψ = B Bᵀ as from eigh (the computation before, commit 0e6e805), empty
    # where Ψ carries no crowd.
    from crowdvib.response.frequency_domain._attached import psd_factor
    for value in (37.5, 5e-7, 0.0):
        psi = np.array([[value]])
        values, vectors = np.linalg.eigh(psi)
        keep = values > values.max(initial=0.0) * 1e-12
        expected = vectors[:, keep] * np.sqrt(values[keep])
        assert psd_factor(psi).shape == expected.shape
        np.testing.assert_allclose(psd_factor(psi), expected, rtol=1e-15)
        np.testing.assert_allclose(psd_factor(psi) @ psd_factor(psi).T, psi, rtol=1e-15)


def test_a_kept_occupancy_law_is_the_law_computed_afresh():
    # occupancy_law keeps its last laws under (density, area weights, mode shape) (issue 39):
    # a structure that differs in its frequencies, damping and masses only gets the same law,
    # and it equals the computation without the cache (the reference: _occupancy_law).
    from crowdvib import ModalModel
    from crowdvib.response.frequency_domain import fluctuation

    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    other = bridge.replace(frequencies=bridge.frequencies * 1.05,
                           modal_masses=bridge.modal_masses * 0.95)
    kept = fluctuation.occupancy_law(bridge, 0.5, 0)
    again = fluctuation.occupancy_law(other, 0.5, 0)
    fresh = fluctuation._occupancy_law(other, 0.5, 0)
    for a, b, c in zip(kept, again, fresh):
        np.testing.assert_array_equal(a, c)
        np.testing.assert_array_equal(b, c)
    kept[1][:] = 0.0                       # the caller's copy: the kept law is untouched
    assert fluctuation.occupancy_law(bridge, 0.5, 0)[1].sum() == pytest.approx(1.0)
    denser = fluctuation.occupancy_law(bridge, 0.8, 0)
    np.testing.assert_array_equal(denser[1], fluctuation._occupancy_law(bridge, 0.8, 0)[1])


_LAW_BITS = """
import hashlib
from crowdvib import ModalModel
from crowdvib.response.frequency_domain.fluctuation import _occupancy_law
bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
print(hashlib.sha256(_occupancy_law(bridge, 0.5, 0)[1].tobytes()).hexdigest())
"""


def test_the_occupancy_law_has_the_same_bits_whatever_blas_threads():
    # A study's tasks give the same numbers in a dask worker (one BLAS thread) as in the
    # calling process (tests/studies/test_sensitivity.py::test_dask_local_cluster_equals_serial):
    # the law is computed without a BLAS product, whose rounding follows the thread count (the
    # law by a matrix product differed in its last bits between 1 and 2 threads).
    import subprocess
    import sys

    found = set()
    for threads in ("1", "2"):
        env = dict(os.environ, OPENBLAS_NUM_THREADS=threads, OMP_NUM_THREADS=threads,
                   MKL_NUM_THREADS=threads)
        found.add(subprocess.run([sys.executable, "-c", _LAW_BITS], env=env, check=True,
                                 capture_output=True, text=True).stdout.strip())
    assert len(found) == 1
