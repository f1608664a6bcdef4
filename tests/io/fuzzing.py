"""Shared pieces of the reader fuzz tests (issue 9: only crowdvib errors may leave a reader).

Each test feeds a reader either random bytes or a file crowdvib itself wrote, damaged by a few
byte flips, truncations, insertions and deletions. What may come out: a crowdvib error
(:class:`CrowdvibError`), or a result that still satisfies the invariants of its type.
"""

import warnings

import numpy as np
from hypothesis import settings
from hypothesis import strategies as st

from crowdvib import Record, check_record
from crowdvib.errors import CrowdvibError, DataError

# Deterministic (derandomize) and sized so that the whole fuzz folder runs in well under 60 s on
# the 2-core test machine; no deadline because a shared machine's timing is not the property.
FUZZ = settings(max_examples=400, derandomize=True, deadline=None)
FUZZ_RANDOM = settings(max_examples=150, derandomize=True, deadline=None)

#: Random bytes: short, because a reader rejects random bytes in its first few.
random_bytes = st.binary(max_size=600)


@st.composite
def mutations(draw, good):
    """``good`` bytes after 1–4 damages: byte flip, truncation, insertion or deletion."""
    data = bytearray(good)
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(("flip", "truncate", "insert", "delete")))
        at = draw(st.integers(0, max(len(data) - 1, 0)))
        if kind == "flip" and data:
            data[at] ^= 1 << draw(st.integers(0, 7))
        elif kind == "truncate":
            del data[at:]
        elif kind == "insert":
            data[at:at] = draw(st.binary(min_size=1, max_size=16))
        elif data:
            del data[at:at + draw(st.integers(1, 64))]
    return bytes(data)


def outcome(call, *args, **kwargs):
    """The result of ``call``, or None when it raised a crowdvib error; any other exception
    propagates and fails the test."""
    try:
        return call(*args, **kwargs)
    except CrowdvibError as error:
        assert str(error), "a crowdvib error must carry a message"
        return None


def assert_record_invariants(record):
    """What every record read from a file satisfies: 2-D data (n_channels, n_samples) with one
    name per channel, at least 2 samples, a finite positive sample rate and a finite start
    time; after :func:`check_record` (or its DataError) every sample is finite."""
    assert isinstance(record, Record)
    assert record.data.ndim == 2
    assert record.data.shape == (len(record.channel_names), record.n_samples)
    assert record.n_samples >= 2
    assert np.isfinite(record.sample_rate) and record.sample_rate > 0
    assert np.isfinite(record.start_time)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")   # flat or clipped stretches are expected in damaged data
        try:
            check_record(record)
        except DataError:
            return
    assert np.all(np.isfinite(record.data))


def small_record():
    """Three channels of 40 seeded samples at 50 Hz from t = 0.5 s: big enough for every layout
    (several UFF data sets), small enough that one read takes a few milliseconds."""
    data = np.random.default_rng(20261123).normal(scale=0.05, size=(3, 40))
    return Record(data=data, sample_rate=50.0, channel_names=("main", "side", "deck"),
                  start_time=0.5)


def read_damaged(path, content, **kwargs):
    """Write ``content`` to ``path`` and read it as a record: a crowdvib error, or a record
    satisfying :func:`assert_record_invariants`. Returns the record or None."""
    from crowdvib import read_record

    path.write_bytes(content)
    record = outcome(read_record, path, **kwargs)
    if record is not None:
        assert_record_invariants(record)
    return record
