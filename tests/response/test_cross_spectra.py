"""Cross-spectral matrices: modelled (SpectralModel.cross_psd_array), measured
(welch_psd(..., cross=True)) and synthesised (gaussian_cross_record); docs: theory, The
cross-spectral matrix."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from scipy import signal

from crowdvib import (DataError, FluctuatingSpectralModel, ModalModel, MSDModel,
                      ParameterError, ResponsePSD, SpectralModel, welch_psd)
from crowdvib.io.casefile import load_case
from crowdvib.response.frequency_domain._welch_model import cross_power_coefficients, power_coefficients
from crowdvib.signals.synthesis import gaussian_cross_record, record_frequencies

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_cross_power_coefficients_reproduce_the_cross_products():
    # Reference: the definition Σ_r P_ar conj(P_br), P_ar = Σ_p A_ap R_pr / (iω − λ_p), summed
    # directly; the diagonal of the coefficients is power_coefficients.
    rng = np.random.default_rng(4)
    poles = -rng.uniform(0.05, 2.0, 6) + 1j * rng.uniform(-30, 30, 6)
    left = rng.normal(size=(3, 6)) + 1j * rng.normal(size=(3, 6))
    right = rng.normal(size=(6, 2)) + 1j * rng.normal(size=(6, 2))
    omega = np.linspace(-40.0, 40.0, 201)
    resolvent = 1.0 / (1j * omega[:, np.newaxis] - poles)
    projected = np.stack([(resolvent * row) @ right for row in left], axis=1)   # (f, a, r)
    direct = np.einsum("far,fbr->abf", projected, projected.conj())
    beta = cross_power_coefficients(poles, left, right)
    half = np.einsum("abp,fp->abf", beta, resolvent)
    expanded = half + np.conj(np.swapaxes(half, 0, 1))
    np.testing.assert_allclose(expanded, direct, rtol=1e-10, atol=1e-12 * np.abs(direct).max())
    np.testing.assert_allclose(np.einsum("aap->ap", beta),
                               power_coefficients(poles, left, right), rtol=1e-12)


def _eeklo():
    case = load_case(EXAMPLES / "eeklo_like.toml")
    return case.structure, case.crowd, case.msd


@pytest.mark.parametrize("hsi", [True, False])
@pytest.mark.parametrize("window", [None, 25.0])
def test_model_cross_matrix_is_hermitian_with_the_psd_on_its_diagonal(hsi, window):
    # Reference: the model's own PSD (psd_array, tested elsewhere) and the definition S_ba =
    # conj S_ab; Eeklo-like bridge (14 modes, two outputs, band around its modes).
    structure, crowd, msd = _eeklo()
    grid = np.arange(50, 220) / 25.0
    model = SpectralModel(structure, crowd, grid, welch_window_length=window)
    cross = model.cross_psd_array(msd if hsi else None)
    psd = model.psd_array(msd if hsi else None)
    assert cross.shape == (2, 2, grid.size)
    np.testing.assert_allclose(np.einsum("aaf->af", cross).real, psd, rtol=1e-12)
    np.testing.assert_array_equal(cross, np.conj(np.swapaxes(cross, 0, 1)))
    # Positive semi-definite: |S_12|² ≤ S_11 S_22 (coherence ≤ 1).
    assert np.all(np.abs(cross[0, 1]) ** 2 <= psd[0] * psd[1] * (1 + 1e-9))


@pytest.mark.parametrize("hsi", [True, False])
def test_welch_cross_matrix_agrees_with_the_dense_rule(hsi):
    # Reference: the dense rectangle rule (16 points per bin of the exact cross-spectra), as for
    # the PSD (test_welch_model): the Hann correction is linear in the spectrum, so it applies
    # to every entry.
    structure, crowd, msd = _eeklo()
    grid = np.arange(50, 220) / 25.0
    model = SpectralModel(structure, crowd, grid, welch_window_length=25.0)
    msd = msd if hsi else None
    fast = model.cross_psd_array(msd)
    dense = model._dense_welch_psd(model._attached(msd), cross=True)
    assert np.abs(fast - dense).max() <= 1e-4 * np.abs(dense).max()


def test_one_mode_gives_a_rank_one_matrix_of_the_mode_shape():
    # Closed form: with one mode every output is φ_o q(t), so S_ab = φ_a φ_b / φ_a² · S_aa (real,
    # rank 1): quarter span of a sine mode φ = sin(π/4) = 1/√2.
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3,
                                              outputs={"midspan": 25.0, "quarter": 12.5})
    from crowdvib import Crowd
    crowd = Crowd.from_density(0.5, body_mass=70.0)
    grid = np.arange(1, 601) / 60.0
    cross = SpectralModel(bridge, crowd, grid, welch_window_length=60.0).cross_psd_array(MSDModel())
    np.testing.assert_allclose(cross[0, 1], cross[0, 0] / np.sqrt(2), rtol=1e-10)
    np.testing.assert_allclose(cross[1, 1], cross[0, 0] / 2, rtol=1e-10)


def test_fluctuating_model_mixes_the_cross_matrix_like_the_psd():
    # Reference: the mixture's own PSD (its diagonal) and the weighted sum of its nodes' models.
    structure, crowd, msd = _eeklo()
    grid = np.arange(63, 201) / 25.0
    # The mixture alone (the slow-modulation correction's matrix: tests/response/test_modulation.py).
    model = FluctuatingSpectralModel(structure, crowd, grid, welch_window_length=25.0,
                                     n_nodes=3, modulation=False)
    cross = model.cross_psd_array(msd)
    np.testing.assert_allclose(np.einsum("aaf->af", cross).real, model.psd_array(msd),
                               rtol=1e-12)
    direct = sum(w * m.cross_psd_array(msd) for w, m in zip(model.weights, model._models))
    np.testing.assert_allclose(cross, direct, rtol=1e-12)


@pytest.mark.parametrize("segment", [200, 201])
def test_measured_cross_spectra_match_scipy_csd(segment):
    # Reference: scipy.signal.csd (conj(X) Y averaged), an independent implementation with the
    # same Hann window, 50 % overlap and constant detrend: S_ab = E[X_a conj X_b] = csd(b, a).
    rng = np.random.default_rng(8)
    x = rng.standard_normal((2, 20000))
    x[1] += 0.6 * np.roll(x[0], 3)
    measured = welch_psd(x, 10.0, window_length=segment / 10.0, cross=True)
    _, csd = signal.csd(x[0], x[1], fs=10.0, window="hann", nperseg=segment,
                        noverlap=segment // 2, detrend="constant")
    np.testing.assert_allclose(measured.cross[1, 0], csd, rtol=1e-9, atol=1e-12 * abs(csd).max())
    np.testing.assert_array_equal(np.einsum("aaf->af", measured.cross).real, measured.psd)


def test_response_psd_keeps_its_cross_spectra_through_select_and_band():
    x = np.random.default_rng(2).standard_normal((3, 4000))
    measured = welch_psd(x, 10.0, window_length=20.0, cross=True, output_names=["a", "b", "c"])
    chosen = measured.select(["c", "a"]).band(1.0, 3.0)
    keep = (measured.frequency >= 1.0) & (measured.frequency <= 3.0)
    np.testing.assert_array_equal(chosen.cross, measured.cross[np.ix_([2, 0], [2, 0])][..., keep])
    assert chosen.cross.flags.writeable is False
    # Backwards compatible: no cross-spectra unless asked for, and none in the dict then.
    plain = welch_psd(x, 10.0, window_length=20.0)
    assert plain.cross is None and "cross" not in plain.to_dict()
    assert np.array(chosen.to_dict()["cross"]["imag"]) == pytest.approx(chosen.cross.imag)
    with pytest.raises(ParameterError, match=r"cross must have shape \(n_outputs, n_outputs, "
                                             r"n_frequencies\) = \(3, 3, 101\)"):
        dataclasses.replace(measured, cross=measured.cross[:2])
    assert isinstance(dataclasses.replace(measured, cross=None), ResponsePSD)
    broken = measured.cross.copy()
    broken[0, 1, 7] = np.nan
    with pytest.raises(DataError, match=r"cross-spectra must be finite, got a non-finite entry "
                                        r"at 0.35 Hz \(index 7\)"):
        dataclasses.replace(measured, cross=broken).check_measured()


def test_gaussian_cross_records_have_the_requested_cross_spectral_matrix():
    # Reference: the requested S itself (definition of the synthesis), checked on the Welch
    # average of 60 records; a singular S (rank 1: one mode at two outputs) gives proportional
    # records.
    rate, duration = 10.0, 400.0
    frequency = record_frequencies(duration, rate)
    peak = 1.0 / (1.0 + 4.0 * (frequency - 1.5) ** 2)
    cross = np.empty((2, 2, frequency.size), complex)
    cross[0, 0], cross[1, 1] = peak + 0.1, 0.25 * peak + 0.05
    cross[0, 1] = 0.4 * peak * np.exp(1j * frequency)
    cross[1, 0] = np.conj(cross[0, 1])
    total = 0.0
    for seed in range(60):
        records = gaussian_cross_record(cross, rate, rng=seed)
        total = total + welch_psd(records, rate, window_length=10.0, cross=True).cross / 60
    # Welch bins (0.1 Hz) are every 40th record bin; S is smooth on 0.1 Hz, so the Welch
    # kernel leaves it as it is (to ~0.5 %) away from 0 Hz and the Nyquist frequency.
    expected = cross[..., ::40]
    inner = (frequency[::40] > 0.3) & (frequency[::40] < 4.5)
    assert np.abs(total - expected)[..., inner].max() < 0.05 * np.abs(expected).max()
    rank_one = np.einsum("a,b,f->abf", [1.0, 0.5], [1.0, 0.5], peak).astype(complex)
    records = gaussian_cross_record(rank_one, rate, rng=1)
    np.testing.assert_allclose(records[1], 0.5 * records[0], atol=1e-12 * np.abs(records).max())
    with pytest.raises(ParameterError, match="cross must be Hermitian"):
        gaussian_cross_record(cross * np.array([1, 1j])[:, np.newaxis, np.newaxis], rate)
