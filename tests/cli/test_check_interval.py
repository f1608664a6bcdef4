"""``crowdvib check --msd-from`` with the estimate's uncertainty (issue 27 §3): the utilisation
per code as a range over the box of f_h1 and ξ_h1 the estimate allows, and the verdict at the
range's conservative end (docs: theory, Design checks, "With an identified MSD")."""

import json
from pathlib import Path

import pytest

from crowdvib import MSDModel, ParameterError, load_case
from crowdvib.cases import check_case, check_over_interval, msd_interval
from crowdvib.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
CASE = EXAMPLES / "check_paper.toml"


@pytest.fixture(scope="module")
def estimate_dir(tmp_path_factory):
    """``crowdvib estimate examples/paper_example.toml``: f_h1, ξ_h1 and their 95 % intervals."""
    out = tmp_path_factory.mktemp("interval") / "estimate"
    assert main(["estimate", str(EXAMPLES / "paper_example.toml"), "--out", str(out),
                 "--quiet"]) == 0
    return out


def _results(folder):
    return json.loads((folder / "results.json").read_text(encoding="utf-8"))


def _hsi_utilisation(case, frequency, damping_ratio, mass_ratio, code):
    """The largest HSI utilisation over the outputs of one code, by check_case at this MSD."""
    rows = check_case(case, msd=MSDModel(frequency, damping_ratio, mass_ratio)).rows
    return max(r["utilisation"] for r in rows if r["code"] == code and r["model"] == "HSI")


def test_range_brackets_the_point_and_the_verdict_takes_its_high_end(estimate_dir):
    case, results = load_case(CASE), _results(estimate_dir)
    estimate = results["estimate"]
    spread = check_over_interval(case, results)
    assert spread.interval["interval"] == "estimate 95 %"
    assert spread.interval["frequency"] == estimate["interval"]["frequency"]
    for code, row in spread.hsi_range().items():
        # The range brackets the point estimate's utilisation, which is check_case's own.
        assert row["low"] < row["utilisation"] < row["high"]
        assert row["utilisation"] == pytest.approx(_hsi_utilisation(
            case, estimate["frequency"], estimate["damping_ratio"], estimate["mass_ratio"], code),
            rel=1e-12)
        # Less crowd damping and a higher f_h1 raise the response (docs/examples how-to 5): the
        # high end is the corner (f_h1 high, ξ_h1 low), the low end the opposite corner.
        (f_low, f_high), (xi_low, xi_high) = (estimate["interval"][name]
                                              for name in ("frequency", "damping_ratio"))
        assert row["high"] == pytest.approx(_hsi_utilisation(
            case, f_high, xi_low, estimate["mass_ratio"], code), rel=1e-12)
        assert row["low"] == pytest.approx(_hsi_utilisation(
            case, f_low, xi_high, estimate["mass_ratio"], code), rel=1e-12)
        assert row["monotone"]
        # The verdict to sign is the one at the conservative end (issue 27 §3).
        assert row["passes"] == (row["high"] <= 1.0)
        assert row["verdict"] == ("passes" if row["high"] <= 1.0 else "FAILS"
                                  if row["low"] > 1.0 else "FAILS at the conservative end")
    # The models without HSI do not depend on the MSD: no range.
    for row in spread.rows:
        if row["model"] != "HSI":
            assert row["low"] == row["high"] == row["utilisation"]


def test_a_finer_grid_finds_the_same_range(estimate_dir):
    # Corners suffice when the utilisation is monotone in each parameter (check_over_interval's
    # docstring): a 5 × 5 grid over the box finds the 3 × 3 grid's extremes, monotone too.
    case, results = load_case(CASE), _results(estimate_dir)
    coarse = check_over_interval(case, results).hsi_range()
    fine = check_over_interval(case, results, grid=5).hsi_range()
    for code, row in fine.items():
        assert row["monotone"]
        assert (row["low"], row["high"]) == pytest.approx(
            (coarse[code]["low"], coarse[code]["high"]), rel=1e-12)


def test_sensitivity_results_give_the_interval_widened_by_the_modelling_bound(estimate_dir):
    # `crowdvib sensitivity` writes "combined" as SensitivityResult.combined: the statistical
    # interval [low, high] widened by the modelling bound B to [low - B, high + B].
    case, results = load_case(CASE), _results(estimate_dir)
    statistical = check_over_interval(case, results, grid=2).hsi_range()
    bound = {"frequency": 0.05, "damping_ratio": 0.02}
    combined = {name: {"interval": results["estimate"]["interval"][name], "bound": b,
                       "combined": [results["estimate"]["interval"][name][0] - b,
                                    results["estimate"]["interval"][name][1] + b],
                       "level": 0.95} for name, b in bound.items()}
    widened = {**results, "command": "sensitivity", "combined": combined}
    box = msd_interval(widened)
    assert box["interval"] == "estimate 95 % + modelling bound"
    assert box["damping_ratio"] == combined["damping_ratio"]["combined"]
    for code, row in check_over_interval(case, widened, grid=2).hsi_range().items():
        assert row["low"] < statistical[code]["low"] and row["high"] > statistical[code]["high"]


def test_check_cli_prints_the_range_and_writes_hsi_range(estimate_dir, tmp_path, capsys):
    out = tmp_path / "check"
    main(["check", str(CASE), "--msd-from", str(estimate_dir), "--out", str(out)])
    printed = capsys.readouterr().out
    written = _results(out)["hsi_range"]
    assert set(written) == {"hivoss", "setra", "en1990", "ukna"}
    # What the command writes is check_case's, given the same results (issue 26 §1).
    library = check_case(load_case(CASE), estimate_results=_results(estimate_dir))
    assert library.msd.frequency == _results(estimate_dir)["estimate"]["frequency"]
    assert json.loads(json.dumps(library.to_dict()["hsi_range"])) == written
    for code, row in written.items():
        assert row["interval"] == "estimate 95 %" and row["low"] < row["high"]
        assert (f"{code:7s} utilisation {row['utilisation']:.2f} (range {row['low']:.2f}–"
                f"{row['high']:.2f} over the 95 % interval of f_h1 and ξ_h1): "
                f"{row['verdict']}") in printed


def test_results_without_an_interval_give_the_point_estimate_with_a_note(tmp_path, capsys):
    # estimation.interval = "none": the estimate alone, as `crowdvib estimate` then writes it.
    source = tmp_path / "estimate"
    source.mkdir()
    (source / "results.json").write_text(json.dumps({"command": "estimate", "estimate": {
        "frequency": 3.1, "damping_ratio": 0.25, "mass_ratio": 0.95}}))
    assert check_over_interval(load_case(CASE), _results(source)) is None
    out = tmp_path / "check"
    main(["check", str(CASE), "--msd-from", str(source), "--out", str(out)])
    printed = capsys.readouterr().out
    assert _results(out)["hsi_range"] is None
    notes = [line for line in printed.splitlines() if "point estimate only" in line]
    assert len(notes) == 1 and 'estimation.interval = "none"' in notes[0]
    assert "range" not in printed


def test_grid_must_hold_the_corners(estimate_dir):
    with pytest.raises(ParameterError, match=r"grid must be an integer of at least 2.*got 1"):
        check_over_interval(load_case(CASE), _results(estimate_dir), grid=1)
