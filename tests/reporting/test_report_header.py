"""The case file's [report] table: who and what the reports are for, in every report's header
and in results.json (issue 27 §4: a report a consultant can send)."""

import datetime

import pytest

from crowdvib import ParameterError, load_case, load_results
from crowdvib._files import write_json
from crowdvib.cases import ESTIMATION_TABLES, check_case
from crowdvib.reporting.report import render_report

BEAM = """name = "beam"
[structure]
type = "simply_supported_beam"
span = 50.0
width = 3.0
frequency = 2.0
damping_ratio = 0.005
modal_mass = 5e4
outputs = { midspan = 25.0 }
[crowd]
density = 0.5
[design]
codes = ["hivoss"]
prediction = false
"""
REPORT = """[report]
client = "City of <Ghent> & Co"
project = "Footbridge comfort"
engineer = "A. N. Engineer"
measurement_date = 2024-05-01
"""


def _case(tmp_path, text):
    path = tmp_path / "case.toml"
    path.write_text(text, encoding="utf-8")
    return load_case(path)


def test_report_table_keeps_text_and_dates_as_text(tmp_path):
    # docs: Case files, [report]: a TOML date is kept as ISO text, free text as written; keys
    # left out are absent, not defaults.
    case = _case(tmp_path, BEAM + REPORT)
    assert case.report == {"client": "City of <Ghent> & Co", "project": "Footbridge comfort",
                           "engineer": "A. N. Engineer", "measurement_date": "2024-05-01"}
    assert datetime.date.fromisoformat(case.report["measurement_date"]).year == 2024
    inputs = case.inputs(ESTIMATION_TABLES)        # kept whatever tables a command keeps
    assert inputs["report"] == case.report
    assert not any(key.startswith("report") for key in inputs["not_set"])
    spring = _case(tmp_path, BEAM + '[report]\nmeasurement_date = "spring 2024"\n')
    assert spring.report == {"measurement_date": "spring 2024"}
    assert "report" not in _case(tmp_path, BEAM).inputs()


@pytest.mark.parametrize("line, message", [
    ('enginer = "A. N. Engineer"', r"unknown key\(s\) \['report.enginer'\].*did you mean "
                                   r"'report.engineer'"),
    ("client = 3", r"report.client must be a string, got 3"),
    ("measurement_date = 20240501", r"report.measurement_date must be a date \(2024-05-01\) or "
                                    r"text, got 20240501"),
])
def test_bad_report_keys_are_refused_by_name(tmp_path, line, message):
    # Like every table of the case file (docs: Case files): the key, the rule and the value.
    with pytest.raises(ParameterError, match=message):
        _case(tmp_path, BEAM + "[report]\n" + line + "\n")


def test_header_shows_the_report_table_escaped_and_not_as_an_input(tmp_path):
    case = _case(tmp_path, BEAM + REPORT)
    page = render_report({"command": "estimate", "inputs": case.inputs(ESTIMATION_TABLES)})
    header = page[page.index("<header>"):page.index("</header>")]
    assert ("<tr><th>Client</th><td>City of &lt;Ghent&gt; &amp; Co</td></tr>"
            "<tr><th>Project</th><td>Footbridge comfort</td></tr>"
            "<tr><th>Engineer</th><td>A. N. Engineer</td></tr>"
            "<tr><th>Date of measurement</th><td>2024-05-01</td></tr>") in header
    inputs = page[page.index('<section id="inputs">'):]
    inputs = inputs[:inputs.index("</section>")]
    assert "Footbridge comfort" not in inputs and "<Ghent>" not in page
    # Without a [report] table the header has no table.
    plain = render_report({"command": "estimate", "inputs": _case(tmp_path, BEAM).inputs()})
    assert "letterhead" not in plain[plain.index("<header>"):plain.index("</header>")]


def test_report_table_round_trips_through_results_json(tmp_path):
    # A check's results.json keeps the table under inputs.report; load_results reads it back.
    found = check_case(_case(tmp_path, BEAM + REPORT))
    write_json(tmp_path / "results.json", found.to_dict())
    loaded = load_results(tmp_path)
    assert loaded.to_dict()["inputs"]["report"] == found.case.report
    assert loaded.to_dict() == found.results().to_dict()
    assert "City of &lt;Ghent&gt; &amp; Co" in render_report(loaded)


def test_case_file_reference_lists_the_report_table(tmp_path):
    # The docs' key reference is generated from the parser (docs/_ext/casefile_keys.py): the
    # [report] table gets its own section with every key, none required.
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "docs" / "_ext"))
    from casefile_keys import parser_sources, write_reference

    from crowdvib.quantities import QUANTITIES

    keys = write_reference(parser_sources(), QUANTITIES, tmp_path / "keys.rst")
    report = {name: row for name, row in keys.items() if name.startswith("report.")}
    assert sorted(report) == [f"report.{key}" for key in (
        "bridge", "client", "engineer", "location", "measurement_date", "project", "template")]
    assert not any(row[2] for row in report.values())                  # none required
    assert "``[report]``\n^^^^^^^^^^^^" in (tmp_path / "keys.rst").read_text(encoding="utf-8")
