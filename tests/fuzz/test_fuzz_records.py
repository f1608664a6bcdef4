"""Fuzzing every record reader (CSV, NPZ, MAT v5, MAT v7.3 through h5py, UFF 58 through pyuff):
only crowdvib errors may come out (issue 9, fault 6: BadZipFile, zlib.error, EOFError, MatReadError,
h5py's OSError, UnicodeDecodeError, IndexError … escaped before)."""

import pytest
from fuzzing import FUZZ, FUZZ_RANDOM, mutations, random_bytes, read_damaged, small_record
from hypothesis import given
from hypothesis import strategies as st

from crowdvib import write_record

#: format → file name crowdvib writes it under
FILES = {"csv": "record.csv", "npz": "record.npz", "mat": "record.mat", "mat73": "record.mat",
         "uff": "record.uff"}


@pytest.fixture(scope="module", params=list(FILES))
def fmt(request):
    if request.param == "mat73":
        pytest.importorskip("h5py")
    if request.param == "uff":
        pytest.importorskip("pyuff")
    return request.param


@pytest.fixture(scope="module")
def good(tmp_path_factory, fmt):
    """A file crowdvib wrote in the format (the seed of every mutation)."""
    path = write_record(small_record(), tmp_path_factory.mktemp(f"good_{fmt}") / FILES[fmt],
                        format=fmt)
    return path.read_bytes()


@pytest.fixture(scope="module")
def target(tmp_path_factory, fmt):
    return tmp_path_factory.mktemp(f"fuzz_{fmt}") / f"damaged_{FILES[fmt]}"


def test_the_seed_file_reads_back(good, target, fmt):
    # Reference: the record written by small_record(), read through the same helper.
    record = read_damaged(target, good, format=fmt)
    assert record is not None and record.channel_names == ("main", "side", "deck")


@FUZZ_RANDOM
@given(content=random_bytes)
def test_random_bytes(target, fmt, content):
    read_damaged(target, content, format=fmt)


@FUZZ
@given(data=st.data())
def test_damaged_file(good, target, fmt, data):
    read_damaged(target, data.draw(mutations(good)), format=fmt)
