"""`crowdvib demo` end to end: the paper's numerical example, truth vs estimate (issues 2 and 3)."""

import json

import pytest

from crowdvib.cli import main


@pytest.mark.slow
def test_demo_simulates_and_recovers_the_msd(demo_run):
    status, out, printed = demo_run           # `crowdvib demo --out OUT` (tests/conftest.py)
    assert status == 0
    results = json.loads((out / "results.json").read_text())
    # The truth is the paper's MSD (docs: theory, The paper's numerical example); recovery from a simulated 1-hour record:
    # f_h1 within 3 %, ξ_h1 within 20 % (the paper's verification, issue 3).
    assert results["truth"] == {"frequency": 3.0, "damping_ratio": 0.3, "mass_ratio": 0.95}
    assert results["estimate"]["frequency"] == pytest.approx(3.0, rel=0.03)
    assert results["estimate"]["damping_ratio"] == pytest.approx(0.30, rel=0.20)
    assert results["estimate"]["mass_ratio"] == 0.95
    assert results["measured"]["n_windows"] == 119
    assert results["diagnostics"]["relative_cost"] < 0.01
    assert (out / "psd_fit.png").stat().st_size > 10_000
    assert "f_h1 [Hz]" in printed and "95 % interval" in printed
    # Issue 12: the demo prints the statistical interval, and the truth lies inside it.
    interval = results["estimate"]["interval"]
    assert interval["level"] == 0.95
    for name in ("frequency", "damping_ratio"):
        low, high = interval[name]
        assert low <= results["truth"][name] <= high
    # Issue 25: the default estimator and the paper's least squares, both shown, the truth
    # inside both intervals of each; the paper's estimate is kept beside the default's.
    assert printed.count("truth inside") == 4
    paper = results["paper_estimator"]
    assert (results["diagnostics"]["method"], paper["method"]) == ("likelihood", "least_squares")
    for name in ("frequency", "damping_ratio"):
        low, high = paper["estimate"]["interval"][name]
        assert low <= results["truth"][name] <= high


def test_demo_spectral_variant(tmp_path):
    out = tmp_path / "demo"
    assert main(["demo", "--spectral", "--seed", "3", "--out", str(out)]) == 0
    results = json.loads((out / "results.json").read_text())
    assert results["seed"] == 3
    assert results["measured"]["source"] == "synthetic"
    # Issue 26 §2 (one layout): the versions as every command's results.json records them.
    assert results["versions"]["crowdvib"] == results["crowdvib_version"]
    assert set(results["versions"]) == {"crowdvib", "numpy", "scipy", "python"}
    assert results["estimate"]["frequency"] == pytest.approx(3.0, rel=0.03)
    assert results["estimate"]["damping_ratio"] == pytest.approx(0.30, rel=0.15)


def test_usage_error_exits_2(capsys):
    assert main(["demo", "--no-such-flag"]) == 2
    assert main([]) == 2
