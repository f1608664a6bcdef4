"""The fluctuating-crowd model removes the bias of the smeared one (docs: theory, The fluctuating crowd).

A cheap case where the effect is large: a 20 m × 2 m footbridge whose 12 walkers (0.3 P/m²) carry
10 % of the modal mass, so the occupancy λ spreads by √(3/(2·12)) = 35 % (Campbell's theorem)
and the occupied frequency with it. One simulated three-hour record (the time-domain simulator
moves every walker and its MSD over the deck: an independent model of the same physics) is
fitted with the smeared and with the fluctuating expected PSD (the mixture over the occupancy);
the truth is the MSD of the simulation (3.0 Hz, 0.30, μ_h1 0.95).
"""

import warnings

import pytest

from crowdvib import (BoundWarning, Crowd, ModalModel, MSDModel, estimate_hsi, simulate,
                      welch_psd)
from crowdvib.response.frequency_domain.fluctuation import FluctuatingSpectralModel

TRUTH = MSDModel(3.0, 0.30, 0.95)


@pytest.fixture(scope="module")
def small_bridge_record():
    bridge = ModalModel.simply_supported_beam(20.0, 2.0, 2.0, 0.005, 4200.0)
    crowd = Crowd(density=0.3, walking_speed=1.3, step_frequency_mean=1.95,
                  step_frequency_std=0.175, body_mass=70.0)
    record = simulate(bridge, crowd, 10800.0, msd=TRUTH, rng=7, warm_up=60.0, sample_rate=50.0)
    measured = welch_psd(record.acceleration, 50.0, window_length=60.0,
                         output_names=record.output_names).band(0.0, 10.0)
    return bridge, crowd, measured


def _fit(record, method, crowd_model):
    bridge, crowd, measured = record
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BoundWarning)
        # Wald intervals (sandwich covariance): the profiles are not the point here; the crowd
        # models are compared at the crowd as given (the step frequencies held), whose density
        # is exact (simulated): the intervals are the record's scatter alone.
        return estimate_hsi(measured, bridge, crowd, band=(0.0, 6.0), method=method,
                            crowd_model=crowd_model, interval="wald",
                            free_step_frequencies=False, density_uncertainty=0.0)


def test_this_bridge_gets_the_mixture_alone(small_bridge_record):
    # κ ≈ 1.4 here (the occupied resonance moves by 1.4 half-widths over the occupancy's
    # spread): beyond the range where the drift correction was checked, so the default model is
    # the mixture alone, which the simulator's records support on this bridge (over 60 three-hour
    # records, the likelihood on their mean PSD reads ξ_h1 +0.02 % without the correction and
    # −4.7 % with it; docs, theory, Beyond the quasi-static mixture). The tests below fit that.
    bridge, crowd, measured = small_bridge_record
    model = FluctuatingSpectralModel(bridge, crowd, measured.frequency)
    assert model.spread_parameter > 1.0 and not model.modulation


@pytest.mark.slow
def test_fluctuating_model_removes_the_damping_bias_of_least_squares(small_bridge_record):
    smeared = _fit(small_bridge_record, "least_squares", "smeared")
    fluctuating = _fit(small_bridge_record, "least_squares", "fluctuating")
    # The smeared model reads the widened resonance as damping: its interval misses the truth.
    assert smeared.interval("damping_ratio")[0] > TRUTH.damping_ratio
    for name in ("frequency", "damping_ratio"):
        low, high = fluctuating.interval(name)
        assert low <= getattr(TRUTH, name) <= high, (name, low, high)
    assert fluctuating.cost < 0.5 * smeared.cost


@pytest.mark.slow
def test_fluctuating_model_removes_the_frequency_bias_of_the_likelihood(small_bridge_record):
    smeared = _fit(small_bridge_record, "likelihood", "smeared")
    fluctuating = _fit(small_bridge_record, "likelihood", "fluctuating")
    # The estimate says what its expected PSD was made of (results.json: crowd_model_details).
    details = fluctuating.to_dict()["crowd_model_details"]
    assert smeared.crowd_model_details == () and len(details) == 1
    assert details[0]["drift_correction"] is False and details[0]["spread_parameter"] > 1.0
    assert details[0]["occupancy_nodes"] >= 9
    assert smeared.interval("frequency")[1] < TRUTH.frequency
    for name in ("frequency", "damping_ratio"):
        low, high = fluctuating.interval(name)
        assert low <= getattr(TRUTH, name) <= high, (name, low, high)
    # The deviance is the data's own verdict on the two models (same record, same bins).
    assert fluctuating.cost < 0.5 * smeared.cost
