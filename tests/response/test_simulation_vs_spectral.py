"""Monte Carlo (time domain) against the spectral model, and parameter recovery (docs: theory, Time domain against spectral model).

The paper's numerical example (docs: theory, The paper's numerical example). Each check runs one seeded realisation; the
tolerances are those of docs: theory, Time domain against spectral model and issue 3. Scatter between seeds seen while writing
these tests (3600 s with HSI, seeds 1, 2, 3): modal-load band ratios within 0.95–1.07, recovered
f_h1 = 2.999, 2.814, 3.041 Hz and ξ_h1 = 0.307, 0.328, 0.328 — a single hour is not always
within 3 % in f_h1 (seed 2 is not), so the recovery check runs five seeds (the paper's own
verification used one: docs: theory, Time domain against spectral model, 2.981 Hz and 0.271).
"""

import numpy as np
import pytest

from crowdvib import ZivanovicForce, estimate_hsi, response_psd, simulate, welch_psd

pytestmark = pytest.mark.slow

BANDS = [(1.5, 2.5), (2.5, 3.5), (3.5, 4.5), (4.5, 10.0)]
WINDOW = 60.0                       # Welch T [s], 50 % overlap (docs: theory, Welch PSDs, filters and convergence, §8.4)
GRID = np.arange(0, 601) / WINDOW   # the Welch grid up to 10 Hz
# Warm-up: the structure starts at rest; 5/(ξ ω) = 5/(0.005·4π) ≈ 80 s (docs: theory, Poisson arrivals).
WARM_UP = 100.0


def _band_ratios(measured, model):
    return np.array([measured.variance(lo, hi)[0] / model.variance(lo, hi)[0] for lo, hi in BANDS])


@pytest.mark.parametrize("hsi", [False, True], ids=["no-HSI", "HSI"])
def test_monte_carlo_matches_spectral_model(paper_bridge, paper_crowd, paper_msd, hsi):
    # docs: theory, Time domain against spectral model: 1500 s after warm-up, band variance ratios MC/spectral within ±15 %
    # (the reference run saw 1.13/1.04/1.00/1.01 without and 1.05/1.04/1.00/1.01 with HSI) and
    # the PSD peak in the same Welch bin as the Welch-smoothed spectral model (2.000 / 1.933 Hz).
    msd = paper_msd if hsi else None
    record = simulate(paper_bridge, paper_crowd, 1500.0, msd=msd, rng=2023, warm_up=WARM_UP)
    measured = record.psd(WINDOW)
    model = response_psd(paper_bridge, paper_crowd, GRID, msd=msd, welch_window_length=WINDOW,
                         crowd_model="smeared")
    ratios = _band_ratios(measured, model)
    assert np.all(np.abs(ratios - 1) <= 0.15), ratios
    assert abs(measured.peak_frequency()[0] - model.peak_frequency()[0]) <= 1 / WINDOW + 1e-9
    # docs: theory, Spectral-model numbers: spectral RMS 0.578 (no HSI) and 0.330 m/s² (HSI).
    assert record.acceleration.std() == pytest.approx(0.330 if hsi else 0.578, rel=0.10)


@pytest.fixture(scope="module")
def hour_with_hsi():
    """One simulated hour of the paper example with HSI (3.0 Hz, 0.30, 0.95), modal load kept."""
    from crowdvib import Crowd, ModalModel, MSDModel
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    crowd = Crowd(density=0.5, walking_speed=1.30, step_frequency_mean=1.89,
                  step_frequency_std=0.175, body_mass=70.0)
    record = simulate(bridge, crowd, 3600.0, msd=MSDModel(3.0, 0.30, 0.95), rng=1,
                      warm_up=WARM_UP, record_modal_load=True)
    return bridge, crowd, record


def test_modal_load_matches_load_spectrum(hour_with_hsi):
    # docs: theory, Modal load PSD of a Poisson crowd: G_Q(f) = Ψ₁₁ s(f) with Ψ₁₁ = n/2 = 37.5 (§8.2). The modal walking load
    # does not depend on the structure: ±5 % per band and in the standard deviation (issue 3).
    bridge, crowd, record = hour_with_hsi
    load = welch_psd(record.modal_load, record.sample_rate, window_length=WINDOW)
    psi = bridge.influence_matrix(crowd.density)[0, 0]
    force = ZivanovicForce()
    model = type(load)(frequency=GRID, psd=force.load_spectrum(GRID, crowd)[None] * psi,
                       output_names=load.output_names)
    ratios = _band_ratios(load, model)
    assert np.all(np.abs(ratios - 1) <= 0.05), ratios
    fine = np.linspace(1e-3, 25.0, 25_001)
    sigma = np.sqrt(psi * np.trapezoid(force.load_spectrum(fine, crowd), fine))
    assert record.modal_load.std() == pytest.approx(sigma, rel=0.05)


def test_recovers_msd_parameters_from_simulated_hours(hour_with_hsi):
    # docs: theory, Time domain against spectral model / the paper's verification: (3.0 Hz, 0.30) back from a simulated hour with
    # the Welch-smoothed spectral model: f_h1 within 3 %, ξ_h1 within 20 %. One hour is one
    # random realisation (seeds 1–7 gave f_h1 = 2.999, 2.814, 3.041, 3.017, 2.934, 2.943, 2.917 Hz
    # and ξ_h1 = 0.307–0.344), so the claim is checked over the first five seeds: at least four
    # meet both tolerances and their mean is within them.
    bridge, crowd, first = hour_with_hsi
    from crowdvib import MSDModel
    found = []
    for seed in range(1, 6):
        record = first if seed == 1 else simulate(bridge, crowd, 3600.0,
                                                  msd=MSDModel(3.0, 0.30, 0.95), rng=seed,
                                                  warm_up=WARM_UP)
        estimate = estimate_hsi(record.psd(WINDOW), bridge, crowd, band=(0.0, 10.0))
        found.append((estimate.msd.frequency, estimate.msd.damping_ratio))
    error = np.array(found) / [3.0, 0.30] - 1.0
    within = (np.abs(error[:, 0]) <= 0.03) & (np.abs(error[:, 1]) <= 0.20)
    assert within.sum() >= 4, found
    assert abs(error[:, 0].mean()) <= 0.03 and abs(error[:, 1].mean()) <= 0.20, found
