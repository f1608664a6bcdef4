"""Fuzzing the CSV record reader: only crowdvib errors may come out (issue 9, fault 6)."""

import pytest
from fuzzing import FUZZ, FUZZ_RANDOM, mutations, random_bytes, read_damaged, small_record
from hypothesis import given
from hypothesis import strategies as st

from crowdvib import write_record


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    """A CSV file crowdvib wrote (the seed of every mutation)."""
    path = write_record(small_record(), tmp_path_factory.mktemp("good") / "record.csv")
    return path.read_bytes()


@pytest.fixture(scope="module")
def target(tmp_path_factory):
    return tmp_path_factory.mktemp("fuzz") / "damaged.csv"


def test_the_seed_file_reads_back(good, target):
    # Reference: the record written by small_record(), read through the same helper.
    record = read_damaged(target, good)
    assert record is not None and record.channel_names == ("main", "side", "deck")


@FUZZ_RANDOM
@given(content=random_bytes)
def test_random_bytes(target, content):
    read_damaged(target, content)


@FUZZ
@given(data=st.data())
def test_damaged_file(good, target, data):
    read_damaged(target, data.draw(mutations(good)))
