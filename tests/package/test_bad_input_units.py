"""Unit mix-ups at every physical entry point (issue 24 §4): each case was silent on 49020a3.

A legal but implausible value gets a PlausibilityWarning naming the value, the likely mix-up
and the value it would then be (the ranges and their sources: docs: theory, Plausible ranges);
an impossible one gets a crowdvib error. The corrected values are the conversions of each
mix-up (2π rad/s per Hz, 60 steps per minute per Hz, 3.6 km/h per m/s, 0.45359237 kg per lb,
1000 mm per m, 100 % per fraction).
"""

import re

import numpy as np
import pytest

from crowdvib import (Crowd, DataError, MeasuredForce, ModalModel, MSDModel, ParameterError,
                      PlausibilityWarning)
from crowdvib.design import TunedMassDamper, design_check, tune_damper

pytestmark = pytest.mark.badinput


def beam(span=50.0, width=3.0, frequency=2.0, damping=0.005, mass=50e3, **options):
    """The paper's bridge (docs: theory, The paper's numerical example) with one value changed."""
    return ModalModel.simply_supported_beam(span, width, frequency, damping, mass, **options)


def crowd(**changes):
    """The paper's crowd (0.5 P/m², 1.30 m/s, N(1.89, 0.175) Hz, 70 kg) with one value changed."""
    values = dict(density=0.5, walking_speed=1.30, step_frequency_mean=1.89,
                  step_frequency_std=0.175, body_mass=70.0)
    return Crowd(**dict(values, **changes))


# (label, call, message pattern: the value, the mix-up and the value it would then be)
WARNINGS = [
    ("damping ratio 0.5 meant as 0.5 %", lambda: beam(damping=0.5),
     r"damping_ratios\[0\] = 0\.5 is above 0\.1, .*percent instead of fraction\? "
     r"\(0\.5 % is 0\.005\)"),
    ("modal mass in tonnes", lambda: beam(mass=50.0),
     r"modal_masses\[0\] = 50 kg stands for a deck of 0\.667 kg/m².*tonnes instead of kg"),
    ("natural frequency in rad/s", lambda: beam(frequency=4 * np.pi),
     r"frequencies\[0\] = 12\.5664 Hz .*rad/s instead of Hz\? \(12\.5664 rad/s is 2 Hz\)"),
    ("span in mm", lambda: beam(span=50e3),
     r"walkway length \(positions\) = 50000 m .*millimetres instead of metres\? "
     r"\(50000 mm is 50 m\)"),
    ("width in mm", lambda: beam(width=3000.0),
     r"width = 3000 m .*millimetres instead of metres\? \(3000 mm is 3 m\)"),
    ("FE node coordinates in mm: a 40 km deck",
     lambda: ModalModel([2.0], [0.005], [50e3], np.linspace(0.0, 40e3, 41),
                        np.sin(np.pi * np.linspace(0.0, 1.0, 41))[:, None], 3.0, ("mid",), [[1.0]]),
     r"walkway length \(positions\) = 40000 m .*\(40000 mm is 40 m\)"),
    ("body mass in tonnes", lambda: crowd(body_mass=0.07),
     r"body_mass = 0\.07 kg is below 30 kg.*tonnes instead of kg\? \(0\.07 t is 70 kg\)"),
    ("body mass in pounds", lambda: crowd(body_mass=154.0),
     r"body_mass = 154 kg is above 120 kg.*pounds instead of kg\? \(154 lb is 69\.85 kg\)"),
    ("body mass in grams", lambda: crowd(body_mass=70e3),
     r"body_mass = 70000 kg .*grams instead of kg\? \(70000 g is 70 kg\)"),
    ("step frequency in rad/s", lambda: crowd(step_frequency_mean=2 * np.pi * 1.89),
     r"step_frequency_mean = 11\.8752 Hz .*rad/s instead of Hz\? \(11\.8752 rad/s is 1\.89 Hz\)"),
    ("step frequency in steps per minute", lambda: crowd(step_frequency_mean=113.4),
     r"step_frequency_mean = 113\.4 Hz .*steps per minute instead of Hz\? "
     r"\(113\.4 per minute is 1\.89 Hz\)"),
    ("step-frequency spread in rad/s", lambda: crowd(step_frequency_std=2 * np.pi * 0.175),
     r"step_frequency_std = 1\.09956 Hz .*rad/s instead of Hz\? \(1\.09956 rad/s is 0\.175 Hz\)"),
    ("walking speed in km/h", lambda: crowd(walking_speed=4.68),
     r"walking_speed = 4\.68 m/s .*km/h instead of m/s\? \(4\.68 km/h is 1\.3 m/s\)"),
    ("MSD frequency in rad/s", lambda: MSDModel(6 * np.pi, 0.3, 0.95),
     r"frequency = 18\.8496 Hz .*MSD.*rad/s instead of Hz\? \(18\.8496 rad/s is 3 Hz\)"),
    ("damper frequency in rad/s", lambda: TunedMassDamper(1000.0, 4 * np.pi, 0.1, 25.0),
     r"frequency = 12\.5664 Hz .*damper.*rad/s instead of Hz\? \(12\.5664 rad/s is 2 Hz\)"),
]


def messages(call):
    """The PlausibilityWarning texts of ``call()`` (a mix-up may leave two ranges at once: a span
    in mm also spreads the modal mass over a 1000 times larger deck)."""
    with pytest.warns(PlausibilityWarning) as caught:
        call()
    return [str(w.message) for w in caught if issubclass(w.category, PlausibilityWarning)]


@pytest.mark.parametrize("label, call, pattern", WARNINGS, ids=[case[0] for case in WARNINGS])
def test_unit_mixup_warns(label, call, pattern):
    found = messages(call)
    assert any(re.search(pattern, text) for text in found), found


def test_plausible_inputs_stay_silent(paper_bridge, paper_crowd, paper_msd):
    # The paper's example (docs: theory, The paper's numerical example) and a 2 % damper on it
    # lie inside every range: the warnings above come from the mix-ups, not from the checks.
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        damper = tune_damper(paper_bridge, 0, 0.02, crowd=paper_crowd, msd=paper_msd)
        check = design_check(paper_bridge, "setra", traffic_class="I", msd=paper_msd,
                             dampers=[damper])
        design_check(paper_bridge, "ukna", traffic_class="B")
    assert damper.mass == pytest.approx(1000.0)       # μ m_j / φ² = 0.02 × 50 t
    assert check.density == 1.0                       # Sétra class I (docs: theory, Design)


@pytest.mark.parametrize("label, bridge, pattern", [
    # Fault of issue 24: with ξ = 0.5 `crowdvib check` passed a bridge that fails every code.
    ("damping ratio 0.5 meant as 0.5 %", dict(damping=0.5), r"damping_ratios\[0\] = 0\.5"),
    ("span in mm", dict(span=50e3), r"walkway length \(positions\) = 50000 m"),
    ("modal mass in tonnes", dict(mass=50.0), r"modal_masses\[0\] = 50 kg"),
])
def test_design_check_names_the_implausible_structure(label, bridge, pattern):
    with pytest.warns(PlausibilityWarning):                 # at construction (above)
        structure = beam(**bridge)
    found = messages(lambda: design_check(structure, "setra", traffic_class="I"))
    assert any(re.match("structure of the design check: " + pattern, t) for t in found), found


def test_design_check_with_damping_in_percent_warns_on_a_passing_verdict():
    # The fault itself: 0.5 read as 50 % makes the Sétra class I check pass (utilisation well
    # below 1) where 0.5 % fails it; the warning is what tells the two apart.
    with pytest.warns(PlausibilityWarning):
        structure = beam(damping=0.5)
    with pytest.warns(PlausibilityWarning, match="percent instead of fraction"):
        wrong = design_check(structure, "setra", traffic_class="I")
    right = design_check(beam(), "setra", traffic_class="I")
    assert wrong.utilisation[0] < 1 < right.utilisation[0]


@pytest.mark.parametrize("code, options", [("setra", {}), ("hivoss", {}), ("ukna", {})])
def test_design_density_above_the_densest_class_warns(paper_bridge, code, options):
    # Sétra class I 1.0 and HiVoSS TC5 1.5 P/m² are the densest design crowds (docs: theory,
    # Plausible ranges); 3 P/m² is legal (below the jam density) but doubtful.
    with pytest.warns(PlausibilityWarning, match=r"density = 3 persons/m² is above 2 persons/m²"):
        design_check(paper_bridge, code, density=3.0, **options)


def test_design_density_beyond_the_jam_density_names_the_count(paper_bridge):
    # 50 "persons/m²" on the 50 m × 3 m walkway is 50/150 = 0.333 P/m² if it was a count.
    with pytest.raises(ParameterError, match=r"density must be < the jam density 5\.4 persons/m² "
                       r"\(Weidmann 1993\), got 50: the number of persons on the deck instead of "
                       r"persons/m²\? \(50 persons on the 150 m² walkway is 0\.333 persons/m²\)"):
        design_check(paper_bridge, "setra", density=50.0)


def test_damper_mass_ratio_in_percent_warns(paper_bridge):
    # mass_ratio = 2 meant as 2 %: m_d = μ m_j / φ² = 2 × 50 t = 100 t, a damper twice the mode.
    with pytest.warns(PlausibilityWarning, match=r"mass_ratio = 2 is above 0\.2, .*percent "
                      r"instead of fraction\? \(2 % is 0\.02\)"):
        damper = tune_damper(paper_bridge, 0, 2.0)
    assert damper.mass == pytest.approx(100e3)


def test_tune_damper_refuses_a_crowd_without_msd(paper_bridge, paper_crowd):
    # On 49020a3 the crowd was ignored: the damper was tuned to the empty bridge.
    with pytest.raises(ParameterError, match=r"msd must be given with crowd"):
        tune_damper(paper_bridge, 0, 0.02, crowd=paper_crowd)


def test_measured_force_without_steps_is_refused():
    # A constant force (a person standing on the plate) has no first harmonic: its step
    # frequency was 0/0, and every walker replayed NaN.
    with pytest.raises(DataError, match=r"forces record 0 \(record_1\) has no walking steps: "
                       r"its first-harmonic DLF in 1\.2–2\.6 Hz is 0, below 0\.02"):
        MeasuredForce(forces=np.full(1000, 700.0), sample_rate=100.0)


@pytest.mark.parametrize("option", ["free_mass_ratio", "free_step_frequencies", "match_welch"])
def test_estimator_switches_must_be_booleans(paper_bridge, paper_crowd, paper_msd, welch_grid,
                                             option):
    # "no" is truthy: on 49020a3 free_mass_ratio="no" freed the mass ratio.
    from crowdvib import estimate_hsi, response_psd

    measured = response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd)
    with pytest.raises(ParameterError, match=rf"{option} must be True or False, got 'no'"):
        estimate_hsi(measured, paper_bridge, paper_crowd, band=(0.0, 10.0), **{option: "no"})


def test_mode_count_must_be_an_integer():
    # True was read as 1 mode on 49020a3 (2.5 was refused already, and still is).
    with pytest.raises(ParameterError, match=r"n_modes must be a positive integer, got True"):
        beam(n_modes=True)


def test_the_docs_table_states_every_range():
    # One table in the code (crowdvib._plausibility.RANGES), one in the docs (docs: theory,
    # Plausible ranges): each key appears there with its bounds, so the two cannot drift apart.
    from pathlib import Path

    from crowdvib._plausibility import RANGES

    page = (Path(__file__).resolve().parents[2] / "docs" / "theory"
            / "plausible-ranges.rst").read_text(encoding="utf-8")
    for key, plausible in RANGES.items():
        row = page[page.index(f"(``{key}``"):].split("   * - ")[0]
        bounds = [f"{b:g}" for b in (plausible.low, plausible.high) if b is not None]
        shown = [b.replace("100000", "1e5") for b in bounds]
        assert all(b in row for b in shown), (key, shown, row[:80])


def test_check_cli_verdict_names_the_damping_in_percent(tmp_path, capsys):
    # Issue 24: with ξ = 0.5 (meant as 0.5 %) `crowdvib check` passed the paper's bridge, which
    # fails EN 1990 (examples/check_paper.toml), and printed "verdict: no warnings".
    from pathlib import Path

    from crowdvib.cli import main

    case = Path(__file__).resolve().parents[2] / "examples" / "check_paper.toml"
    text = case.read_text(encoding="utf-8")
    assert "damping_ratio = 0.005" in text
    wrong = tmp_path / "check_paper.toml"
    wrong.write_text(text.replace("damping_ratio = 0.005", "damping_ratio = 0.5"),
                     encoding="utf-8")
    # Finished, and the verdict doubts it (damping in percent?): exit status 3.
    assert main(["check", str(wrong), "--out", str(tmp_path / "out")]) == 3
    printed, err = capsys.readouterr()
    assert "verdict: no warnings" not in printed
    # One line per finding (issue 36 §3): on stderr as raised, where the case's structure is
    # read, not again as "structure of the design check", and counted by the verdict.
    note = ("PlausibilityWarning: damping_ratios[0] = 0.5 is above 0.1, unusual for a "
            "footbridge mode: percent instead of fraction? (0.5 % is 0.005)")
    assert (printed + err).count(note) == 1 and "structure of the design check" not in err
    assert "warning(s) printed above" in printed


def test_a_mode_shape_zero_at_every_station_is_refused():
    # Issue 24 §4: all-zero mode shapes were accepted; ∫φ² dA = 0 made the deck-mass check
    # divide by zero (a RuntimeWarning), and the mode can be neither loaded nor felt by walkers.
    stations = np.linspace(0.0, 50.0, 11)
    shapes = np.c_[np.sin(np.pi * stations / 50.0), np.zeros(11)]
    with pytest.raises(ParameterError, match=r"mode_shapes must not be zero at every station: "
                                             r"mode\(s\) \[1\]"):
        ModalModel(frequencies=[2.0, 3.0], damping_ratios=[0.005, 0.005],
                   modal_masses=[50e3, 50e3], positions=stations, mode_shapes=shapes, width=3.0,
                   output_names=["midspan"], output_shapes=[[1.0, 0.0]])
