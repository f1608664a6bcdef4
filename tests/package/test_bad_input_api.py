"""Bad-input catalogue, Python API: each case gets a crowdvib error naming the parameter (issue 9).

The rule of architecture §4: validate once at the public boundary; the message names the
parameter, the rule and the value. Cases the older tests cover (tests/package/test_bad_input.py) are
not repeated here.
"""

import numpy as np
import pytest

from crowdvib import (Crowd, DataError, LowPassFilter, MeasuredForce, ModalModel, MSDModel,
                      ParameterError, ZivanovicForce, detrend, estimate_hsi, frf, identify_modes,
                      psd_convergence, resample, response_psd, simulate, simulate_many, welch_psd)
from crowdvib.identification import Estimator
from crowdvib.studies import objective_map
from crowdvib.signals import select_time_frame, synthetic_welch_psd

pytestmark = pytest.mark.badinput

SIGNAL = np.random.default_rng(0).normal(size=(1, 6000))   # 60 s at 100 Hz


@pytest.fixture
def measured(paper_bridge, paper_crowd, paper_msd, welch_grid):
    return response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd)


# (label, call(bridge, crowd, msd, measured), error class, message pattern naming the parameter)
CASES = [
    ("simulate: negative duration", lambda b, c, m, p: simulate(b, c, -1.0, msd=m),
     ParameterError, r"duration must be > 0 s, got -1"),
    ("simulate: NaN duration", lambda b, c, m, p: simulate(b, c, np.nan, msd=m),
     ParameterError, r"duration must be finite, got nan"),
    ("simulate: zero sample rate", lambda b, c, m, p: simulate(b, c, 10.0, sample_rate=0.0),
     ParameterError, r"sample_rate must be > 0 Hz, got 0"),
    ("simulate: seed of the wrong type", lambda b, c, m, p: simulate(b, c, 10.0, rng="abc"),
     ParameterError, r"rng must be None, a non-negative int or a numpy.random.Generator, got str"),
    ("simulate: crowd of the wrong type", lambda b, c, m, p: simulate(b, "crowd", 10.0),
     ParameterError, r"crowd must be a Crowd, got str"),
    ("simulate: structure of the wrong type", lambda b, c, m, p: simulate("bridge", c, 10.0),
     ParameterError, r"structure must be a ModalModel, got str"),
    ("simulate_many: no seeds", lambda b, c, m, p: simulate_many(b, c, 10.0, seeds=[]),
     ParameterError, r"seeds must hold at least one seed, got an empty sequence"),
    ("simulate_many: negative seed", lambda b, c, m, p: simulate_many(b, c, 10.0, seeds=[1, -2]),
     ParameterError, r"seeds must be non-negative integers, got -2"),
    ("simulate_many: zero workers",
     lambda b, c, m, p: simulate_many(b, c, 10.0, seeds=[1], workers=0),
     ParameterError, r"workers must be an integer >= 1 or None, got 0"),
    ("simulate_many: rng given", lambda b, c, m, p: simulate_many(b, c, 10.0, seeds=[1], rng=3),
     ParameterError, r"rng is not an option of simulate_many"),
    ("response_psd: msd of the wrong type",
     lambda b, c, m, p: response_psd(b, c, p.frequency, msd=3.0),
     ParameterError, r"msd must be an MSDModel or None, got float"),
    ("response_psd: force model by name",
     lambda b, c, m, p: response_psd(b, c, p.frequency, force="young"),
     ParameterError, r"force must be a ZivanovicForce or YoungForce, got str"),
    ("response_psd: negative Welch window",
     lambda b, c, m, p: response_psd(b, c, p.frequency, welch_window_length=-60.0),
     ParameterError, r"welch_window_length must be > 0 s, got -60"),
    ("welch_psd: window longer than the record",
     lambda b, c, m, p: welch_psd(SIGNAL, 100.0, window_length=600.0),
     DataError, r"record of 60 s is shorter than one window of 600 s"),
    ("welch_psd: zero sample rate", lambda b, c, m, p: welch_psd(SIGNAL, 0.0, window_length=10.0),
     ParameterError, r"sample_rate must be > 0 Hz, got 0"),
    ("welch_psd: 3-D signals",
     lambda b, c, m, p: welch_psd(np.zeros((2, 2, 100)), 100.0, window_length=0.5),
     ParameterError, r"signals must have shape \(n_channels, n_samples\), got \(2, 2, 100\)"),
    ("welch_psd: overlap of 1",
     lambda b, c, m, p: welch_psd(SIGNAL, 100.0, window_length=10.0, overlap=1.0),
     ParameterError, r"overlap must lie in \[0, 1\), got 1.0"),
    ("welch_psd: NaN samples",
     lambda b, c, m, p: welch_psd(np.full((1, 6000), np.nan), 100.0, window_length=10.0),
     ParameterError, r"signals must be finite, got nan"),
    ("welch_psd: names for two channels of one",
     lambda b, c, m, p: welch_psd(SIGNAL, 100.0, window_length=10.0, output_names=["a", "b"]),
     ParameterError, r"output_names must name every channel \(1\), got 2"),
    ("LowPassFilter: cut-off above Nyquist", lambda b, c, m, p: LowPassFilter(80.0, 4, 100.0),
     ParameterError, r"cutoff must be below the Nyquist frequency 50 Hz, got 80 Hz"),
    ("LowPassFilter: order 0", lambda b, c, m, p: LowPassFilter(10.0, 0, 100.0),
     ParameterError, r"order must be an integer in \[1, 20\], got 0"),
    ("resample: negative rate", lambda b, c, m, p: resample(SIGNAL, 100.0, -5.0),
     ParameterError, r"new_sample_rate must be > 0 Hz, got -5"),
    ("detrend: unknown kind", lambda b, c, m, p: detrend(SIGNAL, kind="quadratic"),
     ParameterError, r"kind must be 'constant' or 'linear', got 'quadratic'"),
    ("psd_convergence: zero window",
     lambda b, c, m, p: psd_convergence(SIGNAL, 100.0, window_length=0.0),
     ParameterError, r"window_length must be > 0 s, got 0"),
    ("psd_convergence: unknown norm",
     lambda b, c, m, p: psd_convergence(SIGNAL, 100.0, window_length=10.0, norm="3"),
     ParameterError, r"norm must be '2' or 'inf', got '3'"),
    ("select_time_frame: frame beyond the record",
     lambda b, c, m, p: select_time_frame(SIGNAL, 100.0, 100.0, 101.0),
     DataError, r"time frame \[100.0, 101.0\] s holds 0 sample\(s\) of a record of 60 s"),
    ("objective_map: NaN in the grid",
     lambda b, c, m, p: objective_map(p, b, c, frequencies=[np.nan], damping_ratios=[0.3],
                                      estimator=Estimator(band=(0, 10))),
     ParameterError, r"frequencies must be finite, got nan"),
    ("estimate_hsi: measured of the wrong type",
     lambda b, c, m, p: estimate_hsi(np.zeros(3), b, c, band=(0, 10)),
     ParameterError, r"measured must be a ResponsePSD, got ndarray"),
    ("estimate_hsi: structure of the wrong type",
     lambda b, c, m, p: estimate_hsi(p, "bridge", c, band=(0, 10)),
     ParameterError, r"structure must be a ModalModel, got str"),
    ("estimate_hsi: no crowd", lambda b, c, m, p: estimate_hsi(p, b, None, band=(0, 10)),
     ParameterError, r"crowd must be a Crowd, got NoneType"),
    ("estimate_hsi: negative frequency weights",
     lambda b, c, m, p: estimate_hsi(p, b, c, band=(0, 10), frequency_weights=lambda f: -f - 1),
     ParameterError, r"frequency_weights must be > 0, got -1"),
    ("estimate_hsi: unknown crowd model",
     lambda b, c, m, p: estimate_hsi(p, b, c, band=(0, 10), crowd_model="frozen"),
     ParameterError, r"crowd_model must be one of \['smeared', 'fluctuating'\], got 'frozen'"),
    ("estimate_hsi: too few bootstrap replicates",
     lambda b, c, m, p: estimate_hsi(p, b, c, band=(0, 10), interval="bootstrap", n_boot=3),
     ParameterError, r"n_boot must be an integer >= 20 for a percentile interval, got 3"),
    ("estimate_hsi: no starting point",
     lambda b, c, m, p: estimate_hsi(p, b, c, band=(0, 10), starts=[]),
     ParameterError, r"starts must hold at least one starting point"),
    ("estimate_hsi: bounds as text",
     lambda b, c, m, p: estimate_hsi(p, b, c, band=(0, 10), bounds={"frequency": "ab"}),
     ParameterError, r"bounds\['frequency'\] must be a pair \(lower, upper\), got 'ab'"),
    ("estimate_hsi: band as text",
     lambda b, c, m, p: estimate_hsi(p, b, c, band=("a", "b")),
     ParameterError, r"band must be a pair \(lower, upper\) in Hz, got \('a', 'b'\)"),
    ("frf: negative frequency", lambda b, c, m, p: frf(b, [-1.0]),
     ParameterError, r"frequency must be >= 0 Hz, got -1"),
    ("Crowd.from_density: negative", lambda b, c, m, p: Crowd.from_density(-1),
     ParameterError, r"density must be > 0 persons/m², got -1"),
    ("Crowd.from_density: NaN", lambda b, c, m, p: Crowd.from_density(np.nan),
     ParameterError, r"density must be finite, got nan"),
    ("Crowd.with_density: text", lambda b, c, m, p: c.with_density("x"),
     ParameterError, r"density must be numeric, got 'x'"),
    ("MSDModel: NaN frequency", lambda b, c, m, p: MSDModel(np.nan, 0.3, 0.95),
     ParameterError, r"frequency must be finite, got nan"),
    ("ModalModel: repeated station",
     lambda b, c, m, p: ModalModel([2.0], [0.01], [1e4], [0, 0], [[1], [1]], 3.0, ["a"], [[1.0]]),
     ParameterError, r"positions must hold at least 2 strictly increasing stations \[m\]"),
    ("ModalModel.simply_supported_beam: no mode",
     lambda b, c, m, p: ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3, n_modes=0),
     ParameterError, r"n_modes must be a positive integer, got 0"),
    ("ZivanovicForce: negative scale", lambda b, c, m, p: ZivanovicForce(scale=-1),
     ParameterError, r"scale must be > 0, got -1"),
    ("synthetic_welch_psd: no window", lambda b, c, m, p: synthetic_welch_psd(p, 0),
     ParameterError, r"n_windows must be >= 1, got 0"),
    ("simulate: measured force with an unknown walk",
     lambda b, c, m, p: simulate(b, c, 10.0, force=MeasuredForce(records=["GaCo01_09"])),
     ParameterError, r"records must name packaged walks"),
    ("response_psd: a measured force has no load PSD",
     lambda b, c, m, p: response_psd(b, c, p.frequency, force=MeasuredForce()),
     ParameterError, r"force must be a ZivanovicForce or YoungForce here: a MeasuredForce"),
    ("identify_modes: one sample per sensor",
     lambda b, c, m, p: identify_modes(np.zeros((3, 1)), 20.0),
     ParameterError, r"signals must have shape \(n_sensors, n_samples\) with at least 100"),
]


@pytest.mark.parametrize("label, call, error, match", CASES, ids=[case[0] for case in CASES])
def test_bad_api_input(label, call, error, match, paper_bridge, paper_crowd, paper_msd, measured):
    with pytest.raises(error, match=match):
        call(paper_bridge, paper_crowd, paper_msd, measured)

