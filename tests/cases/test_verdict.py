"""The verdict in the core (issue 26 §2): ``crowdvib.cases.verdict.findings`` judges a results
dict; the thresholds are the paper's (Fig. 15: a Welch PSD has converged when the last window
changes it by less than 10 %; J/J_noHSI of the paper's fits stays below 2 %, 10 % allowed), and
report.html shows the same findings as ``Results.verdict()``."""

import pytest

from crowdvib.cases import SCHEMA, Results
from crowdvib.cases.verdict import (CONVERGENCE_LEVEL, RELATIVE_COST_LEVEL, Finding, findings,
                                    in_doubt)
from crowdvib.reporting.report import render_report


def _severities(results):
    return [(f.severity, f.key) for f in findings(results)]


def test_the_thresholds_are_the_papers():
    assert CONVERGENCE_LEVEL == 0.10 and RELATIVE_COST_LEVEL == 0.10


@pytest.mark.parametrize("relative, severity", [(0.10, "ok"), (0.1001, "doubt"), (0.02, "ok")])
def test_relative_cost_above_ten_percent_is_a_doubt(relative, severity):
    found = findings({"diagnostics": {"relative_cost": relative}})
    assert [(f.severity, f.key) for f in found] == [(severity, "diagnostics.relative_cost")]


def test_the_convergence_of_each_output_is_judged_on_the_last_window():
    # The last column is 0 by construction (the record against itself); the one before is the
    # change the last window made: 9.9 % converged, 10 % not (paper Fig. 15).
    results = {"diagnostics": {"convergence": {
        "error": [[0.5, 0.099, 0.0], [0.5, 0.10, 0.0]], "output_names": ["mid", "quarter"]}}}
    found = findings(results)
    assert [f.severity for f in found] == ["ok", "doubt"]
    assert found[1].text.startswith("the PSD of quarter has not converged: the last window "
                                    "changed it by 10.0 %")
    bad = findings({"diagnostics": {"convergence": {"error": [["x", 0.1]]}}})
    assert bad == (Finding("doubt", "the PSD convergence in results.json is not numeric and is "
                           "left out.", "diagnostics.convergence"),)


def test_a_design_check_failing_with_the_primary_model_fails():
    # With HSI rows present, HSI is the primary model: the no-HSI failure is not a finding.
    rows = [{"code": "hivoss", "traffic_class": "TC3", "model": "no HSI", "output": "mid",
             "passes": False, "governing": 2.4, "limit": 1.0, "utilisation": 2.4},
            {"code": "hivoss", "traffic_class": "TC3", "model": "HSI", "output": "mid",
             "passes": False, "governing": 1.38, "limit": 1.0, "utilisation": 1.38},
            {"code": "setra", "traffic_class": "II", "model": "HSI", "output": "mid",
             "passes": True, "governing": 0.5, "limit": 1.0, "utilisation": 0.5}]
    found = findings({"design": {"verdict": rows}})
    assert found == (Finding("fail", "HiVoSS TC3 fails at mid with HSI: 1.38 m/s² above the "
                             "limit 1 m/s² (utilisation 1.38).", "design.verdict"),)


def test_a_code_passing_at_the_estimate_and_failing_at_the_conservative_end_fails():
    # Issue 27 §3: the verdict at the conservative end of the estimate's interval. The paper
    # example's UK NA row (tests/cli/test_check_interval.py): 0.91 at the estimate, 0.83–1.01
    # over the 95 % box, the high end at (f_h1 high, ξ_h1 low).
    box = {"interval": "estimate 95 %", "frequency": [2.9, 3.2], "damping_ratio": [0.2, 0.4]}
    ranges = {"ukna": {**box, "utilisation": 0.91, "low": 0.83, "high": 1.01,
                       "conservative_end": {"frequency": 3.2, "damping_ratio": 0.2}},
              "hivoss": {**box, "utilisation": 0.5, "low": 0.45, "high": 0.6},
              "setra": {**box, "utilisation": 1.2, "low": 1.1, "high": 1.3}}
    found = findings({"hsi_range": ranges})
    assert found == (
        Finding("fail", "UK NA passes at the estimate (utilisation 0.91) but fails at the "
                "conservative end of the estimate 95 % interval of f_h1 and ξ_h1 (f_h1 = 3.2 Hz, "
                "ξ_h1 = 0.2): utilisation 1.01 there (range 0.83–1.01).", "hsi_range.ukna"),
        Finding("ok", "HiVoSS passes over the estimate 95 % interval of f_h1 and ξ_h1 "
                "(utilisation 0.45–0.6).", "hsi_range.hivoss"))
    # Sétra fails at the estimate: the design rule's failure, an answer, not this rule's.
    # The interval's failure is undecided by the data: in doubt (exit status 3); a failure at
    # the estimate alone is not.
    assert in_doubt(found) and not in_doubt(found[1:])
    assert not in_doubt((Finding("fail", "setra fails", "design.verdict"),))


def test_a_mode_the_cross_check_misses_is_a_doubt():
    results = {"command": "modes", "method": "ssi-cov",
               "modes": [{"frequency": 2.0}, {"frequency": 7.5}],
               "cross_check": {"method": "efdd", "level": 1.96,
                               "modes": [{"agree": True, "frequency": 2.0},
                                         {"agree": False, "frequency": None}]}}
    assert [f.text for f in findings(results)] == [
        "mode 2 (7.5 Hz): the cross-check by EFDD finds no mode there."]
    results["cross_check"]["modes"][1] = {"agree": True, "frequency": 7.5}
    assert _severities(results) == [("ok", "cross_check")]


def test_every_rule_of_a_bad_study_and_the_report_shows_each_finding():
    # A study with every doubt the rules know (the report's synthetic results, test_report.py).
    data = {"schema": SCHEMA, "kind": "sensitivity", "command": "sensitivity",
            "diagnostics": {"relative_cost": 0.25, "success": False, "message": "max evaluations",
                            "active_bounds": ["damping_ratio:upper"]},
            "sensitivity": {"cases": [{"name": "a", "error": "EstimationError: no fit"},
                                      {"name": "b", "active_bounds": ["frequency:lower"]}]},
            "record_length": [{"duration": 600.0, "error": "EstimationError: too short"}],
            "warnings": ["BoundWarning: on the bound"]}
    result = Results.from_dict(data)
    keys = [f.key for f in result.verdict()]
    assert keys == ["diagnostics.relative_cost", "diagnostics.success",
                    "diagnostics.active_bounds", "record_length", "sensitivity.cases",
                    "sensitivity.cases", "warnings"]
    assert not result.passes and {f.severity for f in result.verdict()} == {"doubt"}
    summary = render_report(result).split('<section id="summary">')[1].split("</section>")[0]
    # Each finding once, in order, its symbols typeset (J/J_noHSI → J/J<sub>noHSI</sub>).
    shown = [item.split("</li>")[0] for item in summary.split('<div class="callout warn">')[1]
             .split("<li>")[1:]]
    assert shown == [f.text.replace("J/J_noHSI", "J/J<sub>noHSI</sub>")
                     for f in result.verdict()]
