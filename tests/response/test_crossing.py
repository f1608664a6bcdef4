"""Finite crossings: the crossing kernel's spread and the smoothed load spectrum (docs: theory,
Finite crossings)."""

import numpy as np
import pytest

from crowdvib import Crowd, ParameterError, ZivanovicForce
from crowdvib.response.frequency_domain._crossing import crossing_spread, smoothed_load_spectrum
from crowdvib.response.frequency_domain.fluctuation import FluctuatingSpectralModel
from crowdvib.response.frequency_domain.spectral import SpectralModel


def sine_kernel(delta, crossing_time):
    """|Φ̂(ω)|² of a half-sine envelope over a crossing (closed form, design note §3.2), as a
    density in Δ [Hz] normalised by its Parseval integral T_c/2."""
    omega, big = 2 * np.pi * delta, np.pi / crossing_time
    with np.errstate(divide="ignore", invalid="ignore"):
        energy = 4 * big**2 * np.cos(omega * crossing_time / 2) ** 2 / (big**2 - omega**2) ** 2
    energy = np.where(np.isclose(np.abs(omega), big), (crossing_time / 2) ** 2, energy)
    return energy / (crossing_time / 2)


def test_spread_of_a_half_sine_is_one_over_twice_the_crossing_time(paper_bridge):
    # σ_K² = v² ∫φ'² / (4π² ∫φ²) = (v/2L)² for φ = sin(πx/L); the stations' differences
    # reach it to the discretisation of the table (201 stations: 1e-4).
    for speed in (0.8, 1.3):
        assert crossing_spread(paper_bridge, speed, 0) == pytest.approx(speed / 100.0, rel=1e-4)


def test_spread_is_the_second_moment_of_the_exact_kernel():
    # Parseval: the variance of |Φ̂|²/∫|Φ̂|² equals v²⟨φ'²⟩/(4π²⟨φ²⟩). Numerical moment of the
    # closed-form kernel (its 1/Δ⁴ tail integrated far out) against the spread.
    crossing_time = 50.0 / 1.3
    delta = np.linspace(-40.0, 40.0, 4_000_001)
    kernel = sine_kernel(delta, crossing_time)
    step = delta[1] - delta[0]
    assert kernel.sum() * step == pytest.approx(1.0, abs=1e-4)
    variance = (kernel * delta**2).sum() * step
    assert np.sqrt(variance) == pytest.approx(1.0 / (2 * crossing_time), rel=1e-3)


def test_three_point_rule_matches_the_convolution_with_the_exact_kernel(paper_crowd):
    # s ∗ K with the closed-form half-sine kernel, by direct quadrature, against the rule:
    # within 2e-4 of the peak of s over 0.5–6 Hz (the rule's error is the kernel's fourth
    # moment against s'''', which the heavy tail makes small but not zero).
    force = ZivanovicForce()
    crossing_time = 50.0 / paper_crowd.walking_speed
    spread = 1.0 / (2 * crossing_time)
    frequency, df = np.linspace(0.5, 6.0, 221, retstep=True)
    delta, spacing = np.linspace(-2.0, 2.0, 200_001, retstep=True)
    weights = sine_kernel(delta, crossing_time) * (delta[1] - delta[0])
    # exact(f_i) = Σ_j w_j s(|f_i − Δ_j|). The frequency step (0.025 Hz) is 1250 steps of Δ
    # (2e-5 Hz), so every f_i − Δ_j lies on one grid u_m = f_0 − Δ_max + m·spacing, at
    # m = 1250 i + (J − j): s is evaluated once there instead of 221 times on 200 001 points.
    # The same quadrature: its nodes move by rounding only (< 1e-15 Hz); against the direct
    # sums (every 11th frequency, checked when this was written) it differs by < 1e-13 of
    # each value, far inside the 2e-4 of the peak asserted.
    stride, last = 1250, delta.size - 1
    assert stride * spacing == pytest.approx(df, rel=1e-14)
    nodes = frequency[0] - delta[-1] + spacing * np.arange(stride * (frequency.size - 1)
                                                          + last + 1)
    load = force.load_spectrum(np.abs(nodes), paper_crowd)
    exact = np.array([weights[::-1] @ load[stride * i:stride * i + last + 1]
                      for i in range(frequency.size)])
    rule = smoothed_load_spectrum(force, frequency, paper_crowd, spread)
    plain = force.load_spectrum(frequency, paper_crowd)
    peak = plain.max()
    assert np.abs(rule - exact).max() < 2e-4 * peak
    assert np.abs(plain - exact).max() > 5 * np.abs(rule - exact).max()   # it does something
    # The kernel keeps the load's variance: ∫ s ∗ K df = ∫ s df.
    grid = np.linspace(0.0, 12.0, 24001)
    assert np.trapezoid(smoothed_load_spectrum(force, grid, paper_crowd, spread), grid) == (
        pytest.approx(np.trapezoid(force.load_spectrum(grid, paper_crowd), grid), rel=1e-6))


def test_fluctuating_model_uses_the_occupied_modes_kernel(paper_bridge, paper_msd):
    crowd = Crowd.from_density(0.25)
    grid = np.linspace(1.5, 2.5, 501)
    model = FluctuatingSpectralModel(paper_bridge, crowd, grid)
    assert model.crossing_spread == pytest.approx(crowd.walking_speed / 100.0, rel=1e-4)
    narrow = FluctuatingSpectralModel(paper_bridge, crowd, grid, finite_crossing=False)
    assert narrow.crossing_spread == 0.0
    # Each node is a smeared model with the smoothed load: one node is SpectralModel with it.
    single = FluctuatingSpectralModel(paper_bridge, crowd, grid, n_nodes=1)
    smeared = SpectralModel(paper_bridge, crowd, grid, crossing_spread=model.crossing_spread)
    np.testing.assert_array_equal(single.psd_array(paper_msd), smeared.psd_array(paper_msd))
    # Near the crowd's mean step frequency s is concave: the smoothing lowers the resonance.
    a, b = model.psd_array(paper_msd)[0], narrow.psd_array(paper_msd)[0]
    assert 0.99 < a.max() / b.max() < 0.999


def test_bad_crossing_input_is_refused(paper_bridge, paper_crowd):
    with pytest.raises(ParameterError, match="crossing_spread must be >= 0 Hz, got -0.1"):
        SpectralModel(paper_bridge, paper_crowd, [1.0, 2.0], crossing_spread=-0.1)
    with pytest.raises(ParameterError, match="crossing_spread is set from the mode shape"):
        FluctuatingSpectralModel(paper_bridge, paper_crowd, [1.0, 2.0], crossing_spread=0.01)
    with pytest.raises(ParameterError, match="finite_crossing"):
        FluctuatingSpectralModel(paper_bridge, paper_crowd, [1.0, 2.0], finite_crossing="yes")
