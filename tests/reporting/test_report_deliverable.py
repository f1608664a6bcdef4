"""report.html as a consultant sends it (issue 27 §4), checked on the file's text, no browser: no
absolute machine path, the tuned damper's parameters in a design report, every warning of
results.json counted, and the estimate report without the estimator's internals among the
inputs."""

import html
import json
import re
import shutil
from pathlib import Path

import pytest

from crowdvib.cli import main
from crowdvib.identification.multistart import JOINED
from crowdvib.reporting.report import REPORT_NAME, render_report, write_report

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _text(page, section=None):
    """The visible text of the report (or of one ``<section id=...>``): tags, styles and
    embedded images removed, entities decoded, white space collapsed."""
    if section is not None:
        page = page[page.index(f'<section id="{section}">'):]
        page = page[:page.index("</section>")]
    page = re.sub(r"<style>.*?</style>|data:image/[^\"]+", " ", page, flags=re.S)
    return re.sub(r"\s+", " ", html.unescape(re.sub(r"<[^>]+>", " ", page))).strip()


@pytest.fixture(scope="module")
def design_dir(tmp_path_factory):
    """``crowdvib check`` of the paper's bridge with a damper crowdvib designs (docs: casefiles,
    [design.damper]; how-to 2): 2 % of mode 1's modal mass."""
    folder = tmp_path_factory.mktemp("design")
    case = folder / "check_paper.toml"
    case.write_text((EXAMPLES / "check_paper.toml").read_text(encoding="utf-8")
                    + "\n[design.damper]\nmode = 1\nmass_ratio = 0.02\n", encoding="utf-8")
    out = folder / "with_tmd"
    # 3: finished, in doubt; 4: finished, a code failed
    assert main(["check", str(case), "--out", str(out)]) in (0, 3, 4)
    return out


def test_no_absolute_machine_path_in_the_report(design_dir, tmp_path):
    # Issue 27 §4: paths relative to the case (inputs) and to the results folder (provenance).
    out = tmp_path / "copy"
    shutil.copytree(design_dir, out)
    results = json.loads((out / "results.json").read_text(encoding="utf-8"))
    # What the run records: the case relative to its results folder, no folder of the machine
    # (issue 36 §3) ...
    assert results["case"] == "../check_paper.toml"
    assert str(design_dir.parent) not in (out / "results.json").read_text(encoding="utf-8")
    # ... and the report of a results.json that holds absolute paths (an earlier crowdvib's)
    # shows none of them.
    case = (design_dir / results["case"]).resolve()
    results["case"] = results["inputs"]["path"] = str(case)
    results["inputs"]["measurement"] = {"files": [str(case.parent / "records" / "bridge.csv"),
                                                  "/srv/far/away/from/the/case/deck.csv"]}
    results["warnings"].append(f"{case.parent}/bridge.py:12: ResolutionWarning: a doubt")
    (out / "results.json").write_text(json.dumps(results), encoding="utf-8")
    page = write_report(out).read_text(encoding="utf-8")
    for machine in (str(case.parent), str(tmp_path), "/srv/"):
        assert machine not in page
    inputs = _text(page, "inputs")
    assert "records/bridge.csv" in inputs and "deck.csv" in inputs   # near: relative; far: name
    assert "path check_paper.toml" in inputs
    assert "bridge.py:12: ResolutionWarning: a doubt" in _text(page, "diagnostics")
    # Provenance: the case as seen from its own results folder, one level below it.
    original = render_report(json.loads((design_dir / "results.json").read_text("utf-8")),
                             design_dir)
    assert "case ../check_paper.toml" in _text(original, "provenance")


def test_design_report_shows_the_damper_crowdvib_designed(design_dir):
    # Issue 27 §4: the damper's mass, frequency, damping ratio and position, with units.
    results = json.loads((design_dir / "results.json").read_text(encoding="utf-8"))
    damper, = results["design"]["dampers"]
    # m_d = μ m_1 = 0.02 × 50 t (docs: casefiles, [design.damper]; examples/check_paper.toml).
    assert damper["mass"] == pytest.approx(1000.0)
    design = _text((design_dir / REPORT_NAME).read_text(encoding="utf-8"), "design")
    assert ("mass [kg] frequency [Hz] damping ratio [-] position along the walkway [m]"
            in design)
    assert (f"damper 1 {damper['mass']:.4g} {damper['frequency']:.4g} "
            f"{damper['damping_ratio']:.3g} {damper['position']:.4g}") in design
    assert "designed by crowdvib for mode 1 with 2 % of its modal mass" in design


def test_design_report_has_no_estimate_skeleton_and_one_label_per_model(design_dir):
    page = (design_dir / REPORT_NAME).read_text(encoding="utf-8")
    text = _text(page)
    assert "no estimate in these results" not in text and "no MSD estimate" not in text
    assert "added_mass" not in text and "added mass" in _text(page, "design")
    # Comfort classes only for the codes that define them (design.codes.comfort_limit).
    design = _text(page, "design")
    assert re.search(r"EN 1990 TC3 HSI midspan [\d.]+ 0\.7 [\d.]+ — yes", design)
    assert re.search(r"Sétra II HSI midspan [\d.]+ 1 [\d.]+ CL\d yes", design)
    # In its place: the MSD the HSI rows used (examples/check_paper.toml [hsi]: 3 Hz, 0.30).
    assert "MSD model used" in text and "f h1 [Hz] 3 ξ h1 [-] 0.3" in _text(page, "estimate")
    # One decision per code (issue 27 §4), with the damper: all four pass with HSI.
    summary = _text(page, "summary")
    for code in ("HiVoSS TC3", "Sétra II", "EN 1990 TC3", "UK NA C"):
        assert summary.count(f"{code}: passes with HSI") == 1


def test_every_warning_is_counted_and_fails_are_told_apart_from_doubts(design_dir, tmp_path):
    # Issue 27 §4: five ResolutionWarnings printed, "No warnings" in the report.
    results = json.loads((design_dir / "results.json").read_text(encoding="utf-8"))
    page = (design_dir / REPORT_NAME).read_text(encoding="utf-8")
    count = len(results["warnings"])
    assert count >= 1
    summary = _text(page, "summary")
    assert "No warnings" not in summary
    assert f"The tool doubts its result: {count} warning(s)" in summary
    assert all(message in summary for message in results["warnings"])
    assert f"Warnings raised during the run ({count})" in _text(page, "diagnostics")
    # Warnings the verdict does not list (the estimator's, under diagnostics) count too.
    listed = render_report({"command": "check",
                            "diagnostics": {"warnings": ["ResolutionWarning: a", "X: b"]}})
    assert "No warnings" not in listed
    assert "The tool doubts its result: 2 warning(s)" in _text(listed, "summary")
    # Without the damper the bridge fails Sétra and EN 1990 with HSI (how-to 2): failures are
    # listed apart from the doubts.
    out = tmp_path / "without_tmd"
    main(["check", str(EXAMPLES / "check_paper.toml"), "--out", str(out)])
    failing = [r for r in json.loads((out / "results.json").read_text())["design"]["verdict"]
               if r["model"] == "HSI" and not r["passes"]]
    summary = _text((out / REPORT_NAME).read_text(encoding="utf-8"), "summary")
    assert failing and f"The bridge fails {len(failing)} design check(s)" in summary
    assert "The tool doubts its result" not in summary
    assert "Sétra II: fails with HSI at midspan" in summary


def test_oma_report_has_no_estimate_section():
    mode = {"frequency": 2.0, "frequency_std": 0.01, "damping_ratio": 0.01,
            "damping_std": 0.002}
    page = render_report({"command": "modes", "method": "ssi-cov",
                          "modes": [mode, {**mode, "frequency": 3.1}]})
    assert '<section id="estimate">' not in page and 'href="#estimate"' not in page
    assert "no estimate in these results" not in page
    assert "2 modes identified by SSI-cov: 2, 3.1 Hz" in _text(page, "summary")


@pytest.fixture(scope="module")
def estimate_dir(tmp_path_factory):
    """``crowdvib estimate`` of the paper's example (examples/paper_example.toml: [hsi] sets
    only μ_h1; f_h1 and ξ_h1 are estimated; an .npz record, no time column)."""
    folder = tmp_path_factory.mktemp("estimate")
    for name in ("paper_example.toml", "paper_example_record.npz"):
        shutil.copy(EXAMPLES / name, folder)
    assert main(["estimate", str(folder / "paper_example.toml"), "--out",
                 str(folder / "out")]) == 0
    return folder / "out"


def test_estimate_report_lists_inputs_not_the_estimators_internals(estimate_dir):
    page = (estimate_dir / REPORT_NAME).read_text(encoding="utf-8")
    inputs = _text(page, "inputs")
    # Issue 27 §4: the [hsi] defaults of f_h1 and ξ_h1 are no inputs when they are estimated;
    # μ_h1, set in the case and held fixed, is.
    hsi = inputs[inputs.index("HSI (MSD model)"):inputs.index("Measurement")]
    assert hsi.strip() == "HSI (MSD model) mass ratio [-] 0.95"
    # An .npz record has no time column: the default name is not shown.
    assert "time column" not in inputs
    for internal in ("match welch", "convergence norm"):
        assert internal not in inputs
    # They are in a closed details section, in words, with how each start ended.
    results = json.loads((estimate_dir / "results.json").read_text(encoding="utf-8"))
    details = page[page.index("<details><summary>Estimator details"):]
    details = _text(details[:details.index("</details>")])
    assert "taken through the measurement's Welch window" in details
    assert "root-mean-square change of the PSD over the band" in details
    starts = results["diagnostics"]["starts"]
    assert f"ran from {len(starts)} starting point(s)" in details
    # scipy.optimize.least_squares: status 1-4 converged, 0 the evaluation limit; the first
    # fit's later starts stop in the basin of the first one's optimum (JOINED, docs: theory,
    # Step frequencies fitted with the MSD). Each start's ending is said in words.
    assert all(s["status"] in range(1, 5) or s["status"] == JOINED for s in starts)
    joined = sum(s["status"] == JOINED for s in starts)
    assert joined == 3
    assert details.count("converged: ") == len(starts) - joined
    assert details.count("in the basin of an earlier start") == joined
    assert "PSD convergence (root-mean-square change over" in _text(page, "diagnostics")


@pytest.mark.parametrize("block, not_set, shown", [
    ({"files": ["bridge.npz"], "sample_rate": None}, {"measurement.time_column": "default"},
     False),                                       # no time column in a binary record
    ({"files": ["bridge.csv"], "sample_rate": 50.0}, {"measurement.time_column": "default"},
     False),                                       # the rate was stated, not read
    ({"files": ["bridge.csv"], "sample_rate": None}, {"measurement.time_column": "default"},
     True),                                        # the rate came from the time stamps
    ({"files": ["bridge.npz"], "sample_rate": None}, {}, True)])   # named in the case file
def test_a_default_time_column_is_shown_only_where_a_record_was_read_by_it(block, not_set,
                                                                           shown):
    from crowdvib.reporting.estimator_section import client_inputs

    rows = client_inputs({}, "measurement", {**block, "time_column": "time"}, not_set)
    assert ("time_column" in rows) is shown
