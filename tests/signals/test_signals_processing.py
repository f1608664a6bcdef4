"""Detrend, resampling, time frames and the PSD convergence error (docs: theory, Welch PSDs, filters and convergence)."""

import numpy as np
import pytest

from crowdvib import LowPassFilter, welch_psd
from crowdvib.errors import DataError, ParameterError
from crowdvib.signals import (detrend, psd_convergence, resample, select_time_frame,
                              stationary_time_frame)


def test_detrend_constant_and_linear():
    t = np.arange(1000) / 100
    x = np.vstack([3.0 + np.sin(2 * np.pi * t), 1.0 + 0.5 * t])
    out = detrend(x)
    np.testing.assert_allclose(out.mean(axis=1), 0.0, atol=1e-12)
    np.testing.assert_allclose(detrend(x[1], "linear"), 0.0, atol=1e-12)
    with pytest.raises(ParameterError, match="kind must be"):
        detrend(x, "quadratic")


def test_resample_keeps_a_sine_and_reports_the_rate():
    rate = 200.0
    t = np.arange(int(60 * rate)) / rate
    x = np.sin(2 * np.pi * 3.3 * t)
    y, new_rate = resample(x, rate, 25.0)
    assert new_rate == 25.0 and y.shape == (1500,)
    t_new = np.arange(y.size) / new_rate
    middle = slice(100, -100)   # away from the polyphase filter's edge transients
    np.testing.assert_allclose(y[middle], np.sin(2 * np.pi * 3.3 * t_new)[middle], atol=2e-3)
    same, same_rate = resample(x, rate, rate)
    assert same_rate == rate and np.array_equal(same, x)


def test_select_time_frame():
    x = np.arange(1000.0).reshape(1, -1)
    np.testing.assert_array_equal(select_time_frame(x, 100.0, 2.0, 3.0), x[:, 200:300])
    with pytest.raises(DataError, match="time frame"):
        select_time_frame(x, 100.0, 20.0, 30.0)


def test_stationary_time_frame_skips_a_burst(rng):
    rate = 50.0
    x = rng.normal(size=int(600 * rate))
    x[: int(120 * rate)] *= 5.0     # the first two minutes: a group passing, not stationary
    start, end = stationary_time_frame(x, rate, block_length=60.0, tolerance=0.5)
    assert (start, end) == (120.0, 600.0)


def test_psd_convergence_matches_explicit_welch(rng):
    # docs: theory, Welch PSDs, filters and convergence: G_kT is the Welch PSD of the first k·T seconds, ΔG the relative 2-norm.
    rate, window = 50.0, 20.0
    x = rng.normal(size=(2, int(200 * rate)))
    conv = psd_convergence(x, rate, window_length=window, band=(2.0, 6.0))
    assert conv.n_windows.tolist() == list(range(1, 11))
    np.testing.assert_allclose(conv.duration, 20.0 * conv.n_windows)
    full = welch_psd(x, rate, window_length=window).band(2.0, 6.0).psd
    for k in (1, 4, 9):
        part = welch_psd(x[:, : int(k * window * rate)], rate, window_length=window)
        part = part.band(2.0, 6.0).psd
        expected = np.linalg.norm(part - full, axis=1) / np.linalg.norm(full, axis=1)
        np.testing.assert_allclose(conv.error[:, k - 1], expected, rtol=1e-10)
        worst = np.max(np.abs(part - full), axis=1) / np.max(np.abs(full), axis=1)
        inf = psd_convergence(x, rate, window_length=window, band=(2.0, 6.0), norm="inf")
        np.testing.assert_allclose(inf.error[:, k - 1], worst, rtol=1e-10)
    np.testing.assert_array_equal(conv.error[:, -1], 0.0)
    # For a stationary signal the error falls roughly like 1/sqrt(k).
    assert np.all(conv.error[:, 0] > 2 * conv.error[:, 7])
    assert conv.to_dict()["norm"] == "2"


def test_psd_convergence_with_lowpass_and_errors(rng):
    x = rng.normal(size=(1, 6000))
    lowpass = LowPassFilter(10.0, 4, 50.0)
    conv = psd_convergence(x, 50.0, window_length=20.0, lowpass=lowpass)
    assert conv.band == (0.0, 25.0)
    assert conv.duration_to_reach(10.0) == 20.0
    with pytest.raises(ParameterError, match="norm must be"):
        psd_convergence(x, 50.0, window_length=20.0, norm="1")
    with pytest.raises(DataError, match="shorter than one window"):
        psd_convergence(x, 50.0, window_length=500.0)
