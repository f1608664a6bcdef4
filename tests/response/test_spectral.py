"""The vectorised spectral model against the per-frequency reference sketch of docs: theory, Response PSD with HSI."""

import numpy as np
import pytest

from crowdvib import Crowd, ModalModel, MSDModel, ZivanovicForce, estimate_hsi, frf, response_psd


def reference_psd(structure, crowd, msd, frequency):
    """docs: theory, Response PSD with HSI written literally: one matrix inverse per frequency."""
    psi = structure.influence_matrix(crowd.density)
    load = ZivanovicForce().load_spectrum(frequency, crowd)
    m = structure.modal_masses
    wn = 2 * np.pi * structure.frequencies
    out = []
    for f, s in zip(frequency, load):
        w = 2 * np.pi * f
        added = msd.apparent_mass(f, crowd.body_mass) * psi if msd else 0.0
        h = np.linalg.inv(np.diag(m * wn**2) - w**2 * (np.diag(m) + added)
                          + 1j * w * np.diag(2 * structure.damping_ratios * m * wn))
        ha = -w**2 * structure.output_shapes @ h
        out.append(np.real(np.diag(ha @ (s * psi) @ ha.conj().T)))
    return np.array(out).T


@pytest.fixture
def coupled_bridge():
    """Three modes whose shapes are not orthogonal on the walkway (Ψ has off-diagonal terms)."""
    x = np.linspace(0, 40.0, 161)
    shapes = np.column_stack([np.sin(np.pi * x / 40), np.sin(np.pi * x / 40) ** 3 * 0.8,
                              np.sin(2 * np.pi * x / 40) + 0.3 * np.sin(np.pi * x / 40)])
    return ModalModel(frequencies=[1.9, 2.9, 4.4], damping_ratios=[0.004, 0.006, 0.01],
                      modal_masses=[30e3, 25e3, 28e3], positions=x, mode_shapes=shapes,
                      width=2.5, output_names=["mid", "quarter"],
                      output_shapes=[shapes[80], shapes[40]])


def test_multi_mode_psd_matches_reference(coupled_bridge):
    crowd = Crowd.from_density(0.8)
    msd = MSDModel(2.7, 0.35, 0.95)
    f = np.linspace(0.05, 9.0, 700)
    psi = coupled_bridge.influence_matrix(0.8)
    assert abs(psi[0, 1]) > 0.1 * psi[0, 0]      # really coupled
    for model in (msd, None):
        ours = response_psd(coupled_bridge, crowd, f, msd=model, crowd_model="smeared").psd
        np.testing.assert_allclose(ours, reference_psd(coupled_bridge, crowd, model, f),
                                   rtol=1e-8, atol=1e-12 * ours.max())


def test_frf_occupied_matches_reference(coupled_bridge):
    crowd = Crowd.from_density(0.8)
    msd = MSDModel(2.7, 0.35, 0.95)
    f = np.linspace(0.5, 6.0, 50)
    got = frf(coupled_bridge, f, crowd=crowd, msd=msd, outputs=["mid"], inputs=["quarter"])
    psi = coupled_bridge.influence_matrix(0.8)
    m, wn = coupled_bridge.modal_masses, 2 * np.pi * coupled_bridge.frequencies
    shapes = coupled_bridge.output_shapes
    for k, fk in enumerate(f):
        w = 2 * np.pi * fk
        h = np.linalg.inv(np.diag(m * wn**2) - w**2 * (np.diag(m) + msd.apparent_mass(fk, 70) * psi)
                          + 1j * w * np.diag(2 * coupled_bridge.damping_ratios * m * wn))
        assert got.values[0, 0, k] == pytest.approx(-w**2 * shapes[0] @ h @ shapes[1], rel=1e-9)


def test_frequency_weights_change_the_fit_only_where_they_act(paper_bridge, paper_crowd,
                                                             paper_msd, welch_grid):
    # On noise-free data every weighting recovers the truth; the cost is the weighted sum of
    # squares (paper Eq. 6 with γ_ω), so doubling all weights leaves the normalised optimum alone.
    measured = response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd,
                            crowd_model="smeared")
    weighted = estimate_hsi(measured, paper_bridge, paper_crowd, band=(0.0, 10.0),
                            method="least_squares",
                            frequency_weights=lambda f: np.where(f > 2.5, 5.0, 1.0))
    assert weighted.msd.frequency == pytest.approx(3.0, rel=1e-3)
    plain = estimate_hsi(measured, paper_bridge, paper_crowd, band=(0.0, 10.0),
                         method="least_squares")
    doubled = estimate_hsi(measured, paper_bridge, paper_crowd, band=(0.0, 10.0),
                           method="least_squares", frequency_weights=np.full(welch_grid.size, 2.0))
    assert doubled.cost_no_hsi == pytest.approx(2 * plain.cost_no_hsi, rel=1e-12)
