"""Measured records: round trips of every format and every bad-record check (issue 4)."""

import numpy as np
import pytest

from crowdvib.errors import DataError, DataWarning, ParameterError
from crowdvib.io.records import (Record, check_record, convert_units, merge_records, read_record,
                              write_record)

FORMATS = [("csv", "record.csv"), ("npz", "record.npz"), ("mat", "record.mat"),
           ("mat73", "record_v73.mat"), ("uff", "record.uff")]


@pytest.fixture
def record(rng):
    data = rng.normal(scale=0.05, size=(2, 1500))
    return Record(data=data, sample_rate=100.0, channel_names=("main_span", "side_span"),
                  start_time=2.5)


def needs_extra(fmt):
    """Skip when the optional reader of a format is missing (h5py: mat73, pyuff: uff)."""
    module = {"mat73": "h5py", "uff": "pyuff"}.get(fmt)
    if module:
        pytest.importorskip(module)


@pytest.mark.parametrize("fmt, name", FORMATS)
def test_round_trip_float64(record, tmp_path, fmt, name):
    needs_extra(fmt)
    path = write_record(record, tmp_path / name, format=fmt)
    back = read_record(path)   # the format is told from the suffix (and the v7.3 header)
    assert back.channel_names == record.channel_names
    assert back.sample_rate == pytest.approx(100.0, rel=1e-12)
    assert back.start_time == pytest.approx(2.5, abs=1e-9)
    np.testing.assert_allclose(back.data, record.data, rtol=1e-15, atol=1e-15)
    assert back.source == str(path)
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]   # no temporary files left


@pytest.mark.parametrize("fmt, name", FORMATS)
def test_round_trip_float32(record, tmp_path, fmt, name):
    needs_extra(fmt)
    back = read_record(write_record(record, tmp_path / name, format=fmt, dtype="float32"))
    np.testing.assert_allclose(back.data, record.data, rtol=1e-6, atol=1e-9)


def test_mat73_file_has_matlab_header(record, tmp_path):
    h5py = pytest.importorskip("h5py")
    path = write_record(record, tmp_path / "r.mat", format="mat73")
    assert path.read_bytes()[:10] == b"MATLAB 7.3"
    assert h5py.is_hdf5(path)   # a v7.3 MAT-file is an HDF5 file with a 512-byte user block


def test_units_g_are_converted_with_standard_gravity(tmp_path):
    path = tmp_path / "g.csv"
    path.write_text("time,a\n0,0.1\n0.01,-0.2\n0.02,0.0\n")
    record = read_record(path, units="g")
    # g = 9.81 m/s² (docs: theory, Conventions)
    np.testing.assert_allclose(record.data[0], [0.981, -1.962, 0.0])
    np.testing.assert_allclose(convert_units([1.0], "m/s2"), [1.0])
    with pytest.raises(ParameterError, match="units must be 'm/s2', 'g', 'mg' or 'mm/s2'"):
        read_record(path, units="mm/s")


def test_csv_without_time_column_needs_a_sample_rate(tmp_path):
    path = tmp_path / "no_time.csv"
    path.write_text("acc1,acc2\n1,2\n3,4\n5,6\n")
    with pytest.raises(DataError, match="no time stamps and no sample rate"):
        read_record(path)
    record = read_record(path, sample_rate=200.0, channels={"main": "acc2"})
    assert record.channel_names == ("main",)
    np.testing.assert_allclose(record.data, [[2, 4, 6]])
    assert record.sample_rate == 200.0


def test_channel_mapping_names_a_missing_channel(record, tmp_path):
    path = write_record(record, tmp_path / "r.npz")
    with pytest.raises(DataError, match=r"r.npz: channel 'nope' \(for 'main'\) is not in"):
        read_record(path, channels={"main": "nope"})


# ------------------------------------------------------------------------ bad records
def test_nan_sample_names_file_channel_and_index(tmp_path):
    path = tmp_path / "nan.csv"
    path.write_text("time,a,b\n0,1,1\n0.01,1,nan\n0.02,1,1\n")
    record = read_record(path)
    with pytest.raises(DataError, match=r"nan.csv: channel 'b': NaN sample at sample index 1"):
        check_record(record)


def test_infinite_sample(tmp_path):
    path = tmp_path / "inf.npz"
    np.savez(path, data=np.array([[0.0, 1.0, np.inf, 2.0]]), channel_names=np.array(["a"]),
             sample_rate=10.0)
    with pytest.raises(DataError, match=r"inf.npz: channel 'a': infinite sample at sample index 2"):
        check_record(read_record(path))


def test_non_uniform_time_stamps(tmp_path):
    path = tmp_path / "jitter.csv"
    path.write_text("time,a\n0,1\n0.01,2\n0.02,3\n0.0315,4\n0.04,5\n0.05,6\n")
    with pytest.raises(DataError, match=r"jitter.csv: time stamps must be uniform: the step "
                                        r"before sample index 3"):
        read_record(path)


def test_decreasing_time_stamps(tmp_path):
    path = tmp_path / "back.csv"
    path.write_text("time,a\n0,1\n0.01,2\n0.005,3\n0.03,4\n")
    with pytest.raises(DataError, match=r"back.csv: time stamps must increase: sample index 2"):
        read_record(path)


def test_gap_in_time_stamps(tmp_path):
    time = np.concatenate([np.arange(10), np.arange(13, 20)]) * 0.01
    np.savez(tmp_path / "gap.npz", data=np.ones((1, time.size)), channel_names=np.array(["a"]),
             time=time)
    with pytest.raises(DataError, match=r"gap.npz: gap in the time stamps before sample index 10"
                                        r".*about 3 sample\(s\) missing"):
        read_record(tmp_path / "gap.npz")


def test_channels_of_different_length(tmp_path):
    np.savez(tmp_path / "len.npz", a=np.zeros(100), b=np.zeros(98), sample_rate=50.0)
    with pytest.raises(DataError, match=r"len.npz: channel 'b': has 98 samples, channel 'a' has "
                                        r"100.*from sample index 98"):
        read_record(tmp_path / "len.npz")


def test_channels_of_different_sample_rate(tmp_path):
    pytest.importorskip("pyuff")
    fast = Record(np.zeros((1, 200)), 100.0, ["a"])
    slow = Record(np.zeros((1, 200)), 50.0, ["b"])
    with pytest.raises(DataError, match=r"channel 'b': sample rate 50 Hz differs from 100 Hz"):
        merge_records([fast, slow])
    # Within one UFF file each channel carries its own Δt.
    write_record(fast, tmp_path / "a.uff")
    import pyuff
    dataset = pyuff.UFF(str(tmp_path / "a.uff")).read_sets()
    dataset.update(id1="b", abscissa_inc=0.02, x=np.arange(200) * 0.02)
    pyuff.UFF(str(tmp_path / "a.uff")).write_sets(dataset, mode="add")
    with pytest.raises(DataError, match=r"a.uff: channel 'b': sample rate 50 Hz differs from "
                                        r"100 Hz of channel 'a'"):
        read_record(tmp_path / "a.uff")


def test_flat_stretch_warns(rng):
    data = rng.normal(size=(2, 1000))
    data[1, 300:500] = 0.123   # a 2 s logger hold on the second channel
    record = Record(data, 100.0, ["a", "b"], source="/data/flat.npz")
    with pytest.warns(DataWarning, match=r"flat.npz: channel 'b': flat stretch of 200 identical "
                                         r"samples .* from sample index 300"):
        check_record(record)


def test_clipped_stretch_warns(rng):
    data = np.sin(np.linspace(0, 20 * np.pi, 2000))
    data = np.clip(data, -0.9, 0.9)   # a saturated sensor
    record = Record(data[np.newaxis], 100.0, ["a"], source="clip.csv")
    with pytest.warns(DataWarning, match=r"clip.csv: channel 'a': looks clipped: \d+ consecutive "
                                         r"samples at the extreme"):
        check_record(record)


def test_sample_rate_too_low_for_band(rng):
    record = Record(rng.normal(size=(1, 500)), 12.0, ["a"], source="slow.mat")
    with pytest.raises(DataError, match=r"slow.mat: sample rate 12 Hz is too low for the band up "
                                        r"to 8 Hz"):
        check_record(record, band=(2.5, 8.0))
    check_record(Record(rng.normal(size=(1, 500)), 25.0, ["a"]), band=(2.5, 8.0))


def test_clean_record_passes_silently(record):
    assert check_record(record, band=(0.0, 10.0)) is record


def test_unknown_suffix_and_missing_file(tmp_path, record):
    with pytest.raises(ParameterError, match="cannot tell the format"):
        read_record(tmp_path / "x.bin")
    with pytest.raises(DataError, match="record file not found"):
        read_record(tmp_path / "missing.npz")
    with pytest.raises(ParameterError, match="dtype must be"):
        write_record(record, tmp_path / "x.npz", dtype="int16")


def test_record_frame_and_select(record):
    part = record.frame(3.0, 5.0)
    assert part.n_samples == 200 and part.start_time == pytest.approx(3.0)
    np.testing.assert_array_equal(part.data, record.data[:, 50:250])
    assert record.select(["side_span"]).channel_names == ("side_span",)
    with pytest.raises(DataError, match="time frame"):
        record.frame(100.0, 200.0)


def test_mat73_as_matlab_writes_it(tmp_path):
    # MATLAB's `save -v7.3` layout: a column vector appears as a (1, n) dataset, a cell array of
    # char rows is a dataset of object references to uint16 char datasets. Here one variable
    # per channel, listed in a cell array, and the sample rate given by the caller.
    h5py = pytest.importorskip("h5py")
    path = tmp_path / "matlab.mat"
    with h5py.File(path, "w", userblock_size=512) as handle:
        refs = handle.create_group("#refs#")
        names = []
        for i, text in enumerate(["A1", "A2"]):
            channel = handle.create_dataset(text, data=(np.arange(6.0) + 10 * i)[np.newaxis])
            channel.attrs["MATLAB_class"] = np.bytes_("double")
            item = refs.create_dataset(f"n{i}", data=np.array([[ord(c)] for c in text],
                                                                dtype=np.uint16))
            item.attrs["MATLAB_class"] = np.bytes_("char")
            names.append(item.ref)
        cell = handle.create_dataset("channel_names", data=np.array([names]).T,
                                     dtype=h5py.ref_dtype)
        cell.attrs["MATLAB_class"] = np.bytes_("cell")
    with open(path, "r+b") as handle:
        handle.write(b"MATLAB 7.3 MAT-file")
    record = read_record(path, sample_rate=50.0, channels={"main_span": "A2"})
    assert record.channel_names == ("main_span",) and record.sample_rate == 50.0
    np.testing.assert_array_equal(record.data, [np.arange(6.0) + 10])


def test_mat73_cell_channel_names_with_data_matrix(tmp_path):
    h5py = pytest.importorskip("h5py")
    path = tmp_path / "m.mat"
    with h5py.File(path, "w", userblock_size=512) as handle:
        handle.create_dataset("data", data=np.arange(12.0).reshape(2, 6))
        refs = handle.create_group("#refs#")
        names = []
        for i, text in enumerate(["A1", "A2"]):
            names.append(refs.create_dataset(f"n{i}", data=np.array(
                [[ord(c)] for c in text], dtype=np.uint16)).ref)
        cell = handle.create_dataset("channel_names", data=np.array([names]).T,
                                     dtype=h5py.ref_dtype)
        cell.attrs["MATLAB_class"] = np.bytes_("cell")
        handle.create_dataset("sample_rate", data=np.array([[50.0]]))
    with open(path, "r+b") as handle:
        handle.write(b"MATLAB 7.3 MAT-file")
    record = read_record(path)
    assert record.channel_names == ("A1", "A2") and record.sample_rate == 50.0
    np.testing.assert_array_equal(record.data, np.arange(12.0).reshape(2, 6))


def test_mat_v5_single_column_vector_and_matrix_without_names(tmp_path):
    from scipy.io import savemat
    savemat(tmp_path / "vector.mat", {"data": np.arange(5.0), "sample_rate": 10.0})
    assert read_record(tmp_path / "vector.mat").data.shape == (1, 5)
    savemat(tmp_path / "matrix.mat", {"data": np.arange(10.0).reshape(5, 2), "sample_rate": 10.0})
    record = read_record(tmp_path / "matrix.mat")   # one column per channel, as in MATLAB
    assert record.channel_names == ("ch0", "ch1")
    np.testing.assert_array_equal(record.data, np.arange(10.0).reshape(5, 2).T)


def test_csv_comment_lines_carry_unit_and_sample_rate(tmp_path):
    path = tmp_path / "logger.csv"
    path.write_text("# logger export\n# unit = g\n# sample_rate = 50\nacc\n0.1\n0.2\n0.3\n")
    record = read_record(path)
    assert record.sample_rate == 50.0
    np.testing.assert_allclose(record.data[0], [0.981, 1.962, 2.943])


def test_mat_v5_skips_variables_of_classes_it_does_not_read(tmp_path):
    # A sparse matrix beside the record is skipped unread (crowdvib.io._matv5 walks only the
    # classes a record uses); the record is the one saved (reference: the arrays written here).
    from scipy.io import savemat
    from scipy.sparse import identity

    path = tmp_path / "mixed.mat"
    samples = np.array([[0.1], [-0.2], [0.3], [0.0]])
    savemat(path, {"data": samples, "sample_rate": 20.0, "stiffness": identity(3, format="csc")})
    record = read_record(path)
    np.testing.assert_array_equal(record.data, samples.T)
    assert record.channel_names == ("ch0",) and record.sample_rate == 20.0
    savemat(path, {"stiffness": identity(3, format="csc")})
    with pytest.raises(DataError, match=r"mixed.mat: holds no channels"):
        read_record(path)
