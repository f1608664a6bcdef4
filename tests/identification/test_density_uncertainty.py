"""The crowd density's uncertainty in the estimate's intervals (issue 33 §4; docs: theory, The
crowd density's uncertainty)."""

import dataclasses
import warnings

import numpy as np
import pytest

from crowdvib import (Crowd, ModalModel, MSDModel, ParameterError, estimate_hsi,
                      estimate_hsi_joint, response_psd, welch_psd)
from crowdvib.identification import HSIEstimate
from crowdvib.signals.synthesis import gaussian_record, record_frequencies

# The paper's numerical example (docs: theory, The paper's numerical example), a 20-min record.
BRIDGE = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
CROWD = Crowd(density=0.5, walking_speed=1.30, step_frequency_mean=1.89,
              step_frequency_std=0.175, body_mass=70.0)
TRUTH = MSDModel(3.0, 0.30, 0.95)
NAMES = ("frequency", "damping_ratio")


@pytest.fixture(scope="module")
def measured():
    frequency = record_frequencies(1200.0, 20.0)
    psd = response_psd(BRIDGE, CROWD, frequency, msd=TRUTH, crowd_model="smeared").psd
    record = gaussian_record(psd, 20.0, rng=7)
    return welch_psd(record, 20.0, window_length=60.0, output_names=["midspan"]).band(0.0, 10.0)


def _estimate(measured, crowd=CROWD, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")     # bound and identifiability notes: not the subject
        return estimate_hsi(measured, BRIDGE, crowd, band=(0.0, 10.0), method="least_squares",
                            starts=[(3.0, 0.3)], **options)


@pytest.fixture(scope="module")
def exact(measured):
    return _estimate(measured, interval="wald", density_uncertainty=0.0)


@pytest.fixture(scope="module")
def uncertain(measured):
    return _estimate(measured, interval="wald", density_uncertainty=0.1)


def test_density_sensitivity_is_the_refit_at_another_stated_density(measured, exact):
    # Reference: the estimate refitted with the density stated 1 % high and 1 % low (central
    # difference in ln ρ); the sensitivity is the implicit-function derivative H⁻¹ s of the
    # sandwich's density term (docs: theory, The crowd density's uncertainty).
    step = 0.01
    up = _estimate(measured, CROWD.with_density(CROWD.density * (1 + step)), interval=None)
    down = _estimate(measured, CROWD.with_density(CROWD.density * (1 - step)), interval=None)
    for name in NAMES:
        refit = (getattr(up.msd, name) - getattr(down.msd, name)) / np.log((1 + step) / (1 - step))
        assert exact.density_sensitivity[name] == pytest.approx(refit, rel=0.05), name
    # The damping ratio moves far more than the frequency: ∂ ln ξ̂/∂ ln ρ of order 1 (the
    # issue's measurement: ξ_h1 −33 / +45 % for a density 10 % low / high).
    assert exact.density_sensitivity["damping_ratio"] / exact.msd.damping_ratio > 0.5


def test_stated_uncertainty_adds_its_variance_to_the_sandwich(exact, uncertain):
    # Reference: the sandwich with the nuisance term (docs: theory, Sandwich covariance):
    # Cov(u) − Cov(0) = u² (H⁻¹ s)(H⁻¹ s)ᵀ, and H⁻¹ s is the sensitivity checked above.
    move = np.array([uncertain.density_sensitivity[n] for n in uncertain.free_parameters])
    added = uncertain.covariance - exact.covariance
    np.testing.assert_allclose(added, 0.1**2 * np.outer(move, move), rtol=1e-6,
                               atol=1e-12 * np.abs(added).max())
    for i, name in enumerate(uncertain.free_parameters):
        assert uncertain.density_share[name] == pytest.approx(
            added[i, i] / uncertain.covariance[i, i], rel=1e-9)
    assert exact.density_share == {} and uncertain.density_uncertainty == 0.1
    # The point estimate is the same: the uncertainty is about the interval only.
    assert uncertain.msd.damping_ratio == exact.msd.damping_ratio


def test_profile_interval_widens_with_the_stated_uncertainty(measured, exact):
    narrow = _estimate(measured, density_uncertainty=0.0)
    wide = _estimate(measured, density_uncertainty=0.1)
    low0, high0 = narrow.intervals["damping_ratio"]
    low1, high1 = wide.intervals["damping_ratio"]
    assert low1 < low0 < narrow.msd.damping_ratio < high0 < high1
    # Reference, to first order: the Wald half-widths z·√Var add in quadrature (sandwich).
    z = 1.959964
    statistical = z * np.sqrt(exact.covariance[1, 1])
    density = z * 0.1 * abs(exact.density_sensitivity["damping_ratio"])
    assert (high1 - low1) / 2 == pytest.approx(np.hypot(statistical, density), rel=0.35)


def test_a_joint_fit_shares_one_density_error(measured):
    # Two records of the same crowd counted the same way: the Welch scatter halves in variance,
    # the density's term does not (one error common to both; docs: theory, The crowd density's
    # uncertainty). Reference: the single record's covariance parts.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        one = [estimate_hsi_joint([measured], BRIDGE, [CROWD], band=(0.0, 10.0),
                                  starts=[(3.0, 0.3)], interval="wald", density_uncertainty=u)
               for u in (0.0, 0.1)]
        two = [estimate_hsi_joint([measured, measured], BRIDGE, [CROWD, CROWD],
                                  band=(0.0, 10.0), starts=[(3.0, 0.3)], interval="wald",
                                  density_uncertainty=u) for u in (0.0, 0.1)]
    np.testing.assert_allclose(two[0].covariance, one[0].covariance / 2, rtol=1e-6)
    added_one = one[1].covariance - one[0].covariance
    added_two = two[1].covariance - two[0].covariance
    np.testing.assert_allclose(added_two, added_one, rtol=1e-6, atol=1e-14)


def test_the_density_terms_survive_the_results_dict(uncertain):
    back = HSIEstimate.from_dict(uncertain.to_dict())
    assert back.density_uncertainty == 0.1
    assert back.density_sensitivity == pytest.approx(uncertain.density_sensitivity)
    assert back.density_share == pytest.approx(uncertain.density_share)


@pytest.mark.badinput
@pytest.mark.parametrize("value", [-0.1, 0.7, float("nan"), "ten percent", True, None])
def test_bad_density_uncertainty_is_refused(measured, value):
    with pytest.raises(ParameterError, match=r"density_uncertainty must be .*\[0, 0\.5\]"):
        _estimate(measured, interval=None, density_uncertainty=value)


def test_a_case_file_states_the_density_uncertainty(tmp_path):
    from tests.conftest import copy_paper_case
    from crowdvib.io import load_case
    from crowdvib._estimators import DEFAULT_DENSITY_UNCERTAINTY

    path = copy_paper_case(tmp_path)
    text = path.read_text()
    stated = "density_uncertainty = 0.0"     # examples/paper_example.toml: a simulated record
    assert stated in text
    assert load_case(path).estimation.density_uncertainty == 0.0
    path.write_text(text.replace(stated, "density_uncertainty = 0.05", 1))
    assert load_case(path).estimation.density_uncertainty == 0.05
    # Not stated: the estimator's default (crowdvib._estimators).
    path.write_text(text.replace(stated, "", 1))
    assert load_case(path).estimation.density_uncertainty == DEFAULT_DENSITY_UNCERTAINTY
    path.write_text(text.replace(stated, "density_uncertainty = 10", 1))
    with pytest.raises(ParameterError, match=r"crowd\.density_uncertainty must be .*got 10"):
        load_case(path)


def test_estimate_hsi_and_case_files_default_alike():
    # One default for the API and case files (crowdvib._estimators).
    import inspect

    from crowdvib._estimators import DEFAULT_DENSITY_UNCERTAINTY
    from crowdvib.io.casespecs import EstimationSpec

    for function in (estimate_hsi, estimate_hsi_joint):
        default = inspect.signature(function).parameters["density_uncertainty"].default
        assert default == DEFAULT_DENSITY_UNCERTAINTY
    assert EstimationSpec().density_uncertainty == DEFAULT_DENSITY_UNCERTAINTY
    assert dataclasses.fields(EstimationSpec)
