"""The MSD's leverage on the occupied frequency, ∂f_occ/∂f_h1 (docs: theory, Studies, findings 5
and 6; ``accuracy/leverage.py``), against the 2-DOF eigenproblem solved here independently."""

import numpy as np
import pytest

from crowdvib import Crowd, MSDModel, effective_modal_properties
from crowdvib.studies.parametric import _paper_family_structure

CROWD = Crowd(density=0.5, walking_speed=1.30, step_frequency_mean=1.89,
              step_frequency_std=0.175, body_mass=70.0)       # the paper's crowd
MSD = MSDModel(3.0, 0.30, 0.95)                                # the paper's truth


def _two_dof_occupied_frequency(f1, xi1, modal_mass, psi, f_h1, msd, body_mass):
    """f = |λ|/2π of the lightly damped root of det(λ²M + λC + K) = 0 for one sine mode with
    the smeared crowd of MSDs (Van Nimmen et al. 2017; docs: theory, The smeared crowd):
    M = diag(m + m_h0 ψ, m_h1), K = [[k + k_h1 ψ, −k_h1 √ψ], [−k_h1 √ψ, k_h1]], C alike, the
    determinant expanded by hand into a quartic and solved with numpy.roots."""
    m_h1 = msd.mass_ratio * body_mass
    m_h0 = body_mass - m_h1
    w1, wh = 2 * np.pi * f1, 2 * np.pi * f_h1
    k, c = modal_mass * w1**2, 2 * xi1 * modal_mass * w1
    kh, ch = m_h1 * wh**2, 2 * msd.damping_ratio * m_h1 * wh
    s = np.sqrt(psi)
    first = [modal_mass + m_h0 * psi, c + ch * psi, k + kh * psi]     # λ² M11 + λ C11 + K11
    second = [m_h1, ch, kh]
    coupling = [-ch * s, -kh * s]                                     # λ C12 + K12
    quartic = np.polysub(np.polymul(first, second), np.polymul(coupling, coupling))
    roots = np.roots(quartic)
    roots = roots[roots.imag > 0]
    ratio = -roots.real / np.abs(roots)
    return float(np.abs(roots[np.argmin(ratio)]) / (2 * np.pi))


def test_leverage_at_3_5_hz_matches_the_two_dof_eigenproblem():
    # Reference: central differences of the hand-expanded 2-DOF characteristic polynomial,
    # with ψ = d L B / 2 = 37.5 (unit sine mode over 50 m × 3 m) and m = m_body ψ / μ_m, the
    # family of the paper's parametric study at f_1 = 3.5 Hz, ξ_1 = 0.5 %, μ_m = 5 %.
    f1, xi1, mu_m = 3.5, 0.005, 0.05
    psi = CROWD.density * 50.0 * 3.0 / 2
    modal_mass = CROWD.body_mass * psi / mu_m
    structure = _paper_family_structure(f1, xi1, mu_m, CROWD)
    assert structure.modal_masses[0] == pytest.approx(modal_mass, rel=1e-12)
    step = 1e-4 * MSD.frequency

    def crowdvib_f(f_h1):
        msd = MSDModel(f_h1, MSD.damping_ratio, MSD.mass_ratio)
        return float(effective_modal_properties(structure, CROWD, msd).frequencies[0])

    def independent_f(f_h1):
        return _two_dof_occupied_frequency(f1, xi1, modal_mass, psi, f_h1, MSD, CROWD.body_mass)

    assert crowdvib_f(MSD.frequency) == pytest.approx(independent_f(MSD.frequency), rel=1e-9)
    ours = (crowdvib_f(MSD.frequency + step) - crowdvib_f(MSD.frequency - step)) / (2 * step)
    theirs = (independent_f(MSD.frequency + step)
              - independent_f(MSD.frequency - step)) / (2 * step)
    assert ours == pytest.approx(theirs, rel=1e-5)
    # The figure docs/theory/studies.rst quotes (accuracy/leverage.py, μ_m = 5 %): −0.137.
    assert ours == pytest.approx(-0.137, abs=0.001)
    # Away from f_h1 the leverage is about 0.01 (6 Hz: 0.013), ten times smaller.
    far = _paper_family_structure(6.0, xi1, mu_m, CROWD)
    lever = [float(effective_modal_properties(
        far, CROWD, MSDModel(MSD.frequency + sign * step, 0.30, 0.95)).frequencies[0])
        for sign in (1, -1)]
    assert (lever[0] - lever[1]) / (2 * step) == pytest.approx(0.0129, abs=0.0005)
