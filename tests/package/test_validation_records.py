"""The ``reference`` fixture behind the docs' validation page: it asserts and records."""

import numpy as np
import pytest

from tests.conftest import Reference


def test_a_reference_check_records_what_it_compared():
    records = []
    check = Reference(records, "tests/x.py::test_y")
    check("a quantity", 1.0005, 1.0, rel=1e-3, unit="m", source="a closed form")
    assert records == [{"test": "tests/x.py::test_y", "quantity": "a quantity",
                        "source": "a closed form", "unit": "m", "obtained": 1.0005,
                        "expected": 1.0, "rel": 1e-3, "abs": None}]
    check("an array", np.array([1.0, 2.0 + 2e-12]), [1.0, 2.0], rel=1e-9, source="scipy")
    assert records[1]["size"] == 2
    assert records[1]["max_relative_deviation"] == pytest.approx(1e-12, rel=1e-3)


def test_a_reference_check_fails_outside_its_tolerance():
    # The page can only show values that passed if the check itself fails when they do not.
    with pytest.raises(AssertionError, match="a quantity: 1.01 against 1.0"):
        Reference([], "t")("a quantity", 1.01, 1.0, rel=1e-3, source="a closed form")
