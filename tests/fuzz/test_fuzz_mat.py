"""Fuzzing the MATLAB readers, v5 (scipy.io) and v7.3 (HDF5 through h5py): only crowdvib errors
may come out (issue 9, fault 6: MatReadError, zlib.error, IndexError, h5py's OSError escaped)."""

import pytest
from fuzzing import FUZZ, FUZZ_RANDOM, mutations, random_bytes, read_damaged, small_record
from hypothesis import given
from hypothesis import strategies as st

from crowdvib import write_record

pytest.importorskip("h5py")


@pytest.fixture(scope="module", params=["mat", "mat73"])
def fmt(request):
    return request.param


@pytest.fixture(scope="module")
def good(tmp_path_factory, fmt):
    """A MAT-file crowdvib wrote in the format (the seed of every mutation)."""
    path = write_record(small_record(), tmp_path_factory.mktemp("good") / "record.mat", format=fmt)
    return path.read_bytes()


@pytest.fixture(scope="module")
def target(tmp_path_factory, fmt):
    return tmp_path_factory.mktemp(f"fuzz_{fmt}") / "damaged.mat"


def test_the_seed_file_reads_back(good, target, fmt):
    # Reference: the record written by small_record(); v5 and v7.3 are told apart by the header.
    record = read_damaged(target, good)
    assert record is not None and record.channel_names == ("main", "side", "deck")


@FUZZ_RANDOM
@given(content=random_bytes)
def test_random_bytes(target, fmt, content):
    read_damaged(target, content, format=fmt)


@FUZZ_RANDOM
@given(content=random_bytes)
def test_random_bytes_behind_a_matlab_header(target, good, fmt, content):
    # Keep the 128-byte header so the bytes reach scipy's / h5py's parser proper.
    read_damaged(target, good[:128] + content, format=fmt)


@FUZZ
@given(data=st.data())
def test_damaged_file(good, target, fmt, data):
    read_damaged(target, data.draw(mutations(good)), format=fmt)
