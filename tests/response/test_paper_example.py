"""The paper's numerical example against its reference numbers (docs: theory, Reference values)."""

import numpy as np
import pytest

from crowdvib import ZivanovicForce, effective_modal_properties, frf, response_psd

pytestmark = pytest.mark.reference

FINE = np.linspace(0.001, 20.0, 200_001)
_PEAK = "docs: theory, The occupied peak at 1.93 Hz (paper: 1.93 Hz)"
_NUMBERS = "docs: theory, Spectral-model numbers (independent check values)"


def test_occupied_peak_of_frf_is_1926_hz(paper_bridge, paper_crowd, paper_msd, reference):
    # docs: theory, The occupied peak at 1.93 Hz: peak of |H| with m_h = 70 kg total, smeared crowd: 1.9260 Hz
    # (the paper prints 1.93 Hz). Displacement receptance peak = peak of |FRF|/ω².
    f = np.linspace(1.8, 2.1, 30_001)
    h = frf(paper_bridge, f, crowd=paper_crowd, msd=paper_msd)
    receptance = np.abs(h.values[0, 0]) / (2 * np.pi * f) ** 2
    reference("paper example: peak of the occupied receptance", f[np.argmax(receptance)], 1.926,
              abs=0.002, unit="Hz", source=_PEAK)


def test_effective_modal_properties(paper_bridge, paper_crowd, paper_msd, reference):
    # docs: theory, The occupied peak at 1.93 Hz, reduced 2-DOF eigen: 1.9263 Hz, ξ = 1.20 % (+ MSD-like 3.111 Hz, 30.0 %).
    props = effective_modal_properties(paper_bridge, paper_crowd, paper_msd)
    reference("paper example: occupied structural frequency", props.frequencies[0], 1.926,
              abs=0.002, unit="Hz", source=_PEAK)
    reference("paper example: occupied structural damping ratio", props.damping_ratios[0],
              0.0120, abs=0.0005, source=_PEAK)
    reference("paper example: MSD-like pole frequency", props.interaction_frequencies[0],
              3.111, abs=0.002, unit="Hz", source=_PEAK)
    reference("paper example: MSD-like pole damping ratio",
              props.interaction_damping_ratios[0], 0.300, abs=0.002, source=_PEAK)


def test_modal_mass_ratio(paper_bridge, reference):
    # docs: theory, The occupied peak at 1.93 Hz: Ψ11 = n/2 = 37.5, μ_m = 70·37.5/50000 = 5.25 %.
    reference("influence Ψ11 of a unity-scaled sine mode at 0.5 P/m² (n/2)",
              paper_bridge.influence_matrix(0.5)[0, 0], 37.5, rel=1e-12, unit="persons",
              source="closed form ∫ρ sin² = n/2; " + _PEAK)
    reference("crowd-to-mode mass ratio μ_m = 70·37.5/50 000",
              paper_bridge.modal_mass_ratios(0.5, 70.0)[0], 0.0525, rel=1e-12, source=_PEAK)


def test_modal_load_standard_deviation(paper_bridge, paper_crowd, reference):
    # docs: theory, Spectral-model numbers: σ of the modal load Q = 1155.9 N (subharmonics on the mean α₁).
    force = ZivanovicForce(subharmonics_follow_sampled_dlf=False)
    psd = force.modal_load_psd(FINE, paper_crowd, paper_bridge)[:, 0, 0]
    reference("paper example: standard deviation of the modal load Q",
              np.sqrt(np.trapezoid(psd, FINE)), 1155.9, rel=0.01, unit="N", source=_NUMBERS)


@pytest.mark.parametrize("hsi, peak_frequency, peak, rms, welch_peak", [
    # docs: theory, Spectral-model numbers: without HSI peak 2.000 Hz, 11.14 (m/s²)²/Hz, RMS 0.578 m/s², Welch 7.36;
    # with HSI (3 Hz, 0.30, 0.95) peak 1.927 Hz, 1.658 (m/s²)²/Hz, RMS 0.330 m/s², Welch 1.39.
    (False, 2.000, 11.14, 0.578, 7.36),
    (True, 1.927, 1.658, 0.330, 1.39),
])
def test_response_psd_reference_values(paper_bridge, paper_crowd, paper_msd, welch_grid,
                                        hsi, peak_frequency, peak, rms, welch_peak, reference):
    force = ZivanovicForce(subharmonics_follow_sampled_dlf=False)
    msd = paper_msd if hsi else None
    exact = response_psd(paper_bridge, paper_crowd, FINE, msd=msd, force=force,
                         crowd_model="smeared")
    case = "with HSI" if hsi else "without HSI"
    reference(f"paper example {case}: frequency of the PSD peak", exact.peak_frequency()[0],
              peak_frequency, abs=0.002, unit="Hz", source=_NUMBERS)
    reference(f"paper example {case}: PSD peak", exact.psd.max(), peak, rel=0.01,
              unit="(m/s²)²/Hz", source=_NUMBERS)
    reference(f"paper example {case}: RMS acceleration", exact.rms()[0], rms, rel=0.01,
              unit="m/s²", source=_NUMBERS)
    welch = response_psd(paper_bridge, paper_crowd, welch_grid, msd=msd, force=force,
                         welch_window_length=60.0, crowd_model="smeared")
    reference(f"paper example {case}: Welch (T = 60 s) PSD peak", welch.psd.max(), welch_peak,
              rel=0.01, unit="(m/s²)²/Hz", source=_NUMBERS)
    # Welch smoothing redistributes power but keeps it (unit-area kernel, docs: theory, What a Welch estimate sees: the expectation kernel).
    assert welch.rms()[0] == pytest.approx(exact.rms()[0], rel=0.002)
