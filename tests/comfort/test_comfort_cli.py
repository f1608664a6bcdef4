"""``crowdvib comfort`` (issue 37): the paper example with a daily traffic profile, and a
synthetic season made by the simulator with a known MSD → results.json (kind "comfort",
round-trip), four figures and a report with a strict CSP, opened in a headless browser."""

import json
import re

import numpy as np
import pytest

from crowdvib import load_results
from crowdvib.cases import comfort_case
from crowdvib.cli import main
from crowdvib.comfort import ComfortYear, Traffic, comfort_year
from crowdvib.io.casefile import load_case
from crowdvib.models.examples import paper_example
from crowdvib.studies.season import write_synthetic_season
from tests.conftest import EXAMPLES, copy_paper_case

#: The paper bridge's daily profile (persons/m² by hour 0–23), as a traffic CSV.
PROFILE = [0.0] * 6 + [0.1, 0.3, 0.6, 0.3, 0.2, 0.2, 0.4, 0.3, 0.2, 0.2, 0.3, 0.7, 0.5, 0.3,
                       0.2, 0.1, 0.05, 0.0]
FIGURES = ["comfort_hours.png", "comfort_exceedance.png", "comfort_week.png",
           "comfort_peaks.png"]


@pytest.fixture
def paper_case(tmp_path):
    """examples/paper_example.toml with a [comfort] table (few densities, for speed; the
    default simulation of the thin crowd switched off) and a daily profile in traffic.csv."""
    case = copy_paper_case(tmp_path)
    case.write_text(case.read_text(encoding="utf-8") + "\n[comfort]\ndensities = 6\n"
                    "damper_mass_ratio = 0.02\nsimulate_below = 0\n", encoding="utf-8")
    (tmp_path / "traffic.csv").write_text(
        "hour,density\n" + "".join(f"{h},{d}\n" for h, d in enumerate(PROFILE)),
        encoding="utf-8")
    return case


def test_comfort_with_a_daily_profile_writes_results_figures_and_report(paper_case, capsys):
    out = paper_case.parent / "out"
    assert main(["comfort", str(paper_case), "--traffic", str(paper_case.parent / "traffic.csv"),
                 "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "8760 h a year, output midspan" in printed and "identified HSI + damper" in printed
    results = load_results(out)
    assert results.kind == "comfort"
    assert type(results).from_dict(results.to_dict()) == results
    year = results.comfort_year()
    assert ComfortYear.from_dict(year.to_dict()) == year
    # hours per class add up to the year's for every model (docs: theory, A year of comfort)
    for row in results.table():
        assert sum(row[f"hours_CL{k}"] for k in range(1, 5)) == pytest.approx(8760.0)
    written = json.loads((out / "results.json").read_text(encoding="utf-8"))
    assert written["figures"] == FIGURES and all((out / f).is_file() for f in FIGURES)
    assert written["traffic_from"] == "the traffic table traffic.csv"
    report = (out / "report.html").read_text(encoding="utf-8")
    assert '<section id="comfort"><h2>A year of comfort</h2>' in report
    assert report.count("data:image/png;base64,") == 4
    # simulate_below = 0: the thin crowd's states (below 100 walkers on the 150 m² walkway) are
    # spectral all the same, and said so: 16 h a day of the profile lie in (0, 2/3) persons/m²
    assert year.settings["thin_crowd_density"] == pytest.approx(100.0 / 150.0)
    assert year.settings["spectral_thin_hours"] == pytest.approx(16 * 365.0)
    assert "are judged by the spectral route all the same" in report


def test_comfort_on_a_report_in_a_headless_browser(paper_case, tmp_path):
    from tests.reporting.test_animation_browser import _check_moving
    from tests.reporting.test_report import _input_rows_without_units, _open_in_browser
    from tests.reporting.test_template_security import _policy_first

    out = tmp_path / "browser"
    assert main(["comfort", str(paper_case), "--traffic", str(paper_case.parent / "traffic.csv"),
                 "--out", str(out), "-q"]) == 0
    # Issue 35 §1: the Content-Security-Policy first in <head>.
    assert _policy_first((out / "report.html").read_text(encoding="utf-8"))
    dom, _, pdf = _open_in_browser(out / "report.html", tmp_path)
    assert re.search(r'data-images="(\d+)"', dom).group(1) == "4"
    assert re.search(r'data-broken-images="(\d+)"', dom).group(1) == "0"
    assert re.search(r'data-split-words="([^"]*)"', dom).group(1) == ""
    assert re.search(r'<section id="comfort">\s*<h2>A year of comfort</h2>', dom)
    assert _input_rows_without_units(dom) == []          # every input with its unit
    assert pdf.read_bytes().startswith(b"%PDF")
    # Issue 38: the bridge's modes swing in this report too (played, paused, slid; no request).
    _check_moving(out / "report.html", tmp_path, ["modes"])


def test_the_hsi_band_from_a_simulated_record_covers_the_true_msd(paper_case, tmp_path):
    # examples/paper_example_record.npz was made by the simulator (moving walkers with the
    # paper's MSD, known: 3.0 Hz, 30 %; examples/make_examples.py). `crowdvib estimate` (the
    # default estimator) gives its MSD with a 95 % interval; `crowdvib comfort --season …
    # --msd-from …` carries it: the band over the interval's box must hold the year computed
    # with the true MSD (docs: theory, A year of comfort). The season (four synthetic records,
    # the paper's least squares) gives the traffic: its windows by their hour of the week.
    paper = paper_example()
    estimate = tmp_path / "estimate"
    assert main(["estimate", str(EXAMPLES / "paper_example.toml"), "--out", str(estimate),
                 "-q"]) == 0
    times = ["2026-06-01T08:00", "2026-06-01T12:00", "2026-06-01T18:00", "2026-06-06T12:00"]
    write_synthetic_season(tmp_path / "records", paper.structure, paper.crowd, paper.msd,
                           densities=[0.6, 0.3, 0.7, 0.2], duration=600.0, sample_rate=25.0,
                           times=times, rng=11)
    season = tmp_path / "season"
    assert main(["season", str(paper_case), str(tmp_path / "records" / "crowd.csv"), "--out",
                 str(season), "--records", str(tmp_path / "records"), "--workers", "1",
                 "-q"]) == 0
    out = tmp_path / "comfort"
    assert main(["comfort", str(paper_case), "--season", str(season), "--msd-from",
                 str(estimate), "--out", str(out), "-q"]) == 0
    found = load_results(out)
    year = found.comfort_year()
    # results.json names no folder of the writer's machine: the estimate relative to the
    # results folder (issue 36 §3, reporting.paths.without_machine_paths)
    assert found.data["msd_source"] == "the estimate in ../estimate"
    assert found.data["traffic_from"] == "the season's windows"
    # four windows stand for their hours of the week, the 164 others filled by the hour rule
    assert len(year.settings["filled_hours"]) == 164
    box = found.data["msd_interval"]
    assert box["frequency"][0] <= 3.0 <= box["frequency"][1]
    assert box["damping_ratio"][0] <= 0.3 <= box["damping_ratio"][1]
    _band_holds_the_truth(load_case(paper_case), season, year, paper.msd)
    # the season's sampling band (its windows drawn again) is reported for every row
    assert all(row["hours_band_sampling"] is not None for row in year.rows)


def test_the_hsi_band_from_a_season_simulated_with_walkers_covers_the_true_msd(paper_case,
                                                                             tmp_path):
    # Issue 37's target: a season made by crowdvib's simulator (moving walkers, each with the
    # paper's MSD, known: 3.0 Hz, 30 %; write_synthetic_season(simulate=True)) gives both the
    # traffic (its windows by their hour of the week) and the MSD (the season's joint estimate
    # and its 95 % interval, `crowdvib comfort --season` alone). The band over the interval's
    # box must hold the year computed with the true MSD on the same traffic (docs: theory, A
    # year of comfort, How the uncertainty is carried). Four 10-minute records keep it short.
    paper = paper_example()
    times = ["2026-06-01T08:00", "2026-06-01T12:00", "2026-06-01T18:00", "2026-06-06T12:00"]
    write_synthetic_season(tmp_path / "records", paper.structure, paper.crowd, paper.msd,
                           densities=[0.6, 0.3, 0.9, 0.45], duration=600.0, sample_rate=25.0,
                           times=times, simulate=True, rng=37)
    season = tmp_path / "season"
    assert main(["season", str(paper_case), str(tmp_path / "records" / "crowd.csv"), "--out",
                 str(season), "--records", str(tmp_path / "records"), "--workers", "1",
                 "-q"]) == 0
    out = tmp_path / "comfort"
    assert main(["comfort", str(paper_case), "--season", str(season), "--out", str(out),
                 "-q"]) == 0
    found = load_results(out)
    year = found.comfort_year()
    assert found.data["msd_source"] == "the season's joint estimate"
    box = found.data["msd_interval"]
    assert box["frequency"][0] <= 3.0 <= box["frequency"][1]
    assert box["damping_ratio"][0] <= 0.3 <= box["damping_ratio"][1]
    _band_holds_the_truth(load_case(paper_case), season, year, paper.msd)


def _band_holds_the_truth(case, season, year, msd):
    """The year at the true ``msd`` (same traffic, same settings) lies in ``year``'s HSI band,
    per class and per limit (docs: theory, A year of comfort, How the uncertainty is carried)."""
    traffic = Traffic.from_season(json.loads((season / "results.json").read_text()))
    truth = comfort_year(case.structure, case.crowd, traffic, msd=msd, n_densities=6,
                         n_resamples=0)
    band, true = year.row("hsi")["hours_band_hsi"], truth.row("hsi")["hours_per_class"]
    for name, value in true.items():
        assert band[name][0] - 1e-6 <= value <= band[name][1] + 1e-6, (name, value, band)
    exceed = year.row("hsi")["exceedance_band_hsi"]
    for limit, value in truth.row("hsi")["exceedance"].items():
        assert exceed[limit][0] - 1e-9 <= value <= exceed[limit][1] + 1e-9


def test_comfort_case_without_traffic_names_the_three_ways(paper_case):
    from crowdvib.errors import ParameterError

    with pytest.raises(ParameterError, match=r"no traffic: give a season \(--season\), a "
                                             r"traffic CSV \(--traffic\) or a \[traffic\]"):
        comfort_case(load_case(paper_case))


def test_a_traffic_table_in_the_case_file(tmp_path):
    case = copy_paper_case(tmp_path)
    case.write_text(case.read_text(encoding="utf-8") + "\n[traffic]\ndensity = [0.2, 0.6]\n"
                    "hours_per_year = [2000, 500]\nyear_hours = 8760\n", encoding="utf-8")
    read = load_case(case)
    assert read.traffic.kind == "table" and read.traffic.density == (0.2, 0.6)
    bad = tmp_path / "bad.toml"
    bad.write_text(case.read_text(encoding="utf-8").replace("[0.2, 0.6]", "[0.2, -0.6]"),
                   encoding="utf-8")
    from crowdvib.errors import ParameterError

    with pytest.raises(ParameterError, match=r"bad.toml: traffic.density must be >= 0"):
        load_case(bad)


def test_the_simulator_stands_in_below_the_gaussian_density():
    # Below simulate_below the states take the fractions of simulated windows: with windows
    # whose peaks are all 0.7 m/s², every hour of those states is CL2 (0.5 < 0.7 ≤ 1.0).
    from crowdvib.comfort.simulated import SimulatedWindows

    paper = paper_example()
    traffic = Traffic.from_table([0.05, 0.6], [1000.0, 100.0])
    windows = SimulatedWindows((0.05,), (np.full(50, 0.7),), (np.full(50, 0.4),))
    year = comfort_year(paper.structure, paper.crowd, traffic, n_densities=3,
                        simulated={("empty", False): windows}, simulate_below=0.1)
    spectral = comfort_year(paper.structure, paper.crowd, Traffic.from_table([0.6], [100.0]),
                            n_densities=3)
    hours = year.row("empty")["hours_per_class"]
    assert hours["CL2"] == pytest.approx(1000.0 + spectral.row("empty")["hours_per_class"]["CL2"])
    assert sum(hours.values()) == pytest.approx(1100.0)


def test_simulated_windows_stand_in_below_the_cases_density(paper_case, tmp_path):
    # [comfort] simulate_below: the states of the profile below 0.15 persons/m² (0.05 and 0.1)
    # take the class fractions of windows simulated at those densities (theory: Where the
    # Gaussian model holds); 1-minute windows and 3 of them per density keep the test short.
    case = paper_case.read_text(encoding="utf-8").replace(
        "simulate_below = 0\n", "simulate_below = 0.15\nsimulated_windows = 3\nduration = 60.0\n")
    paper_case.write_text(case, encoding="utf-8")
    found = comfort_case(load_case(paper_case), traffic=paper_case.parent / "traffic.csv")
    settings = found.year.settings
    assert settings["simulate_below"] == 0.15
    assert settings["simulated_rows"] == [["empty", False], ["empty", True], ["hsi", False],
                                          ["hsi", True]]
    spectral = comfort_case(_without_simulation(paper_case),
                            traffic=paper_case.parent / "traffic.csv")
    for row in found.year.rows:
        assert sum(row["hours_per_class"].values()) == pytest.approx(8760.0)
    # the dense hours are the spectral route's in both: the rows differ by the thin ones only
    # (2 + 1 h a day at 0.05 and 0.1 persons/m², 365 days: ≤ 1095 h can move)
    for row, other in zip(found.year.rows, spectral.year.rows):
        moved = sum(abs(row["hours_per_class"][k] - other["hours_per_class"][k])
                    for k in row["hours_per_class"]) / 2
        assert moved <= 1095.0 + 1e-6


def _without_simulation(case_path):
    text = case_path.read_text(encoding="utf-8").replace("simulate_below = 0.15\n",
                                                         "simulate_below = 0\n")
    plain = case_path.parent / "plain.toml"
    plain.write_text(text, encoding="utf-8")
    return load_case(plain)


def test_the_simulator_stands_in_for_a_thin_crowd_by_default(paper_case):
    # Without simulate_below the states below the thin crowd's density, 100 walkers over the
    # walkway's 150 m² (docs: theory, Where the Gaussian model holds), take simulated windows:
    # every density of the profile but 0.7 persons/m²; 1-minute windows, 3 per density.
    case = paper_case.read_text(encoding="utf-8").replace(
        "simulate_below = 0\n", "simulated_windows = 3\nduration = 60.0\n")
    paper_case.write_text(case, encoding="utf-8")
    out = paper_case.parent / "out"
    assert main(["comfort", str(paper_case), "--traffic", str(paper_case.parent / "traffic.csv"),
                 "--out", str(out), "-q"]) == 0
    settings = load_results(out).comfort_year().settings
    assert settings["simulate_below"] == pytest.approx(100.0 / 150.0)
    assert settings["simulated_rows"] == [["empty", False], ["empty", True], ["hsi", False],
                                          ["hsi", True]]
    assert settings["spectral_thin_hours"] == 0.0
