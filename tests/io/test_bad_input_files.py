"""Bad-input catalogue for files and case files (issue 9: every file problem is a crowdvib error
that names the file, and the key or channel where there is one).

pytestmark = pytest.mark.badinput

Each case builds a small bad file (or case file) in ``tmp_path`` and states the crowdvib error
class and a pattern the message must match; every pattern contains the file's name. The source
of each expectation is the rule the reader documents (crowdvib.io.formats, records, casefile,
modalfiles) or, for the faults of issue 9, the issue itself.
"""

import re
import shutil
import struct
from difflib import SequenceMatcher
from pathlib import Path

import numpy as np
import pytest

from crowdvib import Record, check_record, read_record, write_record
from crowdvib.errors import DataError, ParameterError
from crowdvib.io import load_case, load_measurement, read_modal_model

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


# ------------------------------------------------------------------------------- file makers
def good_record(n_channels=3, n_samples=40):
    data = np.random.default_rng(7).normal(scale=0.05, size=(n_channels, n_samples))
    return Record(data=data, sample_rate=50.0, channel_names="abc"[:n_channels])


def text(name, content):
    def make(tmp_path):
        path = tmp_path / name
        path.write_text(content, encoding="utf-8")
        return path
    return make


def raw(name, content):
    def make(tmp_path):
        path = tmp_path / name
        path.write_bytes(content)
        return path
    return make


def npz(name, **arrays):
    def make(tmp_path):
        path = tmp_path / name
        np.savez(path, **arrays)
        return path
    return make


def mat(name, **variables):
    def make(tmp_path):
        from scipy.io import savemat

        path = tmp_path / name
        savemat(path, variables)
        return path
    return make


def hdf5(name, **datasets):
    def make(tmp_path):
        h5py = pytest.importorskip("h5py")
        path = tmp_path / name
        with h5py.File(path, "w") as handle:
            for key, value in datasets.items():
                handle.create_dataset(key, data=value)
        return path
    return make


def written(name, damage=lambda content: content, **kwargs):
    """A file crowdvib wrote, then damaged by ``damage(bytes) -> bytes``."""
    def make(tmp_path):
        path = write_record(good_record(), tmp_path / ("seed_" + name), **kwargs)
        target = tmp_path / name
        target.write_bytes(damage(path.read_bytes()))
        path.unlink()
        return target
    return make


def folder(name):
    def make(tmp_path):
        path = tmp_path / name
        path.mkdir()
        return path
    return make


def missing(name):
    return lambda tmp_path: tmp_path / name


def drop_from_first_uff_set(content):
    """Delete one float64 (8 bytes) just before the first data set's end tag."""
    end = [m.start() for m in re.finditer(rb"    -1(?=\r|\n|\Z)", content)][1]
    return content[:end - 8] + content[end:]


def cut_in_last_uff_set(content):
    """Cut inside the data of the last (third) data set: its end tag is lost."""
    return content[:len(content) - 100]


RECORD_CASES = [
    # --- CSV
    ("empty_csv", text("empty.csv", ""), DataError, r"empty.csv: has no header line"),
    ("csv_header_only", text("head.csv", "time,a\n"), DataError,
     r"head.csv: has no rows of numbers below its header line"),
    ("csv_non_numeric_cell", text("cell.csv", "time,a,b\n0,1,2\n0.01,3,abc\n"), DataError,
     r"cell.csv: cannot be read as a table of numbers: line 3 \(sample index 1\), column 'b': "
     r"'abc' is not a number"),
    ("csv_ragged_row", text("ragged.csv", "time,a,b\n0,1,2\n0.01,3\n"), DataError,
     r"ragged.csv: .*line 3 \(sample index 1\) has 2 field\(s\), the header names 3"),
    ("csv_not_utf8", raw("latin.csv", "time,a\n0,\xe9\n".encode("latin-1")), DataError,
     r"latin.csv: cannot be read as a CSV file: not UTF-8 text"),
    ("csv_decreasing_time", text("back.csv", "time,a\n0,1\n0.02,2\n0.01,3\n"), DataError,
     r"back.csv: time stamps must increase: sample index 2"),
    ("csv_one_sample", text("one.csv", "# sample_rate = 100\na\n1.0\n"), DataError,
     r"one.csv: channel 'a': holds 1 sample\(s\); a record needs at least 2"),
    ("csv_sample_rate_comment_not_a_number", text("sr.csv", "# sample_rate = fast\na\n1\n2\n"),
     DataError, r"sr.csv: comment 'sample_rate' must be a number, got 'fast'"),
    ("csv_negative_sample_rate", text("neg.csv", "# sample_rate = -100\na\n1\n2\n"), DataError,
     r"neg.csv: sample_rate must be > 0 Hz, got -100"),
    ("csv_zero_sample_rate", text("zero.csv", "# sample_rate = 0\na\n1\n2\n"), DataError,
     r"zero.csv: sample_rate must be > 0 Hz, got 0"),
    ("csv_unknown_unit", text("unit.csv", "# unit = furlong/fortnight\ntime,a\n0,1\n0.1,2\n"),
     DataError, r"unit.csv: units must be 'm/s2', 'g', 'mg' or 'mm/s2', got 'furlong/fortnight'"),
    ("csv_duplicate_channel", text("dup.csv", "time,a,a\n0,1,2\n0.1,3,4\n"), DataError,
     r"dup.csv: channel_names must be unique"),
    ("csv_time_only", text("tonly.csv", "time\n0\n0.1\n"), DataError,
     r"tonly.csv: holds no channels"),
    # --- NPZ
    ("npz_truncated", written("cut.npz", lambda b: b[:len(b) // 2]), DataError,
     r"cut.npz: cannot be read as an NPZ file \("),
    ("npz_empty_file", raw("empty.npz", b""), DataError,
     r"empty.npz: cannot be read as an NPZ file"),
    ("npz_rank_3", npz("cube.npz", data=np.zeros((2, 3, 50)), sample_rate=50.0), DataError,
     r"cube.npz: data must have at most 2 dimension\(s\), got shape \(2, 3, 50\)"),
    ("npz_no_samples", npz("none.npz", data=np.zeros((2, 0)), sample_rate=50.0), DataError,
     r"none.npz: channel 'ch0': holds 0 sample\(s\)"),
    ("npz_scalar_data", npz("scalar.npz", data=np.float64(1.0), sample_rate=50.0), DataError,
     r"scalar.npz: channel 'ch0': holds 1 sample\(s\)"),
    ("npz_text_data", npz("text.npz", data=np.array(["a", "b"]), sample_rate=50.0), DataError,
     r"text.npz: data must hold real numbers, got str.* values"),
    ("npz_complex_data", npz("cplx.npz", data=np.ones((1, 4), complex), sample_rate=50.0),
     DataError, r"cplx.npz: data must hold real numbers, got complex128"),
    ("npz_negative_sample_rate", npz("neg.npz", data=np.ones((1, 4)), sample_rate=-50.0),
     DataError, r"neg.npz: sample_rate must be > 0 Hz, got -50"),
    ("npz_zero_sample_rate", npz("zero.npz", data=np.ones((1, 4)), sample_rate=0.0), DataError,
     r"zero.npz: sample_rate must be > 0 Hz, got 0"),
    ("npz_two_sample_rates", npz("two.npz", data=np.ones((1, 4)), sample_rate=[50.0, 60.0]),
     DataError, r"two.npz: sample_rate must be one number, got shape \(2,\)"),
    ("npz_nan_start_time", npz("start.npz", data=np.ones((1, 4)), sample_rate=50.0,
                               start_time=np.nan), DataError,
     r"start.npz: start time must be finite, got nan"),
    ("npz_names_do_not_match", npz("names.npz", data=np.ones((2, 4)), sample_rate=50.0,
                                   channel_names=np.array(["a", "b", "c"])), DataError,
     r"names.npz: channel_names has 3 names for 2 channels"),
    ("npz_listed_channel_missing", npz("list.npz", a=np.ones(4), sample_rate=50.0,
                                       channel_names=np.array(["a", "b"])), DataError,
     r"list.npz: channel 'b' listed in channel_names has no variable"),
    ("npz_channel_matrix", npz("mat.npz", a=np.ones((3, 4)), sample_rate=50.0), DataError,
     r"mat.npz: channel 'a' must be a vector, got shape \(3, 4\)"),
    ("npy_named_npz", raw("array.npz", b"\x93NUMPY\x01\x00v\x00{'descr': '<f8', 'fortran_order': "
                          b"False, 'shape': (2,), }" + b" " * 73 + b"\n" + b"\x00" * 16),
     DataError, r"array.npz: cannot be read as an NPZ file"),
    # --- MAT v5
    ("mat_truncated", written("cut.mat", lambda b: b[:len(b) // 2]), DataError,
     r"cut.mat: a data element of \d+ bytes runs past the end of the file \(truncated file\?\)"),
    ("mat_empty_file", raw("empty.mat", b""), DataError,
     r"empty.mat: is not a MATLAB v5 file \(no MAT-file header\)"),
    ("mat_rank_3", mat("cube.mat", data=np.zeros((50, 2, 3)), sample_rate=50.0), DataError,
     r"cube.mat: data must have at most 2 dimension\(s\), got shape \(50, 2, 3\)"),
    ("mat_cell_data", mat("cell.mat", data=np.array([[1.0], "x"], dtype=object),
                          sample_rate=50.0), DataError,
     r"cell.mat: data must hold real numbers, got object"),
    ("mat_negative_sample_rate", mat("neg.mat", data=np.ones((4, 1)), sample_rate=-1.0),
     DataError, r"neg.mat: sample_rate must be > 0 Hz, got -1"),
    # --- MAT v7.3
    ("mat73_truncated", written("cut73.mat", lambda b: b[:len(b) // 2], format="mat73"),
     DataError, r"cut73.mat: cannot be read as a MATLAB file \(OSError"),
    ("mat73_rank_3", hdf5("cube73.mat", data=np.zeros((2, 3, 50)), sample_rate=[[50.0]]),
     DataError, r"cube73.mat: data must have at most 2 dimension\(s\)"),
    ("mat73_no_variables", hdf5("bare73.mat"), DataError, r"bare73.mat: holds no channels"),
    # --- UFF 58
    ("uff_last_set_truncated", written("cut.uff", cut_in_last_uff_set), DataError,
     r"cut.uff: data set 3 \(channel 'c'\) is incomplete: the file ends before its end tag"),
    ("uff_samples_missing", written("short.uff", drop_from_first_uff_set), DataError,
     r"short.uff: channel 'a': the header declares 40 samples, the data set holds 39"),
    ("uff_empty_file", raw("empty.uff", b""), DataError,
     r"empty.uff: holds no UFF type-58 data set"),
    ("uff_garbage", raw("junk.uff", b"\x00\xff" * 50), DataError,
     r"junk.uff: holds no UFF type-58 data set"),
    # --- any format
    ("record_is_a_directory", folder("rec.csv"), DataError,
     r"rec.csv: is a directory, expected a record file"),
    ("record_missing", missing("gone.npz"), DataError, r"gone.npz: record file not found"),
    ("unknown_suffix", text("rec.xyz", "time,a\n0,1\n"), ParameterError,
     r"cannot tell the format of 'rec.xyz' from its suffix"),
    ("csv_read_as_npz", text("table.npz", "time,a\n0,1\n0.1,2\n"), DataError,
     r"table.npz: cannot be read as an NPZ file"),
]


@pytest.mark.parametrize("make, error, match", [c[1:] for c in RECORD_CASES],
                         ids=[c[0] for c in RECORD_CASES])
def test_bad_record_file(tmp_path, make, error, match):
    path = make(tmp_path)
    with pytest.raises(error, match=match) as caught:
        read_record(path)
    assert path.name in str(caught.value)


SAMPLE_CASES = [
    ("csv_nan_sample", text("nan.csv", "time,a,b\n0,1,2\n0.1,3,nan\n0.2,5,6\n"),
     r"nan.csv: channel 'b': NaN sample at sample index 1"),
    ("csv_inf_sample", text("inf.csv", "time,a\n0,1\n0.1,inf\n0.2,5\n"),
     r"inf.csv: channel 'a': infinite sample at sample index 1"),
    ("npz_inf_sample", npz("inf.npz", data=[[1.0, 2.0, -np.inf]], sample_rate=10.0),
     r"inf.npz: channel 'ch0': infinite sample at sample index 2"),
    ("mat_nan_sample", mat("nan.mat", data=np.array([[1.0], [np.nan], [2.0]]), sample_rate=10.0),
     r"nan.mat: channel 'ch0': NaN sample at sample index 1"),
]


@pytest.mark.parametrize("make, match", [c[1:] for c in SAMPLE_CASES],
                         ids=[c[0] for c in SAMPLE_CASES])
def test_non_finite_samples_name_file_channel_and_index(tmp_path, make, match):
    # read_record reads the samples as they are; check_record refuses them (docs: theory, Welch PSDs, filters and convergence).
    with pytest.raises(DataError, match=match):
        check_record(read_record(make(tmp_path)))


# -------------------------------------------------------------------------------- case files
BEAM = """name = "beam"
[structure]
type = "simply_supported_beam"
span = 50.0
width = 3.0
frequency = 2.0
damping_ratio = 0.005
modal_mass = 50e3
outputs = { midspan = 25.0 }
[crowd]
density = 0.5
"""


def case(name, old=None, new="", base=BEAM):
    content = base if old is None else base.replace(old, new)
    assert content != base or old is None, "the case must change the base text"
    return text(name, content)


def example_case(name, old, new):
    """The Eeklo-like example with its modal files, one line changed."""
    def make(tmp_path):
        for other in ("eeklo_like_modes.csv", "eeklo_like_shapes.csv", "eeklo_like_outputs.csv"):
            shutil.copy(EXAMPLES / other, tmp_path / other)
        content = (EXAMPLES / "eeklo_like.toml").read_text(encoding="utf-8")
        assert old in content
        path = tmp_path / name
        path.write_text(content.replace(old, new), encoding="utf-8")
        return path
    return make


CASE_CASES = [
    ("case_binary", raw("bin.toml", bytes(range(256))), DataError,
     r"bin.toml: is not a TOML case file: not UTF-8 text"),
    ("case_empty", text("empty.toml", ""), DataError, r"empty.toml: structure is required"),
    ("case_not_toml", text("bad.toml", "density = [0.5"), DataError, r"bad.toml: not valid TOML"),
    ("case_misspelt_key", case("typo.toml", "density = 0.5", "density = 0.5\ndensty = 0.6"),
     DataError, r"typo.toml: unknown key\(s\) \['crowd.densty'\] \('crowd.densty': did you mean "
                r"'crowd.density'\?\)"),
    ("case_misspelt_section", case("sect.toml", "[crowd]", "[crwod]"), DataError,
     r"sect.toml: crowd is required \(found 'crwod': misspelt\?\)"),
    ("case_unknown_key", case("unknown.toml", "name = \"beam\"", "name = \"beam\"\ncolour = 1"),
     DataError, r"unknown.toml: unknown key\(s\) \['colour'\]"),
    ("case_missing_key", case("nowidth.toml", "width = 3.0\n", ""), DataError,
     r"nowidth.toml: structure.width is required"),
    ("case_wrong_type", case("type.toml", "density = 0.5", "density = \"high\""), DataError,
     r"type.toml: crowd.density must be a number, got 'high'"),
    ("case_wrong_table_type", case("tbl.toml", base="crowd = 3\n" + BEAM.split("[crowd]")[0]),
     DataError, r"tbl.toml: crowd must be a table, got 3"),
    ("case_negative_sample_rate", case("negsr.toml", base=BEAM + "[measurement]\n"
                                       "sample_rate = -100\n"), DataError,
     r"negsr.toml: measurement.sample_rate must be > 0, got -100"),
    ("case_zero_sample_rate", case("zerosr.toml", base=BEAM + "[measurement]\n"
                                   "sample_rate = 0\n"), DataError,
     r"zerosr.toml: measurement.sample_rate must be > 0, got 0"),
    ("case_negative_seed", case("seed.toml", "name = \"beam\"", "name = \"beam\"\nseed = -1"),
     DataError, r"seed.toml: seed must be a non-negative integer, got -1"),
    ("case_bad_units", case("units.toml", base=BEAM + "[measurement]\nunits = \"mm\"\n"),
     DataError, r"units.toml: measurement.units must be 'm/s2', 'g', 'mg' or 'mm/s2', got 'mm'"),
    ("case_bad_time_frame", case("frame.toml", base=BEAM + "[measurement]\ntime_frame = 5\n"),
     DataError, r"frame.toml: measurement.time_frame must be a pair"),
    ("case_is_a_directory", folder("dir.toml"), DataError,
     r"dir.toml: is a directory, expected a case file"),
    ("case_missing", missing("gone.toml"), DataError, r"gone.toml: case file not found"),
    ("case_modal_table_is_a_directory",
     example_case("modes_dir.toml", "modal_table = \"eeklo_like_modes.csv\"",
                  "modal_table = \".\""), DataError,
     r"modes_dir.toml: structure.modal_table names a directory, expected a file"),
    ("case_modal_table_missing",
     example_case("modes_gone.toml", "modal_table = \"eeklo_like_modes.csv\"",
                  "modal_table = \"nope.csv\""), DataError,
     r"modes_gone.toml: structure.modal_table names a file that does not exist: 'nope.csv'"),
    ("case_output_position_text", case("pos.toml", "midspan = 25.0", "midspan = \"middle\""),
     DataError, r"pos.toml: structure.outputs\['midspan'\] must be a position x \[m\], "
                r"got 'middle'"),
]


@pytest.mark.parametrize("make, error, match", [c[1:] for c in CASE_CASES],
                         ids=[c[0] for c in CASE_CASES])
def test_bad_case_file(tmp_path, make, error, match):
    path = make(tmp_path)
    with pytest.raises(error, match=match) as caught:
        load_case(path)
    assert path.name in str(caught.value)


def test_case_record_that_is_a_directory(tmp_path):
    # measurement.files names a folder: named as the mix-up it is (issue 9).
    path = tmp_path / "c.toml"
    path.write_text(BEAM + "[measurement]\nfiles = [\"records\"]\n", encoding="utf-8")
    (tmp_path / "records").mkdir()
    with pytest.raises(DataError, match=r"c.toml: measurement.files\[0\] names a directory, "
                                        r"expected a file"):
        load_measurement(load_case(path))


# ------------------------------------------------------------------------------ modal tables
MODES = "mode,frequency,damping_ratio,modal_mass\nmode_1,2.0,0.005,50000\n"
SHAPES = "position,mode_1\n0,0\n25,1\n50,0\n"


def modal(which, content):
    """The three modal CSV files, one of them (``which``) replaced by ``content``."""
    def make(tmp_path):
        files = {"m.csv": MODES, "s.csv": SHAPES}
        for name, value in files.items():
            (tmp_path / name).write_text(value, encoding="utf-8")
        path = tmp_path / which
        if isinstance(content, bytes):
            path.write_bytes(content)
        elif content is None:
            path.unlink()
            path.mkdir()
        else:
            path.write_text(content, encoding="utf-8")
        return path
    return make


MODAL_CASES = [
    ("modal_not_utf8", modal("m.csv", b"frequency\xff\n"), r"m.csv: cannot be read as a CSV file"),
    ("modal_misspelt_column", modal("m.csv", MODES.replace("frequency", "frequncy")),
     r"m.csv: missing column\(s\) \['frequency'\] \('frequncy': did you mean 'frequency'\?\)"),
    ("modal_text_cell", modal("m.csv", MODES.replace("50000", "heavy")),
     r"m.csv: row 1, column 'modal_mass' must hold a finite number, got 'heavy'"),
    ("modal_inf_cell", modal("m.csv", MODES.replace("2.0", "inf")),
     r"m.csv: row 1, column 'frequency' must hold a finite number, got 'inf'"),
    ("modal_empty", modal("m.csv", ""), r"m.csv: must hold a header line and at least one row"),
    ("modal_ragged_row", modal("m.csv", MODES + "mode_2,3.0\n"),
     r"m.csv: row 2 has 2 field\(s\), the header has 4"),
    ("shapes_without_position", modal("s.csv", SHAPES.replace("position", "x")),
     r"s.csv: missing column\(s\) \['position'\]"),
    ("shapes_too_many_modes", modal("s.csv", "position,a,b\n0,0,0\n50,0,0\n"),
     r"s.csv: must have one column per mode of m.csv \(1\) besides 'position' and 'lane', got 2"),
    ("modal_table_is_a_directory", modal("m.csv", None),
     r"m.csv: is a directory, expected a modal CSV file"),
]


@pytest.mark.parametrize("make, match", [c[1:] for c in MODAL_CASES],
                         ids=[c[0] for c in MODAL_CASES])
def test_bad_modal_file(tmp_path, make, match):
    path = make(tmp_path)
    with pytest.raises(DataError, match=match) as caught:
        read_modal_model(tmp_path / "m.csv", tmp_path / "s.csv", width=3.0,
                         outputs={"mid": 25.0})
    assert path.name in str(caught.value)


def test_catalogue_size():
    # Issue 9 asks for >= 80 bad-input cases across API, files, case files and CLI; this file's
    # share (files and case files) is at least 45.
    total = len(RECORD_CASES) + len(SAMPLE_CASES) + len(CASE_CASES) + 1 + len(MODAL_CASES)
    assert total >= 45


# ------------------------------------------------------------------ the faults of issue 9
def test_fault_truncated_uff_no_longer_loses_its_last_channel(tmp_path):
    # Issue 9, fault 5: "a truncated UFF file loses its last channel". Old code: a record with
    # channels ('a', 'b') and no error. Now: refused, naming the incomplete data set.
    path = written("cut.uff", cut_in_last_uff_set)(tmp_path)
    with pytest.raises(DataError, match=r"cut.uff: data set 3 \(channel 'c'\) is incomplete"):
        read_record(path)


def test_fault_3d_npz_is_no_longer_interleaved(tmp_path):
    # Issue 9, fault 5: "a 3-D NPZ array becomes interleaved channels". Old code: 2 channels of
    # 150 samples mixing the 3 × 50 planes. Now: refused, naming the variable and its shape.
    path = tmp_path / "cube.npz"
    np.savez(path, data=np.arange(300.0).reshape(2, 3, 50), sample_rate=50.0)
    with pytest.raises(DataError, match=r"cube.npz: data must have at most 2 dimension"):
        read_record(path)


def test_fault_binary_case_file_is_a_data_error(tmp_path):
    # Issue 9, fault 6: "a binary case file too" reached the user as a UnicodeDecodeError.
    path = tmp_path / "photo.toml"
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)))
    with pytest.raises(DataError, match=r"photo.toml: is not a TOML case file") as caught:
        load_case(path)
    assert not isinstance(caught.value, UnicodeDecodeError)


def mat_element(kind, payload):
    """One MAT v5 data element: type, size, payload padded to 8 bytes (MAT-File Format)."""
    return struct.pack("<II", kind, len(payload)) + payload + b"\0" * (-len(payload) % 8)


def test_fault_mat_v5_that_crashed_scipy_is_refused_first(tmp_path):
    # Found by the fuzz tests of issue 9, fault 6: a double array whose data element claims the
    # type miMATRIX (14) makes scipy 1.17's loadmat raise ZeroDivisionError, and after a few
    # such files crash the interpreter (segmentation fault). The file is now walked before
    # scipy sees it and refused, naming the variable.
    header = b"MATLAB 5.0 MAT-file".ljust(116) + b"\0" * 8 + struct.pack("<H", 0x0100) + b"IM"
    matrix = (mat_element(6, struct.pack("<II", 6, 0)) + mat_element(5, struct.pack("<ii", 1, 4))
              + struct.pack("<I", (4 << 16) | 1) + b"data" + mat_element(14, b"\0" * 32))
    path = tmp_path / "crafted.mat"
    path.write_bytes(header + mat_element(14, matrix))
    for _ in range(20):   # one read was enough to crash now and then; many reads, no crash
        with pytest.raises(DataError, match=r"crafted.mat: variable 'data': real part has "
                                            r"element type 14"):
            read_record(path, sample_rate=10.0)


SECRET = "root:x:0:0:SECRET-PASSWORD-HASH:/root:/bin/bash"


@pytest.mark.parametrize("reader", ["record", "modal_table", "case_record", "case_channels"])
def test_fault_messages_never_print_a_files_lines(tmp_path, reader):
    # Issue 9, fault 3: "an error message prints the first lines of any file a case names".
    # Old code: the CSV reader echoed the header line ({header}) and numpy's message with the
    # offending row; the modal reader printed "found [header]". Now: file, rule, short token.
    secret = tmp_path / "passwd.csv"
    secret.write_text(SECRET + "\n" + SECRET.replace("root", "daemon") + "\n", encoding="utf-8")
    with pytest.raises(DataError) as caught:
        if reader == "record":
            read_record(secret, sample_rate=100.0)
        elif reader == "modal_table":
            (tmp_path / "s.csv").write_text(SHAPES, encoding="utf-8")
            read_modal_model(secret, tmp_path / "s.csv", width=3.0, outputs={"mid": 25.0})
        elif reader == "case_channels":
            # A file that parses (a header line, numbers below): the channel map names a
            # channel it lacks, and the message lists the file's channel names, shortened.
            secret.write_text(SECRET + "\n1\n2\n3\n", encoding="utf-8")
            path = tmp_path / "c.toml"
            path.write_text(BEAM + "[measurement]\nfiles = [\"passwd.csv\"]\nsample_rate = 100\n"
                            "channels = { midspan = \"acc\" }\n", encoding="utf-8")
            load_measurement(load_case(path))
        else:
            path = tmp_path / "c.toml"
            path.write_text(BEAM + "[measurement]\nfiles = [\"passwd.csv\"]\nsample_rate = 100\n",
                            encoding="utf-8")
            load_measurement(load_case(path))
    message = str(caught.value)
    assert "passwd.csv" in message
    # At most one short quoted token (<= 40 characters, quotes included) of the file may appear:
    # never a whole line.
    for line in secret.read_text(encoding="utf-8").splitlines():
        match = SequenceMatcher(None, message, line).find_longest_match()
        assert match.size <= 38, message
