"""PSD conventions against Parseval, closed forms and scipy (docs: theory, Conventions, §3, §3.4)."""

import numpy as np
import pytest
from scipy import integrate, signal, stats

from crowdvib import ModalModel, MSDModel, ZivanovicForce, frf, welch_psd
from crowdvib.models.loading import STANDARD_GRAVITY
from crowdvib.signals import LowPassFilter, welch_kernel

pytestmark = pytest.mark.reference


def test_crowd_load_variance_matches_campbell_closed_form(paper_bridge, paper_crowd, reference):
    # docs: theory, Modal load PSD of a Poisson crowd check: σ_Q² = Ψ11 W² Σ_c E[α_c²]/2, the expectation over f_s ~ N(μ, σ)
    # computed here independently by quadrature in the step frequency (not in f).
    force = ZivanovicForce()
    f = np.linspace(1e-3, 25.0, 250_001)
    variance = np.trapezoid(force.modal_load_psd(f, paper_crowd, paper_bridge)[:, 0, 0], f)
    pdf = stats.norm(paper_crowd.step_frequency_mean, paper_crowd.step_frequency_std).pdf

    def mean_square(c):
        def integrand(fs):
            return force.mean_square_dlf(np.full((10,), fs))[c] * pdf(fs)
        return integrate.quad(integrand, 0.5, 3.5)[0]

    expected = (37.5 * (70 * STANDARD_GRAVITY) ** 2
                * sum(mean_square(c) for c in range(10)) / 2)
    reference("modal load variance of a Poisson crowd (paper example)", variance, expected,
              rel=1e-3, unit="N²", source="Campbell's theorem by quadrature over f_s (docs: "
                                          "theory, Modal load PSD of a Poisson crowd)")


def test_sdof_frf_matches_closed_form(reference):
    # Closed form of an SDOF accelerance at the antinode: H = −ω²/(k − ω² m + iωc).
    bridge = ModalModel.simply_supported_beam(40.0, 2.0, 2.5, 0.01, 30e3)
    f = np.linspace(0.1, 6.0, 500)
    w, wn = 2 * np.pi * f, 2 * np.pi * 2.5
    expected = -w**2 / (30e3 * wn**2 - w**2 * 30e3 + 1j * w * 2 * 0.01 * 30e3 * wn)
    got = frf(bridge, f).values[0, 0]
    reference("SDOF accelerance, real part (500 frequencies)", got.real, expected.real,
              rel=1e-12, unit="1/kg", source="closed form −ω²/(k − ω²m + iωc)")
    reference("SDOF accelerance, imaginary part (500 frequencies)", got.imag, expected.imag,
              rel=1e-12, unit="1/kg", source="closed form −ω²/(k − ω²m + iωc)")
    # Resonance: |displacement receptance| = 1/(2ξk).
    at = frf(bridge, [2.5]).values[0, 0, 0] / -(wn**2)
    reference("SDOF receptance at resonance", abs(at), 1 / (2 * 0.01 * 30e3 * wn**2), rel=1e-12,
              unit="m/N", source="closed form 1/(2ξk)")


def test_coupled_poles_match_characteristic_polynomial(paper_bridge, paper_crowd, paper_msd,
                                                       reference):
    # 1 mode + smeared MSD is a 2-DOF system (docs: theory, The smeared crowd and the occupied bridge); its poles are the roots of
    # det(λ²M + λC + K) = 0, a quartic written out here by hand.
    from crowdvib import effective_modal_properties
    psi, mh = 37.5, 70.0
    m1, k1 = paper_msd.sprung_mass(mh), paper_msd.stiffness(mh)
    c1 = paper_msd.damping(mh)
    m0 = mh - m1
    ms, ws = 50e3, 2 * np.pi * 2.0
    M11, M22 = ms + m0 * psi, m1 * psi
    K11, K12, K22 = ms * ws**2 + k1 * psi, -k1 * psi, k1 * psi
    C11, C12, C22 = 2 * 0.005 * ms * ws + c1 * psi, -c1 * psi, c1 * psi
    p11 = np.array([M11, C11, K11])
    p22 = np.array([M22, C22, K22])
    p12 = np.array([0.0, C12, K12])
    quartic = np.polysub(np.polymul(p11, p22), np.polymul(p12, p12))
    roots = np.roots(quartic)
    roots = roots[roots.imag > 0]
    expected = np.sort(np.abs(roots) / (2 * np.pi))
    props = effective_modal_properties(paper_bridge, paper_crowd, paper_msd)
    got = np.sort(np.r_[props.frequencies, props.interaction_frequencies])
    reference("poles of the mode + smeared MSD (paper example)", got, expected, rel=1e-9,
              unit="Hz", source="roots of the hand-written characteristic quartic (docs: theory, "
                                "The smeared crowd and the occupied bridge)")


def test_welch_of_white_noise_is_flat_at_variance_over_nyquist(rng, reference):
    # One-sided density convention: white noise of variance σ² has G = σ²/(fs/2) (docs: theory, Conventions).
    fs, sigma = 100.0, 0.7
    x = rng.normal(0, sigma, size=400_000)
    psd = welch_psd(x, fs, window_length=20.0)
    inner = psd.psd[0, 1:-1]
    reference("Welch PSD level of white noise", inner.mean(), sigma**2 / (fs / 2), rel=0.01,
              unit="1/Hz", source="one-sided convention G = σ²/(f_s/2) (docs: theory, Conventions)")
    # Parseval: ∫ G df = variance of the record.
    reference("Parseval: ∫G df of a Welch PSD", psd.variance()[0], x.var(), rel=0.01,
              source="variance of the record (Parseval)")


def test_welch_psd_equals_scipy_welch(rng, reference):
    # Same numbers as scipy.signal.welch(Hann, 50 %, constant detrend, density).
    x = rng.normal(size=(2, 12_000))
    ours = welch_psd(x, 50.0, window_length=10.0, output_names=("a", "b"))
    f, ref = signal.welch(x, fs=50.0, window="hann", nperseg=500, noverlap=250,
                          detrend="constant", scaling="density", axis=-1)
    np.testing.assert_allclose(ours.frequency, f)
    reference("Welch PSD of two noise records", ours.psd, ref, rel=1e-12,
              source="scipy.signal.welch (Hann, 50 %, constant detrend, density)")
    assert ours.n_windows == 47


def test_welch_kernel_has_unit_area_and_predicts_a_sinusoid(reference):
    # docs: theory, What a Welch estimate sees: the expectation kernel: E[Ĝ](f) = ∫ G(ν) K(f−ν) dν with ∫K = 1. A sinusoid of amplitude A at f0
    # has G = A²/2 δ(f − f0), so its Welch PSD is (A²/2) K(f − f0), here checked against scipy.
    T = 20.0
    nu = np.linspace(-40, 40, 400_001) / T
    reference("area of the Welch expectation kernel", np.trapezoid(welch_kernel(nu, T), nu), 1.0,
              abs=2e-5, source="unit area (docs: theory, What a Welch estimate sees)")
    fs, amplitude, f0 = 100.0, 0.3, 2.0 + 0.37 / T      # between two bins
    t = np.arange(int(600 * fs)) / fs
    x = amplitude * np.sin(2 * np.pi * f0 * t + 0.4)
    psd = welch_psd(x, fs, window_length=T)
    near = np.abs(psd.frequency - f0) < 3 / T
    expected = amplitude**2 / 2 * welch_kernel(psd.frequency[near] - f0, T)
    np.testing.assert_allclose(psd.psd[0, near], expected, rtol=0.02, atol=1e-6 * expected.max())


def test_lowpass_power_gain_matches_filtered_noise(rng, reference):
    # A zero-phase filter applies |H|² twice: the PSD of filtered white noise is G·|H|⁴.
    fs = 100.0
    lowpass = LowPassFilter(cutoff=5.0, order=4, sample_rate=fs)
    x = rng.normal(size=600_000)
    raw = welch_psd(x, fs, window_length=20.0)
    filtered = welch_psd(x, fs, window_length=20.0, lowpass=lowpass)
    band = (raw.frequency > 1) & (raw.frequency < 7)
    ratio = filtered.psd[0, band] / raw.psd[0, band]
    reference("zero-phase low-pass: filtered/raw PSD of white noise, 1–7 Hz", ratio,
              lowpass.power_gain(raw.frequency[band]), rel=0.02, abs=1e-4,
              source="|H|⁴ of a forward-backward Butterworth filter (docs: theory, Conventions)")
    assert filtered.lowpass is lowpass


_APPARENT = ("M_app(0) = m_h, M_app(∞) = (1 − μ_h1) m_h (docs: theory, Occupied receptance and "
             "FRFs)")


def test_apparent_mass_limits(reference):
    # docs: theory, Occupied receptance and FRFs: M_app(0) = m_h, M_app(∞) = m_h0 = (1 − μ_h1) m_h.
    msd = MSDModel(3.0, 0.3, 0.95)
    reference("apparent mass of the MSD at 0 Hz", msd.apparent_mass(0.0, 70.0), 70.0, rel=1e-6,
              unit="kg", source=_APPARENT)
    reference("apparent mass of the MSD far above f_h1", msd.apparent_mass(1e9, 70.0), 3.5,
              rel=1e-6, unit="kg", source=_APPARENT)


def test_modal_scaling_does_not_change_physics(paper_crowd, paper_msd, welch_grid):
    # docs: theory, Conventions: every formula is invariant to mode scaling with m_j = φᵀMφ.
    from crowdvib import response_psd
    bridge = ModalModel.simply_supported_beam(60.0, 4.0, [1.8, 3.1], [0.006, 0.004],
                                              [60e3, 45e3], n_modes=2,
                                              outputs={"mid": 30.0, "quarter": 15.0})
    a = response_psd(bridge, paper_crowd, welch_grid, msd=paper_msd, crowd_model="smeared")
    b = response_psd(bridge.mass_normalised(), paper_crowd, welch_grid, msd=paper_msd,
                     crowd_model="smeared")
    np.testing.assert_allclose(b.psd, a.psd, rtol=1e-9, atol=1e-14 * a.psd.max())


@pytest.mark.parametrize("mean, std", [(0.07, 0.03), (0.03, 0.015), (0.3644, 0.0583),
                                       (-0.01, 0.02)])
def test_positive_normal_moments_match_scipy_truncnorm(mean, std, reference):
    # Reference: scipy.stats.truncnorm (X > 0) for a positive mean; for a mean ≤ 0 the sampler
    # clips at 0, E[max(X, 0)^k] by numerical quadrature.
    from crowdvib.models.loading import positive_normal_moments

    first, second = positive_normal_moments(mean, std)
    if mean > 0:
        law = stats.truncnorm(-mean / std, np.inf, loc=mean, scale=std)
        reference(f"mean of a DLF N({mean}, {std}) redrawn until positive", first, law.mean(),
                  rel=1e-10, source="scipy.stats.truncnorm")
        reference(f"mean square of a DLF N({mean}, {std}) redrawn until positive", second,
                  law.moment(2), rel=1e-10, source="scipy.stats.truncnorm")
    else:
        law = stats.norm(mean, std)
        assert first == pytest.approx(integrate.quad(lambda x: x * law.pdf(x), 0, 1)[0],
                                      rel=1e-6)
        assert second == pytest.approx(integrate.quad(lambda x: x * x * law.pdf(x), 0, 1)[0],
                                       rel=1e-6)


def test_spectral_dlf_moments_are_those_the_simulator_draws(reference):
    # Issue 12: the sampler redraws non-positive DLFs; the spectral load now uses the moments of
    # exactly those draws (it used untruncated ones, 0.6–2.2 % off for harmonics 2–5). Reference:
    # a Monte Carlo of 400 000 pedestrians at f_s = 1.89 Hz (relative error ≈ 0.3 % at 3σ).
    force = ZivanovicForce()
    amplitudes, _ = force.sample(np.full(400_000, 1.89), np.random.default_rng(2))
    spectral = force.mean_square_dlf(np.full((10, 1), 1.89))[:, 0]
    reference("mean-square DLFs of the spectral load (10 components, f_s = 1.89 Hz)", spectral,
              (amplitudes**2).mean(axis=0), rel=6e-3,
              source="Monte Carlo of 400 000 pedestrians drawn by the simulator's sampler")


@pytest.mark.parametrize("cutoff, order, fs", [(10.0, 4, 25.0), (5.0, 4, 100.0), (2.3, 2, 50.0),
                                               (10.0, 8, 50.0), (0.5, 1, 20.0)])
def test_lowpass_power_gain_closed_form_equals_the_designed_filter(cutoff, order, fs):
    # The closed-form |H|⁴ of LowPassFilter.power_gain (issue 39) against the reference it
    # replaced: |sosfreqz(butter(...))|⁴ of the filter apply() runs, from 0 to beyond Nyquist.
    lowpass = LowPassFilter(cutoff=cutoff, order=order, sample_rate=fs)
    frequency = np.linspace(0.0, 0.75 * fs, 2001)
    _, response = signal.sosfreqz(lowpass._sos(), worN=frequency, fs=fs)
    np.testing.assert_allclose(lowpass.power_gain(frequency), np.abs(response) ** 4,
                               rtol=1e-9, atol=1e-14)
