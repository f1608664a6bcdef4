"""A truncated UFF 58 file never silently loses its last channel (issue 9, fault 5); the generic
fuzzing of the reader is in test_fuzz_records.py."""

import re

import pytest
from fuzzing import FUZZ, read_damaged, small_record
from hypothesis import given
from hypothesis import strategies as st

from crowdvib import write_record

pytestmark = pytest.mark.fuzz

pytest.importorskip("pyuff")
# A data set opens and closes with "    -1" ending a line (or the file).
END_TAG = re.compile(rb"    -1(?=\r|\n|\Z)")


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    """A UFF file crowdvib wrote: three type-58 data sets (the seed of every mutation)."""
    path = write_record(small_record(), tmp_path_factory.mktemp("good") / "record.uff")
    return path.read_bytes()


@pytest.fixture(scope="module")
def target(tmp_path_factory):
    return tmp_path_factory.mktemp("fuzz") / "damaged.uff"


@FUZZ
@given(data=st.data())
def test_truncation_never_drops_a_channel_silently(good, target, data):
    # Issue 9, fault 5: pyuff drops a last data set that lost its end tag. A truncated file
    # either is refused or ends exactly after a complete data set (then it *is* a shorter file).
    cut = data.draw(st.integers(0, len(good) - 1))
    record = read_damaged(target, good[:cut])
    if record is not None and record.n_channels < 3:
        head = good[:cut]
        tags = END_TAG.findall(head)
        assert len(tags) % 2 == 0 and head.rstrip().endswith(b"    -1")
