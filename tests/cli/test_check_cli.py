"""``crowdvib check`` end to end on examples/check_paper.toml: the results directory, its verdict
table against the API's design_check, and an MSD fed from another run's results."""

import json
from pathlib import Path

import numpy as np
import pytest

from crowdvib import MSDModel, load_case
from crowdvib._manifest import write_manifest
from crowdvib.cases.schema import schema_header
from crowdvib.cli import main
from crowdvib.design import design_check, predict_response

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_check_writes_results_verdict_figures_and_report(tmp_path, capsys):
    out = tmp_path / "check"
    # The bridge fails codes with HSI (docs: how-to 2): the checks' answer, exit status 4.
    assert main(["check", str(EXAMPLES / "check_paper.toml"), "--out", str(out)]) == 4
    printed = capsys.readouterr().out
    names = {p.name for p in out.iterdir()}
    assert {"results.json", "report.html", "design_utilisation.png",
            "design_modes.png", "crowdvib-manifest.json"} <= names
    results = json.loads((out / "results.json").read_text())
    assert results["command"] == "check"
    design = results["design"]
    assert set(design["checks"]) == {"hivoss", "setra", "en1990", "ukna"}
    # The verdict rows are the API's own checks (design_check with the case's [hsi] MSD).
    case = load_case(EXAMPLES / "check_paper.toml")
    reference = design_check(case.structure, "ukna", traffic_class="C", crowd=case.crowd,
                             msd=case.msd, site_factors={"k1": 1.0, "k2": 1.0, "k3": 1.0})
    rows = [r for r in design["verdict"] if r["code"] == "ukna"]
    assert [r["model"] for r in rows] == ["no HSI"] * 2 + ["added mass"] * 2 + ["HSI"] * 2
    hsi_mid = next(r for r in rows if r["model"] == "HSI" and r["output"] == "midspan")
    assert hsi_mid["governing"] == pytest.approx(reference.governing[0], rel=1e-12)
    assert hsi_mid["utilisation"] == pytest.approx(reference.utilisation[0], rel=1e-12)
    assert hsi_mid["passes"] is bool(reference.utilisation[0] <= 1)
    hivoss = design_check(case.structure, "hivoss", traffic_class="TC3", crowd=case.crowd,
                          msd=case.msd)
    row = next(r for r in design["verdict"] if r["code"] == "hivoss" and r["model"] == "no HSI")
    assert row["governing"] == pytest.approx(hivoss.governing_of("empty")[0], rel=1e-12)
    prediction = predict_response(case.structure, case.crowd, msd=case.msd, weighting="Wb")
    assert np.allclose(design["prediction"]["rms"], prediction.rms, rtol=1e-12, atol=0)
    # W_b running RMS of the UK NA crossings is recorded (weighting = "Wb" in the case).
    assert "running_rms" in design["checks"]["ukna"]["details"]
    report = (out / "report.html").read_text()
    assert "Design checks" in report and "utilisation" in report
    # A failing check is a printed warning (HiVoSS TC3 with HSI: 1.38 m/s² > 1.0 m/s²).
    assert "HiVoSS TC3 fails at midspan with HSI" in printed


def test_check_takes_the_msd_of_another_run(tmp_path):
    # --msd-from: the estimate in a results.json (as `crowdvib estimate` writes it).
    source = tmp_path / "estimate"
    source.mkdir()
    estimate = {"frequency": 2.8, "damping_ratio": 0.35, "mass_ratio": 0.9}
    (source / "results.json").write_text(json.dumps({**schema_header("estimate"),
                                                     "estimate": estimate}))
    write_manifest(source, "estimate")      # as crowdvib estimate leaves it: verified before use
    out = tmp_path / "check"
    assert main(["check", str(EXAMPLES / "check_paper.toml"), "--out", str(out),
                 "--msd-from", str(source)]) == 4        # fails codes, not in doubt
    results = json.loads((out / "results.json").read_text())
    assert results["msd"]["frequency"] == 2.8 and "estimate" in results["msd"]["source"]
    case = load_case(EXAMPLES / "check_paper.toml")
    reference = design_check(case.structure, "hivoss", traffic_class="TC3", crowd=case.crowd,
                             msd=MSDModel(2.8, 0.35, 0.9))
    assert results["design"]["checks"]["hivoss"]["governing"] == pytest.approx(
        reference.governing.tolist(), rel=1e-12)


def test_check_with_a_tuned_damper(tmp_path):
    text = (EXAMPLES / "check_paper.toml").read_text()
    text = text.replace('codes = ["hivoss", "setra", "en1990", "ukna"]', 'codes = ["hivoss"]')
    text = text.split("[design.classes]")[0] + '[design.classes]\nhivoss = "TC3"\n' \
        "[design.damper]\nmode = 1\nmass_ratio = 0.02\n"
    case_path = tmp_path / "case.toml"
    case_path.write_text(text)
    out = tmp_path / "check"
    assert main(["check", str(case_path), "--out", str(out)]) == 0
    results = json.loads((out / "results.json").read_text())
    damper = results["design"]["dampers"][0]
    assert damper["position"] == pytest.approx(25.0, abs=0.5)       # antinode of mode 1
    # A 2 % damper lowers the HSI governing acceleration against the undamped check.
    case = load_case(EXAMPLES / "check_paper.toml")
    undamped = design_check(case.structure, "hivoss", traffic_class="TC3", crowd=case.crowd,
                            msd=case.msd)
    assert results["design"]["checks"]["hivoss"]["governing"][0] < undamped.governing[0]
