"""UK National Annex to BS EN 1991-2 (NA.2.44): walkers and joggers against an independent ODE
solution, the crowd's closed form, and the tabled constants at their tabulated points."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from crowdvib import ModalModel, MSDModel, ParameterError
from crowdvib.design import design_check
from crowdvib.design.codes import (UKNA_CLASSES, effective_span, ukna_crowd_gamma, ukna_gamma,
                                   ukna_k_factor, ukna_limit)

SPAN, WIDTH, MASS, DAMPING = 50.0, 3.0, 50e3, 0.005


def beam(frequency):
    """Simply supported beam, sine mode scaled to 1, outputs at mid-span and quarter span."""
    return ModalModel.simply_supported_beam(SPAN, WIDTH, frequency, DAMPING, MASS,
                                            n_points=2001, outputs={"mid": 25.0, "q": 12.5})


def ode_peak(frequency, amplitude, speed):
    """Independent reference: M q̈ + 2ξωM q̇ + ω²M q = F sin(ωt)|sin(π v t / L)| for one
    crossing from rest (the closed-form sine mode, force flipped with the shape), solved by
    scipy.integrate.solve_ivp (DOP853, rtol 1e-10) and sampled 400 times per period; the peak
    modal acceleration |q̈| = |Q/M − 2ξω q̇ − ω² q|."""
    omega = 2 * np.pi * frequency

    def load(t):
        return amplitude * np.sin(omega * t) * np.abs(np.sin(np.pi * speed * t / SPAN))

    def rhs(t, y):
        return [y[1], load(t) / MASS - 2 * DAMPING * omega * y[1] - omega**2 * y[0]]

    end = SPAN / speed
    t = np.linspace(0.0, end, int(end * frequency * 400) + 1)
    solution = solve_ivp(rhs, (0.0, end), [0.0, 0.0], method="DOP853", t_eval=t, rtol=1e-10,
                         atol=1e-14)
    q, qd = solution.y
    return np.abs(load(t) / MASS - 2 * DAMPING * omega * qd - omega**2 * q).max()


@pytest.mark.parametrize("traffic_class", ["A", "B", "C", "D"])
@pytest.mark.parametrize("frequency", [1.8, 2.3])
def test_walkers_against_solve_ivp(traffic_class, frequency, reference):
    check = design_check(beam(frequency), "ukna", traffic_class=traffic_class)
    size = UKNA_CLASSES[traffic_class][0]
    # NA.2.44.4: F = F0 k(f) sqrt(1 + γ (N − 1)), F0 = 280 N at 1.7 m/s (Table NA.8);
    # S_eff of the sine = (2L/π)/0.634 (Figure NA.7), δ = 2πξ.
    s_eff = 2 * SPAN / np.pi / 0.634
    force = 280.0 * ukna_k_factor(frequency) * np.sqrt(
        1 + ukna_gamma(2 * np.pi * DAMPING, s_eff) * (size - 1))
    expected = ode_peak(frequency, force, 1.7)
    walkers = check.case_accelerations[check.cases.index("walkers"), 0]   # empty model
    reference(f"UK NA walkers class {traffic_class} at {frequency} Hz: midspan peak", walkers[0, 0],
              expected, rel=0.01, unit="m/s²",
              source="scipy.integrate.solve_ivp (DOP853) of the moving pulsating force, NA.2.44.4")
    assert walkers[1, 0] == pytest.approx(expected * np.sin(np.pi / 4), rel=0.01)
    assert check.details["cases"]["walkers"]["group_size"] == size


def test_the_check_names_the_uncorrected_gamma_figure():
    # Issue 25 §2: γ is read from Figure NA.9 as published (DynSys digitisation), 0.19 for a
    # 2 Hz, 0.5 % beam of S_eff = 50.2 m, where PD 6688-2's corrected figure is said to give
    # 0.27; the corrected values were not available, so the result must say which figure it used.
    check = design_check(beam(2.0), "ukna", traffic_class="B")
    assert check.details["cases"]["walkers"]["gamma"][0][0] == pytest.approx(0.1918, abs=1e-4)
    assert "uncorrected" in check.details["gamma_figure"]
    assert "non-conservative" in check.to_dict()["details"]["gamma_figure"]


def test_joggers_against_solve_ivp(reference):
    check = design_check(beam(2.4), "ukna", traffic_class="D")
    s_eff = 2 * SPAN / np.pi / 0.634
    # Table NA.7 class D: 4 joggers; Table NA.8: F0 = 910 N at 3.0 m/s.
    force = 910.0 * ukna_k_factor(2.4, "joggers") * np.sqrt(
        1 + ukna_gamma(2 * np.pi * DAMPING, s_eff) * 3)
    joggers = check.case_accelerations[check.cases.index("joggers"), 0]
    reference("UK NA joggers class D at 2.4 Hz: midspan peak", joggers[0, 0],
              ode_peak(2.4, force, 3.0), rel=0.01, unit="m/s²",
              source="scipy.integrate.solve_ivp (DOP853), NA.2.44.4")


@pytest.mark.parametrize("traffic_class, density", [("B", 0.4), ("C", 0.8), ("D", 1.5)])
def test_crowd_steady_state_closed_form(traffic_class, density, reference):
    # NA.2.44.5: w = 1.8 (F0/A) k(f) sqrt(γ N / λ), N = ρA, γ = 0.23 δ/0.2, λ = 0.634 S_eff/S
    # = 2/π for the sine; resonant a = w B (2L/π) / (2 ξ M) at mid-span.
    check = design_check(beam(2.0), "ukna", traffic_class=traffic_class)
    area = SPAN * WIDTH
    gamma = 0.23 * 2 * np.pi * DAMPING / 0.2
    w = 1.8 * 280.0 / area * ukna_k_factor(2.0) * np.sqrt(gamma * density * area / (2 / np.pi))
    expected = w * WIDTH * 2 * SPAN / np.pi / (2 * DAMPING * MASS)
    crowd = check.case_accelerations[check.cases.index("crowd"), 0]
    reference(f"UK NA crowd class {traffic_class}: steady-state midspan response", crowd[0, 0],
              expected, rel=1e-5, unit="m/s²", source="closed form of NA.2.44.5 on a sine mode")
    assert check.density == density


def test_effective_span_of_a_sine():
    # Figure NA.7: S_eff = ∫|φ|dx / (0.634 max|φ|) = 2L / (0.634 π); λ = 0.634 S_eff / L = 2/π.
    span, lam = effective_span(beam(2.0))
    assert span[0] == pytest.approx(2 * SPAN / (0.634 * np.pi), rel=1e-6)
    assert lam[0] == pytest.approx(2 / np.pi, rel=1e-6)


@pytest.mark.parametrize("delta, s_eff, expected", [
    # Grid points of Figure NA.9 as digitised in DynSys (UKNA_BSEN1991_2_Figure_NA_9): rows
    # δ = 0, 0.04, 0.2; columns S_eff = 10, 30, 300 m.
    (0.0, 10.0, 0.680), (0.04, 30.0, 0.280), (0.2, 300.0, 0.513), (0.1, 60.0, 0.335),
    # Bilinear between (0.04|0.06) × (20|30 m): (0.320 + 0.280 + 0.350 + 0.315) / 4.
    (0.05, 25.0, 0.31625),
    # Clamped: S_eff below 10 m takes the 10 m curve.
    (0.0, 5.0, 0.680)])
def test_gamma_at_tabulated_points(delta, s_eff, expected):
    assert ukna_gamma(delta, s_eff) == pytest.approx(expected, abs=1e-12)


@pytest.mark.parametrize("frequency, group, expected", [
    # Figure NA.8 as digitised in DynSys (UKNA_BSEN1991_2_Figure_NA_8): walkers peak 1.0 at
    # 1.8 Hz, joggers 1.16 at 2.4 Hz, zero from 9 Hz; linear between points (2.2 → 0.90 and
    # 2.4 → 0.65 give 0.775 at 2.3 Hz).
    (1.8, "walkers", 1.0), (2.3, "walkers", 0.775), (3.6, "walkers", 0.36),
    (2.4, "joggers", 1.16), (3.0, "joggers", 0.64), (9.0, "walkers", 0.0),
    (12.0, "joggers", 0.0)])
def test_k_factor_at_tabulated_points(frequency, group, expected):
    assert ukna_k_factor(frequency, group) == pytest.approx(expected, abs=1e-12)


def test_crowd_gamma_and_limit():
    # Figure NA.9 (crowds): γ = 0.23 at δ = 0.2, linear through 0.
    assert ukna_crowd_gamma(0.2) == pytest.approx(0.23)
    # NA.2.44.6: a_limit = 1.0 k1 k2 k3 k4 bounded to [0.5, 2.0] m/s².
    assert ukna_limit({"k1": 1.3, "k2": 1.0, "k3": 1.1})[0] == pytest.approx(1.43)
    assert ukna_limit((0.6, 0.7, 0.7, 1.0))[0] == 0.5
    assert ukna_limit({"k1": "rural", "k2": "alternative", "k3": "below_4m"})[0] == 2.0
    check = design_check(beam(2.0), "ukna", traffic_class="B", site_factors=(1.3, 1, 1, 1))
    assert check.limit == pytest.approx(1.3)
    assert check.utilisation[0] == pytest.approx(check.governing[0] / 1.3)


def test_hsi_and_added_mass_use_the_occupied_modes():
    # The "hsi" model's crowd case takes the occupied mode's frequency, damping ratio and modal
    # mass (effective_modal_properties): with its larger damping the steady-state response falls.
    check = design_check(beam(2.0), "ukna", traffic_class="C", msd=MSDModel())
    crowd = check.cases.index("crowd")
    empty, _, hsi = check.case_accelerations[crowd, :, 0, 0]
    assert check.models == ("empty", "added_mass", "hsi")
    assert hsi < empty
    frequencies = check.details["cases"]["crowd"]["frequencies"]
    assert frequencies[1][0] < frequencies[0][0]          # added mass lowers the frequency


def test_ukna_bad_input():
    with pytest.raises(ParameterError, match="traffic_class"):
        design_check(beam(2.0), "ukna", traffic_class="E")
    with pytest.raises(ParameterError, match="site_factors"):
        design_check(beam(2.0), "ukna", traffic_class="B", site_factors=(1, 2))
    with pytest.raises(ParameterError, match="site factor k1"):
        design_check(beam(2.0), "ukna", traffic_class="B", site_factors={"k1": "city"})
    with pytest.raises(ParameterError, match=r"site_factors does not apply to code 'hivoss' "
                                             r"\(it takes \['comfort_class', 'neq_damping'\]\)"):
        design_check(beam(2.0), "hivoss", traffic_class="TC1", site_factors=(1, 1, 1, 1))
    with pytest.raises(ParameterError, match="weighting"):
        design_check(beam(2.0), "ukna", traffic_class="B", weighting="Wk")


def test_weighted_running_rms_of_the_crossing():
    # The crossing's response near its peak is a sine at f_v with an envelope that changes
    # little over 1 s (ξ = 0.5 %): the largest 1-s running RMS of the W_b-weighted record is
    # |W_b(f_v)| · peak / √2 (Parseval; W_b from signals.weighting, checked there), within 1 %.
    from crowdvib.signals.weighting import wb_response

    check = design_check(beam(2.0), "ukna", traffic_class="C", weighting="Wb")
    rms = np.array(check.details["running_rms"]["walkers"])          # (n_models, out, modes)
    peak = check.case_accelerations[check.cases.index("walkers")]
    expected = abs(wb_response(2.0)) * peak / np.sqrt(2)
    assert rms == pytest.approx(expected, rel=0.01)
