"""estimate_hsi with a crowd whose density is a profile: the MSD from a record whose crowd changes (docs: theory, A crowd
that changes; issue 28 §1 "the estimate with the counts recovers the truth where assuming the
mean density is biased")."""

import warnings

import numpy as np
import pytest

from crowdvib import (Crowd, CrowdProfile, ModalModel, MSDModel, ParameterError, estimate_hsi,
                      response_psd, simulate, welch_psd)
from crowdvib.identification.objective import PSDObjective

TRUTH = MSDModel()       # the paper's 3 Hz, 30 %, 0.95
HOUR = 3600.0


@pytest.fixture(scope="module")
def ramp_record():
    """An hour at 50 Hz on the paper's bridge while the density ramps 0.2 → 1.0 P/m²."""
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    walkers = Crowd.from_density(0.6)
    profile = CrowdProfile([0.0, HOUR], [0.2, 1.0])
    record = simulate(bridge, walkers.with_density(profile), HOUR, msd=TRUTH, rng=1,
                      sample_rate=50.0, warm_up=60.0)
    measured = welch_psd(record.acceleration, 50.0, window_length=60.0,
                         output_names=record.output_names)
    return bridge, walkers, profile, measured


def test_profile_recovers_the_truth_where_the_mean_density_is_biased(ramp_record):
    # The paper's least squares on the band 0.5–10 Hz, with 95 % profile intervals. With the
    # profile the intervals hold the truth; the model of the mean crowd (0.6 P/m²) misses the
    # windows at high density, which weigh most in the PSD, and puts f_h1 low (seed 1: an
    # interval that excludes 3 Hz). Figures in docs: theory, A crowd that changes.
    bridge, walkers, profile, measured = ramp_record
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")        # the mean-density fit may warn of its misfit
        with_profile = estimate_hsi(measured, bridge, walkers.with_density(profile),
                                    band=(0.5, 10.0), method="least_squares")
        mean_density = estimate_hsi(measured, bridge, walkers, band=(0.5, 10.0),
                                    method="least_squares")
    low, high = with_profile.intervals["frequency"]
    assert low < TRUTH.frequency < high
    low, high = with_profile.intervals["damping_ratio"]
    assert low < TRUTH.damping_ratio < high
    assert abs(with_profile.msd.frequency - TRUTH.frequency) < 0.1
    assert mean_density.intervals["frequency"][1] < TRUTH.frequency
    assert mean_density.msd.frequency < TRUTH.frequency - 0.15
    # The profile's model is fitted at the record's mean deck density, as the Welch average sees it.
    assert with_profile.relative_cost < 0.5 * mean_density.relative_cost


def test_a_constant_profile_is_the_stationary_estimate(ramp_record):
    # One level at the profile's density: the same objective as the stationary crowd's.
    bridge, walkers, _, measured = ramp_record
    band = (1.0, 4.0)
    stationary = PSDObjective(measured, bridge, walkers, band=band, method="least_squares")
    profiled = PSDObjective(measured, bridge,
                            walkers.with_density(CrowdProfile.constant(walkers.density)),
                            band=band, method="least_squares")
    assert profiled.cost(TRUTH) == pytest.approx(stationary.cost(TRUTH), rel=1e-10)


def test_profile_needs_a_welch_estimate(ramp_record):
    bridge, walkers, profile, _ = ramp_record
    frequency = np.arange(1, 301) / 60.0
    model = response_psd(bridge, walkers, frequency, msd=TRUTH,
                         crowd_model="smeared")     # no n_windows
    with pytest.raises(ParameterError, match=r"a crowd whose density is a profile needs a Welch "
                                             r"estimate"):
        estimate_hsi(model, bridge, walkers.with_density(profile), band=(1.0, 4.0),
                     method="least_squares")
    with pytest.raises(ParameterError, match=r"density must be a number \[persons/m²\] or a "
                                             r"CrowdProfile, got \{'time'"):
        walkers.with_density({"time": [0], "density": [0.5]})


def test_the_bootstraps_exact_model_weighs_the_record_as_its_welch_windows(ramp_record):
    # A parametric bootstrap draws a record from the exact PSD and Welch-averages it (docs:
    # theory, Parametric bootstrap): with a profile that exact PSD must average the densities as
    # the Welch windows weigh the record's times (less at its ends), the law of the Welch model
    # itself, not uniformly over the record.
    from crowdvib.response.frequency_domain.varying import VaryingCrowdModel

    bridge, walkers, profile, measured = ramp_record
    objective = PSDObjective(measured, bridge, walkers.with_density(profile), band=(1.0, 4.0),
                             method="least_squares")
    exact = objective.exact_model(np.linspace(0.0, 5.0, 51))
    assert exact.welch_window_length is None

    def moments(model):        # Σ p d^k, k = 1, 2, 3: a Gauss rule of 2+ nodes holds them exactly
        return [model.probabilities @ model.levels ** k for k in (1, 2, 3)]

    # The same law (each chooses its own number of nodes: the exact PSD is smoother).
    np.testing.assert_allclose(moments(exact), moments(objective.model), rtol=1e-9)
    # Uniform weights would give another law on this ramp: the record's ends count fully.
    uniform = VaryingCrowdModel(bridge, walkers.with_density(profile), np.linspace(0.0, 5.0, 51),
                                duration=exact.duration, levels=exact.levels.size,
                                crowd_model="smeared")
    assert abs(moments(uniform)[1] / moments(exact)[1] - 1) > 1e-4
