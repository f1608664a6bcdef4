"""Parametric bootstrap of least squares (docs: theory, Parametric bootstrap).

Gaussian records with the paper example's PSD (truth 3.0 Hz, 0.30): the bootstrap's scatter must
agree with the sandwich covariance, an independent derivation of the same quantity
(docs: theory, Sandwich covariance), and the replicates must be reproducible from their seed.
The coverage over 200 records is measured by ``accuracy/intervals.py bootstrap``.
"""

import warnings

import numpy as np
import pytest

from crowdvib import BoundWarning, ParameterError, estimate_hsi, response_psd, welch_psd
from crowdvib.signals.synthesis import gaussian_record, record_frequencies


@pytest.fixture(scope="module")
def one_record():
    from crowdvib import Crowd, ModalModel, MSDModel

    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    crowd = Crowd(density=0.5, walking_speed=1.30, step_frequency_mean=1.89,
                  step_frequency_std=0.175, body_mass=70.0)
    psd = response_psd(bridge, crowd, record_frequencies(3600.0, 20.0),
                       msd=MSDModel(3.0, 0.30, 0.95), crowd_model="smeared").psd
    measured = welch_psd(gaussian_record(psd, 20.0, rng=3), 20.0, window_length=60.0,
                         output_names=["midspan"]).band(0.0, 10.0)
    return measured, bridge, crowd


def _fit(record, **options):
    measured, bridge, crowd = record
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BoundWarning)
        return estimate_hsi(measured, bridge, crowd, band=(0.0, 10.0), method="least_squares",
                            **options)


@pytest.mark.slow
def test_bootstrap_scatter_matches_the_sandwich_and_is_seeded(one_record):
    estimate = _fit(one_record, interval="bootstrap", n_boot=60, rng=11)
    samples = estimate.bootstrap_samples
    assert samples.shape == (60, 2)
    # 60 replicates estimate a standard deviation within about ±18 % (2σ of its sampling
    # error √(1/(2·59)) = 9 %); the sandwich is the reference.
    for i, name in enumerate(estimate.free_parameters):
        assert samples[:, i].std(ddof=1) == pytest.approx(estimate.standard_errors[name],
                                                          rel=0.2)
        low, high = estimate.interval(name)
        assert low < getattr(estimate.msd, name) < high
        assert (low, high) == pytest.approx(tuple(np.quantile(samples[:, i], [0.025, 0.975])))
    assert estimate.to_dict()["estimate"]["interval"]["method"] == "bootstrap"
    again = _fit(one_record, interval="bootstrap", n_boot=60, rng=11)
    np.testing.assert_array_equal(again.bootstrap_samples, samples)


def test_coherent_records_share_their_random_phases():
    # Two rows with proportional PSDs (4:1) drawn coherently are the same record scaled by 2:
    # the fully coherent outputs of one mode (docs: theory, Parametric bootstrap).
    psd = np.vstack([4.0 * np.ones(101), np.ones(101)])
    rows = gaussian_record(psd, 10.0, rng=5, coherent=True)
    np.testing.assert_allclose(rows[0], 2.0 * rows[1], atol=1e-12)
    independent = gaussian_record(psd, 10.0, rng=5)
    assert abs(np.corrcoef(independent)[0, 1]) < 0.3


def test_bootstrap_needs_enough_replicates(one_record):
    with pytest.raises(ParameterError, match="n_boot must be an integer >= 20"):
        _fit(one_record, interval="bootstrap", n_boot=5)
    with pytest.raises(ParameterError, match="interval must be one of"):
        _fit(one_record, interval="jackknife")
