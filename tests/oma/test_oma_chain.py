"""Full chain on simulated data (issue 13): ambient record → identify_modes → modal model →
crowd record → estimate_hsi recovers the paper's MSD (3.0 Hz, 0.30) within its own interval."""

import pytest

from crowdvib import (
    LowPassFilter,
    ModalModel,
    estimate_hsi,
    identify_modes,
    simulate,
    welch_psd,
)
from crowdvib.oma.identify import ambient_response
from crowdvib.models import paper_example

pytest.importorskip("pyoma2")

SENSORS = {"quarter": 12.5, "mid": 25.0, "three_quarter": 37.5}


def test_ambient_to_estimate():
    example = paper_example()             # truth: f_h1 = 3.0 Hz, ξ_h1 = 0.30 (the paper's example)
    truth = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3, outputs=SENSORS)
    fe = truth.replace(frequencies=[2.1], damping_ratios=[0.01])    # an uncalibrated FE model
    # 30 min of ambient response to white-noise modal load (exact Gaussian synthesis)
    ambient = ambient_response(truth, 1800.0, 20.0, 200.0**2, rng=5)
    modes = identify_modes(ambient, 20.0, n_modes=1, frequency_band=(1.0, 9.0),
                           sensor_names=list(SENSORS), max_order=20)
    structure = modes.modal_model(fe)
    assert structure.frequencies[0] == pytest.approx(2.0, rel=0.005)
    assert structure.damping_ratios[0] == pytest.approx(0.005, rel=0.2)
    record = simulate(truth, example.crowd, 3600.0, msd=example.msd, rng=7, warm_up=100.0)
    measured = welch_psd(record.acceleration, 100.0, window_length=60.0,
                         output_names=record.output_names,
                         lowpass=LowPassFilter(10.0, 4, 100.0)).band(0, 10)
    estimate = estimate_hsi(measured, structure, example.crowd, band=(0.0, 10.0))
    low, high = estimate.interval("frequency")
    assert low <= 3.0 <= high
    low, high = estimate.interval("damping_ratio")
    assert low <= 0.30 <= high
