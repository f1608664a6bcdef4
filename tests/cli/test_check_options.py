"""``[design]`` keys gamma_figure (UK NA γ figure) and neq_damping (the damping of Sétra/HiVoSS
n_eq) through ``crowdvib check``: results.json and report.html name the γ figure, the NA's crowd
density cap, both n_eq readings side by side and the defaults not verified against the guides
(issue 33 §1–§3)."""

import json
import re
from pathlib import Path

import pytest

from crowdvib import ParameterError, load_case
from crowdvib.cases import check_case
from crowdvib.cli import main
from crowdvib.design import design_check

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _case(tmp_path, lines, codes='["hivoss", "ukna"]', classes='hivoss = "TC3"\nukna = "D"\n'):
    """examples/check_paper.toml with its [design] replaced by ``lines`` (no prediction)."""
    text = (EXAMPLES / "check_paper.toml").read_text().split("[design]")[0]
    text += f"[design]\ncodes = {codes}\nprediction = false\n{lines}\n[design.classes]\n{classes}"
    path = tmp_path / "case.toml"
    path.write_text(text)
    return path


def test_gamma_figure_and_neq_damping_from_the_case_file(tmp_path):
    path = _case(tmp_path, 'gamma_figure = "na9"\nneq_damping = "empty"\n')
    case = load_case(path)
    found = check_case(case)
    # The checks are the API's with the same options (design_check is tested against the NA
    # and the closed forms in tests/design).
    ukna = design_check(case.structure, "ukna", traffic_class="D", crowd=case.crowd,
                        msd=case.msd, gamma_figure="na9")
    hivoss = design_check(case.structure, "hivoss", traffic_class="TC3", crowd=case.crowd,
                          msd=case.msd, neq_damping="empty")
    assert found.checks["ukna"].details["gamma_figure"] == "na9"
    assert found.checks["ukna"].governing == pytest.approx(ukna.governing, rel=1e-12)
    assert found.checks["hivoss"].details["equivalent_pedestrians"]["damping"] == "empty"
    # The paper example, HiVoSS TC3 with HSI at midspan: 0.89 m/s² with n_eq at the empty ξ
    # against 1.38 m/s² at the occupied ξ (docs: theory, The equivalent crowd with HSI).
    assert found.checks["hivoss"].governing[0] == pytest.approx(hivoss.governing[0], rel=1e-12)
    assert found.checks["hivoss"].governing[0] == pytest.approx(0.89, abs=0.005)


@pytest.mark.parametrize("lines, message", [
    ('gamma_figure = "corrected"', r"design\.gamma_figure must be one of \['pd6688-2', 'na9'\], "
                                   r"got 'corrected'"),
    ('neq_damping = "bare"', r"design\.neq_damping must be one of \['occupied', 'empty'\], "
                             r"got 'bare'"),
])
def test_bad_option_values_are_refused(tmp_path, lines, message):
    with pytest.raises(ParameterError, match=message):
        check_case(load_case(_case(tmp_path, lines)))


def _text(html):
    return re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", html))


def test_report_names_the_figure_the_cap_both_readings_and_unverified_defaults(tmp_path):
    out = tmp_path / "check"
    assert main(["check", str(_case(tmp_path, "")), "--out", str(out)]) in (0, 4)
    results = json.loads((out / "results.json").read_text())
    ukna = results["design"]["checks"]["ukna"]["details"]
    assert ukna["gamma_figure"] == "pd6688-2"                # the default
    # NA.2.44.5(1): class D's 1.5 persons/m² loads the crowd case as 1.0.
    assert ukna["cases"]["crowd"]["density"] == 1.5
    assert ukna["cases"]["crowd"]["load_density"] == 1.0
    hivoss = results["design"]["checks"]["hivoss"]["details"]["equivalent_pedestrians"]
    occupied, empty = (hivoss["governing"][name][2][0] for name in ("occupied", "empty"))
    # docs: theory, The equivalent crowd with HSI (paper example, HiVoSS TC3, HSI, midspan).
    assert (occupied, empty) == pytest.approx((1.38, 0.89), abs=0.005)
    report = _text((out / "report.html").read_text())
    assert ("γ of the walkers and joggers from PD 6688-2:2011 Figure 2 (the corrected Figure "
            'NA.9) (gamma_figure = "pd6688-2")') in report
    assert "the load takes ρ = 1 persons/m², the class's 1.5 capped as NA.2.44.5(1)" in report
    assert f"HiVoSS TC3 midspan {occupied:.3g} {occupied:.3g} {empty:.3g} {empty:.3g} occupied" \
        in report                                            # limit 1.0 m/s²: a = utilisation
    assert ("defaults not verified against the guide UK NA: limit 1.0 k1 k2 k3 k4 within "
            "0.5–2.0 m/s²") in report
    assert results["design"]["checks"]["hivoss"]["details"]["unverified_defaults"] == []
