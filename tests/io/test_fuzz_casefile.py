"""Fuzzing the TOML case parser: only crowdvib errors may come out (issue 9, fault 6: a binary
case file gave a UnicodeDecodeError traceback)."""

import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from fuzzing import FUZZ, FUZZ_RANDOM, mutations, outcome, random_bytes
from hypothesis import given
from hypothesis import strategies as st

from crowdvib.errors import CrowdvibError
from crowdvib.io import Case, load_case

pytestmark = pytest.mark.fuzz

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """The Eeklo-like example's case file and modal CSV files (the records are not read)."""
    folder = tmp_path_factory.mktemp("case")
    for name in ("eeklo_like.toml", "eeklo_like_modes.csv", "eeklo_like_shapes.csv",
                 "eeklo_like_outputs.csv"):
        shutil.copy(EXAMPLES / name, folder / name)
    return folder


@pytest.fixture(scope="module")
def good(folder):
    return (folder / "eeklo_like.toml").read_bytes()


def load_damaged(folder, content):
    path = folder / "damaged.toml"
    path.write_bytes(content)
    case = outcome(load_case, path)
    if case is not None:
        # What a loaded case guarantees to the commands: checked, finite, positive models.
        assert isinstance(case, Case)
        assert np.all(np.isfinite(case.structure.frequencies))
        assert np.all(case.structure.frequencies > 0) and case.crowd.density > 0
        assert len(case.structure.output_names) >= 1
    return case


def test_the_seed_case_loads(folder, good):
    # Reference: examples/eeklo_like.toml names the outputs main_span and side_span.
    case = load_damaged(folder, good)
    assert case is not None and case.structure.output_names == ("main_span", "side_span")


@FUZZ_RANDOM
@given(content=random_bytes)
def test_random_bytes(folder, content):
    load_damaged(folder, content)


@FUZZ_RANDOM
@given(text=st.text(alphabet=st.characters(codec="utf-8"), max_size=300))
def test_random_text(folder, text):
    load_damaged(folder, text.encode("utf-8"))


@FUZZ
@given(data=st.data())
def test_damaged_case_file(folder, good, data):
    load_damaged(folder, data.draw(mutations(good)))



@FUZZ_RANDOM
@given(data=st.data())
def test_a_line_given_twice(folder, good, data):
    # Issue 24: a key or table given twice gave tomllib's "Cannot overwrite a value" without the
    # key. A line of the example copied elsewhere loads, or its message is crowdvib's own.
    lines = good.decode("utf-8").splitlines(keepends=True)
    line = data.draw(st.sampled_from([text for text in lines if "=" in text or "[" in text]))
    at = data.draw(st.integers(0, len(lines)))
    path = folder / "twice.toml"
    path.write_text("".join(lines[:at] + [line] + lines[at:]), encoding="utf-8")
    try:
        load_case(path)
    except CrowdvibError as error:
        assert not re.search(r"Cannot (overwrite|declare)", str(error)), str(error)
