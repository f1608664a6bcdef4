"""A crowd that carries its own density, a number or a profile (issue 34 §3; crowdvib.models.crowd;
docs: theory, A crowd that changes): the simulator and the estimator follow the profile as the
former ``crowd_profile=`` argument did, to the bit; the models of a stationary crowd refuse it."""

import hashlib

import numpy as np
import pytest

from crowdvib import (Crowd, CrowdProfile, FluctuatingSpectralModel, ModalModel, MSDModel,
                      ParameterError, SpectralModel, frf, response_psd, simulate, welch_psd)
from crowdvib.design.stochastic import predict_response
from crowdvib.identification.objective import PSDObjective


@pytest.fixture(scope="module")
def bridge():
    return ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)


@pytest.fixture(scope="module")
def ramp_crowd():
    return Crowd.from_density(0.6).with_density(CrowdProfile([0.0, 300.0], [0.2, 1.0]))


@pytest.fixture(scope="module")
def ramp_record(bridge, ramp_crowd):
    return simulate(bridge, ramp_crowd, 300.0, msd=MSDModel(), rng=1, sample_rate=50.0,
                    warm_up=30.0)


def test_a_profile_crowd_simulates_the_record_of_the_former_pair(ramp_record):
    # The reference: main at 0a353c1 (before issue 34 §3), the same seed and options with the
    # pair `simulate(bridge, Crowd.from_density(0.6), 300.0, ..., crowd_profile=ramp)`:
    # sha256 of the acceleration row's float64 bytes 9f18814c…, of n_on_deck as int64
    # ea3b84b3…; the record here gave the same two hashes (bit-identical). The walkers are
    # integers and hashed; the accelerations are compared to 1e-12 at the values main printed,
    # so that a machine whose JIT rounds otherwise (FMA) still checks the numbers.
    on_deck = np.asarray(ramp_record.n_on_deck, dtype=np.int64)
    assert hashlib.sha256(on_deck.tobytes()).hexdigest().startswith("ea3b84b31ca6058e")
    a = ramp_record.acceleration[0]
    assert a.size == 15000
    assert np.sqrt(np.mean(a**2)) == pytest.approx(0.286016309292863, rel=1e-12)
    assert [a[1000], a[7500], a[14999]] == pytest.approx(
        [-0.0066580198604064104, -0.08868774781703856, -0.22858501465999337], rel=1e-12)


def test_a_profile_crowd_fits_the_objective_of_the_former_pair(bridge, ramp_crowd, ramp_record):
    # The reference: PSDObjective(measured, bridge, Crowd.from_density(0.6), band=(1, 4),
    # method=..., crowd_profile=ramp).cost(msd) on main at 0a353c1, the same record.
    measured = welch_psd(ramp_record.acceleration, 50.0, window_length=60.0,
                         output_names=ramp_record.output_names)
    for method, costs in (("least_squares", (0.08530285142765166, 0.09182235653349685)),
                          ("likelihood", (121.28709747779567, 130.20877162417605))):
        objective = PSDObjective(measured, bridge, ramp_crowd, band=(1.0, 4.0), method=method)
        assert [objective.cost(MSDModel()), objective.cost(MSDModel(2.8, 0.25, 0.9))] == \
            pytest.approx(costs, rel=1e-12)


def test_the_density_is_a_number_or_a_profile(ramp_crowd):
    # crowd.profile narrows the one value; from_density sets the walkers at the profile's mean
    # over its table (0.6 on the ramp 0.2 → 1.0: Weidmann's speed at 0.6, as a case file does).
    assert ramp_crowd.profile.peak == 1.0 and Crowd.from_density(0.6).profile is None
    walkers = Crowd.from_density(ramp_crowd.profile)
    assert walkers.walking_speed == Crowd.from_density(0.6).walking_speed
    assert walkers == ramp_crowd
    assert ramp_crowd.with_density(0.4).density == 0.4          # back to a number
    stationary = Crowd.from_density(0.6)
    assert stationary.check_stationary("response_psd") is stationary
    with pytest.raises(ParameterError, match=r"density must be a number \[persons/m²\] or a "
                                             r"CrowdProfile, got \(0.2, 0.4\)"):
        ramp_crowd.with_density((0.2, 0.4))


@pytest.mark.parametrize("call, name", [
    (lambda b, c: SpectralModel(b, c, [1.0, 2.0]), "SpectralModel"),
    (lambda b, c: FluctuatingSpectralModel(b, c, [1.0, 2.0]), "FluctuatingSpectralModel"),
    (lambda b, c: response_psd(b, c, [1.0, 2.0], msd=MSDModel()), "response_psd"),
    (lambda b, c: frf(b, [1.0, 2.0], crowd=c, msd=MSDModel()), "frf"),
    (lambda b, c: c.arrival_rate(b.width), "Crowd.arrival_rate"),
    (lambda b, c: predict_response(b, c), "predict_response"),
])
def test_a_stationary_model_refuses_a_profile_crowd(bridge, ramp_crowd, call, name):
    # The models of one density do not reduce a profile to a number silently: the message names
    # the parameter, the rule and what models a crowd that changes.
    with pytest.raises(ParameterError, match=rf"crowd.density must be a number \[persons/m²\] "
                                             rf"for {name}, a model of a stationary crowd, got "
                                             r"a CrowdProfile .*varying_response_psd"):
        call(bridge, ramp_crowd)
