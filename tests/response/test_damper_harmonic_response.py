"""Tuned mass dampers in the time-domain simulator: a harmonic force on the deck with a damper
against the spectral FRF with ``dampers=`` (docs: theory, Tuned mass dampers in the simulator)."""

import numpy as np
import pytest

from crowdvib import ModalModel, ParameterError, Pedestrian, frf, simulate
from crowdvib.design import TunedMassDamper

TMD = TunedMassDamper(1000.0, 1.96, 0.03, 25.0)


def bridge():
    return ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3,
                                            outputs={"mid": 25.0, "quarter": 12.5})


def steady_amplitude(signal, rate, frequency, seconds):
    """Amplitude of the f-component over the last whole periods (least squares on sin, cos)."""
    n = round(seconds * rate)
    t = np.arange(signal.size)[-n:] / rate
    basis = np.column_stack([np.sin(2 * np.pi * frequency * t), np.cos(2 * np.pi * frequency * t)])
    coefficients = np.linalg.lstsq(basis, signal[-n:], rcond=None)[0]
    return np.hypot(*coefficients)


@pytest.mark.parametrize("frequency", [1.85, 1.96, 2.12])
def test_harmonic_force_with_damper_matches_frf(frequency):
    # A standing pedestrian at mid-span with one force harmonic of W·α: after the transient
    # (warm-up 120 s ≫ 1/(ξω) ≈ 5 s of the coupled modes) each output vibrates at
    # |H_o,mid(f)| W α, H the accelerance of structure + damper (crowdvib.frf, dampers=).
    weight, alpha = 70.0 * 9.81, 0.4
    walker = Pedestrian(arrival_time=-200.0, walking_speed=0.0, step_frequency=frequency,
                        body_mass=70.0, harmonics=((1.0, alpha, 0.0),), position=25.0)
    record = simulate(bridge(), duration=20.0, pedestrians=[walker], sample_rate=200.0,
                      warm_up=120.0, rng=1, dampers=[TMD])
    reference = np.abs(frf(bridge(), [frequency], inputs=["mid"], dampers=[TMD]).values[:, 0, 0])
    for o in range(2):
        amplitude = steady_amplitude(record.acceleration[o], 200.0, frequency, 10.0)
        assert amplitude == pytest.approx(reference[o] * weight * alpha, rel=5e-3)
    assert record.n_on_deck.max() == 1 and record.n_pedestrians == 1     # people only


def test_damper_changes_the_response_and_off_walkway_is_rejected():
    walker = Pedestrian(arrival_time=-300.0, walking_speed=0.0, step_frequency=2.0,
                        body_mass=70.0, harmonics=((1.0, 0.4, 0.0),), position=25.0)
    # Warm-up 250 s: the empty mode's transient decays as exp(−ξωt), e^−16 by then.
    with_tmd = simulate(bridge(), duration=10.0, pedestrians=[walker], warm_up=250.0, rng=1,
                        dampers=[TMD])
    without = simulate(bridge(), duration=10.0, pedestrians=[walker], warm_up=250.0, rng=1)
    # At the empty resonance the damper cuts the response (|H| with/without from crowdvib.frf).
    ratio = (np.abs(frf(bridge(), [2.0], inputs=["mid"], dampers=[TMD]).values[0, 0, 0])
             / np.abs(frf(bridge(), [2.0], inputs=["mid"]).values[0, 0, 0]))
    measured = (steady_amplitude(with_tmd.acceleration[0], 100.0, 2.0, 5.0)
                / steady_amplitude(without.acceleration[0], 100.0, 2.0, 5.0))
    assert measured == pytest.approx(ratio, rel=0.01)
    with pytest.raises(ParameterError, match="damper position must lie on the walkway"):
        simulate(bridge(), duration=1.0, pedestrians=[walker], rng=1,
                 dampers=[TunedMassDamper(500.0, 2.0, 0.05, 60.0)])
    with pytest.raises(ParameterError, match="dampers must be a sequence of TunedMassDamper"):
        simulate(bridge(), duration=1.0, pedestrians=[walker], rng=1, dampers=3)
