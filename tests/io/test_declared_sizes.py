"""A record file's declared sizes are checked against the file before anything is allocated
(issue 35 §1): a 2.5 KB NPZ or MAT v7.3 (HDF5) file declaring 10.7 GB made crowdvib allocate
10.7 GB. Each hostile file is built here, tiny, and refused at once by a DataError naming the
file, the array, its declared shape and the rule (crowdvib._resources.check_declared_size)."""

import io
import time
import zipfile
import zlib

import numpy as np
import pytest
from numpy.lib import format as npy

import crowdvib._resources
from crowdvib import DataError, read_record

#: 2 channels × 670 million samples of float64: 10.72 GB.
SHAPE = (2, 670_000_000)
DECLARED = "declares shape \\(2, 670000000\\) × 8 B = 10720000000 bytes"


def _npy(shape, payload=b"\0" * 16):
    """A .npy member: a header declaring ``shape`` (float64), then ``payload``."""
    buffer = io.BytesIO()
    npy.write_array_header_1_0(buffer, {"descr": "<f8", "fortran_order": False, "shape": shape})
    return buffer.getvalue() + payload


def _refused_at_once(path, message):
    started = time.perf_counter()
    with pytest.raises(DataError, match=f"{path.name}: {message}"):
        read_record(path, sample_rate=100.0)
    assert time.perf_counter() - started < 2.0


@pytest.mark.parametrize("method", [zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED])
def test_an_npz_declaring_more_than_it_holds_is_refused(tmp_path, method):
    path = tmp_path / "lie.npz"
    with zipfile.ZipFile(path, "w", compression=method) as archive:
        archive.writestr("data.npy", _npy(SHAPE))
        archive.writestr("sample_rate.npy", _npy(()))
    assert path.stat().st_size < 2500
    _refused_at_once(path, f"array 'data' {DECLARED}, but the file holds 16 bytes for it: its "
                           "declared size is false")


def test_an_npz_whose_zip_directory_lies_too_is_refused(tmp_path):
    # The zip's own sizes of the member made to agree with its header (2.08 GB): a member
    # stored as it is still holds no more than the file.
    path = tmp_path / "lie.npz"
    shape = (2, 130_000_000)
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("data.npy", _npy(shape))
    member = _npy(shape)
    true = len(member).to_bytes(4, "little")
    false = (len(member) - 16 + 2_080_000_000).to_bytes(4, "little")
    data = path.read_bytes()
    assert data.count(true + true) == 2                   # local header and central directory
    path.write_bytes(data.replace(true + true, false + false))
    with zipfile.ZipFile(path) as archive:
        assert archive.getinfo("data.npy").file_size > 2e9   # the lie is read back
        try:
            archive.open("data.npy").close()
            zip_sees_it = False
        except zipfile.BadZipFile:
            # Newer zipfile modules (CPython's fix for overlapping members, in 3.13 here) refuse
            # a member whose stored size reaches past the next record themselves: still refused
            # at once, by a DataError naming the file, before crowdvib reads the array's header.
            zip_sees_it = True
    if zip_sees_it:
        _refused_at_once(path, "cannot be read as an NPZ file \\(BadZipFile: \"Overlapped entries")
    else:
        _refused_at_once(path, "array 'data' declares shape \\(2, 130000000\\) × 8 B = "
                               "2080000000 bytes, but the file holds \\d+ bytes for it")


def test_an_npz_bomb_is_refused_by_the_memory_available(tmp_path, monkeypatch):
    # Honest sizes, compressed 1000:1: allowed by the file, refused by the memory (made small
    # here, rather than the test allocating gigabytes).
    path = tmp_path / "zeros.npz"
    np.savez_compressed(path, data=np.zeros((2, 500_000)), sample_rate=100.0)
    assert path.stat().st_size < 20_000
    monkeypatch.setattr(crowdvib._resources, "available_memory", lambda: 4e6)
    _refused_at_once(path, "array 'data' declares shape \\(2, 500000\\) × 8 B = 8000000 bytes, "
                           "more than half the 0.004 GB of memory available")


def test_the_deflate_bound_refuses_what_no_compressed_member_can_expand_to():
    with pytest.raises(DataError, match="more than its 100 compressed bytes can expand to "
                                        "\\(1032:1\\)"):
        crowdvib._resources.check_declared_size("f.npz: ", "array 'x'", (200_000,), 8,
                                             compressed=100)
    assert crowdvib._resources.check_declared_size("f.npz: ", "array 'x'", (1000,), 8,
                                                compressed=100, stored=8000) == 8000


@pytest.mark.parametrize("layout", ["contiguous", "gzip"])
def test_a_mat73_declaring_more_than_it_holds_is_refused(tmp_path, layout):
    h5py = pytest.importorskip("h5py")
    path = tmp_path / "lie.mat"
    options = {} if layout == "contiguous" else {"chunks": (1, 1_000_000), "compression": "gzip"}
    with h5py.File(path, "w") as handle:
        handle.create_dataset("data", shape=SHAPE, dtype="f8", **options)   # never written
        handle.create_dataset("sample_rate", data=100.0)
    assert path.stat().st_size < 2500
    rule = ("but the file holds 0 bytes for it" if layout == "contiguous"
            else "more than its 0 compressed bytes can expand to")
    _refused_at_once(path, f"variable 'data' {DECLARED}, {rule}")


def test_honest_files_are_read_as_before(tmp_path):
    h5py = pytest.importorskip("h5py")
    data = np.random.default_rng(1).normal(size=(2, 5000))
    np.savez_compressed(tmp_path / "a.npz", data=data, sample_rate=100.0)
    np.savez(tmp_path / "b.npz", data=data, sample_rate=100.0)
    with h5py.File(tmp_path / "c.mat", "w") as handle:
        handle.create_dataset("data", data=data, chunks=(1, 1000), compression="gzip")
        handle.create_dataset("sample_rate", data=100.0)
    for name in ("a.npz", "b.npz", "c.mat"):
        record = read_record(tmp_path / name, sample_rate=100.0)
        assert np.array_equal(np.asarray(record.data), data), name


def test_a_mat_v5_compressed_element_is_inflated_no_further_than_the_memory(tmp_path,
                                                                            monkeypatch):
    from scipy.io import savemat

    path = tmp_path / "zeros.mat"
    savemat(path, {"data": np.zeros((2, 500_000)), "sample_rate": 100.0}, do_compression=True)
    assert path.stat().st_size < 50_000
    monkeypatch.setattr(crowdvib._resources, "available_memory", lambda: 4e6)
    with pytest.raises(DataError, match="zeros.mat: a compressed element of \\d+ bytes expands "
                                        "past 2000000 bytes"):
        read_record(path, sample_rate=100.0)
    assert len(zlib.compress(b"\0" * 8_000_000)) < 50_000          # why it could
