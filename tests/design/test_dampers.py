"""Tuned mass dampers: coupled model against direct solves, and the classical tuning optima."""

import numpy as np
import pytest
from scipy import linalg
from scipy.optimize import brentq

from crowdvib import Crowd, ModalModel, MSDModel, ParameterError, effective_modal_properties, frf
from crowdvib import response_psd, ZivanovicForce
from crowdvib.design import TunedMassDamper, optimal_tuning, tune_damper
from crowdvib.errors import PlausibilityWarning


def direct_matrices(structure, dampers):
    """Mass, damping, stiffness of modes + dampers written out by hand (one DOF per damper,
    coupled through its mode-shape row: the textbook 2-DOF primary + absorber generalised)."""
    n, d = structure.n_modes, len(dampers)
    m = structure.modal_masses
    wn = 2 * np.pi * structure.frequencies
    mass = np.diag(np.concatenate([m, [t.mass for t in dampers]]))
    damping = np.zeros((n + d, n + d))
    stiffness = np.zeros((n + d, n + d))
    damping[:n, :n] = np.diag(2 * structure.damping_ratios * m * wn)
    stiffness[:n, :n] = np.diag(m * wn**2)
    for k, t in enumerate(dampers):
        phi = structure.shapes_at([t.position], None if t.lane is None else [t.lane])[0]
        for matrix, value in ((damping, t.damping()), (stiffness, t.stiffness())):
            matrix[:n, :n] += value * np.outer(phi, phi)
            matrix[:n, n + k] -= value * phi
            matrix[n + k, :n] -= value * phi
            matrix[n + k, n + k] += value
    return mass, damping, stiffness


def direct_poles(structure, dampers):
    """Poles with Im > 0 of the generalised eigenproblem of (M, C, K) in state form."""
    mass, damping, stiffness = direct_matrices(structure, dampers)
    size = mass.shape[0]
    a = np.block([[np.zeros((size, size)), np.eye(size)], [-stiffness, -damping]])
    b = np.block([[np.eye(size), np.zeros((size, size))], [np.zeros((size, size)), mass]])
    poles = linalg.eig(a, b, right=False)
    return np.sort_complex(poles[poles.imag > 0])


@pytest.fixture
def two_mode_bridge():
    return ModalModel.simply_supported_beam(40.0, 2.5, 1.8, [0.005, 0.008], [30e3, 28e3],
                                            n_modes=2, outputs={"mid": 20.0, "quarter": 10.0})


def poles_from(props):
    """Poles λ = −ξ|λ| + i|λ|sqrt(1 − ξ²) of every reported mode."""
    f = np.concatenate([props.frequencies, props.interaction_frequencies])
    z = np.concatenate([props.damping_ratios, props.interaction_damping_ratios])
    w = 2 * np.pi * f
    return np.sort_complex(-z * w + 1j * w * np.sqrt(1 - z**2))


def test_coupled_poles_match_direct_eigen_solve(paper_bridge, two_mode_bridge, reference):
    # Reference: scipy.linalg.eig of the hand-written 2-DOF (and 4-DOF) M, C, K.
    one = [TunedMassDamper(1000.0, 1.96, 0.08, 25.0)]
    two = [TunedMassDamper(600.0, 1.75, 0.06, 20.0), TunedMassDamper(500.0, 7.0, 0.1, 10.0)]
    for structure, dampers in ((paper_bridge, one), (two_mode_bridge, two)):
        ours = poles_from(effective_modal_properties(structure, dampers=dampers))
        direct = direct_poles(structure, dampers)
        assert ours.size == structure.n_modes + len(dampers)
        np.testing.assert_allclose(ours, direct, rtol=1e-9)     # complex: damping too
        reference(f"poles of {structure.n_modes} mode(s) with {len(dampers)} TMD(s) (|λ|)",
                  np.abs(ours), np.abs(direct), rel=1e-9, unit="rad/s",
                  source="scipy.linalg.eig of the hand-written M, C, K")


def test_frf_with_dampers_matches_direct_solve(two_mode_bridge):
    # Reference: −ω² φ_oᵀ [K − ω²M + iωC]⁻¹ φ_i restricted to the modal block, per frequency.
    dampers = [TunedMassDamper(600.0, 1.75, 0.06, 17.0), TunedMassDamper(500.0, 7.0, 0.1, 10.0)]
    f = np.linspace(0.5, 9.0, 120)
    got = frf(two_mode_bridge, f, dampers=dampers).values
    mass, damping, stiffness = direct_matrices(two_mode_bridge, dampers)
    shapes = two_mode_bridge.output_shapes
    n = two_mode_bridge.n_modes
    for k, fk in enumerate(f):
        w = 2 * np.pi * fk
        h = np.linalg.inv(stiffness - w**2 * mass + 1j * w * damping)[:n, :n]
        np.testing.assert_allclose(got[:, :, k], -w**2 * shapes @ h @ shapes.T, rtol=1e-10)


def test_psd_with_crowd_and_dampers_matches_literal_formula(two_mode_bridge):
    # Reference: docs: theory, Response PSD with HSI written literally, the damper's apparent mass m_d T(ω) φ_d φ_dᵀ
    # added beside the crowd's M_app Ψ (one inverse per frequency).
    crowd = Crowd.from_density(0.6)
    msd = MSDModel(2.8, 0.3, 0.95)
    damper = TunedMassDamper(700.0, 1.72, 0.07, 18.0)
    f = np.linspace(0.2, 8.0, 400)
    got = response_psd(two_mode_bridge, crowd, f, msd=msd, dampers=[damper],
                       crowd_model="smeared").psd
    psi = two_mode_bridge.influence_matrix(0.6)
    load = ZivanovicForce().load_spectrum(f, crowd)
    m, wn = two_mode_bridge.modal_masses, 2 * np.pi * two_mode_bridge.frequencies
    phi = two_mode_bridge.shapes_at([18.0])[0]
    reference = []
    for fk, s in zip(f, load):
        w = 2 * np.pi * fk
        k_d, c_d = damper.stiffness(), damper.damping()
        m_app_d = damper.mass * (k_d + 1j * w * c_d) / (k_d - w**2 * damper.mass + 1j * w * c_d)
        added = msd.apparent_mass(fk, crowd.body_mass) * psi + m_app_d * np.outer(phi, phi)
        h = np.linalg.inv(np.diag(m * wn**2) - w**2 * (np.diag(m) + added)
                          + 1j * w * np.diag(2 * two_mode_bridge.damping_ratios * m * wn))
        ha = -w**2 * two_mode_bridge.output_shapes @ h
        reference.append(np.real(np.diag(ha @ (s * psi) @ ha.conj().T)))
    reference = np.array(reference).T
    np.testing.assert_allclose(got, reference, rtol=1e-8, atol=1e-12 * reference.max())


def test_engaged_modal_mass():
    # Empty structure: the modal mass itself. A crowd of MSDs tuned far above the mode moves
    # with the deck, so it engages its whole mass m_h Ψ_jj (added-mass limit, docs: theory, Occupied receptance and FRFs:
    # M_app → m_h as f/f_h1 → 0); the residual is O((f/f_h1)²) ≈ 0.3 %.
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    crowd = Crowd.from_density(0.5)
    assert effective_modal_properties(bridge).modal_masses[0] == 50e3
    with pytest.warns(PlausibilityWarning, match="frequency = 40 Hz"):   # far above on purpose
        far = MSDModel(40.0, 0.3, 0.95)
    stiff = effective_modal_properties(bridge, crowd, far)
    added = 50e3 + crowd.body_mass * bridge.influence_matrix(0.5)[0, 0]
    assert stiff.modal_masses[0] == pytest.approx(added, rel=5e-3)


def test_tuning_check_values():
    # docs: theory, Why modes just above f_h1 feel the crowd most / §8.5 check values (Asami et al. 2002 acceleration optimum).
    assert optimal_tuning(0.05) == pytest.approx((0.9759, 0.1353), abs=5e-5)
    assert optimal_tuning(0.1) == pytest.approx((0.9535, 0.1890), abs=5e-5)
    # Den Hartog (1956): γ = 1/(1+μ), (c/(2 m_d ω_j))² = 3μ/(8(1+μ)³); referred to the damper's
    # own frequency ζ = sqrt(3μ/(8(1+μ))): μ = 0.1 → 0.90909, 0.184637 (not 0.167852, issue 25 §2).
    assert optimal_tuning(0.1, "displacement") == pytest.approx((1 / 1.1, 0.184637), abs=1e-6)


def two_dof_response(g, mu, gamma, zeta, power):
    """|(ω/ω_j)^power X / X_st| of an undamped primary (mass 1, ω_j = 1) with an absorber of mass
    μ, frequency γ and its OWN damping ratio ζ = c/(2 μ γ), at frequency ratios g: the closed-form
    2-DOF receptance (Den Hartog 1956, §3.3), independent of crowdvib's FRF."""
    k, c = mu * gamma**2, 2 * zeta * mu * gamma
    absorber = k + 1j * c * g - mu * g**2
    return np.abs(g**power * absorber / ((1 - g**2) * absorber - mu * g**2 * (k + 1j * c * g)))


def flat_damping(mu, gamma, g, power):
    """The absorber damping ratio ζ (its own) that makes the response curve horizontal at g."""
    def slope(zeta):
        step = 1e-6 * g
        return (two_dof_response(g + step, mu, gamma, zeta, power)
                - two_dof_response(g - step, mu, gamma, zeta, power))
    return brentq(slope, 1e-3, 1.0, xtol=1e-12)


@pytest.mark.parametrize("mu", [0.01, 0.02, 0.05])
@pytest.mark.parametrize("criterion, power", [("displacement", 0), ("acceleration", 2)])
def test_optimal_damping_is_the_fixed_point_construction(criterion, power, mu):
    # Den Hartog's construction (Mechanical Vibrations, 1956, §3.3; Asami et al. 2002 for the
    # accelerance): with the optimal γ the fixed points P and Q have equal heights; the damping
    # that makes the curve horizontal at P and at Q, found here numerically from the closed-form
    # FRF and averaged in square as Den Hartog does, is the optimum. Referred to the damper's
    # own frequency it is optimal_tuning's ζ; Den Hartog's sqrt(3μ/(8(1+μ)³)), referred to the
    # structure's, is (1+μ) smaller: 1 / 2 / 4.8 % too small for μ = 0.01 / 0.02 / 0.05.
    gamma, zeta = optimal_tuning(mu, criterion)
    p, q = fixed_points(mu, gamma, criterion)
    heights = [two_dof_response(g, mu, gamma, 0.1, power) for g in (p, q)]
    assert heights[0] == pytest.approx(heights[1], rel=1e-9)
    for other in (1e-4, 0.5):                          # P and Q are fixed: any damping passes
        assert two_dof_response(p, mu, gamma, other, power) == pytest.approx(heights[0],
                                                                              rel=1e-9)
    construction = np.sqrt((flat_damping(mu, gamma, p, power) ** 2
                            + flat_damping(mu, gamma, q, power) ** 2) / 2)
    assert zeta == pytest.approx(construction, rel=1e-6)
    if criterion == "displacement":
        structure_referred = np.sqrt(3 * mu / (8 * (1 + mu) ** 3))
        assert zeta / structure_referred == pytest.approx(1 + mu, rel=1e-12)
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    assert tune_damper(bridge, 0, mu, criterion=criterion).damping_ratio == zeta


def fixed_points(mu, gamma, output):
    """Den Hartog's fixed-point frequency ratios g of an undamped primary with an absorber:
    (2+μ) g⁴ − 2 (1 + γ² (1+μ)) g² + 2 γ² = 0 (the same for displacement and acceleration)."""
    roots = np.roots([2 + mu, -2 * (1 + gamma**2 * (1 + mu)), 2 * gamma**2])
    return np.sqrt(np.sort(roots.real))


@pytest.mark.parametrize("mu", [0.02, 0.05, 0.1])
def test_den_hartog_fixed_points(mu, reference):
    # Den Hartog, Mechanical Vibrations (1956), §3.3: with γ = 1/(1+μ) the two fixed points of
    # |X/X_st| have equal heights sqrt(1 + 2/μ), whatever the absorber damping.
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.0, 50e3)
    tuned = tune_damper(bridge, 0, mu, criterion="displacement")
    k = 50e3 * (2 * np.pi * 2.0) ** 2
    g = fixed_points(mu, tuned.frequency / 2.0, "displacement")
    f = 2.0 * g

    def amplitude(damper, frequency):
        accelerance = frf(bridge, frequency, dampers=[damper]).values[0, 0]
        return np.abs(accelerance) / (2 * np.pi * frequency) ** 2 * k

    heights = amplitude(tuned, f)
    other = TunedMassDamper(tuned.mass, tuned.frequency, 0.4, tuned.position)
    np.testing.assert_allclose(amplitude(other, f), heights, rtol=1e-9)   # really fixed
    reference(f"Den Hartog fixed-point heights, μ = {mu}", heights,
              np.full(2, np.sqrt(1 + 2 / mu)), rel=1e-9,
              source="sqrt(1 + 2/μ) (Den Hartog, Mechanical Vibrations, 1956, §3.3)")
    # Den Hartog's ζ puts the maxima near (not exactly at) the fixed points: the peak of the
    # curve cannot be below them and, for μ <= 0.1, is within 2.1 % (0.7 % at μ = 0.05).
    peak = amplitude(tuned, np.linspace(1.5, 2.5, 100001)).max()
    assert np.sqrt(1 + 2 / mu) <= peak <= np.sqrt(1 + 2 / mu) * 1.021


def test_asami_fixed_points_have_equal_accelerance_heights():
    # docs: theory, Why modes just above f_h1 feel the crowd most: with γ = 1/sqrt(1+μ) the accelerance fixed points (heights
    # g²/|1 − (1+μ) g²| relative to 1/m) are equal.
    mu = 0.05
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.0, 50e3)
    tuned = tune_damper(bridge, 0, mu)
    f = 2.0 * fixed_points(mu, tuned.frequency / 2.0, "acceleration")
    heights = np.abs(frf(bridge, f, dampers=[tuned]).values[0, 0]) * 50e3
    assert heights[0] == pytest.approx(heights[1], rel=1e-9)
    g = f / 2.0
    np.testing.assert_allclose(heights, g**2 / np.abs(1 - (1 + mu) * g**2), rtol=1e-9)


def occupied_peak(case, damper, grid):
    values = frf(case.structure, grid, crowd=case.crowd, msd=case.msd, dampers=[damper]).values
    return np.abs(values[0, 0]).max()


def test_crowd_detunes_a_damper_tuned_to_the_empty_bridge():
    # The paper example (docs: theory, The paper's numerical example) with a 2 % damper (1 t at midspan): HSI lowers the
    # mode from 2.00 to 1.93 Hz and engages 55 t instead of 50 t. The damper tuned to the
    # occupied mode gives a lower occupied FRF peak than the one tuned to the empty bridge.
    from crowdvib.models.examples import paper_example

    case = paper_example()
    empty = tune_damper(case.structure, 0, 0.02)
    occupied = tune_damper(case.structure, 0, 0.02, crowd=case.crowd, msd=case.msd)
    assert empty.mass == occupied.mass == pytest.approx(1000.0)
    assert occupied.frequency < empty.frequency - 0.05             # detuned by > 0.05 Hz
    grid = np.linspace(1.5, 2.5, 20001)
    peak_empty_tuned = occupied_peak(case, empty, grid)
    peak_occupied_tuned = occupied_peak(case, occupied, grid)
    assert peak_occupied_tuned < peak_empty_tuned


def test_bad_dampers_are_refused(paper_bridge):
    with pytest.raises(ParameterError, match="mass must be > 0 kg, got -1"):
        TunedMassDamper(-1.0, 2.0, 0.1, 25.0)
    with pytest.raises(ParameterError, match="damping_ratio .*fractions, not percent.*8"):
        TunedMassDamper(1000.0, 2.0, 8.0, 25.0)
    with pytest.raises(ParameterError, match=r"position must lie on the walkway \[0, 50\] m"):
        frf(paper_bridge, [2.0], dampers=[TunedMassDamper(1000.0, 2.0, 0.1, 60.0)])
    with pytest.raises(ParameterError, match=r"dampers\[1\] must be a TunedMassDamper"):
        frf(paper_bridge, [2.0], dampers=[TunedMassDamper(1000.0, 2.0, 0.1, 6.0), 3.0])
    with pytest.raises(ParameterError, match=r"mode must be an integer index in \[0, 0\]"):
        tune_damper(paper_bridge, 1, 0.02)
    with pytest.raises(ParameterError, match="criterion must be one of"):
        tune_damper(paper_bridge, 0, 0.02, criterion="velocity")
    with pytest.raises(ParameterError, match="mass_ratio must be > 0"):
        tune_damper(paper_bridge, 0, 0.0)


def test_damper_on_a_lane_of_a_twisting_deck():
    # Two lanes at the deck edges; mode 2 twists the deck (opposite signs across the width), so
    # a damper at mid-width does not touch it and one on a lane does. Reference: direct eigen-
    # solve with the coupling row φ(x, y) read from the lane's shapes.
    x = np.linspace(0.0, 30.0, 121)
    bending = np.sin(np.pi * x / 30.0)
    shapes = np.stack([np.column_stack([bending, bending]), np.column_stack([bending, -bending])])
    bridge = ModalModel(frequencies=[2.0, 2.6], damping_ratios=[0.005, 0.005],
                        modal_masses=[20e3, 15e3], positions=x, mode_shapes=shapes, width=4.0,
                        lanes=[0.0, 4.0], output_names=["edge"], output_shapes=[[1.0, 1.0]])
    tuned = tune_damper(bridge, 1, 0.03)
    assert tuned.position == 15.0 and tuned.lane in (0.0, 4.0)
    assert np.allclose(np.abs(bridge.shapes_at([15.0], [tuned.lane])[0]), [1.0, 1.0])
    ours = poles_from(effective_modal_properties(bridge, dampers=[tuned]))
    np.testing.assert_allclose(ours, direct_poles(bridge, [tuned]), rtol=1e-9)
    middle = TunedMassDamper(tuned.mass, tuned.frequency, tuned.damping_ratio, 15.0)
    untouched = effective_modal_properties(bridge, dampers=[middle])
    assert untouched.frequencies[1] == pytest.approx(2.6, rel=1e-12)   # torsion not coupled
