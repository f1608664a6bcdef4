"""Fuzzing behind a valid MATLAB header, v5 (scipy.io) and v7.3 (HDF5 through h5py), so the bytes
reach the parsers proper (the generic cases are in test_fuzz_records.py; issue 9, fault 6)."""

import pytest
from fuzzing import FUZZ_RANDOM, random_bytes, read_damaged, small_record
from hypothesis import given

from crowdvib import write_record

pytestmark = pytest.mark.fuzz

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


@FUZZ_RANDOM
@given(content=random_bytes)
def test_random_bytes_behind_a_matlab_header(target, good, fmt, content):
    # Keep the 128-byte header so the bytes reach scipy's / h5py's parser proper.
    read_damaged(target, good[:128] + content, format=fmt)

