"""report.html of ``crowdvib season`` in a real headless browser (issue 36 §1, "Must show"): the
document a client reads of a season names every record with its row of the crowd table, the
joint estimate with the records it rests on, the records' warnings counted; and the trend
figure's axes are set by the informative records.

The season: the paper's example (tests.conftest.copy_paper_case, the paper's least squares;
docs: theory, The paper's numerical example), four records of 600 s at 0.4–1.0 persons/m² and
one at 0.004 persons/m² (0.6 persons on the 150 m² deck), which holds almost nothing of the
MSD: its ξ_h1 interval spans the whole search range 0.001–1.99. The browser is Debian's
``chromium`` (tests.reporting.test_report).
"""

import json
import subprocess
import sys

import pytest

from crowdvib import load_results
from crowdvib.cli.common import IN_DOUBT
from crowdvib.models.examples import paper_example
from crowdvib.reporting.report import REPORT_NAME
from crowdvib.studies.plots import plot_season_trends
from crowdvib.studies.season import write_synthetic_season
from tests.conftest import copy_paper_case
from tests.reporting.test_report import _check_in_browser, _rendered_text

DENSITIES = [0.4, 0.6, 0.8, 1.0, 0.004]
TIMES = ["2026-06-01T08:00", "2026-06-01T18:00", "2026-06-02T08:00", "2026-06-02T18:00",
         "2026-06-03T03:00"]


@pytest.fixture(scope="module")
def season_run(tmp_path_factory):
    """``crowdvib season`` run as a user runs it: (results folder, what it printed, status)."""
    folder = tmp_path_factory.mktemp("season")
    paper = paper_example()
    write_synthetic_season(folder / "records", paper.structure, paper.crowd, paper.msd,
                           densities=DENSITIES, duration=600.0, sample_rate=25.0, times=TIMES,
                           rng=36)
    (folder / "records" / "crowd.csv").rename(folder / "crowd.csv")
    copy_paper_case(folder, "season.toml")
    done = subprocess.run([sys.executable, "-m", "crowdvib", "season", "season.toml",
                           "crowd.csv", "--records", "records", "--out", "out", "--workers",
                           "1"], capture_output=True, text=True, timeout=900, check=False,
                          cwd=folder)
    return folder / "out", done.stdout + done.stderr, done.returncode


def test_the_season_report_names_every_record_and_what_the_joint_estimate_rests_on(
        season_run, tmp_path):
    out, printed, status = season_run
    results = json.loads((out / "results.json").read_text(encoding="utf-8"))
    rows = results["records"]
    thin = rows[4]
    # The thin record is in doubt (its interval reaches both search bounds of ξ_h1): the
    # verdict doubts the season, exit status 3 (docs: Command line, Exit status).
    assert thin["status"] == "doubt" and thin["damping_ratio_high"] == pytest.approx(1.99)
    assert status == IN_DOUBT, printed[-3000:]
    dom = _check_in_browser(out / REPORT_NAME, tmp_path)
    text = " ".join(_rendered_text(dom).split())
    # Its span under the title: rows, records, dates, hours (5 × 600 s), densities.
    assert ("A season of 5 row(s) of crowd.csv on 5 record(s), 2026-06-01 08:00 to 2026-06-03 "
            "03:00, 0.833 h of records estimated, densities 0.004–1 persons/m²") in text
    # Every record with its row of the crowd table, its time, crowd and both estimates.
    section = dom[dom.index('<section id="records">'):]
    section = " ".join(_rendered_text(section[:section.index("</section>")]).split())
    for number, row in enumerate(rows, start=1):
        assert (f"{number} record_{number:03d}.npz {TIMES[number - 1].replace('T', ' ')} 600 "
                f"{row['count'] if row['count'] is not None else '—'}") in section
        assert (f"{row['frequency']:.3g} ({row['frequency_low']:.3g}–"
                f"{row['frequency_high']:.3g})") in section
    assert section.count("yes") == 5
    # The joint estimate with the records it rests on, all five, each with its row.
    assert ("The joint estimate rests on 5 of the 5 row(s): row 1 record_001.npz, row 2 "
            "record_002.npz, row 3 record_003.npz, row 4 record_004.npz, row 5 "
            "record_005.npz.") in section
    joint = results["estimate"]
    assert f"fh1 = {joint['frequency']:.3g} Hz (95 %: " in text.replace("f h1", "fh1")
    assert "the joint fit of 5 records, each with its crowd (Wald interval" in text
    # The warnings counted, the doubtful record's among them: not "No warnings".
    summary = " ".join(_rendered_text(dom[dom.index('<section id="summary">'):
                                          dom.index('<section id="estimate">')]).split())
    assert "No warnings" not in summary and "Check before use" in summary
    assert "The records' own warnings (1 row(s)): row 5 record_005.npz (doubt): BoundWarning" \
        in summary
    # Not the estimate report's words for one record, nor the case file's own record.
    assert "this record" not in text and "paper_example_record.npz" not in text
    assert "record 1: midspan" not in text


def test_the_season_trend_axes_are_set_by_the_informative_records(season_run):
    out, _, _ = season_run
    results = load_results(out)
    rows = results.table()
    informative, thin = rows[:4], rows[4]
    figure = plot_season_trends(rows, joint=results.estimate)
    for panel, key in ((0, "frequency"), (1, "damping_ratio")):
        low, high = figure.axes[panel].get_ylim()
        # The four records' intervals and the joint one are on the axis ...
        assert low <= min(r[f"{key}_low"] for r in informative)
        assert high >= max(r[f"{key}_high"] for r in informative)
        # ... and the thin record's interval does not set it: for ξ_h1 it spans 0.001–1.99.
        span = (max(r[f"{key}_high"] for r in informative)
                - min(r[f"{key}_low"] for r in informative))
        assert high - low <= 1.17 * span
        assert high - low < 0.5 * (thin[f"{key}_high"] - thin[f"{key}_low"]) or \
            thin[f"{key}_high"] < low
    # The thin record's f_h1 (locked near the bridge's 2 Hz) lies below the axis: a triangle
    # on its lower edge says where it is.
    marks = [line for line in figure.axes[0].lines if line.get_gid() == "off_axis"]
    assert thin["frequency"] < figure.axes[0].get_ylim()[0] and len(marks) == 1
    assert marks[0].get_marker() == "v"
