"""Files from someone else are data, never instructions (issue 35 §1): a received results folder
names no file of this machine for its report, a case file's template lies beside it, and a
results.json edited since its run wrote it is not used unseen."""

import json
from pathlib import Path

import pytest

from crowdvib import DataError, ParameterError, UnverifiedWarning, load_case
from crowdvib._manifest import write_manifest
from crowdvib.cases import identified_levels
from crowdvib.cases.schema import schema_header
from crowdvib.cli import main
from crowdvib.reporting.report import REPORT_NAME
from tests.conftest import paper_case_least_squares
from tests.oma.test_oma_levels import MODES
from tests.reporting.test_report_header import BEAM

pytest.importorskip("jinja2")

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SECRET = "SECRET-7f3a: a line of a file outside the folder"
LETTER = "<!DOCTYPE html><html><head><title>{{ title }}</title></head><body>{}{{{{ body }}}}" \
         "</body></html>"


def _received(tmp_path, template):
    """A results folder as received: its results.json names ``template`` for the report."""
    folder = tmp_path / "received"
    folder.mkdir()
    results = {"command": "check", "case": "/far/away/case.toml",
               "inputs": {"report": {"client": "Someone", "template": template}}}
    (folder / "results.json").write_text(json.dumps(results), encoding="utf-8")
    return folder


@pytest.mark.parametrize("template", ["/etc/passwd", "../outside.html", "link.html",
                                      "inside.txt", "sub/../../outside.html"])
def test_a_received_results_folder_names_no_file_of_this_machine(tmp_path, capsys, template):
    # Before: `crowdvib report DIR` rendered whatever results.json named, /etc/passwd included.
    (tmp_path / "outside.html").write_text(LETTER.format(SECRET), encoding="utf-8")
    folder = _received(tmp_path, template)
    (folder / "link.html").symlink_to(tmp_path / "outside.html")        # a link out of it
    (folder / "inside.txt").write_text(SECRET, encoding="utf-8")
    assert main(["report", str(folder)]) == 0, capsys.readouterr().err
    page = (folder / REPORT_NAME).read_text(encoding="utf-8")
    assert "SECRET-7f3a" not in page and "root:" not in page
    assert "recorded in the results is not used: a recorded template must" in page
    assert '<section id="inputs">' in page                     # the built-in layout


def test_a_template_inside_the_folder_or_named_on_the_command_line_is_used(tmp_path, capsys):
    folder = _received(tmp_path, "letter.html")
    (folder / "letter.html").write_text(LETTER.format("INSIDE-LETTER"), encoding="utf-8")
    assert main(["report", str(folder)]) == 0, capsys.readouterr().err
    assert "INSIDE-LETTER" in (folder / REPORT_NAME).read_text(encoding="utf-8")
    # One outside it, named by the user: the command line is the user's word.
    (tmp_path / "mine.j2").write_text(LETTER.format("MY-LETTER"), encoding="utf-8")
    assert main(["report", str(folder), "--template", str(tmp_path / "mine.j2")]) == 0
    assert "MY-LETTER" in (folder / REPORT_NAME).read_text(encoding="utf-8")
    # Named, but no template: refused by name.
    (tmp_path / "notes.txt").write_text("x", encoding="utf-8")
    assert main(["report", str(folder), "--template", str(tmp_path / "notes.txt")]) == 1
    assert "report template notes.txt: must be a .html or .j2 file" in capsys.readouterr().err


@pytest.fixture
def case_folder(tmp_path):
    folder = tmp_path / "cases" / "here"
    (folder / "templates").mkdir(parents=True)
    (folder / "templates" / "letter.html").write_text(LETTER.format("CASE-LETTER"),
                                                      encoding="utf-8")
    (tmp_path / "any.txt").write_text(SECRET, encoding="utf-8")
    (tmp_path / "any.html").write_text(LETTER.format(SECRET), encoding="utf-8")
    (folder / "escape.html").symlink_to(tmp_path / "any.html")
    return folder


def _case(folder, template):
    path = folder / "case.toml"
    path.write_text(BEAM + f'[report]\ntemplate = "{template}"\n', encoding="utf-8")
    return path


@pytest.mark.parametrize("template, rule", [
    ("../../any.txt", "must be a .html or .j2 file"),
    ("../../any.html", "must lie in here or below it"),
    ("escape.html", "must lie in here or below it"),
])
def test_a_case_files_template_lies_beside_it(case_folder, template, rule):
    with pytest.raises(ParameterError, match=rf"case.toml: report.template {rule}.*got "
                                             rf"'{template}'"):
        load_case(_case(case_folder, template))


def test_a_case_files_template_is_recorded_relative_to_its_folder(case_folder, tmp_path, capsys):
    case = load_case(_case(case_folder, "templates/letter.html"))
    assert case.report["template"] == "templates/letter.html"
    out = tmp_path / "out"
    assert main(["check", str(case_folder / "case.toml"), "--out", str(out)]) in (0, 3, 4)
    assert "CASE-LETTER" in (out / REPORT_NAME).read_text(encoding="utf-8")
    recorded = json.loads((out / "results.json").read_text())["inputs"]["report"]["template"]
    assert recorded == "templates/letter.html"
    # Later, in the results folder alone, the template (outside it) is not used.
    assert main(["report", str(out)]) == 0
    assert "CASE-LETTER" not in (out / REPORT_NAME).read_text(encoding="utf-8")


# ------------------------------------------------------------------ --msd-from, --modes-from
def _estimate_folder(tmp_path, *, manifest=True):
    source = tmp_path / "estimate"
    source.mkdir()
    estimate = {"frequency": 2.8, "damping_ratio": 0.35, "mass_ratio": 0.9}
    (source / "results.json").write_text(json.dumps({**schema_header("estimate"),
                                                     "estimate": estimate}))
    if manifest:
        write_manifest(source, "estimate")
    return source


def _edit(results):
    data = json.loads(results.read_text())
    data.setdefault("estimate", {})["damping_ratio"] = 0.05
    results.write_text(json.dumps(data))


def test_check_refuses_an_msd_edited_since_its_run(tmp_path, capsys):
    source = _estimate_folder(tmp_path)
    _edit(source / "results.json")
    out = tmp_path / "check"
    assert main(["check", str(EXAMPLES / "check_paper.toml"), "--out", str(out),
                 "--msd-from", str(source)]) == 1
    err = capsys.readouterr().err
    assert f"{source / 'results.json'} (--msd-from): its SHA-256" in err
    assert "differs from the manifest's" in err and "crowdvib-manifest.json" in err
    assert not out.exists()


def test_check_warns_that_an_msd_without_a_manifest_cannot_be_verified(tmp_path, capsys):
    source = _estimate_folder(tmp_path, manifest=False)
    out = tmp_path / "check"
    assert main(["check", str(EXAMPLES / "check_paper.toml"), "--out", str(out),
                 "--msd-from", str(source)]) == 3               # written, in doubt
    assert "UnverifiedWarning" in capsys.readouterr().err
    assert any("cannot be verified" in w for w in
               json.loads((out / "results.json").read_text())["warnings"])


def test_sensitivity_refuses_modes_edited_since_their_run(tmp_path, capsys):
    modes = tmp_path / "modes"
    modes.mkdir()
    (modes / "results.json").write_text(json.dumps({"command": "modes", "modes": MODES}))
    write_manifest(modes, "modes")
    assert identified_levels(modes)["frequencies"]                # verified: used
    edited = [{**mode, "damping_std": 1e-9} for mode in MODES]
    (modes / "results.json").write_text(json.dumps({"command": "modes", "modes": edited}))
    with pytest.raises(DataError, match="differs from the manifest's"):
        identified_levels(modes)
    out = tmp_path / "study"
    assert main(["sensitivity", str(paper_case_least_squares()), "--out", str(out),
                 "--modes-from", str(modes)]) == 1
    assert "(--modes-from): its SHA-256" in capsys.readouterr().err
    # A file the manifest does not list is no more crowdvib's than an edited one.
    (modes / "crowdvib-manifest.json").write_text(json.dumps(
        {"crowdvib_manifest": 1, "files": []}))
    with pytest.raises(DataError, match="is not a file crowdvib wrote there"):
        identified_levels(modes)
    (modes / "crowdvib-manifest.json").unlink()
    with pytest.warns(UnverifiedWarning, match="crowdvib-manifest.json is missing"):
        identified_levels(modes)
