"""The Welch expectation from a coarse rule with exact pole corrections (response.frequency_domain._welch_model)."""

from pathlib import Path

import numpy as np
import pytest

from crowdvib import MSDModel, SpectralModel
from crowdvib.io.casefile import load_case
from crowdvib.models.examples import paper_example
from crowdvib.response.frequency_domain._welch_model import hann_pole_convolution, power_coefficients
from crowdvib.signals import LowPassFilter, welch_kernel

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_power_coefficients_reproduce_the_summed_squared_modulus():
    # Reference: the definition Σ_r |Σ_p A_opr / (iω − λ_p)|², summed directly.
    rng = np.random.default_rng(3)
    poles = -rng.uniform(0.05, 2.0, 6) + 1j * rng.uniform(-30, 30, 6)
    left = rng.normal(size=(2, 6)) + 1j * rng.normal(size=(2, 6))
    right = rng.normal(size=(6, 3)) + 1j * rng.normal(size=(6, 3))
    omega = np.linspace(-40.0, 40.0, 301)
    resolvent = 1.0 / (1j * omega[:, np.newaxis] - poles)
    direct = np.stack([(np.abs((resolvent * row) @ right) ** 2).sum(axis=1) for row in left])
    beta = power_coefficients(poles, left, right)
    expanded = 2.0 * (resolvent @ beta.T).real.T
    np.testing.assert_allclose(expanded, direct, rtol=1e-10, atol=1e-12 * direct.max())


@pytest.mark.parametrize("pole", [-2 * np.pi * 0.05 + 2j * np.pi * 2.0,
                                  -2 * np.pi * 0.004 + 2j * np.pi * 1.7])
def test_hann_pole_convolution_matches_quadrature_of_the_kernel(pole):
    # Reference: signals.welch_kernel (the closed-form Hann kernel) times 1/(2πiν − λ),
    # integrated by a fine rectangle rule over ±400 bins (the kernel tail beyond is < 1e-12).
    window = 10.0
    frequency = np.array([1.5, 1.7, 1.73, 2.0, 2.2])
    nu = np.arange(-40.0 + 1.7, 40.0 + 1.7, 1.0 / (window * 400))
    exact = hann_pole_convolution(np.array([pole]), frequency, window)[:, 0]
    quadrature = np.array([
        (welch_kernel(f - nu, window) / (2j * np.pi * nu - pole)).sum() * (nu[1] - nu[0])
        for f in frequency])
    np.testing.assert_allclose(exact, quadrature, rtol=1e-6)


def _cases():
    paper = paper_example()
    eeklo = load_case(EXAMPLES / "eeklo_like.toml")
    return [("paper", paper.structure, paper.crowd, paper.msd, 60.0, np.arange(0, 601) / 60.0),
            ("eeklo", eeklo.structure, eeklo.crowd, eeklo.msd, 25.0, np.arange(0, 251) / 25.0),
            ("eeklo band", eeklo.structure, eeklo.crowd, eeklo.msd, 25.0,
             np.arange(63, 201) / 25.0)]


@pytest.mark.parametrize("case", _cases(), ids=lambda case: case[0])
@pytest.mark.parametrize("filtered", [False, True])
@pytest.mark.parametrize("hsi", [True, False])
def test_corrected_rule_agrees_with_the_dense_rule(case, filtered, hsi):
    # Reference: the dense rectangle rule (16 points per bin of the exact PSD), the model's
    # previous evaluation, kept as SpectralModel._dense_welch_psd.
    _, structure, crowd, msd, window, grid = case
    lowpass = LowPassFilter(10.0, 4, 25.0) if filtered else None
    model = SpectralModel(structure, crowd, grid, welch_window_length=window, lowpass=lowpass)
    msd = msd if hsi else None
    fast = model.psd_array(msd)
    dense = model._dense_welch_psd(model._attached(msd))
    peak = dense.max(axis=1, keepdims=True)
    assert np.abs(fast - dense).max() <= 1e-4 * peak.min()
    # Pointwise wherever the response is within 1 % of its peak (the bins that carry the fit).
    strong = dense >= 1e-2 * peak
    np.testing.assert_allclose(fast[strong], dense[strong], rtol=1e-4)


def test_corrected_rule_resolves_a_peak_narrower_than_its_grid():
    # A 0.1 %-damped mode at 2 Hz (half-power half-width 0.002 Hz) and T = 60 s: the coarse rule
    # (1/240 Hz) cannot resolve the peak alone. Reference: the dense rule at 64 points per bin
    # with the kernel kept to ±40 bins (the correction convolves the peak with the whole kernel).
    from crowdvib.models.structure import ModalModel
    from crowdvib.response.frequency_domain._welch_model import WelchRule
    paper = paper_example()
    structure = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.001, 50e3)
    grid = np.arange(60, 180) / 60.0
    model = SpectralModel(structure, paper.crowd, grid, welch_window_length=60.0)
    rule = WelchRule(grid, 60.0, 64, half_width_bins=40)
    fine = rule.apply(model._exact_psd(model._model_grid(rule.grid), ()))
    near = np.abs(grid - 2.0) <= 8 / 60.0     # the outputs whose kernel sees the peak
    fast = model.psd_array(None)
    np.testing.assert_allclose(fast[:, near], fine[:, near], rtol=1e-4)
    assert np.abs(fast - fine).max() <= 1e-4 * fine.max()
    msd = MSDModel()
    fine_hsi = rule.apply(model._exact_psd(model._model_grid(rule.grid), model._attached(msd)))
    np.testing.assert_allclose(model.psd_array(msd)[:, near], fine_hsi[:, near], rtol=1e-4)


def test_an_undamped_mode_falls_back_to_the_dense_rule():
    # ξ = 0 is allowed; without HSI its poles sit on the imaginary axis, where the closed form
    # does not hold. Reference: the dense rule, which the model then uses.
    from crowdvib.models.structure import ModalModel
    paper = paper_example()
    structure = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.0, 50e3)
    grid = np.arange(60, 180) / 60.0
    model = SpectralModel(structure, paper.crowd, grid, welch_window_length=60.0)
    with np.errstate(divide="ignore", invalid="ignore"):    # the dense grid hits f = 2 Hz
        psd = model.psd_array(None)
        np.testing.assert_array_equal(psd, model._dense_welch_psd(()))



@pytest.mark.parametrize("cross", [False, True])
def test_kept_pole_terms_give_a_fresh_models_values(paper_bridge, paper_crowd, paper_msd,
                                                     welch_grid, cross):
    # A model for other step frequencies (_for_crowd) reuses the poles' terms its parent kept
    # at the same MSD (issue 39): its PSD must be the one a model built afresh for that crowd
    # computes (the reference: SpectralModel(structure, other crowd), empty caches).
    import dataclasses

    lowpass = LowPassFilter(cutoff=10.0, order=4, sample_rate=25.0)
    options = dict(welch_window_length=60.0, lowpass=lowpass)
    model = SpectralModel(paper_bridge, paper_crowd, welch_grid, **options)
    other_crowd = dataclasses.replace(paper_crowd, step_frequency_mean=1.95,
                                      step_frequency_std=0.2)
    evaluate = "cross_psd_array" if cross else "psd_array"
    getattr(model, evaluate)(paper_msd)                          # keeps the poles' terms
    other = model._for_crowd(other_crowd)
    assert other._expansions is model._expansions and other._expansions
    fresh = SpectralModel(paper_bridge, other_crowd, welch_grid, **options)
    np.testing.assert_allclose(getattr(other, evaluate)(paper_msd),
                               getattr(fresh, evaluate)(paper_msd), rtol=1e-13, atol=0)
    # another density is another attachment: not answered from the kept terms
    denser = model._for_crowd(paper_crowd.with_density(0.8))
    np.testing.assert_allclose(
        getattr(denser, evaluate)(paper_msd),
        getattr(SpectralModel(paper_bridge, paper_crowd.with_density(0.8), welch_grid,
                              **options), evaluate)(paper_msd), rtol=1e-13, atol=0)
