"""The FRF of the governing mode without and with the tuned mass damper, which the design report
draws (issue 27 §4: the numbers a client pays for, and what they buy)."""

import numpy as np
import pytest

from crowdvib import load_case
from crowdvib.cases import check_case, damper_frf
from crowdvib.reporting.report import render_report

# The paper's 50 m beam (2 Hz, 0.5 %, 50 t) checked to EN 1990 without HSI, with a damper of 2 %
# of the modal mass tuned to its mode (docs: theory, Tuning a TMD).
CASE = """name = "damped beam"
[structure]
type = "simply_supported_beam"
span = 50.0
width = 3.0
frequency = 2.0
damping_ratio = 0.005
modal_mass = 5e4
outputs = { midspan = 25.0, quarter = 12.5 }
[crowd]
density = 0.5
[design]
codes = ["en1990"]
hsi = false
prediction = false
[design.classes]
en1990 = "TC3"
"""
DAMPER = "[design.damper]\nmode = 1\nmass_ratio = 0.02\n"


@pytest.fixture(scope="module")
def damped(tmp_path_factory):
    path = tmp_path_factory.mktemp("frf") / "case.toml"
    path.write_text(CASE + DAMPER, encoding="utf-8")
    return check_case(load_case(path))


def test_frf_without_the_damper_peaks_at_the_closed_form_and_the_damper_lowers_it(damped,
                                                                                  reference):
    frf = damped.to_dict()["design"]["frf"]
    assert (frf["code"], frf["model"], frf["output"], frf["mode"]) == ("en1990", "no HSI",
                                                                      "midspan", 1)
    frequency = np.asarray(frf["frequency"])
    without, with_damper = np.asarray(frf["without_damper"]), np.asarray(frf["with_damper"])
    # A single mode at resonance: |−ω² φ H| = 1 / (2 ξ m) per unit modal force (unity shape).
    reference("peak accelerance without the damper", without.max(), 1 / (2 * 0.005 * 5e4),
              rel=0.01, unit="(m/s²)/N", source="closed form 1/(2ξm) of a single mode")
    assert frequency[without.argmax()] == pytest.approx(2.0, abs=0.005)
    # A 2 % damper tuned to the mode: the peak amplification over the static 1/m is bounded by
    # Den Hartog's fixed points, sqrt(1 + 2/μ) = 10.05 (undamped structure; its own 0.5 % lowers
    # it), against 1/(2ξ) = 100 without the damper.
    amplification = with_damper.max() * 5e4
    assert 0.8 * np.sqrt(1 + 2 / 0.02) < amplification <= np.sqrt(1 + 2 / 0.02)
    # It splits the mode: two peaks, either side of the undamped one.
    peaks = np.flatnonzero((with_damper[1:-1] > with_damper[:-2])
                           & (with_damper[1:-1] > with_damper[2:])) + 1
    assert len(peaks) == 2 and frequency[peaks[0]] < 2.0 < frequency[peaks[1]]


def test_frf_is_none_without_a_damper(tmp_path):
    path = tmp_path / "case.toml"
    path.write_text(CASE, encoding="utf-8")
    found = check_case(load_case(path))
    assert damper_frf(found) is None and found.to_dict()["design"]["frf"] is None


def test_design_report_draws_the_frf_and_lists_the_damper(damped):
    page = render_report(damped.to_dict())
    damper = damped.dampers[0]
    # The figure is drawn from results.json alone, with its caption.
    assert 'alt="damper_frf.png (drawn from results.json)"' in page
    assert "without the tuned mass damper (dashed) and with it" in page
    design = page[page.index('<section id="design">'):]
    assert f"<td>{damper.mass:.4g}</td><td>{damper.frequency:.4g}</td>" in design
