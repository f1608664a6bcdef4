"""Statistics of Welch ordinates that the intervals rest on (docs: theory, Welch statistics).

References: the DFT of a Hann window is −¼, ½, −¼ at bins −1, 0, 1, so the squared coherence of
neighbouring periodogram bins of white noise is (Σw² e^{2πit/N}/Σw²)² = (2/3)² = 4/9, and 1/36 two
bins apart; Parseval for the spectral synthesis: variance = Σ G Δf.
"""

import numpy as np
import pytest

from crowdvib import welch_psd
from crowdvib.signals.synthesis import gaussian_record, record_frequencies
from crowdvib.signals.welch import welch_bin_correlation, welch_degrees_of_freedom

pytestmark = pytest.mark.reference


_HANN = "closed form from the Hann window's DFT (−¼, ½, −¼): (2/3)², (1/6)²"


def test_single_hann_segment_bin_correlation_is_closed_form(reference):
    rho = welch_bin_correlation(1, max_lag=3)
    assert rho[0] == 1.0
    reference("Hann periodogram: correlation of neighbouring bins", rho[1], 4 / 9, rel=1e-9,
              source=_HANN)
    reference("Hann periodogram: correlation two bins apart", rho[2], 1 / 36, rel=1e-9,
              source=_HANN)
    assert rho[3] == pytest.approx(0.0, abs=1e-12)


def test_white_noise_synthesis_has_the_requested_variance(reference):
    # Flat one-sided PSD G0 up to Nyquist: σ² = G0 · f_s / 2 (Parseval).
    sample_rate, g0 = 20.0, 0.3
    frequency = record_frequencies(600.0, sample_rate)
    records = gaussian_record(np.full((8, frequency.size), g0), sample_rate, rng=5)
    assert records.shape == (8, 12000)
    reference("variance of synthesised white noise", records.var(), g0 * sample_rate / 2,
              rel=0.02, source="Parseval: σ² = G0 f_s/2")


def test_welch_of_synthetic_white_noise_has_the_predicted_scatter_and_correlation(reference):
    # Welch ordinates of Gaussian records scatter as G·χ²_ν/ν with neighbours correlated as
    # welch_bin_correlation predicts (the assumptions of the sandwich covariance).
    sample_rate, g0, duration, window = 20.0, 1.0, 1200.0, 20.0
    frequency = record_frequencies(duration, sample_rate)
    records = gaussian_record(np.full((40, frequency.size), g0), sample_rate, rng=11)
    psd = welch_psd(records, sample_rate, window_length=window)
    inner = psd.psd[:, 5:-5]                       # away from 0 Hz and Nyquist
    relative = inner / g0 - 1.0
    dof = welch_degrees_of_freedom(psd.n_windows)
    assert inner.mean() == pytest.approx(g0, rel=0.01)
    reference("relative variance of Welch ordinates (40 noise records)", relative.var(), 2 / dof,
              rel=0.05, source="χ²_ν/ν with ν of the overlapped Hann estimate (docs: theory, "
                               "Welch statistics)")
    rho = welch_bin_correlation(psd.n_windows)
    for lag in (1, 2):
        measured = np.mean(relative[:, :-lag] * relative[:, lag:]) / relative.var()
        assert measured == pytest.approx(rho[lag], abs=0.03)


def test_record_frequencies_refuses_odd_sample_counts():
    from crowdvib import ParameterError

    with pytest.raises(ParameterError, match="even number of samples"):
        record_frequencies(1.05, 20.0)


def test_measured_dispersion_is_one_for_a_gaussian_record_and_more_for_a_changing_one():
    # A stationary Gaussian record scatters as χ²_ν: dispersion 1 (mean over four records).
    sample_rate = 20.0
    frequency = record_frequencies(3600.0, sample_rate)
    records = gaussian_record(np.ones((4, frequency.size)), sample_rate, rng=3)
    steady = welch_psd(records, sample_rate, window_length=60.0)
    assert steady.dispersion[:, 5:-5].mean() == pytest.approx(1.0, abs=0.04)
    # The amplitude switched between a² = 1 and 4 every 5 minutes (a crowd that comes and goes):
    # the segments scatter about their mean by E[a⁴] + Var(a²) = 10.75 against the χ² value
    # E[a²]² = 6.25 (in units of G²), a ratio of 1.72 before the persistence of each level,
    # which only adds.
    envelope = np.where((np.arange(records.shape[1]) // 6000) % 2, 2.0, 1.0)
    changing = welch_psd(records * envelope, sample_rate, window_length=60.0)
    assert changing.dispersion[:, 5:-5].mean() > 10.75 / 6.25
    # The band and output selections carry it along.
    part = changing.band(1.0, 2.0).select(["ch1"])
    assert part.dispersion.shape == part.psd.shape == (1, 61)


def test_welch_cross_matrices_of_noise_scatter_as_complex_wishart(reference):
    # The premises of the two-output likelihood (docs: theory, The likelihood of several
    # outputs): Welch cross-spectral matrices of Gaussian records, whitened by their expectation
    # (E = C⁻¹ Ŝ C⁻ᴴ − I, C Cᴴ = S), have diagonal entries of variance 1/n = 2/ν and
    # off-diagonal real and imaginary parts of variance 1/ν (complex Wishart with n = ν/2,
    # Yuen, Katafygiotis & Beck 2002), and each coordinate correlates with its neighbour one bin
    # away by ρ(1), as one output's ordinates do. Two white outputs with coherence 0.64.
    from crowdvib.signals.synthesis import gaussian_cross_record

    sample_rate, duration, window = 20.0, 1200.0, 20.0
    frequency = record_frequencies(duration, sample_rate)
    cross = np.array([[1.0, 0.8 * np.exp(0.6j)], [0.8 * np.exp(-0.6j), 1.0]])
    factor = np.linalg.cholesky(cross)
    whitened = []
    for seed in range(40):
        records = gaussian_cross_record(np.repeat(cross[..., np.newaxis], frequency.size, -1),
                                        sample_rate, rng=100 + seed)
        measured = welch_psd(records, sample_rate, window_length=window, cross=True)
        inner = np.moveaxis(measured.cross[..., 5:-5], -1, 0)
        half = np.linalg.solve(factor, inner)
        whitened.append(np.linalg.solve(factor, np.conj(np.swapaxes(half, 1, 2))) - np.eye(2))
    whitened = np.array(whitened)                                    # (records, bins, 2, 2)
    dof = welch_degrees_of_freedom(measured.n_windows)
    coordinates = {"diagonal": whitened[..., 0, 0].real, "Re off-diagonal": whitened[..., 0, 1].real,
                   "Im off-diagonal": whitened[..., 0, 1].imag}
    expected = {"diagonal": 2 / dof, "Re off-diagonal": 1 / dof, "Im off-diagonal": 1 / dof}
    rho = welch_bin_correlation(measured.n_windows)
    for name, values in coordinates.items():
        reference(f"variance of whitened Welch cross-matrix entries: {name}", values.var(),
                  expected[name], rel=0.06, source="complex Wishart with n = ν/2 [YKB02]")
        lagged = np.mean(values[:, :-1] * values[:, 1:]) / values.var()
        assert lagged == pytest.approx(rho[1], abs=0.04)
