"""``crowdvib season`` (issue 28 §2): a case file, its records and a crowd table → the season's
table (CSV, Parquet), trend figure, results.json of kind "season" and report; resumable."""

import csv
import importlib.util
import json

import numpy as np
import pytest

from crowdvib import load_results
from crowdvib.cli import main
from crowdvib.models.examples import paper_example
from crowdvib.studies.season import TABLE_COLUMNS, write_synthetic_season
from tests.conftest import copy_paper_case


@pytest.fixture
def season(tmp_path):
    """The paper's numerical example (docs: theory, The paper's numerical example), its
    bridge, crowd, MSD and least squares (tests.conftest.copy_paper_case), four records of 600 s
    at 25 Hz at four densities in ``records/``."""
    paper = paper_example()
    write_synthetic_season(tmp_path / "records", paper.structure, paper.crowd, paper.msd,
                           densities=[0.25, 0.5, 0.75, 1.0], duration=600.0, sample_rate=25.0,
                           times=[f"2026-06-0{day}T18:00" for day in range(1, 5)], rng=6)
    (tmp_path / "records" / "crowd.csv").rename(tmp_path / "crowd.csv")
    copy_paper_case(tmp_path, "season.toml")      # the paper's bridge and least squares
    return tmp_path


def test_season_writes_its_table_figure_and_results_and_resumes(season, capsys):
    out = season / "out"
    arguments = ["season", str(season / "season.toml"), str(season / "crowd.csv"), "--out",
                 str(out), "--records", str(season / "records"), "--workers", "1"]
    assert main(arguments) == 0
    printed = capsys.readouterr().out
    # The joint estimate names its estimator: the case's (here the paper's least squares).
    assert "4 row(s): 4 ok" in printed
    assert "joint estimate (least squares), every record with its crowd" in printed
    with open(out / "season.csv", encoding="utf-8", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert list(rows[0]) == list(TABLE_COLUMNS) and len(rows) == 4
    assert [float(row["density"]) for row in rows] == [0.25, 0.5, 0.75, 1.0]
    assert rows[3]["time"] == "2026-06-04T18:00"
    results = load_results(out)
    assert results.kind == "season" and len(results.table()) == 4
    # The joint estimate's 95 % interval holds the truth the records were made with.
    low, high, level = results.interval("frequency")
    assert low <= 3.0 <= high and level == 0.95
    written = json.loads((out / "results.json").read_text())
    assert written["figures"] == ["season_trends.png"] and (out / "season_trends.png").is_file()
    if importlib.util.find_spec("pyarrow") is not None:    # the parquet extra
        import pandas

        table = pandas.read_parquet(out / "season.parquet")
        assert np.allclose(table["frequency"], [float(row["frequency"]) for row in rows])
    # Existing results are not overwritten; --resume estimates no record again.
    assert main(arguments) == 1
    assert "--resume to continue it or --force" in capsys.readouterr().err
    stamps = {p: p.stat().st_mtime_ns for p in (out / "tasks").glob("*.json")}
    assert main(arguments + ["--resume"]) == 0
    assert "resuming: 4 finished record(s)" in capsys.readouterr().out
    assert {p: p.stat().st_mtime_ns for p in (out / "tasks").glob("*.json")} == stamps
    assert load_results(out).table() == results.table()


def test_season_with_a_bad_crowd_table_names_it_and_writes_no_results(season, capsys):
    (season / "crowd.csv").write_text("record,count\nrecord_001.npz,lots\n", encoding="utf-8")
    assert main(["season", str(season / "season.toml"), str(season / "crowd.csv"), "--out",
                 str(season / "out"), "--workers", "1"]) == 1
    assert ("crowd.csv: row 1, column 'count' must hold a finite number, got 'lots'"
            in capsys.readouterr().err)
    assert not (season / "out").exists()        # refused before any output


def test_season_with_a_bad_batch_size_is_a_usage_error(season, capsys):
    assert main(["season", str(season / "season.toml"), str(season / "crowd.csv"), "--out",
                 str(season / "out"), "--batch-size", "0"]) == 2
    assert "argument --batch-size: must be >= 1, got 0" in capsys.readouterr().err


def _refused(season, capsys, table_text, *options):
    """Run a season on a crowd table of ``table_text``: its error message; nothing written."""
    (season / "crowd.csv").write_text(table_text, encoding="utf-8")
    out = season / "out"
    assert main(["season", str(season / "season.toml"), str(season / "crowd.csv"), "--out",
                 str(out), "--workers", "1", *options]) == 1
    assert not out.exists(), sorted(p.name for p in out.iterdir())
    return capsys.readouterr().err


def test_no_input_error_of_a_season_leaves_anything_behind(season, capsys):
    # Issue 36 §1: a row naming an unknown record or a forgotten --records wrote a manifest and
    # an empty tasks/ before failing, and the corrected run was refused as "already holds
    # results". Every input is checked before anything is written.
    records = ["--records", str(season / "records")]
    good = (season / "crowd.csv").read_text(encoding="utf-8")
    err = _refused(season, capsys, good + "record_042.npz,0.5,2026-06-05T18:00\n", *records)
    assert ("crowd.csv: row 5, column 'record': 'record_042.npz' is not among the season's 4 "
            "record(s): the records given (record_001.npz, record_002.npz, record_003.npz, "
            "…)") in err
    # Without --records the season's one record is the case file's own: the message says so.
    err = _refused(season, capsys, good)
    assert ("'record_001.npz' is not among the season's 1 record(s): the case file's own "
            "record paper_example_record.npz, from its measurement.files, as no records were "
            "given: give the season's records with crowdvib season --records DIR") in err
    # A row whose crowd cannot be (45 persons/m², above the jam density 5.4: Weidmann).
    err = _refused(season, capsys, "record,density\nrecord_001.npz,45\n", *records)
    assert "crowd.csv: row 1: density must be < the jam density 5.4 persons/m², got 45" in err
    # ... with the doubt that led to it, one line (cases.season._crowd: a count of persons?).
    assert ("crowdvib season: warning: crowd.csv: row 1, density = 45 persons/m² is above 2, "
            "unusual for a crowd on a footbridge: a count of persons?") in err
    # The corrected run (here one row, the joint estimate left out) is not refused.
    (season / "crowd.csv").write_text("record,density\nrecord_001.npz,0.25\n", encoding="utf-8")
    assert main(["season", str(season / "season.toml"), str(season / "crowd.csv"), "--out",
                 str(season / "out"), "--workers", "1", "--no-joint", *records]) == 0
    assert load_results(season / "out").table()[0]["status"] == "ok"
