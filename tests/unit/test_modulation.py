"""The slow-modulation correction to the quasi-static mixture (docs: theory, The fluctuating
crowd, Beyond the quasi-static mixture)."""

import dataclasses
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from crowdvib import (Crowd, ModalModel, ModelRangeWarning, MSDModel,
                      effective_modal_properties)
import crowdvib.response._modulation as module
from crowdvib.response._modulation import (_STEP, _OccupiedMode, expansion,
                                           modulation_correction, occupancy_rate_variance)
from crowdvib.response.fluctuation import FluctuatingSpectralModel
from crowdvib.response.spectral import SpectralModel

GRID = np.arange(601) / 60.0


def test_rate_variance_of_a_half_sine(paper_bridge):
    # Campbell: Var ψ̇ = d v² ∫(∂φ²/∂x)² dA = d v² B π²/(2L) and ψ̄ = d B L / 2 for φ = sin(πx/L),
    # so Var λ̇ = 2π² v² / (d B L³); the stations' differences reach it to 1e-4.
    for density, speed in ((0.25, 1.34), (1.0, 0.8)):
        expected = 2 * np.pi**2 * speed**2 / (density * 3.0 * 50.0**3)
        assert occupancy_rate_variance(paper_bridge, density, speed, 0) == pytest.approx(
            expected, rel=1e-4)


def _direct_transfer(occupied, shape, path, frequency, duration=120.0):
    """G(ω, s) = ∫₀^T C Φ(s+u, s) b e^{−iωu} du along a prescribed occupancy path λ(s+u), by
    integrating the state equation (an independent route to the expansion)."""
    omega = 2 * np.pi * frequency
    load = occupied.system(path(0.0))[1][:, 0].astype(complex)

    def rates(u, y):
        state = occupied.system(path(u))[0]
        z = y[:-1]
        return np.append((state - 1j * omega * np.eye(len(z))) @ z, shape * z[0])

    solution = solve_ivp(rates, (0.0, duration), np.append(load, 0j), method="DOP853",
                         rtol=1e-11, atol=1e-16)
    return solution.y[-1, -1]


@pytest.mark.parametrize("frequency", [1.94, 1.985])
def test_expansion_is_second_order_in_the_rate_of_change(paper_bridge, paper_msd, frequency):
    # The residual of G₀ + λ̇ G₁ + λ̇² G₂ against the direct integration along λ = 1 + λ̇ u is of
    # third order: halving λ̇ divides it by 8 (±25 %), and the expansion takes away most of the
    # change G − G₀. Likewise for a curvature λ̈ (residual of G₀ + λ̈ G₃ of second order in λ̈).
    crowd = Crowd.from_density(0.25)
    attached = SpectralModel(paper_bridge, crowd, GRID)._attached(paper_msd)
    occupied = _OccupiedMode(paper_bridge, attached, 0)
    g0, g1, g2, g3 = expansion(occupied, np.array([1.0]), np.array([1.0]),
                               np.array([frequency]))
    g0, g3 = g0[0, 1, 0, 0, 0], g3[0, 1, 0, 0, 0]
    g1, g2 = g1[0, 0, 0, 0, 0], g2[0, 0, 0, 0, 0]

    def residuals(rate, curvature):
        direct = _direct_transfer(occupied, 1.0, lambda u: 1.0 + rate * u + curvature * u**2 / 2,
                                  frequency)
        model = g0 + rate * g1 + rate**2 * g2 + curvature * g3
        return abs(direct - model), abs(direct - g0)

    rate = 2e-3                                   # λ̇ [1/s]: a tenth of σ_λ̇ at 0.25 P/m²
    (big, change), (small, _) = residuals(rate, 0.0), residuals(rate / 2, 0.0)
    assert big < 0.2 * change
    assert 8 / 1.25 < big / small < 8 * 1.25
    curvature = 1e-4                              # λ̈ [1/s²] (at 4e-4 third order shows)
    (big, change), (small, _) = residuals(0.0, curvature), residuals(0.0, curvature / 2)
    assert big < 0.2 * change
    assert 4 / 1.25 < big / small < 4 * 1.25


def test_correction_is_left_out_without_hsi_or_with_one_node(paper_bridge, paper_crowd,
                                                             paper_msd):
    # Without MSDs nothing in the system depends on λ but the load's intensity, whose mean is
    # the mixture's: the correction is zero. One node is the smeared model, by definition.
    on = FluctuatingSpectralModel(paper_bridge, paper_crowd, GRID, welch_window_length=60.0)
    off = FluctuatingSpectralModel(paper_bridge, paper_crowd, GRID, welch_window_length=60.0,
                                   modulation=False)
    assert on.rate_variance > 0 and off.rate_variance == 0
    np.testing.assert_array_equal(on.psd_array(None), off.psd_array(None))
    one = FluctuatingSpectralModel(paper_bridge, paper_crowd, GRID, welch_window_length=60.0,
                                   n_nodes=1)
    np.testing.assert_array_equal(
        one.psd_array(paper_msd),
        SpectralModel(paper_bridge, paper_crowd, GRID, welch_window_length=60.0,
                      crossing_spread=one.crossing_spread).psd_array(paper_msd))
    # With HSI it moves the occupied resonance by a few per cent, not more (docs: the
    # second-order term at 0.5 P/m² and 1.3 m/s).
    a, b = on.psd_array(paper_msd)[0], off.psd_array(paper_msd)[0]
    assert 0.002 < np.abs(a - b).max() / b.max() < 0.05


def test_cross_spectral_matrix_carries_the_same_correction(paper_msd):
    # Two outputs of a two-mode beam: the diagonal of the corrected cross-spectral matrix is the
    # corrected PSD, and the matrix stays Hermitian.
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3, n_modes=2,
                                              outputs={"mid": 25.0, "quarter": 12.5})
    crowd = Crowd.from_density(0.5)
    model = FluctuatingSpectralModel(bridge, crowd, GRID, welch_window_length=60.0)
    assert model.rate_variance > 0
    cross = model.cross_psd_array(paper_msd)
    np.testing.assert_allclose(np.einsum("aaf->af", cross).real, model.psd_array(paper_msd),
                               rtol=1e-9, atol=1e-12 * cross.real.max())
    np.testing.assert_allclose(cross, np.conj(np.swapaxes(cross, 0, 1)),
                               atol=1e-12 * np.abs(cross).max())


def test_correction_is_negligible_beyond_its_reach(paper_bridge, paper_msd, monkeypatch):
    # Computed within 40 half-power widths of the occupied pole: against a reach of 400, the
    # truncated part is below 1e-3 of the PSD's peak.
    crowd = Crowd.from_density(0.25)
    model = FluctuatingSpectralModel(paper_bridge, crowd, GRID)
    attached = model._base._attached(paper_msd)
    args = (paper_bridge, attached, model._base._shapes, 0, model.nodes, model.weights,
            model.rate_variance, GRID)
    default = modulation_correction(*args)
    monkeypatch.setattr(module, "_REACH", 400.0)
    monkeypatch.setattr(module, "_MIN_REACH", 5.0)
    wide = modulation_correction(*args)
    mixture = FluctuatingSpectralModel(paper_bridge, crowd, GRID, modulation=False)
    weight = model._base._weight_at(GRID)
    assert np.abs((wide - default) * weight).max() < 1e-3 * mixture.psd_array(paper_msd).max()
    assert np.abs(default).max() > 0


def test_fast_occupancy_leaves_the_correction_out_with_a_warning(paper_bridge, paper_msd):
    # Walkers at 3 m/s on the paper's example: expansion parameter 3.9 (> 1), where the
    # second-order term overshoots (docs); the quasi-static mixture is used and the user told.
    crowd = dataclasses.replace(Crowd.from_density(0.25), walking_speed=3.0)
    with pytest.warns(ModelRangeWarning, match="changes too fast"):
        fast = FluctuatingSpectralModel(paper_bridge, crowd, GRID, welch_window_length=60.0)
    # ε = Var λ̇ / (Var λ Γ²) from independent pieces: Var λ̇ = 2π²v²/(dBL³) and Var λ = 3/(2n),
    # n = dBL walkers (Campbell, closed forms for the half sine), Γ = ξ 2πf of the occupied
    # mode with the paper's MSD (effective_modal_properties, the smeared model's own poles).
    occupied = effective_modal_properties(paper_bridge, crowd, MSDModel())
    decay = occupied.damping_ratios[0] * 2 * np.pi * occupied.frequencies[0]
    walkers = crowd.density * 3.0 * 50.0
    expected = (2 * np.pi**2 * 3.0**2 / (crowd.density * 3.0 * 50.0**3)
                / (1.5 / walkers * decay**2))
    assert fast.modulation_parameter == pytest.approx(expected, rel=2e-3)
    assert fast.modulation_parameter > 1
    assert fast.rate_variance == 0
    plain = FluctuatingSpectralModel(paper_bridge, crowd, GRID, welch_window_length=60.0,
                                     modulation=False)
    np.testing.assert_array_equal(fast.psd_array(paper_msd), plain.psd_array(paper_msd))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        slow = FluctuatingSpectralModel(paper_bridge, Crowd.from_density(0.25), GRID)
    # The same ε at Weidmann's 1.34 m/s: the speed enters squared.
    speed = Crowd.from_density(0.25).walking_speed
    assert slow.modulation_parameter == pytest.approx(expected * (speed / 3.0) ** 2, rel=2e-3)
    assert slow.modulation_parameter < 1


def test_with_step_frequencies_keeps_the_correction(paper_bridge, paper_msd):
    # The estimator's free step frequencies rebuild the models: the corrected PSD must equal a
    # model built directly for that crowd.
    crowd = Crowd.from_density(0.25)
    other = dataclasses.replace(crowd, step_frequency_mean=1.95, step_frequency_std=0.2)
    model = FluctuatingSpectralModel(paper_bridge, crowd, GRID, welch_window_length=60.0)
    direct = FluctuatingSpectralModel(paper_bridge, other, GRID, welch_window_length=60.0)
    np.testing.assert_allclose(model.with_step_frequencies(other).psd_array(paper_msd),
                               direct.psd_array(paper_msd), rtol=1e-12)


def test_expansion_terms_against_dense_algebra(paper_bridge, paper_msd):
    # G₁ = C R A' R² b and G₃ = C R A' R³ b from the eigenbasis against explicit inverses
    # R = (iω − A)⁻¹ and a central difference for A', at two nodes and two frequencies.
    attached = SpectralModel(paper_bridge, Crowd.from_density(0.5), GRID)._attached(paper_msd)
    occupied = _OccupiedMode(paper_bridge, attached, 0)
    nodes, frequency = np.array([0.8, 1.1]), np.array([1.90, 1.93])
    _, g1, _, g3 = expansion(occupied, np.array([1.0]), nodes, frequency)
    for i, node in enumerate(nodes):
        h = _STEP * node
        state, load = occupied.system(node)
        slope = (occupied.system(node + h)[0] - occupied.system(node - h)[0]) / (2 * h)
        for j, f in enumerate(frequency):
            resolvent = np.linalg.inv(2j * np.pi * f * np.eye(len(state)) - state)
            first = resolvent @ slope @ resolvent @ resolvent
            assert g1[i, 0, j, 0, 0] == pytest.approx((first @ load)[0, 0], rel=1e-8)
            assert g3[i, 1, j, 0, 0] == pytest.approx((first @ resolvent @ load)[0, 0],
                                                      rel=1e-8)
