"""Crowd relations, walking-force constants and walkway quadrature against docs: theory check values."""

import numpy as np
import pytest

from crowdvib import Crowd, ModalModel, YoungForce, ZivanovicForce
from crowdvib.models.crowd import bruno_venuti_step_frequency, weidmann_speed


@pytest.mark.parametrize("density, speed, step", [
    # docs: theory, The crowd table (Weidmann speed, Bruno & Venuti step frequency)
    (0.25, 1.339, 1.913), (0.50, 1.298, 1.890), (0.80, 1.165, 1.809), (1.00, 1.058, 1.735),
    (1.50, 0.807, 1.513)])
def test_crowd_relations(density, speed, step):
    assert weidmann_speed(density) == pytest.approx(speed, abs=5e-4)
    crowd = Crowd.from_density(density)
    assert crowd.walking_speed == pytest.approx(speed, abs=5e-4)
    assert crowd.step_frequency_mean == pytest.approx(step, abs=5e-4)
    assert crowd.step_frequency_std == 0.175      # AFGC 2006 via the paper


def test_bruno_venuti_reproduces_paper():
    # docs: theory, The crowd: f_s(1.30) = 1.891 Hz, the paper's 1.89 Hz.
    assert bruno_venuti_step_frequency(1.30) == pytest.approx(1.891, abs=5e-4)


def test_arrival_rate():
    # docs: theory, Poisson arrivals: λ = d·B·v.
    assert Crowd(0.5, 1.3, 1.89).arrival_rate(3.0) == pytest.approx(1.95)


@pytest.mark.parametrize("fs, mu1", [(1.68, 0.2762), (1.77, 0.3150), (1.87, 0.3564),
                                     (1.89, 0.3644), (2.00, 0.4051)])
def test_zivanovic_first_harmonic(fs, mu1):
    # docs: theory, Živanović, Pavić & Reynolds (2007) check values of μ₁(f_s).
    assert ZivanovicForce.first_harmonic_dlf(fs) == pytest.approx(mu1, abs=1e-4)


def test_zivanovic_subharmonic_means():
    # docs: theory, Živanović, Pavić & Reynolds (2007) table, subharmonic DLFs at α₁ = μ₁(1.89) = 0.3644 (mean-α₁ option).
    force = ZivanovicForce(subharmonics_follow_sampled_dlf=False)
    rms = np.sqrt(force.mean_square_dlf(np.full(10, 1.89))[5:])
    np.testing.assert_allclose(rms, [0.0126, 0.0370, 0.0204, 0.0140, 0.0127], atol=1e-4)


def test_zivanovic_sampling_statistics(rng):
    # Sampled DLFs follow the table: α₂ ~ N(0.07, 0.03), α₁ ~ N(μ₁, 0.16 μ₁) (docs: theory, Živanović, Pavić & Reynolds (2007)).
    amplitudes, phases = ZivanovicForce().sample(np.full(200_000, 1.89), rng)
    assert amplitudes.shape == phases.shape == (200_000, 10)
    assert amplitudes[:, 0].mean() == pytest.approx(0.3644, rel=0.005)
    assert amplitudes[:, 0].std() == pytest.approx(0.16 * 0.3644, rel=0.02)
    assert amplitudes[:, 1].mean() == pytest.approx(0.07, rel=0.02)   # truncation adds < 1 %
    assert np.all(amplitudes >= 0)
    assert phases.min() >= 0 and phases.max() < 2 * np.pi


def test_young_dlfs():
    # docs: theory, Young (2001) at f_s = 2 Hz: α₁ = 0.41·1.05, α₂ = 0.069 + 0.0056·4, α₃ = 0.033 + 0.0064·6,
    # α₄ = 0.013 + 0.0065·8; α₁ capped at 0.56 (f_s = 3 Hz).
    dlf = YoungForce().dlf(np.full(4, 2.0))
    np.testing.assert_allclose(dlf, [0.4305, 0.0914, 0.0714, 0.065], rtol=1e-12)
    assert YoungForce().dlf(np.full(4, 3.0))[0] == 0.56


def test_time_history_is_seeded_and_has_the_right_power():
    force = ZivanovicForce()
    t = np.arange(0, 600, 0.01)
    a = force.time_history(t, 1.89, 70.0, rng=5)
    np.testing.assert_array_equal(a, force.time_history(t, 1.89, 70.0, rng=5))
    assert not np.array_equal(a, force.time_history(t, 1.89, 70.0, rng=6))
    # The ten components sit at distinct frequencies, so over a long record the mean square of
    # W Σ α_c sin(2π r_c f_s t + θ_c) is W² Σ α_c²/2 (docs: theory, Modal load PSD of a Poisson crowd check, one pedestrian).
    amplitudes, _ = force.sample(np.array([1.89]), np.random.default_rng(5))
    expected = (70 * 9.81) ** 2 * np.sum(amplitudes**2) / 2
    assert np.mean(a**2) == pytest.approx(expected, rel=0.01)


def test_influence_matrix_of_a_torsional_mode():
    # φ(x, y) = sin(πx/L)·(2y/B − 1): ∫∫ φ² = (L/2)(B/3), cross term with bending ∫(2y/B−1) = 0.
    L, B = 25.0, 6.9
    x = np.linspace(0, L, 101)
    lanes = np.linspace(0, B, 201)
    bending = np.sin(np.pi * x / L)
    shapes = np.stack([np.column_stack([bending, bending * (2 * y / B - 1)]) for y in lanes])
    model = ModalModel(frequencies=[3.3, 4.14], damping_ratios=[0.0086, 0.0025],
                       modal_masses=[40e3, 30e3], positions=x, mode_shapes=shapes, width=B,
                       lanes=lanes, output_names=["edge"], output_shapes=[[1.0, 1.0]])
    psi = model.influence_matrix(1.0)
    assert psi[0, 0] == pytest.approx(L / 2 * B, rel=1e-6)
    assert psi[1, 1] == pytest.approx(L / 2 * B / 3, rel=1e-4)
    assert psi[0, 1] == pytest.approx(0.0, abs=1e-9)
    # Interpolated shapes: at the edge lane the torsion shape is ±sin.
    rows = model.shapes_at([L / 2, L / 2, 30.0], [0.0, B, B / 2])
    np.testing.assert_allclose(rows, [[1, -1], [1, 1], [0, 0]], atol=1e-12)


def test_body_mass_spread_enters_the_load_as_mean_square_weight():
    # docs: theory, Modal load PSD of a Poisson crowd: G_QQ ∝ E[W²] = g²(m² + σ_m²); σ_m = 0 is the paper's single mass.
    f = np.linspace(0.5, 10, 50)
    plain = ZivanovicForce().load_spectrum(f, Crowd(0.5, 1.3, 1.89, body_mass=70.0))
    spread = ZivanovicForce().load_spectrum(
        f, Crowd(0.5, 1.3, 1.89, body_mass=70.0, body_mass_std=14.0))
    np.testing.assert_allclose(spread, plain * (70**2 + 14**2) / 70**2, rtol=1e-12)


def test_simulated_body_masses_follow_the_crowd():
    from crowdvib.response import generate_traffic
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    crowd = Crowd(0.5, 1.3, 1.89, body_mass=72.0, body_mass_std=12.0)
    masses = np.array([p.body_mass for p in generate_traffic(bridge, crowd, 1800.0, rng=4)])
    assert masses.size > 3000
    assert masses.mean() == pytest.approx(72.0, abs=0.5)       # N(72, 12): s.e. of mean ≈ 0.2
    assert masses.std() == pytest.approx(12.0, rel=0.05)
    fixed = generate_traffic(bridge, crowd.__class__(0.5, 1.3, 1.89, body_mass=72.0), 60.0, rng=4)
    assert {p.body_mass for p in fixed} == {72.0}


def test_body_mass_spread_must_be_below_the_mass():
    from crowdvib import ParameterError
    with pytest.raises(ParameterError, match=r"body_mass_std must be < body_mass \(70 kg\), got 80"):
        Crowd(0.5, 1.3, 1.89, body_mass=70.0, body_mass_std=80.0)


def test_short_reprs_name_what_matters(paper_bridge, paper_crowd, paper_msd, welch_grid):
    # Issue 10: results print as one line, not hundreds of lines of arrays.
    from crowdvib import response_psd

    assert repr(paper_bridge) == ("ModalModel('simply supported beam', 2 Hz, walkway 50 m × 3 m, "
                                  "outputs ['midspan'])")
    psd = response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd,
                       welch_window_length=60.0, crowd_model="smeared")
    assert repr(psd) == ("ResponsePSD(['midspan'], 601 frequencies 0–10 Hz, T = 60 s, "
                         "source='model')")


@pytest.mark.parametrize("force", [ZivanovicForce(), ZivanovicForce(False), YoungForce()],
                         ids=["zivanovic", "zivanovic-mean-sub", "young"])
def test_load_spectrum_is_the_formula_on_every_call(force, paper_crowd, welch_grid):
    # docs: theory, Modal load PSD of a Poisson crowd: s(f) = E[W²] Σ_c E[α_c²|f/r_c]/2 ·
    # p_fs(f/r_c)/r_c. The DLF moments are kept per frozen model and grid: the second call (from
    # the cache) and another crowd on the same grid must still give the formula.
    other = Crowd(density=1.0, walking_speed=1.1, step_frequency_mean=2.0,
                  step_frequency_std=0.2, body_mass=80.0)
    for crowd in (paper_crowd, paper_crowd, other):
        ratios = force.ratios[:, np.newaxis]
        step = welch_grid / ratios
        expected = crowd.mean_square_weight() * (force.mean_square_dlf(step) / 2.0
                                                 * crowd.step_frequency_pdf(step) / ratios).sum(0)
        np.testing.assert_array_equal(force.load_spectrum(welch_grid, crowd),
                                      force.scale**2 * expected)


def test_a_mutable_force_model_is_never_answered_from_the_cache(paper_crowd, welch_grid):
    # A user's model whose DLFs change between calls (docs: theory, Your own model): the load
    # follows the change (the cache holds frozen dataclasses only).
    from crowdvib.models.loading import WalkingForce

    class Tunable(WalkingForce):
        ratios = np.array([1.0])
        level = 0.1

        def mean_square_dlf(self, step_frequency):
            return np.full(np.shape(step_frequency), self.level**2)

    force = Tunable()
    first = force.load_spectrum(welch_grid, paper_crowd)
    force.level = 0.2
    # (atol: the Gaussian tail far above the step frequencies is subnormal, rounded apart)
    np.testing.assert_allclose(force.load_spectrum(welch_grid, paper_crowd), 4 * first,
                               rtol=1e-12, atol=1e-300)
