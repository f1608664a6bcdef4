"""The simulator against closed-form single-degree-of-freedom results (docs: theory, The coupled time-domain model)."""

import numpy as np
import pytest

from crowdvib import ModalModel, MSDModel, Pedestrian, simulate
from crowdvib.errors import PlausibilityWarning

pytestmark = pytest.mark.reference


def test_resonant_harmonic_force_at_midspan(reference):
    # Closed form (any dynamics text, e.g. Chopra, Dynamics of Structures, §3.2): a harmonic
    # force F sin(ω_n t) on an SDOF (k, ξ) has the steady-state displacement amplitude
    # F/(2ξk), hence acceleration amplitude ω_n² F/(2ξk). Unity-scaled sine mode, force at the
    # antinode (φ = 1), f = f_1 = 2 Hz, ξ = 0.5 %: transient e^{−ξωt} = 4e-17 after 600 s.
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    force = 70.0 * 9.81 * 0.4
    walker = Pedestrian(0.0, 0.0, 2.0, 70.0, harmonics=[(1.0, 0.4, 0.0)], position=25.0)
    record = simulate(bridge, duration=600.0, pedestrians=[walker], rng=0, sample_rate=200.0)
    omega = 2 * np.pi * 2.0
    expected = omega**2 * force / (2 * 0.005 * 50e3 * omega**2)
    last_cycles = record.acceleration[0, -2000:]
    reference("simulator: resonant acceleration amplitude of an SDOF under F sin(ω_n t)",
              np.abs(last_cycles).max(), expected, rel=0.005, unit="m/s²",
              source="closed form ω_n² F/(2ξk) (Chopra, Dynamics of Structures, §3.2)")


def test_standing_msd_shifts_the_resonance(reference):
    # A standing MSD adds its apparent mass M_app(f) (docs: theory, Occupied receptance and FRFs); with m_h = 70 kg on a
    # 500 kg modal mass the occupied peak moves. Compare the steady-state accelerance at 1.9 Hz
    # from the simulator with the closed-form FRF H = 1/(k − ω²(m + M_app(ω)) + iωc).
    with pytest.warns(PlausibilityWarning, match="deck of 6.67 kg/m²"):   # light on purpose
        bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.02, 500.0)
    msd = MSDModel(3.0, 0.30, 0.95)
    f = 1.9
    walker = Pedestrian(0.0, 0.0, f, 70.0, harmonics=[(1.0, 0.1, 0.0)], position=25.0)
    record = simulate(bridge, duration=120.0, pedestrians=[walker], msd=msd, rng=0,
                      sample_rate=200.0)
    w, wn = 2 * np.pi * f, 2 * np.pi * 2.0
    h = 1 / (500 * wn**2 - w**2 * (500 + msd.apparent_mass(f, 70.0)) + 1j * w * 2 * 0.02 * 500 * wn)
    expected = w**2 * abs(h) * 70 * 9.81 * 0.1
    reference("simulator: steady accelerance with a standing MSD at 1.9 Hz",
              np.abs(record.acceleration[0, -2000:]).max(), expected, rel=0.005, unit="m/s²",
              source="closed-form FRF with the apparent mass (docs: theory, Occupied receptance "
                     "and FRFs)")
