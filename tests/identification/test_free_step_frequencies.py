"""The step-frequency distribution fitted with the MSD (docs: theory, Step frequencies fitted
with the MSD).

The likelihood weighs relative errors over the whole band, flanks of the load spectrum
included, so an error in the crowd's mean step frequency that least squares barely feels moves
its ξ_h1 a lot. Fitted with the MSD, (μ_fs, σ_fs) come from the same record and their
uncertainty enters the intervals. Records: Gaussian with the paper example's PSD (exact Welch
statistics); the truth is what made them (MSD 3.0 Hz, 0.30; crowd N(1.89, 0.175) Hz).
"""

import dataclasses
import warnings

import numpy as np
import pytest

from crowdvib import (BoundWarning, Crowd, ModalModel, MSDModel, ParameterError, estimate_hsi,
                      response_psd, welch_psd)
from crowdvib.response import FluctuatingSpectralModel
from crowdvib.signals.synthesis import gaussian_record, record_frequencies

SAMPLE_RATE, WINDOW = 20.0, 60.0
TRUTH = MSDModel(3.0, 0.30, 0.95)
BRIDGE = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
CROWD = Crowd(density=0.5, walking_speed=1.30, step_frequency_mean=1.89,
              step_frequency_std=0.175, body_mass=70.0)
#: What a user might believe: μ_fs 3 % high, σ_fs 14 % low.
WRONG = dataclasses.replace(CROWD, step_frequency_mean=1.89 * 1.03, step_frequency_std=0.15)


@pytest.fixture(scope="module")
def measured():
    frequency = record_frequencies(3600.0, SAMPLE_RATE)
    psd = response_psd(BRIDGE, CROWD, frequency, msd=TRUTH, crowd_model="smeared").psd
    record = gaussian_record(psd, SAMPLE_RATE, rng=200)
    return welch_psd(record, SAMPLE_RATE, window_length=WINDOW,
                     output_names=["midspan"]).band(0.0, 10.0)


def _estimate(measured, crowd, **options):
    # The record holds the smeared model's PSD: the likelihood fits that model, with the step
    # frequencies held unless the test frees them.
    # The records' density is exact (simulated): their intervals are the Welch scatter's alone.
    options = dict(dict(crowd_model="smeared", free_step_frequencies=False,
                        density_uncertainty=0.0), **options)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BoundWarning)
        return estimate_hsi(measured, BRIDGE, crowd, band=(0.0, 10.0), method="likelihood",
                            **options)


@pytest.mark.slow
def test_fitted_step_frequencies_make_the_likelihood_robust_to_a_wrong_crowd(measured):
    held = _estimate(measured, WRONG)
    free = _estimate(measured, WRONG, free_step_frequencies=True)
    # Held at the wrong crowd, the likelihood is far off (measured on this record: f_h1 2.80 Hz,
    # ξ_h1 0.225, i.e. −7 % and −25 %) and its intervals, which trust the crowd, miss the truth.
    low, high = held.interval("damping_ratio")
    assert abs(held.msd.damping_ratio / TRUTH.damping_ratio - 1) > 0.15
    assert not low <= TRUTH.damping_ratio <= high
    # Fitted, every parameter's 95 % interval covers the truth that made the record.
    truth = {"frequency": 3.0, "damping_ratio": 0.30, "step_frequency_mean": 1.89,
             "step_frequency_std": 0.175}
    for name, value in truth.items():
        low, high = free.interval(name)
        assert low <= value <= high, (name, low, high)
    # The crowd is found to better than 1 % (μ_fs) and 5 % (σ_fs) from one hour.
    assert free.crowd.step_frequency_mean == pytest.approx(1.89, rel=0.01)
    assert free.crowd.step_frequency_std == pytest.approx(0.175, rel=0.05)
    assert free.free_parameters == ("frequency", "damping_ratio", "step_frequency_mean",
                                    "step_frequency_std")
    found = free.to_dict()["estimate"]
    assert found["step_frequency_mean"] == free.value("step_frequency_mean")
    assert set(found["interval"]) >= {"step_frequency_mean", "step_frequency_std"}


@pytest.mark.slow
def test_the_answer_does_not_depend_on_the_starting_crowd(measured):
    # The same optimum from the true and from the wrong crowd (a well-posed fit), to far below
    # the record's scatter (SE of f_h1 ≈ 0.05 Hz).
    a = _estimate(measured, CROWD, free_step_frequencies=True, interval=None)
    b = _estimate(measured, WRONG, free_step_frequencies=True, interval=None)
    for name in a.free_parameters:
        assert b.value(name) == pytest.approx(a.value(name), rel=2e-3), name


def test_fluctuating_model_for_other_step_frequencies_is_a_new_model():
    # with_step_frequencies keeps the occupancy rule and rebuilds the smeared terms: the same
    # PSD as a model built from scratch with that crowd and node count (reference), to round-off.
    frequency = np.linspace(0.5, 6.0, 400)
    base = FluctuatingSpectralModel(BRIDGE, CROWD, frequency, welch_window_length=60.0)
    other = base.with_step_frequencies(WRONG)
    fresh = FluctuatingSpectralModel(BRIDGE, WRONG, frequency, welch_window_length=60.0,
                                     n_nodes=base.nodes.size)
    np.testing.assert_allclose(other.psd_array(TRUTH), fresh.psd_array(TRUTH), rtol=1e-12)
    with pytest.raises(ParameterError, match=r"step frequencies only .* got density 0\.5 → 1\.0$"):
        base.with_step_frequencies(CROWD.with_density(1.0))
    with pytest.raises(ParameterError, match=r"step frequencies only .* got body_mass .* → 80\.0$"):
        base.with_step_frequencies(dataclasses.replace(WRONG, body_mass=80.0))


def test_a_three_value_start_needs_the_mass_ratio_free(measured):
    with pytest.raises(ParameterError, match=r"starts must hold \(f_h1, ξ_h1\)"):
        _estimate(measured, CROWD, free_step_frequencies=True, starts=[(3.0, 0.3, 1.9)],
                  interval=None)
