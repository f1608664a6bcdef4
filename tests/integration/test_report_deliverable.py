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
    assert main(["check", str(case), "--out", str(out)]) in (0, 3)   # 3: finished, in doubt
    return out


def test_no_absolute_machine_path_in_the_report(design_dir, tmp_path):
    # Issue 27 §4: paths relative to the case (inputs) and to the results folder (provenance).
    out = tmp_path / "copy"
    shutil.copytree(design_dir, out)
    results = json.loads((out / "results.json").read_text(encoding="utf-8"))
    case = Path(results["case"])
    assert case.is_absolute()                      # what the run records
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
