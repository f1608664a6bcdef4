"""The paper's numerical example against the reference numbers of docs: theory, Reference values."""

import numpy as np
import pytest

from crowdvib import ZivanovicForce, effective_modal_properties, frf, response_psd

FINE = np.linspace(0.001, 20.0, 200_001)


def test_occupied_peak_of_frf_is_1926_hz(paper_bridge, paper_crowd, paper_msd):
    # docs: theory, The occupied peak at 1.93 Hz: peak of |H| with m_h = 70 kg total, smeared crowd: 1.9260 Hz
    # (the paper prints 1.93 Hz). Displacement receptance peak = peak of |FRF|/ω².
    f = np.linspace(1.8, 2.1, 30_001)
    h = frf(paper_bridge, f, crowd=paper_crowd, msd=paper_msd)
    receptance = np.abs(h.values[0, 0]) / (2 * np.pi * f) ** 2
    assert f[np.argmax(receptance)] == pytest.approx(1.926, abs=0.002)


def test_effective_modal_properties(paper_bridge, paper_crowd, paper_msd):
    # docs: theory, The occupied peak at 1.93 Hz, reduced 2-DOF eigen: 1.9263 Hz, ξ = 1.20 % (+ MSD-like 3.111 Hz, 30.0 %).
    props = effective_modal_properties(paper_bridge, paper_crowd, paper_msd)
    assert props.frequencies[0] == pytest.approx(1.926, abs=0.002)
    assert props.damping_ratios[0] == pytest.approx(0.0120, abs=0.0005)
    assert props.interaction_frequencies[0] == pytest.approx(3.111, abs=0.002)
    assert props.interaction_damping_ratios[0] == pytest.approx(0.300, abs=0.002)


def test_modal_mass_ratio(paper_bridge):
    # docs: theory, The occupied peak at 1.93 Hz: Ψ11 = n/2 = 37.5, μ_m = 70·37.5/50000 = 5.25 %.
    assert paper_bridge.influence_matrix(0.5)[0, 0] == pytest.approx(37.5, rel=1e-12)
    assert paper_bridge.modal_mass_ratios(0.5, 70.0)[0] == pytest.approx(0.0525, rel=1e-12)


def test_modal_load_standard_deviation(paper_bridge, paper_crowd):
    # docs: theory, Spectral-model numbers: σ of the modal load Q = 1155.9 N (subharmonics on the mean α₁).
    force = ZivanovicForce(subharmonics_follow_sampled_dlf=False)
    psd = force.modal_load_psd(FINE, paper_crowd, paper_bridge)[:, 0, 0]
    assert np.sqrt(np.trapezoid(psd, FINE)) == pytest.approx(1155.9, rel=0.01)


@pytest.mark.parametrize("hsi, peak_frequency, peak, rms, welch_peak", [
    # docs: theory, Spectral-model numbers: without HSI peak 2.000 Hz, 11.14 (m/s²)²/Hz, RMS 0.578 m/s², Welch 7.36;
    # with HSI (3 Hz, 0.30, 0.95) peak 1.927 Hz, 1.658 (m/s²)²/Hz, RMS 0.330 m/s², Welch 1.39.
    (False, 2.000, 11.14, 0.578, 7.36),
    (True, 1.927, 1.658, 0.330, 1.39),
])
def test_response_psd_reference_values(paper_bridge, paper_crowd, paper_msd, welch_grid,
                                        hsi, peak_frequency, peak, rms, welch_peak):
    force = ZivanovicForce(subharmonics_follow_sampled_dlf=False)
    msd = paper_msd if hsi else None
    exact = response_psd(paper_bridge, paper_crowd, FINE, msd=msd, force=force)
    assert exact.peak_frequency()[0] == pytest.approx(peak_frequency, abs=0.002)
    assert exact.psd.max() == pytest.approx(peak, rel=0.01)
    assert exact.rms()[0] == pytest.approx(rms, rel=0.01)
    welch = response_psd(paper_bridge, paper_crowd, welch_grid, msd=msd, force=force,
                         welch_window_length=60.0)
    assert welch.psd.max() == pytest.approx(welch_peak, rel=0.01)
    # Welch smoothing redistributes power but keeps it (unit-area kernel, docs: theory, What a Welch estimate sees: the expectation kernel).
    assert welch.rms()[0] == pytest.approx(exact.rms()[0], rel=0.002)
