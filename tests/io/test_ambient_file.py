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
