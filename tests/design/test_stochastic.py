"""Stochastic prediction: spectral moments and Davenport's peak factor (closed forms)."""

import numpy as np
import pytest

from crowdvib import ParameterError, response_psd
from crowdvib.design.stochastic import davenport_peak_factor, predict_response


def test_davenport_peak_factor():
    # Davenport (1964): g = sqrt(2 ln νT) + 0.5772/sqrt(2 ln νT); ν = 2 Hz, T = 600 s.
    x = np.sqrt(2 * np.log(1200.0))
    assert davenport_peak_factor(2.0, 600.0) == pytest.approx(x + 0.5772156649 / x)


def test_prediction_matches_direct_integration_of_response_psd(paper_bridge, paper_crowd,
                                                               paper_msd):
    # σ² = ∫ G df and ν0² = ∫ f² G df / σ² of crowdvib.response_psd on an independent, much
    # finer grid (0.0002 Hz to 6 Hz) integrated with the trapezoid rule.
    prediction = predict_response(paper_bridge, paper_crowd, msd=paper_msd, duration=600.0)
    grid = np.linspace(0.0, 6.0, 30001)
    for model, msd in (("empty", None), ("hsi", paper_msd)):
        psd = response_psd(paper_bridge, paper_crowd, grid, msd=msd, crowd_model="smeared").psd[0]
        variance = np.trapezoid(psd, grid)
        rate = np.sqrt(np.trapezoid(psd * grid**2, grid) / variance)
        index = prediction.models.index(model)
        assert prediction.rms[index, 0] == pytest.approx(np.sqrt(variance), rel=2e-3)
        assert prediction.crossing_rate[index, 0] == pytest.approx(rate, rel=2e-3)
        assert prediction.expected_peak[index, 0] == pytest.approx(
            davenport_peak_factor(rate, 600.0) * np.sqrt(variance), rel=3e-3)
    # docs: theory, Spectral-model numbers: 0.578 m/s² rms without HSI, 0.330 with HSI.
    assert prediction.rms[:, 0][[0, 2]] == pytest.approx([0.578, 0.330], abs=1.5e-3)


def test_prediction_bad_input(paper_bridge, paper_crowd):
    with pytest.raises(ParameterError, match="duration must be > 0 s"):
        predict_response(paper_bridge, paper_crowd, duration=0.0)
    with pytest.raises(ParameterError, match="density must be > 0"):
        predict_response(paper_bridge, paper_crowd.with_density(0.0))
    with pytest.raises(ParameterError, match="weighting must be None or 'Wb'"):
        predict_response(paper_bridge, paper_crowd, weighting="Wd")
