"""The expected PSDs a user gets without options are of the model the default estimator fits
(issue 33 §3): one default, ``crowdvib._estimators``, read by every entry point.
"""

import inspect

import numpy as np
import pytest

from crowdvib import estimate_hsi, response_psd
from crowdvib._estimators import DEFAULT_CROWD_MODEL, estimator_defaults
from crowdvib.response import VaryingCrowdModel, varying_response_psd


def _default(function, name):
    return inspect.signature(function).parameters[name].default


def test_the_expected_psds_default_to_the_estimators_crowd_model():
    # Reference: estimate_hsi's own resolution of its defaults (method, then the method's crowd
    # model). Fails if response_psd or the varying crowd's expected PSD drift from it.
    method = _default(estimate_hsi, "method")
    crowd_model = estimator_defaults(method, _default(estimate_hsi, "crowd_model"))[0]
    assert crowd_model == DEFAULT_CROWD_MODEL == "fluctuating"
    for function in (response_psd, varying_response_psd, VaryingCrowdModel):
        assert _default(function, "crowd_model") == crowd_model, function.__name__


@pytest.fixture(scope="module")
def fluctuating_psd():
    """The paper's example as a noise-free Welch expectation (T = 60 s) of the fluctuating crowd,
    made with response_psd's default and checked to be crowd_model="fluctuating"."""
    from crowdvib import Crowd, ModalModel, MSDModel

    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    crowd = Crowd(density=0.5, walking_speed=1.30, step_frequency_mean=1.89,
                  step_frequency_std=0.175, body_mass=70.0)
    truth = MSDModel(3.0, 0.30, 0.95)
    grid = np.arange(0, 601) / 60.0
    default = response_psd(bridge, crowd, grid, msd=truth, welch_window_length=60.0)
    stated = response_psd(bridge, crowd, grid, msd=truth, welch_window_length=60.0,
                          crowd_model="fluctuating")
    np.testing.assert_array_equal(default.psd, stated.psd)
    return bridge, crowd, truth, default


def test_default_estimate_recovers_response_psds_default_exactly(fluctuating_psd):
    # Reference: the MSD that made the noise-free PSD (paper example, 3.0 Hz, 30 %). The default
    # estimator (likelihood, fluctuating crowd, step frequencies fitted) gives it back to 1e-4;
    # the paper's smeared crowd, fitted by the same estimator, is off by more than 0.1 % in f_h1
    # (+0.37 % and ξ_h1 +0.54 % on this example, on 28c53bc), which a drift of the pair would show.
    bridge, crowd, truth, measured = fluctuating_psd
    fit = estimate_hsi(measured, bridge, crowd, band=(0.0, 10.0), interval=None)
    assert (fit.method, fit.crowd_model) == ("likelihood", "fluctuating")
    assert fit.msd.frequency == pytest.approx(truth.frequency, rel=1e-4)
    assert fit.msd.damping_ratio == pytest.approx(truth.damping_ratio, rel=1e-4)
    smeared = response_psd(bridge, crowd, measured.frequency, msd=truth,
                           welch_window_length=60.0, crowd_model="smeared")
    off = estimate_hsi(smeared, bridge, crowd, band=(0.0, 10.0), interval=None)
    assert abs(off.msd.frequency / truth.frequency - 1) > 1e-3
