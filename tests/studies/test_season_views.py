"""What a season shows (issue 36 §1): its trend figure's axes, its table as a DataFrame, its
notebook view and its report's verdict, on a season's table written out by hand.

The table: ten rows of a synthetic season of the paper's example (truth f_h1 = 3 Hz, ξ_h1 = 0.3;
docs: theory, A season of records): nine records whose 95 % intervals are 0.4 Hz and 0.2 wide
around the truth, and one thin-crowd record whose f_h1 interval spans the whole search range
0.001–10 Hz (the record of the issue that squashed nine good ones into a band).
"""

import datetime

import matplotlib
import numpy as np
import pandas
import pytest

from crowdvib.cases import SCHEMA, Results
from crowdvib.reporting.report import render_report
from crowdvib.studies.plots import plot_season_trends, season_axis_limits
from crowdvib.studies.season import TABLE_COLUMNS

matplotlib.use("Agg")

#: The first row's time; one row every two hours, into the next day.
START = datetime.datetime(2026, 5, 4, 8, 0)
#: The joint estimate of the nine, with its Wald interval.
JOINT = {"frequency": 3.01, "damping_ratio": 0.31, "mass_ratio": 0.95,
         "interval": {"frequency": [2.93, 3.09], "damping_ratio": [0.27, 0.35], "level": 0.95,
                      "method": "wald"}}


def _row(number, frequency, damping, *, low=None, high=None, status="ok", density=0.5,
         warnings=""):
    row = dict.fromkeys(TABLE_COLUMNS)
    row.update(row=number, name=f"record_{number:03d}.npz", record=f"record_{number:03d}.npz",
               time=(START + datetime.timedelta(hours=2 * (number - 1))).isoformat(
                   timespec="minutes"),
               duration=600.0, density=density,
               count=150 * density, frequency=frequency,
               frequency_low=frequency - 0.2 if low is None else low,
               frequency_high=frequency + 0.2 if high is None else high,
               damping_ratio=damping, damping_ratio_low=damping - 0.1,
               damping_ratio_high=damping + 0.1, mass_ratio=0.95, level=0.95,
               relative_cost=0.01, status=status, warnings=warnings, in_joint=True)
    return row


def _table():
    rng = np.random.default_rng(36)
    rows = [_row(n, 3.0 + 0.1 * rng.standard_normal(), 0.3 + 0.03 * rng.standard_normal())
            for n in range(1, 10)]
    # The thin crowd: an estimate at 6 Hz, its interval the whole search range.
    rows.append(_row(10, 6.0, 0.3, low=0.001, high=10.0, status="doubt", density=0.01,
                     warnings="BoundWarning: the 95% interval reaches a search bound "
                              "(frequency:lower)"))
    return rows


def test_the_f_h1_axis_is_set_by_the_informative_records():
    rows = _table()
    figure = plot_season_trends(rows, joint=JOINT)
    for ax in (figure.axes[0], figure.axes[2]):          # f_h1 against density, against time
        low, high = ax.get_ylim()
        # Every interval of the nine and the joint one is on the axis ...
        assert low <= min(r["frequency_low"] for r in rows[:9])
        assert high >= max(r["frequency_high"] for r in rows[:9])
        # ... within 8 % margins of their span, so the nine are not a band: the thin record's
        # 0.001–10 Hz would make the axis 10 Hz tall, and its estimate (6 Hz) is off it.
        span = max(r["frequency_high"] for r in rows[:9]) - min(r["frequency_low"]
                                                                for r in rows[:9])
        assert high - low <= 1.17 * span < 2.0
        # The thin record is drawn at the axis' edge as a triangle (its value lies beyond).
        (edge,) = [line for line in ax.lines if line.get_gid() == "off_axis"]
        assert edge.get_ydata()[0] == pytest.approx(high) and edge.get_marker() == "^"
    # The rule holds for a wide interval not in doubt as well: its width, not its status.
    rows[9]["status"] = "ok"
    value, low, high = (np.array([r[k] for r in rows]) for k in
                        ("frequency", "frequency_low", "frequency_high"))
    limits = season_axis_limits(value, low, high, [False] * 10)
    assert limits[1] < 7.0 and limits[0] > 2.0      # holds the 6 Hz estimate, not 0.001–10


def test_the_time_axis_reads_as_dates_and_hours():
    figure = plot_season_trends(_table(), joint=JOINT)
    figure.figure.canvas.draw()
    ax = figure.axes[2]
    labels = [label.get_text() for label in ax.get_xticklabels() if label.get_text()]
    # The rows run 08:00 to 02:00 the next day: hours on the ticks, the date where it changes
    # and the year and month in the corner (matplotlib's concise date labels).
    assert sum(":00" in text for text in labels) >= 3
    assert "2026" in ax.xaxis.get_offset_text().get_text() or any("May" in t for t in labels)


def test_a_season_with_no_row_estimated_draws_without_a_legend_warning(recwarn):
    # Every row failed: nothing to label (matplotlib warned "No artists with labels").
    rows = [dict(_row(1, 3.0, 0.3), status="error", frequency=None)]
    plot_season_trends(rows)
    assert not [w for w in recwarn if "No artists" in str(w.message)]


def _season_results(rows, **extra):
    return Results.from_dict({
        "schema": SCHEMA, "kind": "season", "command": "season",
        "inputs": {"name": "bridge <B>"}, "crowd_table": "crowd.csv", "records": rows,
        "estimate": JOINT, "diagnostics": {"relative_cost": 0.004, "method": "least_squares"},
        "joint_error": None, "joint_min_density": 0.0, "warnings": [], **extra})


def test_the_season_table_has_missing_values_not_none_objects():
    frame = _season_results(_table()).to_dataframe()
    assert list(frame.columns) == list(TABLE_COLUMNS)
    # A season without windows: no start and end, NaN in float columns (issue 36 §1).
    for column in ("start", "end"):
        assert frame[column].dtype == float and frame[column].isna().all()
    assert frame["row"].tolist() == list(range(1, 11)) and frame["row"].dtype == np.int64
    assert frame["time"].iloc[0] == pandas.Timestamp("2026-05-04T08:00")
    assert frame["in_joint"].dtype == bool


def test_the_notebook_view_shows_the_joint_estimate_and_every_record():
    view = _season_results(_table())._repr_html_()
    # The joint f_h1 and ξ_h1 with their intervals, escaped names, every row.
    assert "3.01 (95 %: 2.93 – 3.09)" in view and "0.31 (95 %: 0.27 – 0.35)" in view
    assert "bridge &lt;B&gt;" in view and "10 (9 ok, 1 doubt)" in view
    assert all(f"record_{n:03d}.npz" in view for n in range(1, 11))
    # The doubtful row makes the verdict doubt (cases.verdict._season).
    assert "check before use" in view and "1 of 10 row(s) of the season are in doubt" in view


def test_the_report_counts_the_records_warnings_and_names_the_joint_estimate():
    page = render_report(_season_results(_table()).to_dict())
    summary = page.split('<section id="summary">')[1].split("</section>")[0]
    assert "No warnings" not in summary and "Check before use" in summary
    assert "The records' own warnings (1 row(s))" in summary
    assert "row 10 record_010.npz (doubt): BoundWarning" in summary
    assert "the joint estimate rests on 10 of the 10 row(s) (named under Records)" in summary
    # The joint fit's interval is not "this one record"'s.
    assert "this record" not in page
    assert "the joint fit of 10 records, each with its crowd (Wald interval" in page
    records = page.split('<section id="records">')[1].split("</section>")[0]
    assert records.count("<tr>") == 11             # the header and every row
    assert "<td>10</td><td>record_010.npz</td>" in records
