"""The crowd table of a monitoring season (issue 28 §2; the columns in crowdvib.io.crowdtable):
read, and every bad table refused with a DataError naming the file, the row and the column."""

import pytest

from crowdvib.errors import DataError
from crowdvib.io.crowdtable import read_crowd_table
from crowdvib.io.formats import file_formats

pytestmark = pytest.mark.badinput


def _table(tmp_path, text):
    path = tmp_path / "crowd.csv"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_crowd_table_of_records_and_windows_is_read(tmp_path):
    path = _table(tmp_path, "# from the camera\nrecord,start,end,count,density,"
                            "step_frequency_mean,time\n"
                            "a.npz,,,42,,1.85,2026-05-04T08:00\n"
                            "b.npz,0,600,,0.25,,\n")
    first, second = read_crowd_table(path).rows
    assert (first.record, first.count, first.density, first.step_frequency_mean) == \
        ("a.npz", 42.0, None, 1.85)
    assert first.density_on(150.0) == pytest.approx(0.28)      # 42 persons on 150 m²
    assert (second.start, second.end, second.name) == (0.0, 600.0, "b.npz[0-600s]")
    assert second.density_on(150.0) == 0.25 and first.row == 1 and second.row == 2
    assert file_formats("crowd")["csv"].reader is read_crowd_table   # the formats table


@pytest.mark.parametrize("text, message", [
    ("record,speed\na.npz,1\n", "unknown column(s) ['speed']"),
    ("record,time\na.npz,2026-05-04\n", "needs a 'record' column and a 'count' or 'density'"),
    ("record,count,density\na.npz,4,0.1\n", "row 1: give the crowd as 'count' or as 'density', "
                                            "exactly one"),
    ("record,count\na.npz,\n", "row 1: give the crowd as 'count' or as 'density'"),
    ("record,count\na.npz,-3\n", "row 1, column 'count' must be >= 0 (persons on the deck), "
                                 "got -3"),
    ("record,count\na.npz,1\nb.npz,many\n", "row 2, column 'count' must hold a finite number, "
                                            "got 'many'"),
    ("record,count\n,4\n", "row 1, column 'record' is empty"),
    ("record,density,start\na.npz,0.1,5\n", "row 1: a window needs both 'start' and 'end'"),
    ("record,density,start,end\na.npz,0.1,600,300\n", "row 1: column 'start' must be before "
                                                      "'end', got 600 >= 300 s"),
    ("record,density,start,end,duration\na.npz,0.1,0,300,300\n", "leave 'duration' empty"),
    ("record,density,step_frequency_std\na.npz,0.1,0\n", "row 1, column 'step_frequency_std' "
                                                         "must be > 0, got 0"),
    ("record,density,time\na.npz,0.1,4 May\n", "row 1, column 'time' must be an ISO 8601"),
    ("record,density\na.npz,0.1\na.npz,0.2\n", "row 2 repeats row 1 (record 'a.npz', the same "
                                               "window)"),
    ("record,density\na.npz,0.1,7\n", "row 1 has 3 field(s), the header has 2"),
    ("record,density\n", "must hold a header line and at least one row"),
])
def test_a_bad_crowd_table_is_refused_naming_file_row_and_column(tmp_path, text, message):
    with pytest.raises(DataError) as error:
        read_crowd_table(_table(tmp_path, text))
    assert str(error.value).startswith("crowd.csv") and message in str(error.value)


def test_a_missing_crowd_table_is_named(tmp_path):
    with pytest.raises(DataError, match="crowd table file not found"):
        read_crowd_table(tmp_path / "nowhere.csv")
