"""The ambient-test file's [record] is read as a case file's [measurement] is (issue 27 §1: "give
`modes` the same reader machinery as case files"): a CSV with a `Time [s]` column and values in g,
``units``, ``time_column`` and ``format`` (docs: Case files, Ambient-test files)."""

import numpy as np
import pytest

from crowdvib import ParameterError
from crowdvib.io.ambient import read_ambient

# 20 s at 50 Hz, in g, as a logger writes it: a header row, a `Time [s]` column, no sample rate.
TIME = np.arange(1000) / 50.0
IN_G = 0.01 * np.vstack([np.sin(2 * np.pi * 2.0 * TIME), np.cos(2 * np.pi * 2.0 * TIME)])


@pytest.fixture
def logger_csv(tmp_path):
    rows = "\n".join(f"{t:.2f},{a:.6f},{b:.6f}" for t, (a, b) in zip(TIME, IN_G.T))
    (tmp_path / "bridge.csv").write_text("Time [s],left,right\n" + rows + "\n")
    return tmp_path


@pytest.mark.parametrize("extra", ['units = "g"', 'units = "g"\ntime_column = "Time [s]"\n'
                                                  'format = "csv"'])
def test_a_logger_csv_in_g(logger_csv, extra):
    (logger_csv / "ambient.toml").write_text(f'[record]\nfile = "bridge.csv"\n{extra}\n')
    _, records, _, _ = read_ambient(logger_csv / "ambient.toml")
    record = records[0]
    # The rate from the time stamps; g → 9.81 m/s² (docs: theory, Conventions).
    assert record.sample_rate == pytest.approx(50.0)
    assert record.channel_names == ("left", "right")
    np.testing.assert_allclose(record.data, 9.81 * IN_G, rtol=0, atol=9.81 * 5e-7)  # 6 decimals


@pytest.mark.parametrize("key, value, pattern", [
    ("units", '"gee"', r"ambient.toml: record.units must be 'm/s2', 'g', 'mg' or 'mm/s2', got 'gee'"),
    ("format", '"xlsx"', r"ambient.toml: record.format must be one of \[.*'csv'.*\], "
                         r"got 'xlsx'"),
])
def test_bad_record_keys_are_named(logger_csv, key, value, pattern):
    (logger_csv / "ambient.toml").write_text(f'[record]\nfile = "bridge.csv"\n{key} = {value}\n')
    with pytest.raises(ParameterError, match=pattern):
        read_ambient(logger_csv / "ambient.toml")


def test_a_case_file_is_named_as_one(tmp_path):
    # Issue 36 §3: `crowdvib modes` given a case file answered with its keys ("record is
    # required", "found 'report': misspelt?"); it names the file for what it is.
    from pathlib import Path

    case = Path(__file__).resolve().parents[2] / "examples" / "check_paper.toml"
    with pytest.raises(ParameterError, match=r"check_paper.toml: is a case file \(\[structure\], "
                                             r"\[crowd\], \[hsi\], \[design\]\), not an "
                                             r"ambient-test file"):
        read_ambient(case)


def test_a_logger_preamble_and_header_row_in_record(tmp_path):
    # [record] takes header_row / skip_rows as [measurement] does (issue 36 §2).
    rows = "\n".join(f"{t:.2f},{a:.6f},{b:.6f}" for t, (a, b) in zip(TIME, IN_G.T))
    (tmp_path / "b.csv").write_text("Logger: X\nSerial: 1\nTime [s],left [g],right [g]\n"
                                    + rows + "\n")
    for key in ("header_row = 3", "skip_rows = 2", ""):
        (tmp_path / "ambient.toml").write_text(f'[record]\nfile = "b.csv"\n{key}\n')
        (record,) = read_ambient(tmp_path / "ambient.toml")[1]
        # The header's [g] read: g = 9.81 m/s² (docs: theory, Conventions).
        np.testing.assert_allclose(record.data, IN_G * 9.81, atol=1e-5)
