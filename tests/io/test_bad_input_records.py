"""Records, CSV and case files that were read silently wrong, or refused with a foreign error or
an unhelpful message (issue 24, §3 CSV, §4 "also silent", §5 files and case files).

Each test fails on commit 49020a3 (where the tester measured the issue): the reading was silent,
or the message lacked what the issue asks for. The rules come from the readers' documentation
(crowdvib.io.formats, crowdvib.io.records, crowdvib.io._toml) and from the issue itself.
"""

import csv
import re

import numpy as np
import pytest

from crowdvib import Record, check_record, read_record, write_record
from crowdvib.cli import main
from crowdvib.errors import DataError, ParameterError
from crowdvib.io import load_case, load_measurement
from crowdvib.signals.spectrum import ResponsePSD
from tests.io.test_bad_input_files import BEAM   # a one-mode beam case, 11 lines

pytestmark = pytest.mark.badinput


#: Channel names that break a naive CSV writer or run as spreadsheet formulas (OWASP "CSV
#: injection": a cell starting with = + - @), and names that look like the writer's own escape.
HOSTILE = ["a,b", "=SUM(A1:A9)", "+1", "-x", "@cmd", 'q"uote', "semi;colon", "tab\tinside",
           "'=quoted", "''@x", "'plain", "time", "time_", "#hash", "new\nline", "cr\rin",
           "ünïcode", "", "Time [s]", "t"]


def record_of(names, n_samples=30, sample_rate=50.0, start_time=0.5):
    data = np.random.default_rng(24).normal(scale=0.05, size=(len(names), n_samples))
    return Record(data=data, sample_rate=sample_rate, channel_names=names,
                  start_time=start_time)


def write(tmp_path, name, content):
    path = tmp_path / name
    path.write_text(content, encoding="utf-8")
    return path


# ---------------------------------------------------------------------- §3: the CSV writer
def test_csv_round_trip_keeps_hostile_channel_names(tmp_path):
    # Issue 24 §3: a name with a comma wrote a record crowdvib could not read back (49020a3:
    # "has 20 columns of data but 21 names"). RFC 4180 quoting, and the formula guard taken
    # off again, give back the same names, samples, rate and start time.
    record = record_of(HOSTILE)
    back = read_record(write_record(record, tmp_path / "hostile.csv"))
    assert back.channel_names == tuple(HOSTILE)
    np.testing.assert_array_equal(back.data, record.data)      # 17 digits: exact
    assert back.sample_rate == 50.0 and back.start_time == 0.5


def test_csv_header_cells_are_no_spreadsheet_formulas(tmp_path):
    # Issue 24 §3: "a name starting with = lands as a formula in a spreadsheet". OWASP: a cell
    # starting with = + - @ is run; written behind a "'" it is text.
    path = write_record(record_of(HOSTILE), tmp_path / "hostile.csv")
    lines = [line for line in path.read_text(encoding="utf-8").split("\n")
             if not line.startswith("#")]
    header = next(csv.reader(lines))
    assert len(header) == len(HOSTILE) + 1           # the time column, then every channel
    assert not [cell for cell in header if cell[:1] in ("=", "+", "-", "@")]
    assert "'=SUM(A1:A9)" in header and "'+1" in header and "'''@x" in header


@pytest.mark.parametrize("fmt, name, rule", [
    ("csv", " b", "must not start or end with blanks"),
    ("npz", "b\t", "must not start or end with blanks"),
    ("mat73", "a,b", "must not hold a comma"),
    ("mat", "", "must not be empty"),
    ("uff", "x" * 81, "must fit the 80 characters of one UFF ID line"),
    ("uff", "two\nlines", "must fit the 80 characters of one UFF ID line")])
def test_writers_refuse_a_name_their_format_cannot_give_back(tmp_path, fmt, name, rule):
    # The records module's promise "every writer's output reads back to the same record": at
    # 49020a3 these names were written and read back changed (stripped, "[]", cut at 80
    # characters, split at the comma) or not at all. Refused before writing, naming the channel.
    if fmt in ("mat73", "uff"):
        pytest.importorskip({"mat73": "h5py", "uff": "pyuff"}[fmt])
    path = tmp_path / f"r.{ {'mat73': 'mat'}.get(fmt, fmt)}"
    with pytest.raises(ParameterError, match=rf"channel_names\[1\] {re.escape(rule)}.* in {fmt} "
                                             r"format, got .*: rename it, or write CSV or NPZ"):
        write_record(record_of(["a", name]), path, format=fmt)
    assert not path.exists()


# --------------------------------------------------------------------- §4: silent readings
def test_all_zero_measured_psd_is_refused():
    # Issue 24 §4: an all-zero PSD passed check_measured (a dead channel gave an "estimate").
    psd = ResponsePSD([0.5, 1.0, 1.5], [[1e-6, 2e-6, 1e-6], [0.0, 0.0, 0.0]], ["good", "dead"],
                      source="welch")
    with pytest.raises(DataError, match=r"measured PSD of output 'dead' is zero at all 3 "
                                        r"frequencies"):
        psd.check_measured()


def test_complex_samples_are_refused():
    # Issue 24 §4: complex samples lost their imaginary part (numpy's ComplexWarning only).
    with pytest.raises(ParameterError, match=r"data must hold real accelerations \[m/s²\], "
                                             r"got complex128 samples"):
        Record(data=np.ones((1, 8)) * (1 + 2j), sample_rate=50.0, channel_names=["a"])


@pytest.mark.parametrize("fmt", ["npz", "mat"])
def test_integer_samples_are_refused_as_raw_counts(tmp_path, fmt):
    # Issue 24 §4: int16 raw counts were taken as m/s² (a count of 1000 became 1000 m/s²).
    counts = (np.arange(80, dtype=np.int16) * 37 % 2000).reshape(2, 40)
    path = tmp_path / f"counts.{fmt}"
    if fmt == "npz":
        np.savez(path, data=counts, sample_rate=50.0, channel_names=np.array(["a", "b"]))
    else:
        from scipy.io import savemat

        savemat(path, {"a": counts[0], "b": counts[1], "sample_rate": 50.0})
    with pytest.raises(DataError, match=rf"counts.{fmt}: .*holds int16 samples, the raw counts "
                                        r"of a logger.*scale them to m/s²"):
        read_record(path)


def test_duplicated_column_is_refused_naming_it(tmp_path):
    # Issue 24 §4: a duplicated column kept the first silently (49020a3 read "time,time,a" and
    # took the first time column).
    path = write(tmp_path, "dup.csv", "time,time,a\n0,5,1\n0.1,6,2\n0.2,7,3\n")
    with pytest.raises(DataError, match=r"dup.csv: channel_names must be unique: column 'time' "
                                        r"is both column 1 and column 2 of the header"):
        read_record(path)


def test_time_stamps_and_a_different_sample_rate_are_refused(tmp_path):
    # Issue 24 §4: a case with a time column and a different sample_rate used the stamps
    # silently, and the report then showed both rates. Refused naming both.
    write(tmp_path, "rec.csv", "time,a\n" + "".join(f"{i / 100:.2f},{(-1) ** i * 0.01}\n"
                                                     for i in range(400)))
    case = write(tmp_path, "c.toml", BEAM + '[measurement]\nfiles = ["rec.csv"]\n'
                 'sample_rate = 200.0\nchannels = { midspan = "a" }\n'
                 '[estimation]\nband = [0.5, 5.0]\n')
    with pytest.raises(DataError, match=r"rec.csv: its time column 'time' gives 100 Hz but the "
                                        r"given sample_rate \(measurement.sample_rate\) is 200 "
                                        r"Hz: they must agree"):
        load_measurement(load_case(case))


def test_a_files_own_sample_rate_and_time_stamps_must_agree(tmp_path):
    # The same rule inside one file: an NPZ with time stamps at 50 Hz and sample_rate = 100.
    path = tmp_path / "both.npz"
    np.savez(path, a=np.ones(20), time=np.arange(20) / 50.0, sample_rate=100.0)
    with pytest.raises(DataError, match=r"both.npz: its time column 'time' gives 50 Hz but its "
                                        r"variable 'sample_rate' is 100 Hz"):
        read_record(path)
    # Agreeing, the stated rate is kept exactly (a crowdvib CSV states it beside its stamps).
    np.savez(path, a=np.ones(20), time=np.arange(20) / 50.0, sample_rate=50.0)
    assert read_record(path).sample_rate == 50.0


@pytest.mark.parametrize("key, tables", [
    ("estimation.band", '[estimation]\nband = "19"\n'),
    ("measurement.time_frame", '[measurement]\ntime_frame = "19"\n'
                               '[estimation]\nband = [0.5, 5.0]\n'),
    ("estimation.starts", '[estimation]\nband = [0.5, 5.0]\nstarts = [["3", "0.3"]]\n')])
def test_a_string_where_numbers_belong_is_refused(tmp_path, key, tables):
    # Issue 24 §4: band = "19" was read as [1, 9] Hz (a string unpacks to its characters);
    # starts of strings were converted to numbers.
    case = write(tmp_path, "c.toml", BEAM + tables)
    with pytest.raises(ParameterError, match=rf"c.toml: {key} must be a .*, got "):
        load_case(case)


@pytest.mark.parametrize("shape", [(1, 0), (1, 1), (0, 5)])
def test_check_record_of_too_few_samples(shape):
    # Issue 24 §4: check_record on a 0-sample record raised numpy's "zero-size array to
    # reduction operation maximum" (a foreign ValueError).
    record = Record(data=np.zeros(shape), sample_rate=50.0, channel_names=["a"] * shape[0])
    with pytest.raises(DataError, match=rf"record: holds {shape[0]} channel\(s\) of {shape[1]} "
                                        r"sample\(s\); a record needs a channel of at least 2"):
        check_record(record)


# ------------------------------------------------------------------ time headers, separators
@pytest.mark.parametrize("header", ["Time [s]", "t", "time_s", "Zeit", "temps", "Tijd",
                                    "t (s)", "TIME", "Zeit/s", "tiempo [sec]"])
def test_usual_time_headers_are_recognised(tmp_path, header):
    # Issue 24 §4: "Time [s]" was not recognised ("has no time stamps and no sample rate").
    path = write(tmp_path, "h.csv", f"{header},acc\n2.0,1\n2.004,2\n2.008,3\n")
    record = read_record(path)
    assert record.channel_names == ("acc",)
    assert record.sample_rate == pytest.approx(250.0) and record.start_time == 2.0


def test_time_in_milliseconds_is_refused(tmp_path):
    # A time header in another unit would give a rate 1000 times off: refused, not guessed.
    path = write(tmp_path, "ms.csv", "time [ms],acc\n0,1\n4,2\n8,3\n")
    with pytest.raises(DataError, match=r"ms.csv: column 'time \[ms\]' looks like time in ms, "
                                        r"crowdvib reads time stamps in s"):
        read_record(path)


def test_two_time_headers_are_refused(tmp_path):
    path = write(tmp_path, "two.csv", "t,Time [s],acc\n0,0,1\n0.1,0.1,2\n0.2,0.2,3\n")
    with pytest.raises(DataError, match=r"two.csv: columns \['t', 'Time \[s\]'\] all look like "
                                        r"time stamps"):
        read_record(path)


def test_no_time_column_message_lists_the_columns(tmp_path):
    # Issue 24 §4: the message did not list the columns found.
    path = write(tmp_path, "none.csv", "stamp,acc1,acc2\n0,1,2\n1,3,4\n")
    with pytest.raises(DataError, match=r"none.csv: has no time stamps and no sample rate: none "
                                        r"of its columns \['stamp', 'acc1', 'acc2'\] is a time "
                                        r"column .*measurement.sample_rate"):
        read_record(path)


def test_semicolons_and_decimal_commas_are_read(tmp_path):
    # Issue 24 §4: a CSV with ";" separators and decimal commas (a European spreadsheet) must be
    # read or refused clearly; 49020a3 took "time;a" for one column.
    path = write(tmp_path, "eu.csv", "Zeit;Sensor 1;Sensor 2\n0;0,5;-1,25\n0,01;1,5;2\n"
                                     "0,02;-0,75;0\n")
    record = read_record(path)
    assert record.channel_names == ("Sensor 1", "Sensor 2")
    np.testing.assert_allclose(record.data, [[0.5, 1.5, -0.75], [-1.25, 2.0, 0.0]])
    assert record.sample_rate == pytest.approx(100.0)


def test_spreadsheet_csv_with_byte_order_mark_and_crlf_is_read(tmp_path):
    # A spreadsheet's "CSV UTF-8" starts with a byte-order mark: at 49020a3 the first header
    # became "\ufefftime", no time column was found and the record was refused.
    path = tmp_path / "excel.csv"
    path.write_bytes(b"\xef\xbb\xbftime;acc\r\n0;0,25\r\n0,02;-0,5\r\n0,04;1\r\n")
    record = read_record(path)
    assert record.channel_names == ("acc",) and record.sample_rate == pytest.approx(50.0)
    np.testing.assert_allclose(record.data, [[0.25, -0.5, 1.0]])


def test_decimal_commas_mixed_with_points_are_refused(tmp_path):
    path = write(tmp_path, "mixed.csv", "time;a\n0;1,5\n0.01;2\n")
    with pytest.raises(DataError, match=r"mixed.csv: mixes decimal commas \(line 2\) and decimal "
                                        r"points \(line 3\)"):
        read_record(path)


def test_decimal_commas_between_commas_get_a_hint(tmp_path):
    # "0,1,5" under a two-column header cannot be split: refused, with the likely cause.
    path = write(tmp_path, "comma.csv", "time,a\n0,1,5\n0,01,2,5\n")
    with pytest.raises(DataError, match=r"comma.csv: .*line 2 \(sample index 0\) has 3 "
                                        r"field\(s\), the header names 2 column\(s\) \(decimal "
                                        r"commas\? separate the columns with ';'\)"):
        read_record(path)


# ------------------------------------------------------------------------ §5: the messages
SECRET = "root:x:0:0:SECRET-PASSWORD-HASH:/root:/bin/bash"


def test_a_case_naming_a_system_file_does_not_quote_it(tmp_path):
    # Issue 24 §5: a case file naming ../../../etc/passwd as a record was refused, but the
    # message quoted that file's first lines. Now: the path and the rule, no content.
    system = tmp_path / "etc"
    system.mkdir()
    (system / "passwd").write_text(SECRET + "\n" + SECRET.replace("root", "daemon") + "\n")
    folder = tmp_path / "bridges" / "beam"
    folder.mkdir(parents=True)
    case = write(folder, "c.toml", BEAM + '[measurement]\nfiles = ["../../etc/passwd"]\n'
                 'format = "csv"\nsample_rate = 100.0\n')
    with pytest.raises(DataError) as caught:
        load_measurement(load_case(case))
    message = str(caught.value)
    assert str(system / "passwd") in message and "is not a row of numbers" in message
    rest = message.replace(str(system / "passwd"), "")     # the temporary path may hold "root"
    assert not re.search(r"root|daemon|SECRET|bash", rest), message


def test_demo_duration_names_the_option(capsys, tmp_path):
    # Issue 24 §5: `crowdvib demo --duration-s -1` said "n_windows must be >= 1".
    assert main(["demo", "--duration-s", "-1", "--spectral", "--out", str(tmp_path / "d")]) == 1
    error = capsys.readouterr().err
    assert "--duration-s must be at least one Welch window, T = 60 s, got -1" in error
    assert not (tmp_path / "d").exists()       # refused before any work or output


def test_duplicated_case_file_key_names_the_key_and_lines(tmp_path):
    # Issue 24 §5: tomllib's "Cannot overwrite a value (at line 13, column 14)" named no key.
    case = write(tmp_path, "c.toml", BEAM + "density = 0.6\n")
    with pytest.raises(DataError, match=r"c.toml: key 'crowd.density' is given twice \(lines 11 "
                                        r"and 12\): keep one"):
        load_case(case)
    case = write(tmp_path, "c.toml", BEAM + "[structure]\nwidth = 3.0\n")
    with pytest.raises(DataError, match=r"c.toml: table \[structure\] is declared twice "
                                        r"\(lines 2 and 12\)"):
        load_case(case)


def test_design_msd_errors_name_design_msd(tmp_path):
    # Issue 24 §5: an MSDModel rule broken in [design.msd] was reported as hsi.damping_ratio.
    case = write(tmp_path, "c.toml", BEAM + '[design]\ncodes = ["setra"]\n[design.msd]\n'
                 "damping_ratio = 30.0\n")
    with pytest.raises(ParameterError, match=r"c.toml: design.msd.damping_ratio must be > 0 and "
                                             r"< 2 \(fractions, not percent\), got 30"):
        load_case(case)

