"""Dropouts in a record: found, and cut at or bridged, as the case file says (issue 36 §2).

A logger that misses samples leaves empty cells, which the CSV reader reads as NaN. The record's
checks refuse NaN samples; a case file's ``measurement.gaps`` chooses instead: ``"cut"`` keeps
the longest stretch without a dropout, ``"bridge"`` interpolates each dropout linearly between
its neighbours when it lasts no more than ``measurement.max_gap`` [s] (a longer one is refused:
a straight line across it would be a stretch of signal the bridge never made). Either is stated
in the record's notes, which results.json and the console show with the record.
"""

import numpy as np

from ..errors import DataError, ParameterError
from ._common import where

__all__ = ["GAP_MODES", "dropouts", "mend_gaps", "describe_gaps"]

#: measurement.gaps: what to do with a dropout.
GAP_MODES = ("cut", "bridge")


def dropouts(record):
    """(first sample index, length in samples) of every run of samples missing (NaN) in any
    channel, in time order."""
    missing = np.isnan(record.data).any(axis=0)
    edges = np.flatnonzero(np.diff(np.concatenate(([0], missing.view(np.int8), [0]))))
    return [(int(start), int(end - start)) for start, end in zip(edges[::2], edges[1::2])]


def describe_gaps(record, gaps):
    """The dropouts in words: their count, the longest, where the first is."""
    rate = record.sample_rate
    longest = max(length for _, length in gaps)
    first = gaps[0][0]
    return (f"{len(gaps)} dropout(s) (empty cells), the longest {longest} sample(s) "
            f"({longest / rate:.3g} s), the first at sample index {first} "
            f"(t = {record.start_time + first / rate:.6g} s)")


def mend_gaps(record, mode, max_gap=0.1):
    """The record with its dropouts cut at or bridged (``mode`` "cut" or "bridge"), its notes
    saying so; the record itself when it has none.

    Parameters
    ----------
    record : Record
    mode : {"cut", "bridge"} or None
        None leaves the dropouts to :func:`crowdvib.io.check_record`, which refuses them.
    max_gap : float
        "bridge": the longest dropout interpolated [s].

    Raises
    ------
    DataError
        "bridge" with a dropout longer than ``max_gap``; "cut" leaving fewer than 2 samples.
    """
    if mode is not None and mode not in GAP_MODES:
        raise ParameterError(f"gaps must be one of {list(GAP_MODES)}, got {mode!r}")
    gaps = dropouts(record)
    if mode is None or not gaps:
        return record
    rate, found = record.sample_rate, describe_gaps(record, gaps)
    if mode == "cut":
        # The stretches between dropouts; the longest is kept.
        bounds = [0] + [i for start, length in gaps for i in (start, start + length)] \
            + [record.n_samples]
        stretches = list(zip(bounds[::2], bounds[1::2]))
        first, last = max(stretches, key=lambda s: s[1] - s[0])
        if last - first < 2:
            raise DataError(f"{where(record.source)}has no stretch of 2 samples without a "
                            f"dropout to cut to: {found}")
        kept = record.replace(data=record.data[:, first:last],
                              start_time=record.start_time + first / rate)
        note = (f"cut at the dropouts: {found}; kept the longest stretch without one, "
                f"t = {kept.start_time:.6g}–{kept.start_time + kept.duration:.6g} s "
                f"({kept.duration:g} s of {record.duration:g} s)")
        return kept.replace(notes=record.notes + (note,))
    longest = max(length for _, length in gaps)
    if longest / rate > max_gap:
        raise DataError(f"{where(record.source)}measurement.gaps = \"bridge\" interpolates "
                        f"dropouts up to measurement.max_gap = {max_gap:g} s, got {found}: "
                        "cut the record at it (gaps = \"cut\") or raise max_gap")
    if gaps[0][0] == 0 or gaps[-1][0] + gaps[-1][1] == record.n_samples:
        raise DataError(f"{where(record.source)}a dropout at the start or end of the record "
                        f"has no neighbour on one side to bridge to ({found}): use gaps = "
                        "\"cut\"")
    data = np.array(record.data)
    index = np.arange(record.n_samples)
    for row in data:
        missing = np.isnan(row)
        if missing.any():
            row[missing] = np.interp(index[missing], index[~missing], row[~missing])
    note = (f"bridged the dropouts by linear interpolation: {found} "
            f"(up to measurement.max_gap = {max_gap:g} s)")
    return record.replace(data=data, notes=record.notes + (note,))
