"""Design-code checks: the Sétra/HiVoSS closed forms, the tabled constants and the HSI check."""

import numpy as np
import pytest

from crowdvib import (Crowd, ModalModel, MSDModel, ParameterError, PlausibilityWarning,
                      effective_modal_properties, frf)
from crowdvib.design import TunedMassDamper, design_check, tune_damper
from crowdvib.design.codes import (comfort_class, equivalent_pedestrians, reduction_factor)

SPAN, WIDTH, MASS, DAMPING = 50.0, 3.0, 50e3, 0.005


def beam(frequency, n_points=2001):
    """Simply supported beam, sine mode scaled to 1 (fine stations: the trapezoid rule's error
    on ∫|sin| is (π/2000)²/12 ≈ 2e-7 relative)."""
    return ModalModel.simply_supported_beam(SPAN, WIDTH, frequency, DAMPING, MASS,
                                            n_points=n_points, outputs={"mid": 25.0, "q": 12.5})


def closed_form(density, force, damping=DAMPING, n_persons=None):
    """Sétra 2006 / HiVoSS 2008 resonant response of a unity-scaled sine mode: p = F n_eq / A,
    modal force F_m = p·B·2L/π (∫ sin over the span = 2L/π), a = F_m / (2 ξ M)."""
    area = SPAN * WIDTH
    n = density * area if n_persons is None else n_persons
    n_eq = 1.85 * np.sqrt(n) if density >= 1 else 10.8 * np.sqrt(damping * n)
    modal_force = force * n_eq / area * WIDTH * 2 * SPAN / np.pi
    return modal_force / (2 * damping * MASS)


@pytest.mark.parametrize("traffic_class, density, n_persons",
                         [("TC1", 15 / 150, 15), ("TC2", 0.2, None), ("TC3", 0.5, None),
                          ("TC4", 1.0, None), ("TC5", 1.5, None)])
def test_hivoss_classes_on_a_simply_supported_beam(traffic_class, density, n_persons, reference):
    # First harmonic, ψ = 1 at 2.0 Hz (plateau 1.7–2.1 Hz): 280 N per equivalent pedestrian.
    check = design_check(beam(2.0), "hivoss", traffic_class=traffic_class)
    expected = closed_form(density, 280.0, n_persons=n_persons)
    assert check.density == pytest.approx(density, rel=1e-12)
    reference(f"HiVoSS {traffic_class}: resonant midspan acceleration of a 2 Hz beam",
              check.peak_acceleration[0, 0], expected, rel=1e-6, unit="m/s²",
              source="closed form F = p·n_eq/A·B·2L/π, a = F/(2ξM) (HiVoSS 2008; docs: theory, "
                     "Design-guide load models)")
    # The quarter point sees sin(π/4) of it.
    assert check.peak_acceleration[1, 0] == pytest.approx(expected * np.sqrt(0.5), rel=1e-6)
    assert check.harmonics[0, 0] == 1


@pytest.mark.parametrize("traffic_class, density", [("I", 1.0), ("II", 0.8), ("III", 0.5)])
def test_setra_classes_second_harmonic(traffic_class, density, reference):
    # Second harmonic, ψ = 1 at 3.8 Hz (plateau 3.4–4.2 Hz): 70 N per equivalent pedestrian.
    check = design_check(beam(3.8), "setra", traffic_class=traffic_class)
    reference(f"Sétra class {traffic_class}: second-harmonic response of a 3.8 Hz beam",
              check.peak_acceleration[0, 0], closed_form(density, 70.0), rel=1e-6, unit="m/s²",
              source="closed form with 70 N per equivalent pedestrian (Sétra/AFGC 2006)")
    assert check.harmonics[0, 0] == 2


def test_density_overrides_class_and_limits():
    check = design_check(beam(2.0), "en1990", traffic_class="TC4", density=0.3)
    assert check.density == 0.3
    assert check.limit == 0.7                            # EN 1990 A2.4.3.2 (recalled)
    assert check.utilisation[0] == pytest.approx(closed_form(0.3, 280.0) / 0.7, rel=1e-6)
    assert design_check(beam(2.0), "setra", density=0.3, comfort_class="CL1").limit == 0.5


@pytest.mark.parametrize("frequency, harmonic, expected", [
    # Corners and mid-slopes of the ψ curves tabled in codes.py (RECALLED from Sétra 2006 /
    # HiVoSS 2008, docs: theory, Design-guide load models): 0 → 1 on 1.25–1.7, 1 to 2.1, → 0 at 2.3 Hz; second
    # harmonic 0 → 1 on 2.5–3.4, 1 to 4.2, → 0 at 4.6 Hz.
    (1.0, 1, 0.0), (1.25, 1, 0.0), (1.475, 1, 0.5), (1.7, 1, 1.0), (2.1, 1, 1.0), (2.2, 1, 0.5),
    (2.3, 1, 0.0), (2.4, 1, 0.0), (2.5, 2, 0.0), (2.95, 2, 0.5), (3.4, 2, 1.0), (4.2, 2, 1.0),
    (4.4, 2, 0.5), (4.6, 2, 0.0), (5.0, 2, 0.0), (2.0, 2, 0.0)])
def test_reduction_factor_at_tabulated_points(frequency, harmonic, expected):
    assert reduction_factor(frequency, harmonic) == pytest.approx(expected, abs=1e-12)


def test_equivalent_pedestrians_and_comfort_classes():
    # HiVoSS 2008 / Sétra 2006: 10.8 sqrt(ξ n) below 1 P/m², 1.85 sqrt(n) at and above.
    assert equivalent_pedestrians(0.5, 150.0, 0.005) == pytest.approx(10.8 * np.sqrt(0.375))
    assert equivalent_pedestrians(1.0, 150.0, 0.005) == pytest.approx(1.85 * np.sqrt(150.0))
    # HiVoSS CL1–CL4 upper bounds 0.5, 1.0, 2.5 m/s² (bounds belong to the better class).
    assert comfort_class([0.2, 0.5, 0.51, 1.0, 2.5, 2.6]) == ("CL1", "CL1", "CL2", "CL2",
                                                              "CL3", "CL4")


def test_modes_outside_the_walking_range_are_not_loaded():
    check = design_check(beam(6.0), "hivoss", traffic_class="TC3")
    assert check.peak_acceleration[0, 0] == 0.0 and check.harmonics[0, 0] == 0


def test_hsi_check_on_the_paper_example(paper_bridge):
    # Paper example (docs: theory, The paper's numerical example) at its 0.5 P/m² (HiVoSS TC3), MSD (3.0, 0.30, 0.95).
    # Added mass: m = 50 t + 70 kg × Ψ₁₁ (37.5) = 52.625 t, f = 2 sqrt(50/52.625) = 1.9495 Hz;
    # ψ stays 1, so the response falls by exactly 50/52.625. HSI: the occupied mode of
    # effective_modal_properties (1.926 Hz, ξ 1.2 %, engaged 55.3 t).
    msd = MSDModel(3.0, 0.3, 0.95)
    check = design_check(paper_bridge, "hivoss", traffic_class="TC3", msd=msd)
    assert check.models == ("empty", "added_mass", "hsi")
    assert check.frequencies[1, 0] == pytest.approx(2 * np.sqrt(50 / 52.625), rel=1e-12)
    assert check.ratios["added_mass/empty"][0] == pytest.approx(50 / 52.625, rel=1e-9)
    occupied = effective_modal_properties(paper_bridge, Crowd.from_density(0.5), msd)
    # Closed form with the occupied ξ and engaged mass; 201 stations: the trapezoid rule's
    # error on ∫|sin| is (π/200)²/12 ≈ 2e-5.
    hsi = closed_form(0.5, 280.0, damping=occupied.damping_ratios[0]) * MASS \
        / occupied.modal_masses[0]
    assert check.governing[0] == pytest.approx(hsi, rel=1e-4)
    # ψ(1.926 Hz) = 1 too, and the check is done at n_eq with the occupied damping:
    # a ∝ sqrt(ξ)/(ξ m), so HSI lowers the response to ~58 % of the empty check.
    assert check.ratios["hsi/empty"][0] == pytest.approx(
        np.sqrt(0.005 / occupied.damping_ratios[0]) * MASS / occupied.modal_masses[0], rel=1e-9)
    assert check.ratios["hsi/empty"][0] < 0.65
    assert check.primary == "hsi" and check.comfort_class == ("CL3",)


def test_equivalent_crowd_with_the_occupied_or_the_empty_damping(paper_bridge):
    # Issue 25 §2 / docs: theory, Design checks, The equivalent crowd with HSI. HiVoSS TC3 on the
    # paper example with HSI: n_eq = 10.8 sqrt(ξ n) read at the occupied ξ (1.198 %, default)
    # or at the empty 0.5 %; the resonant 1/(2 ξ m) keeps the occupied ξ and engaged mass in
    # both, so the readings differ by sqrt(ξ_occ / 0.005) = 1.55 (1.38 against 0.89 m/s²).
    msd = MSDModel(3.0, 0.3, 0.95)
    occupied = effective_modal_properties(paper_bridge, Crowd.from_density(0.5), msd)
    xi, mass = occupied.damping_ratios[0], occupied.modal_masses[0]
    # Closed form of test_hsi_check_on_the_paper_example with n_eq from ξ_empty.
    empty_reading = closed_form(0.5, 280.0, damping=DAMPING) * DAMPING / xi * MASS / mass
    default = design_check(paper_bridge, "hivoss", traffic_class="TC3", msd=msd)
    empty = design_check(paper_bridge, "hivoss", traffic_class="TC3", msd=msd,
                         neq_damping="empty")
    assert empty.governing[0] == pytest.approx(empty_reading, rel=1e-4)
    assert default.governing[0] / empty.governing[0] == pytest.approx(np.sqrt(xi / DAMPING),
                                                                        rel=1e-9)
    assert default.governing[0] == pytest.approx(1.38, abs=0.005)
    assert empty.governing[0] == pytest.approx(0.89, abs=0.005)
    # The empty and added-mass models have the empty damping: both readings agree there.
    np.testing.assert_array_equal(empty.peak_accelerations[:2], default.peak_accelerations[:2])
    # Both readings are reported, whichever is chosen.
    for check, chosen in ((default, "occupied"), (empty, "empty")):
        info = check.details["equivalent_pedestrians"]
        assert info["damping"] == chosen
        assert info["governing"]["occupied"][2] == pytest.approx(default.governing.tolist())
        assert info["governing"]["empty"][2] == pytest.approx(empty.governing.tolist())
        assert info["n_eq"]["empty"][2][0] == pytest.approx(10.8 * np.sqrt(DAMPING * 75.0))
        assert info["n_eq"]["occupied"][2][0] == pytest.approx(10.8 * np.sqrt(xi * 75.0))


def test_to_dict_is_json_ready(paper_bridge):
    import json

    check = design_check(paper_bridge, "setra", traffic_class="III", msd=MSDModel())
    data = json.loads(json.dumps(check.to_dict()))
    assert data["models"] == ["empty", "added_mass", "hsi"]
    assert data["governing"] == pytest.approx(check.governing.tolist())
    assert np.array(data["peak_accelerations"]).shape == (3, 1, 1)


def test_bad_design_inputs(paper_bridge):
    with pytest.raises(ParameterError,
                       match=r"code must be one of \['setra', 'hivoss', 'en1990', 'ukna'\]"):
        design_check(paper_bridge, "bs5400", traffic_class="TC3")
    with pytest.raises(ParameterError, match="traffic_class must be one of .* got 'TC3'"):
        design_check(paper_bridge, "setra", traffic_class="TC3")
    with pytest.raises(ParameterError, match="'IV' of Sétra .* requires no comfort check"):
        design_check(paper_bridge, "setra", traffic_class="IV")
    with pytest.raises(ParameterError, match="needs traffic_class, density or crowd"):
        design_check(paper_bridge, "hivoss")
    with pytest.raises(ParameterError, match="density must be >= 0 persons/m², got -1"):
        design_check(paper_bridge, "hivoss", density=-1)
    with pytest.raises(ParameterError, match="comfort_class must be one of"):
        design_check(paper_bridge, "hivoss", traffic_class="TC2", comfort_class="CL4")
    with pytest.raises(ParameterError, match="EN 1990 has one limit"):
        design_check(paper_bridge, "en1990", traffic_class="TC2", comfort_class="CL1")
    with pytest.raises(ParameterError, match="msd must be an MSDModel"):
        design_check(paper_bridge, "hivoss", traffic_class="TC2", msd=(3.0, 0.3, 0.95))
    # neq_damping: a reading of the Sétra/HiVoSS n_eq only (the UK NA has γ instead).
    with pytest.raises(ParameterError, match=r"neq_damping must be one of \['occupied', "
                                             r"'empty'\], got neq_damping='structure'"):
        design_check(paper_bridge, "hivoss", traffic_class="TC2", neq_damping="structure")
    with pytest.raises(ParameterError, match="neq_damping does not apply to code 'ukna'"):
        design_check(paper_bridge, "ukna", traffic_class="B", neq_damping="empty")


def test_a_negligible_damper_reproduces_the_modal_check(paper_bridge):
    # With dampers each mode's response is the peak of its exact steady-state response over its
    # band; with a 1 g damper far from the mode that must be the code's |Q|/(2ξm) (to the
    # grid's 0.2 %), and for HSI the engaged-mass formula (exact occupied receptance vs the
    # single-pole approximation of effective_modal_properties: within 0.3 %).
    msd = MSDModel(3.0, 0.3, 0.95)
    plain = design_check(paper_bridge, "hivoss", traffic_class="TC3", msd=msd)
    with pytest.warns(PlausibilityWarning, match="mass = 0.001 kg is below 10 kg"):  # issue 35
        tiny = [TunedMassDamper(1e-3, 9.0, 0.1, 10.0)]
    damped = design_check(paper_bridge, "hivoss", traffic_class="TC3", msd=msd, dampers=tiny)
    np.testing.assert_allclose(damped.peak_accelerations[:2], plain.peak_accelerations[:2],
                               rtol=2e-3)
    np.testing.assert_allclose(damped.peak_accelerations[2], plain.peak_accelerations[2],
                               rtol=3e-3)


def test_damped_check_against_the_point_frf(paper_bridge):
    # Reference: the midspan point accelerance of crowdvib.frf with the damper (unity-scaled
    # sine mode, so it is the modal accelerance there) times the code load
    # 280 N ψ(f) n_eq/A · B·2L/π, maximised over a fine grid of the mode's band.
    damper = tune_damper(paper_bridge, 0, 0.02)
    check = design_check(paper_bridge, "hivoss", traffic_class="TC3", dampers=[damper])
    ratio = check.damping_ratios[0, 0]
    grid = np.linspace(1.5, 2.5, 200001)
    accelerance = np.abs(frf(paper_bridge, grid, dampers=[damper]).values[0, 0])
    n_eq = 10.8 * np.sqrt(ratio * 75.0)
    load = 280.0 * reduction_factor(grid, 1) * n_eq / 150.0 * 3.0 * 2 * 50.0 / np.pi
    # 201 stations: ∫|sin| to 2e-5; the check's grid finds the peak to 0.2 %.
    assert check.peak_acceleration[0, 0] == pytest.approx((accelerance * load).max(), rel=3e-3)
    assert check.governing[0] < 0.35 * design_check(paper_bridge, "hivoss",
                                                     traffic_class="TC3").governing[0]


def test_damper_tuned_to_the_occupied_bridge_wins_the_hsi_check(paper_bridge):
    # Paper example, 0.5 P/m², MSD (3.0, 0.30, 0.95), 2 % damper at midspan.
    msd = MSDModel(3.0, 0.3, 0.95)
    crowd = Crowd(density=0.5, walking_speed=1.30, step_frequency_mean=1.89, body_mass=70.0)
    empty = tune_damper(paper_bridge, 0, 0.02)
    occupied = tune_damper(paper_bridge, 0, 0.02, crowd=crowd, msd=msd)
    hsi = [design_check(paper_bridge, "hivoss", traffic_class="TC3", crowd=crowd, msd=msd,
                        dampers=[damper]).governing_of("hsi")[0] for damper in (empty, occupied)]
    assert hsi[1] < hsi[0]


def test_checks_and_tuning_do_not_depend_on_the_mode_scaling():
    # docs: theory, Conventions: every result is invariant to the mode-shape scaling when the modal masses
    # follow it (here: mass-normalised shapes, and a flipped, doubled mode).
    bridge = ModalModel.simply_supported_beam(40.0, 2.5, [1.9, 3.7], [0.006, 0.008],
                                              [30e3, 28e3], n_modes=2,
                                              outputs={"mid": 20.0, "quarter": 10.0})
    msd = MSDModel(3.0, 0.3, 0.95)
    reference = design_check(bridge, "setra", traffic_class="II", msd=msd)
    damper = tune_damper(bridge, 0, 0.03, crowd=Crowd.from_density(0.8), msd=msd)
    for scaled in (bridge.mass_normalised(), bridge.rescaled([-2.0, 0.5])):
        check = design_check(scaled, "setra", traffic_class="II", msd=msd)
        # atol: mode 2 has a node at midspan (values ~1e-16 m/s² of round-off there).
        np.testing.assert_allclose(check.peak_accelerations, reference.peak_accelerations,
                                   rtol=1e-9, atol=1e-12)
        other = tune_damper(scaled, 0, 0.03, crowd=Crowd.from_density(0.8), msd=msd)
        assert other.mass == pytest.approx(damper.mass, rel=1e-9)
        assert other.frequency == pytest.approx(damper.frequency, rel=1e-9)
        assert other.damping_ratio == pytest.approx(damper.damping_ratio, rel=1e-9)
        damped = design_check(scaled, "setra", traffic_class="II", msd=msd, dampers=[damper])
        np.testing.assert_allclose(
            damped.peak_accelerations,
            design_check(bridge, "setra", traffic_class="II", msd=msd,
                         dampers=[damper]).peak_accelerations, rtol=1e-9, atol=1e-12)


def test_a_nearly_undamped_mode_with_dampers_warns_about_resolution():
    # ξ = 1e-6 at 2.2 Hz needs millions of frequencies to resolve its peak: capped, with a
    # warning (one per model checked).
    from crowdvib import ResolutionWarning

    bridge = ModalModel.simply_supported_beam(50.0, 3.0, [2.0, 2.2], [0.005, 1e-6], 50e3,
                                              n_modes=2)
    with pytest.warns(ResolutionWarning, match=r"need \d{7} frequencies to resolve"):
        design_check(bridge, "hivoss", traffic_class="TC3",
                     dampers=[tune_damper(bridge, 0, 0.02)])


def test_unverified_defaults_are_listed_once_in_the_docs_and_in_every_result(paper_bridge):
    # Issue 33 §2: the defaults no public text confirmed (sources.md: NOT FOUND) are one registry
    # (codes.UNVERIFIED_DEFAULTS) that docs/theory/design.rst lists verbatim, and every check
    # carries its code's entries; each names a constant that codes.py marks RECALLED.
    import re
    from pathlib import Path

    from crowdvib.design import code_names
    from crowdvib.design.codes import UNVERIFIED_DEFAULTS

    root = Path(__file__).resolve().parents[2]
    docs = (root / "docs" / "theory" / "design.rst").read_text(encoding="utf-8")
    source = (root / "src" / "crowdvib" / "design" / "codes.py").read_text(encoding="utf-8")
    section = docs.split("Defaults not verified against the guide\n")[1].split("\n.. _")[0]
    listed = [line[2:] for line in section.splitlines() if line.startswith("* ")]
    entries = [entry for code in code_names() for entry in UNVERIFIED_DEFAULTS[code]]
    assert listed[:len(entries)] == entries
    assert UNVERIFIED_DEFAULTS["ukna"] and UNVERIFIED_DEFAULTS["setra"]
    for entry in entries:
        for name in entry.rsplit("(", 1)[1].rstrip(")").split(", "):
            assignment = re.search(rf"^[A-Z_, ]*\b{name}\b[A-Z_, ]* = ", source, re.MULTILINE)
            assert assignment, name
            assert "RECALLED" in source[:assignment.start()].rsplit("\n\n", 1)[-1], name
    for code, traffic_class in (("setra", "II"), ("hivoss", "TC2"), ("ukna", "B")):
        check = design_check(paper_bridge, code, traffic_class=traffic_class)
        assert check.to_dict()["details"]["unverified_defaults"] == list(UNVERIFIED_DEFAULTS[code])
