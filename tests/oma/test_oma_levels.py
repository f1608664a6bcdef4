"""Uncertainty carried forward (issue 13): the modelling-error study takes ε_f and ε_ξ from the
identified standard deviations of `crowdvib modes` instead of fixed percentages."""

import json

import pytest

from crowdvib import ParameterError
from crowdvib._manifest import write_manifest
from crowdvib.cli import main
from crowdvib.oma.identify import identified_error_levels
from tests.conftest import paper_case_least_squares

#: The paper example with the paper's estimator (the study's levels are the subject).
CASE = paper_case_least_squares()
MODES = [{"frequency": 2.0, "frequency_std": 0.01, "damping_ratio": 0.005, "damping_std": 0.001},
         {"frequency": 8.0, "frequency_std": 0.02, "damping_ratio": 0.01, "damping_std": 0.001}]


def test_levels_are_one_and_two_relative_sigma_of_the_least_certain_mode():
    # Closed form: max σ_f/f = max(0.01/2, 0.02/8) = 0.5 %; max σ_ξ/ξ = max(0.2, 0.1) = 20 %.
    levels = identified_error_levels([2.0, 8.0], [0.01, 0.02], [0.005, 0.01], [0.001, 0.001])
    assert levels["frequencies"] == pytest.approx((0.005, 0.010))
    assert levels["damping_ratios"] == pytest.approx((0.20, 0.40))
    assert levels["modal_masses"] == (0.02, 0.05)          # the paper's, kept
    with pytest.raises(ParameterError, match="one per mode"):
        identified_error_levels([2.0], [0.01, 0.02], [0.005], [0.001])


def test_sensitivity_takes_its_levels_from_a_modes_results_directory(tmp_path, capsys):
    modes = tmp_path / "modes"
    modes.mkdir()
    (modes / "results.json").write_text(json.dumps({"command": "modes", "modes": MODES}))
    write_manifest(modes, "modes")      # as crowdvib modes leaves it: verified before use
    out = tmp_path / "study"
    assert main(["sensitivity", str(CASE), "--out", str(out), "--no-joint", "--no-record-length",
                 "--workers", "1", "--modes-from", str(modes)]) == 0
    assert "error levels from" in capsys.readouterr().out
    levels = json.loads((out / "results.json").read_text())["sensitivity"]["levels"]
    assert levels["frequencies"] == pytest.approx([0.005, 0.010])
    assert levels["damping_ratios"] == pytest.approx([0.20, 0.40])
    # Not a modes directory: a clear error before any work.
    assert main(["sensitivity", str(CASE), "--out", str(tmp_path / "x"), "--modes-from",
                 str(tmp_path)]) == 1
    assert "results.json: crowdvib modes results file not found" in capsys.readouterr().err
