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


#: γ of a 2 Hz, ξ = 0.5 % simply supported beam of 50 m (δ = 0.031416, S_eff = 2L/(0.634π) =
#: 50.207 m), bilinear on the two digitised figures (DynSys's tables, MEMAndersen/DynSys
#: @5226de3): PD 6688-2:2011 Figure 2 (corrected) and Figure NA.9 as published.
GAMMA_CORRECTED, GAMMA_NA9 = 0.26782, 0.19183
#: DynSys (MEMAndersen/DynSys @5226de3, PD 6688-2 correction on, its default) walkers' peaks of
#: that beam, empty bridge, classes A–D [m/s²] (issue 33 §1).
DYNSYS_WALKER_PEAKS = {"A": 0.3803, "B": 0.4534, "C": 0.5724, "D": 0.7556}


@pytest.mark.parametrize("traffic_class", ["A", "B", "C", "D"])
def test_walkers_with_the_corrected_gamma_against_dynsys_and_solve_ivp(traffic_class, reference):
    # NA.2.44.4: F(t) = F0 k √(1 + γ(N − 1)) sin(2πft) moving at 1.7 m/s, F0 = 280 N (Table NA.8),
    # k(2.0 Hz) = 0.997 (Figure NA.8 as digitised in DynSys), γ of PD 6688-2 Figure 2 (the
    # default): the modal SDOF solved by solve_ivp (ode_peak), independent of crowdvib's solver.
    check = design_check(beam(2.0), "ukna", traffic_class=traffic_class)
    size = UKNA_CLASSES[traffic_class][0]
    walkers = check.case_accelerations[check.cases.index("walkers"), 0, 0, 0]   # empty, mid
    assert check.details["cases"]["walkers"]["gamma"][0][0] == pytest.approx(GAMMA_CORRECTED,
                                                                               abs=5e-5)
    expected = ode_peak(2.0, 280.0 * 0.997 * np.sqrt(1 + GAMMA_CORRECTED * (size - 1)), 1.7)
    reference(f"UK NA walkers class {traffic_class}, 2 Hz beam, PD 6688-2 γ: midspan peak",
              walkers, expected, rel=0.01, unit="m/s²",
              source="solve_ivp (DOP853) of NA.2.44.4's moving force with γ = 0.2678")
    reference(f"UK NA walkers class {traffic_class}, 2 Hz beam: against DynSys", walkers,
              DYNSYS_WALKER_PEAKS[traffic_class], rel=0.01, unit="m/s²",
              source="DynSys 1.8.0 (PD 6688-2 correction, its default)")


@pytest.mark.parametrize("traffic_class, rise", [("A", 0.031), ("B", 0.070), ("C", 0.108),
                                                 ("D", 0.138)])
def test_the_uncorrected_figure_is_an_option_and_named(traffic_class, rise):
    # gamma_figure="na9": Figure NA.9 as published, γ = 0.1918 on this beam; the corrected
    # figure raises the walkers' peak by √((1 + 0.2678(N − 1)) / (1 + 0.1918(N − 1))) − 1 =
    # 3.1 / 7.0 / 10.8 / 13.8 % for N = 2, 4, 8, 16 (sources.md §4).
    corrected = design_check(beam(2.0), "ukna", traffic_class=traffic_class)
    original = design_check(beam(2.0), "ukna", traffic_class=traffic_class, gamma_figure="na9")
    assert original.details["cases"]["walkers"]["gamma"][0][0] == pytest.approx(GAMMA_NA9,
                                                                               abs=5e-5)
    walkers = [c.case_accelerations[c.cases.index("walkers"), 0, 0, 0]
               for c in (corrected, original)]
    assert walkers[0] / walkers[1] - 1 == pytest.approx(rise, abs=5e-4)
    assert corrected.details["gamma_figure"] == "pd6688-2"
    assert "PD 6688-2:2011 Figure 2" in corrected.to_dict()["details"]["gamma_figure_label"]
    assert original.to_dict()["details"]["gamma_figure"] == "na9"
    assert "Figure NA.9" in original.details["gamma_figure_source"]


def test_a_short_span_reads_gamma_at_10_m_and_says_so():
    # An 8 m beam: S_eff = 2·8/(0.634π) = 8.033 m, below the figures' 10 m. The check reads γ at
    # 10 m (the larger γ: conservative) and states it. PD 6688-2 Figure 2 at 10 m: 0.700 (δ =
    # 0.02) and 0.712 (δ = 0.04), so γ(0.031416) = 0.700 + 0.012 · 0.5708 = 0.70685.
    short = ModalModel.simply_supported_beam(8.0, WIDTH, 2.0, DAMPING, 8e3, n_points=801)
    check = design_check(short, "ukna", traffic_class="B")
    assert check.details["cases"]["walkers"]["gamma"][0][0] == pytest.approx(0.70685, abs=1e-5)
    outside = check.details["gamma_outside_grid"]
    assert outside and all("effective_span must be within 10–300 m" in note and "got 8.033 m" in note
                           and "read at 10 m" in note for note in outside)


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


def test_a_decrement_above_the_grid_reads_gamma_at_0_2_with_a_warning():
    # ξ = 4 %: δ = 2π·0.04 = 0.2513 > 0.20. γ is read on the 0.20 row of PD 6688-2 Figure 2
    # (0.560 at 40 m, 0.545 at 60 m), bilinear at S_eff = 50.207 m: 0.560 − 0.015 · 0.5103 =
    # 0.55235; the warning and the result both say so.
    from crowdvib import ResolutionWarning

    damped = ModalModel.simply_supported_beam(SPAN, WIDTH, 2.0, 0.04, MASS, n_points=2001)
    with pytest.warns(ResolutionWarning, match=r"logarithmic decrements up to 0.251 exceed"):
        check = design_check(damped, "ukna", traffic_class="B")
    assert check.details["cases"]["walkers"]["gamma"][0][0] == pytest.approx(0.55235, abs=1e-5)
    assert any("log_decrement must be within 0–0.2" in note and "got 0.2513: read at 0.2" in note
               for note in check.details["gamma_outside_grid"])


@pytest.mark.parametrize("traffic_class, density", [("B", 0.4), ("C", 0.8), ("D", 1.5)])
def test_crowd_steady_state_closed_form(traffic_class, density, reference):
    # NA.2.44.5: w = 1.8 (F0/A) k(f) sqrt(γ N / λ), N = ρA, γ = 0.23 δ/0.2, λ = 0.634 S_eff/S
    # = 2/π for the sine; resonant a = w B (2L/π) / (2 ξ M) at mid-span. NA.2.44.5(1): ρ is the
    # class's density "but with a maximum value of 1.0 persons/m²" (class D: 1.0, not 1.5).
    check = design_check(beam(2.0), "ukna", traffic_class=traffic_class)
    area, rho = SPAN * WIDTH, min(density, 1.0)
    gamma = 0.23 * 2 * np.pi * DAMPING / 0.2
    w = 1.8 * 280.0 / area * ukna_k_factor(2.0) * np.sqrt(gamma * rho * area / (2 / np.pi))
    expected = w * WIDTH * 2 * SPAN / np.pi / (2 * DAMPING * MASS)
    crowd = check.case_accelerations[check.cases.index("crowd"), 0]
    reference(f"UK NA crowd class {traffic_class}: steady-state midspan response", crowd[0, 0],
              expected, rel=1e-5, unit="m/s²", source="closed form of NA.2.44.5 on a sine mode")
    assert check.density == density                     # the class's crowd, on the deck
    assert check.details["cases"]["crowd"]["load_density"] == rho


def test_class_d_crowd_is_capped_at_one_person_per_square_metre():
    # NA.2.44.5(1): the crowd load's ρ is at most 1.0 persons/m², so class D (1.5) loads as
    # 1.0 and its crowd case is √(1.0/0.8) = 1.1180 times class C's (0.8) on the same bridge
    # (w ∝ √ρ); without the cap it would be √(1.5/0.8) = 1.369.
    c, d = (design_check(beam(2.0), "ukna", traffic_class=name) for name in ("C", "D"))
    ratio = (d.case_accelerations[d.cases.index("crowd"), 0, 0, 0]
             / c.case_accelerations[c.cases.index("crowd"), 0, 0, 0])
    assert ratio == pytest.approx(np.sqrt(1.0 / 0.8), rel=1e-9)
    # A density given above 1.0 is capped alike: 2.0 persons/m² loads as class D's 1.0.
    given = design_check(beam(2.0), "ukna", density=2.0)
    assert given.case_accelerations[0, 0, 0, 0] == pytest.approx(
        d.case_accelerations[d.cases.index("crowd"), 0, 0, 0], rel=1e-12)


def test_effective_span_of_a_sine():
    # Figure NA.7: S_eff = ∫|φ|dx / (0.634 max|φ|) = 2L / (0.634 π); λ = 0.634 S_eff / L = 2/π.
    span, lam = effective_span(beam(2.0))
    assert span[0] == pytest.approx(2 * SPAN / (0.634 * np.pi), rel=1e-6)
    assert lam[0] == pytest.approx(2 / np.pi, rel=1e-6)


@pytest.mark.parametrize("figure, delta, s_eff, expected", [
    # Grid points of Figure NA.9 as published, digitised in DynSys (UKNA_BSEN1991_2_Figure_NA_9,
    # apply_PD6688_2_correction=False): rows δ = 0, 0.04, 0.2; columns S_eff = 10, 30, 300 m.
    ("na9", 0.0, 10.0, 0.680), ("na9", 0.04, 30.0, 0.280), ("na9", 0.2, 300.0, 0.513),
    ("na9", 0.1, 60.0, 0.335),
    # Bilinear between (0.04|0.06) × (20|30 m): (0.320 + 0.280 + 0.350 + 0.315) / 4.
    ("na9", 0.05, 25.0, 0.31625),
    # PD 6688-2 Figure 2 (DynSys, correction on): (0, 12 m) 0.615, (0.04, 15 m) 0.568,
    # (0.04, 100 m) 0.205; the 300 m column equals Figure NA.9's (0.513 at δ = 0.2).
    ("pd6688-2", 0.0, 12.0, 0.615), ("pd6688-2", 0.04, 15.0, 0.568),
    ("pd6688-2", 0.04, 100.0, 0.205), ("pd6688-2", 0.2, 300.0, 0.513)])
def test_gamma_at_tabulated_points(figure, delta, s_eff, expected):
    assert ukna_gamma(delta, s_eff, figure) == pytest.approx(expected, abs=1e-12)


def test_gamma_outside_the_grid_is_refused_or_clamped():
    # The figures span δ 0–0.20 and S_eff 10–300 m: outside, a ParameterError naming the
    # parameter, the grid and the value; clamp=True reads the edge (S_eff 5 m → the 10 m curve).
    with pytest.raises(ParameterError, match=r"effective_span must be within 10–300 m .*got 5 m"):
        ukna_gamma(0.0, 5.0)
    with pytest.raises(ParameterError, match=r"log_decrement must be within 0–0.2 .*got 0.25"):
        ukna_gamma(0.25, 50.0, "na9")
    assert ukna_gamma(0.0, 5.0, "na9", clamp=True) == pytest.approx(0.680, abs=1e-12)
    with pytest.raises(ParameterError, match=r"gamma_figure must be one of \['pd6688-2', "
                                             r"'na9'\], got gamma_figure='na10'"):
        ukna_gamma(0.0, 50.0, "na10")


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
    with pytest.raises(ParameterError, match="gamma_figure must be one of"):
        design_check(beam(2.0), "ukna", traffic_class="B", gamma_figure="corrected")
    with pytest.raises(ParameterError, match="gamma_figure does not apply to code 'hivoss'"):
        design_check(beam(2.0), "hivoss", traffic_class="TC1", gamma_figure="na9")


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
