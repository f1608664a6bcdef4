"""Measured acceleration records: the Record, its checks, reading and writing (docs: theory, Welch PSDs, filters and convergence).

A :class:`Record` holds uniformly sampled accelerations [m/s²] of named channels, time on the last
axis. Records come from, and go to, CSV, NPZ, MATLAB v5 (``scipy.io``), MATLAB v7.3 (HDF5, needs
the ``mat73`` extra: ``h5py``) and UFF type 58 (needs the ``uff`` extra: ``pyuff``) files; every
writer's output reads back to the same record.

Checks raise a :class:`DataError` naming the file, the channel and the sample index for what makes a
record unusable (NaN or infinite samples, non-uniform, decreasing or gapped time stamps, channels of
different length or sample rate, a sample rate too low for the analysis band) and warn with a
:class:`DataWarning` for what is doubtful but usable (flat or clipped stretches).

The units of the samples (and their conversion to m/s²) are in :mod:`crowdvib.io.units`, the
file formats themselves (one reader and writer each, their layouts) in
:mod:`crowdvib.io.formats`; every reader runs inside one guard, so any file problem is a
:class:`DataError` naming the file (issue 9).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .._validation import check_positive
from ..errors import DataError, DataWarning, ParameterError
from .._files import require_file
from ._common import (quote, quote_names, reading, refuse_transposed, same_rate,
                      sample_rate_from_time, where)
from .formats import check_names, file_formats, suffix_format
from .units import _check_declared_units, _unit_key, convert_units
from ..signals.spectrum import xarray_module

__all__ = ["Record", "read_record", "write_record", "check_record", "merge_records",
           "RECORD_FORMATS", "convert_units"]

#: Record file formats by name → file suffixes (from the formats table, io.formats.FORMATS).
RECORD_FORMATS = {name: row.suffixes for name, row in file_formats("record").items()}


#: |sample| beyond which a record is refused: no accelerometer nor unit mix-up gives it, and its
#: square (a PSD) overflows near 1e154 (a CSV cell of 1e308 was read silently: issue 35 §3).
MAX_SAMPLE = 1e100


def _refuse_absurd_samples(source, names, data, units=""):
    """DataError naming channel and sample index of the first |sample| > MAX_SAMPLE."""
    with np.errstate(invalid="ignore"):     # NaN and inf: refused by their own checks
        absurd = np.isfinite(data) & (np.abs(data) > MAX_SAMPLE)
    if absurd.any():
        channel, index = np.argwhere(absurd)[0]
        raise DataError(f"{where(source, names[channel])}samples must be below {MAX_SAMPLE:g} in "
                        f"magnitude, got {data[channel, index]:g}{units} at sample index "
                        f"{index}: a damaged cell or a wrong scale")


@dataclass(frozen=True, eq=False)
class Record:
    """Uniformly sampled acceleration record of named channels.

    Parameters
    ----------
    data : array_like, shape (n_channels, n_samples)
        Accelerations [m/s²] (convert g with :func:`convert_units`).
    sample_rate : float
        Sample rate f_samp [Hz], > 0.
    channel_names : sequence of str
        One unique name per channel (the structure's output names once mapped).
    start_time : float
        Time of the first sample [s].
    source : str
        File the record was read from (for messages); empty for records made in memory.
    notes : tuple of str
        What was done to the samples as read, in words (a dropout cut or bridged:
        :func:`crowdvib.io.gaps.mend_gaps`); results.json states them with the record.

    Notes
    -----
    The constructor checks shapes and names only; :func:`check_record` checks the samples.
    """

    data: np.ndarray
    sample_rate: float
    channel_names: tuple
    start_time: float = 0.0
    source: str = ""
    notes: tuple = ()

    def __post_init__(self):
        if np.iscomplexobj(self.data):    # numpy would drop the imaginary part with a warning
            raise ParameterError(f"data must hold real accelerations [m/s²], got "
                                 f"{np.asarray(self.data).dtype.name} samples: take the real "
                                 "part or the magnitude first, as the measurement means")
        data = np.array(self.data, dtype=float)
        if data.ndim == 1:
            data = data[np.newaxis]
        if data.ndim != 2:
            raise ParameterError(
                f"data must have shape (n_channels, n_samples), got {np.shape(self.data)}")
        names = tuple(str(n) for n in self.channel_names)
        if len(names) != data.shape[0]:
            raise ParameterError(
                f"channel_names must name every channel ({data.shape[0]}), got {len(names)}")
        if len(set(names)) != len(names):
            raise ParameterError(f"channel_names must be unique, got {names}")
        data.flags.writeable = False
        object.__setattr__(self, "data", data)
        object.__setattr__(self, "channel_names", names)
        object.__setattr__(self, "sample_rate",
                           check_positive("sample_rate", self.sample_rate, unit="Hz"))
        object.__setattr__(self, "start_time", float(self.start_time))
        object.__setattr__(self, "source", str(self.source))
        object.__setattr__(self, "notes", tuple(str(note) for note in self.notes))

    @property
    def n_channels(self) -> int:
        """Number of channels."""
        return self.data.shape[0]

    @property
    def n_samples(self) -> int:
        """Number of samples per channel."""
        return self.data.shape[1]

    @property
    def duration(self) -> float:
        """Record length n_samples / f_samp [s]."""
        return self.n_samples / self.sample_rate

    @property
    def time(self) -> np.ndarray:
        """Time stamps [s] of the samples."""
        return self.start_time + np.arange(self.n_samples) / self.sample_rate

    def to_xarray(self) -> Any:
        """The record as an ``xarray.DataArray`` of dims (output, time), as
        :meth:`crowdvib.Simulation.to_xarray` gives a simulated one.

        Needs xarray (``pip install 'crowdvib[notebook]'``).

        Returns
        -------
        xarray.DataArray
            Named ``"acceleration"``, the samples (a copy), coordinates ``output`` (the channel
            names) and ``time`` [s] (from :attr:`start_time`), attributes ``units`` "m/s²",
            ``sample_rate`` [Hz], ``duration`` [s] and ``source`` (the file read, or "").

        Raises
        ------
        ModuleNotFoundError
            xarray is not installed; the message names the extra that installs it.

        Examples
        --------
        >>> from crowdvib.io import Record
        >>> array = Record([[0.0, 0.1, -0.1]], 100.0, ("mid",), start_time=2.0).to_xarray()
        >>> array.dims, array.attrs["units"], float(array.time[-1])
        (('output', 'time'), 'm/s²', 2.02)
        """

        xarray = xarray_module("Record.to_xarray")
        return xarray.DataArray(
            np.array(self.data), dims=("output", "time"), name="acceleration",
            attrs={"units": "m/s²", "long_name": "measured acceleration",
                   "sample_rate": self.sample_rate, "duration": self.duration,
                   "source": self.source},
            coords={"output": list(self.channel_names),
                    "time": ("time", self.time, {"units": "s"})})

    def select(self, channels: str | Sequence[str] | Mapping[str, str]) -> Record:
        """The named channels in that order; a ``dict`` maps new names to names in the record.

        Parameters
        ----------
        channels : sequence of str or dict of str to str
            Channel names, or output name → channel name (renames while selecting).
        """
        mapping = (dict(channels) if isinstance(channels, dict)
                   else {name: name for name in ([channels] if isinstance(channels, str)
                                                 else channels)})
        rows = []
        sources: dict[str, str] = {}
        for new, old in mapping.items():
            if old in sources:       # one sensor read as two outputs: identical "channels"
                raise DataError(f"{self._where()}channels must each be read once, got channel "
                                f"{quote(old)} for both {quote(sources[old])} and {quote(new)}")
            sources[old] = new
            if old not in self.channel_names:
                raise DataError(f"{self._where()}channel {quote(old)} (for {quote(new)}) is "
                                f"not in the record; its channels are "
                                f"{quote_names(self.channel_names)}")
            rows.append(self.channel_names.index(old))
        return self.replace(data=self.data[rows], channel_names=tuple(mapping))

    def frame(self, start: float | None = None, end: float | None = None) -> Record:
        """The samples with start <= t < end [s] (times as in :attr:`time`).

        Parameters
        ----------
        start, end : float, optional
            The frame [s] (default the record's first and last sample).
        """
        first = 0 if start is None else int(np.ceil((start - self.start_time) * self.sample_rate
                                                    - 1e-9))
        last = self.n_samples if end is None else int(np.ceil((end - self.start_time)
                                                              * self.sample_rate - 1e-9))
        first, last = max(first, 0), min(last, self.n_samples)
        if last - first < 2:
            raise DataError(f"{self._where()}time frame [{start}, {end}] s holds "
                            f"{max(last - first, 0)}"
                            f" sample(s) of a record spanning [{self.start_time:g}, "
                            f"{self.start_time + self.duration:g}] s")
        return self.replace(data=self.data[:, first:last],
                            start_time=self.start_time + first / self.sample_rate)

    def replace(self, **changes: Any) -> Record:
        """A copy with some fields changed (validated again).

        Parameters
        ----------
        **changes
            Fields of :class:`Record` and their new values.
        """
        fields = dict(data=self.data, sample_rate=self.sample_rate,
                      channel_names=self.channel_names, start_time=self.start_time,
                      source=self.source, notes=self.notes)
        fields.update(changes)
        return Record(**fields)

    def _where(self):
        return f"{Path(self.source).name}: " if self.source else ""

    def metadata(self) -> dict[str, Any]:
        """Metadata as a JSON-ready dict (no samples: the record is its file,
        :func:`write_record` and :func:`read_record`)."""
        found = {"source": self.source, "channel_names": list(self.channel_names),
                 "sample_rate": self.sample_rate, "n_samples": self.n_samples,
                 "start_time": self.start_time, "duration": self.duration}
        return {**found, "notes": list(self.notes)} if self.notes else found


# ------------------------------------------------------------------------------------ checks
def _flat_runs(row, min_length):
    """(start, length) of the longest run of identical consecutive samples if >= min_length."""
    same = np.diff(row) == 0
    if not same.any():
        return None
    edges = np.flatnonzero(np.diff(np.concatenate(([0], same.view(np.int8), [0]))))
    starts, ends = edges[::2], edges[1::2]
    lengths = ends - starts + 1          # samples in the run
    k = int(np.argmax(lengths))
    return (int(starts[k]), int(lengths[k])) if lengths[k] >= min_length else None


def check_record(record: Record, *, band: tuple[float, float] | None = None,
                 flat_duration: float = 1.0, clip_samples: int = 5) -> Record:
    """Check the samples of a record; raise or warn naming file, channel and sample index.

    Parameters
    ----------
    record : Record
    band : (float, float), optional
        Analysis band [Hz]; the Nyquist frequency f_samp/2 must lie above its upper edge.
    flat_duration : float
        A run of identical samples at least this long [s] is a flat stretch (a dead or saturated
        sensor, a logger hold): :class:`DataWarning`.
    clip_samples : int
        At least this many consecutive samples at the channel's extreme value look clipped:
        :class:`DataWarning` (5 by default: a quantised signal may repeat its peak 2–3 times).

    Returns
    -------
    Record
        The same record, for chaining.

    Raises
    ------
    DataError
        NaN or infinite samples; a sample rate too low for the band.

    Warns
    -----
    DataWarning
        Flat or clipped stretches.
    """
    if not isinstance(record, Record):
        raise ParameterError(f"record must be a Record, got {type(record).__name__}")
    source = record.source
    if record.n_channels == 0 or record.n_samples < 2:
        raise DataError(f"{where(source)}holds {record.n_channels} channel(s) of "
                        f"{record.n_samples} sample(s); a record needs a channel of at least 2")
    finite = np.isfinite(record.data)
    if not finite.all():
        channel, index = np.argwhere(~finite)[0]
        value = record.data[channel, index]
        kind = "NaN" if np.isnan(value) else "infinite"
        gap = (" (a dropout: an empty cell or NaN): set measurement.gaps = \"cut\" to keep the "
               "longest stretch without one, or \"bridge\" to interpolate gaps up to "
               "measurement.max_gap" if np.isnan(value) else "")
        raise DataError(f"{where(source, record.channel_names[channel])}{kind} sample at sample "
                        f"index {index} "
                        f"(t = {record.start_time + index / record.sample_rate:.6g} s){gap}")
    if band is not None:
        upper = float(band[1])
        nyquist = record.sample_rate / 2
        if nyquist <= upper:
            raise DataError(f"{where(source)}sample rate {record.sample_rate:g} Hz is too low for "
                            f"the band up to {upper:g} Hz: the Nyquist frequency "
                            f"{nyquist:g} Hz must exceed it")
    min_flat = max(int(round(flat_duration * record.sample_rate)), 2)
    for name, row in zip(record.channel_names, record.data):
        run = _flat_runs(row, min_flat)
        if run is not None:
            warnings.warn(f"{where(source, name)}flat stretch of {run[1]} identical samples "
                          f"({run[1] / record.sample_rate:.3g} s, value {row[run[0]]:.6g}) from "
                          f"sample index {run[0]}", DataWarning, stacklevel=2)
            continue
        peak = np.max(np.abs(row))
        if peak > 0 and clip_samples >= 2:
            at_peak = np.abs(row) == peak
            run = _flat_runs(np.where(at_peak, 1.0, np.arange(row.size) + 2.0), clip_samples)
            if run is not None:
                warnings.warn(f"{where(source, name)}looks clipped: {run[1]} consecutive samples "
                              f"at the extreme {row[run[0]]:.6g} m/s² from sample index {run[0]}",
                              DataWarning, stacklevel=2)
    return record


def merge_records(records):
    """Channels of several records side by side; they must share sample rate and length.

    Parameters
    ----------
    records : iterable of Record
        At least one; their channel names must differ.

    Returns
    -------
    Record
        The channels of every record, in order.

    Raises
    ------
    DataError
        Records of other sample rates or lengths (the message names the channels and files).

    Examples
    --------
    >>> import numpy as np
    >>> from crowdvib.io import Record, merge_records
    >>> a = Record(np.zeros((1, 8)), sample_rate=4.0, channel_names=("mid",))
    >>> b = Record(np.ones((1, 8)), sample_rate=4.0, channel_names=("quarter",))
    >>> merge_records([a, b]).channel_names
    ('mid', 'quarter')
    """
    records = list(records)
    if not records:
        raise ParameterError("records must hold at least one Record")
    first = records[0]
    names = []
    for record in records:
        if abs(record.sample_rate - first.sample_rate) > 1e-9 * first.sample_rate:
            raise DataError(f"{where(record.source, record.channel_names[0])}sample rate "
                            f"{record.sample_rate:g} Hz differs from {first.sample_rate:g} Hz of "
                            f"channel {first.channel_names[0]!r} in {where(first.source)[:-2]}")
        if record.n_samples != first.n_samples:
            raise DataError(f"{where(record.source, record.channel_names[0])}has "
                            f"{record.n_samples} samples, channel {first.channel_names[0]!r} in "
                            f"{where(first.source)[:-2]} has {first.n_samples}: channels must "
                            "have the same length")
        names.extend(record.channel_names)
    sources = sorted({r.source for r in records})
    return Record(data=np.concatenate([r.data for r in records]), sample_rate=first.sample_rate,
                  channel_names=tuple(names), start_time=first.start_time,
                  source=sources[0] if len(sources) == 1 else ", ".join(sources),
                  notes=tuple(note for record in records for note in record.notes))


def _assemble(source, channels, *, sample_rate=None, rate_source=None, time=None,
              time_name="time", units="m/s2", start_time=0.0):
    """A Record from per-channel arrays; checks their lengths and the time base.

    ``channels`` is a list of (name, samples, channel_sample_rate or None); ``sample_rate`` is
    the rate the caller gave or the file states (``rate_source`` says which), ``time`` the time
    stamps of column (variable) ``time_name``. Stamps and a stated rate must agree.
    """
    if not channels:
        raise DataError(f"{where(source)}holds no channels")
    if time is not None:
        rate = sample_rate_from_time(time, source)
        start_time = float(np.asarray(time, dtype=float)[0])
        if sample_rate is not None:
            if not same_rate(rate, sample_rate):
                raise DataError(f"{where(source)}its time column {quote(time_name)} gives "
                                f"{rate:.9g} Hz but {rate_source or 'the given sample_rate'} is "
                                f"{sample_rate:.9g} Hz: they must agree (drop or fix one)")
            rate = float(sample_rate)   # exact, where the stamps are rounded in the file
    elif sample_rate is not None:
        rate = float(sample_rate)
    else:
        rates = [r for _, _, r in channels if r is not None]
        if not rates:
            raise DataError(f"{where(source)}has no time stamps and no sample rate: none of its "
                            f"columns {quote_names(n for n, _, _ in channels)} is a time column "
                            "(time, t, Time [s], time_s, Zeit, temps, Tijd …): give "
                            "measurement.sample_rate [Hz] or name it in measurement.time_column")
        rate = rates[0]
    if not np.isfinite(start_time):
        raise DataError(f"{where(source)}start time must be finite, got {start_time}")
    first_name, first, _ = channels[0]
    if np.size(first) < 2:
        raise DataError(f"{where(source, first_name)}holds {np.size(first)} sample(s); a record "
                        "needs at least 2")
    for name, samples, channel_rate in channels:
        if channel_rate is not None and not same_rate(channel_rate, rate):
            raise DataError(f"{where(source, name)}sample rate {channel_rate:.9g} Hz differs "
                            f"from {rate:.9g} Hz of channel {first_name!r}")
        if np.size(samples) != np.size(first):
            raise DataError(f"{where(source, name)}has {np.size(samples)} samples, channel "
                            f"{first_name!r} has {np.size(first)}: channels must have the same "
                            f"length (they differ from sample index "
                            f"{min(np.size(samples), np.size(first))})")
    if time is not None and np.size(time) != np.size(first):
        raise DataError(f"{where(source)}has {np.size(time)} time stamps but {np.size(first)} "
                        "samples per channel")
    names = [n for n, _, _ in channels]
    refuse_transposed(source, len(names), np.size(first))
    raw = np.stack([np.asarray(s, dtype=float).ravel() for _, s, _ in channels])
    _refuse_absurd_samples(source, names, raw)
    if _unit_key(units, "") != "m/s2":
        _check_declared_units(source, names, raw, _unit_key(units, ""))
    data = convert_units(raw, units)
    return Record(data=data, sample_rate=rate, channel_names=[n for n, _, _ in channels],
                  start_time=start_time, source=str(source))


# ------------------------------------------------------------------------------------ formats
def _format_of(path, format):
    if format is not None:
        if format not in RECORD_FORMATS:
            raise ParameterError(f"format must be one of {list(RECORD_FORMATS)}, got {format!r}")
        return format
    row = suffix_format(path, "record")
    if row is not None:
        return row.name
    raise ParameterError(f"cannot tell the format of {Path(path).name!r} from its suffix: "
                         f"give format= one of {list(RECORD_FORMATS)}")


def read_record(path: str | os.PathLike, *, format: str | None = None,
                channels: Mapping[str, str] | Sequence[str] | None = None,
                units: str | None = None, sample_rate: float | None = None,
                time_column: str = "time", header_row: int | None = None) -> Record:
    """Read an acceleration record from a CSV, NPZ, MAT (v5, v7.3) or UFF-58 file.

    Parameters
    ----------
    path : str or Path
        The file.
    format : {"csv", "npz", "mat", "mat73", "uff"}, optional
        Default from the suffix (.csv/.txt, .npz, .mat — v5 or v7.3 told apart by the header —,
        .uff/.unv).
    channels : sequence of str or dict of str to str, optional
        Channels to keep, or output name → channel name in the file (renames them to the
        structure's output names). Default all channels, as named in the file.
    units : {"m/s2", "g", "mg", "mm/s2"}, optional
        Units of the samples; default the unit stored in the file (a CSV's ``# unit`` comment,
        else the unit its column headers close in, ``a [mg]``), else m/s². g → 9.81 m/s².
    sample_rate : float, optional
        Sample rate [Hz] for files without time stamps (CSV without a time column).
    time_column : str
        Name of the time column/variable [s].
    header_row : int, optional
        CSV only: the line number (1 for the first line) of the header row. Default: the first
        line that names as many columns as the rows below it hold numbers (the metadata lines a
        logger writes above it are skipped).

    Returns
    -------
    Record
        In m/s²; time stamps are checked (uniform, increasing, no gaps), the samples are not —
        call :func:`check_record`.

    Warns
    -----
    DataWarning
        ``units`` differ from the unit a column header states (``a [mg]`` read as g).
    """
    record, meta = _read_record(path, format=format, units=units, sample_rate=sample_rate,
                                time_column=time_column, header_row=header_row)
    stated = meta.get("header_units") or {}
    if units is not None:
        other = {name: unit for name, unit in stated.items() if unit != _unit_key(units, "")}
        if other:
            warnings.warn(f"{where(path)}read in {units!r} as given, but the header of column(s) "
                          + ", ".join(f"{quote(name)} states {unit!r}"
                                      for name, unit in other.items())
                          + ": is the given unit right?", DataWarning, stacklevel=2)
    return record if channels is None else record.select(channels)


def _read_record(path, *, format, units, sample_rate, time_column, header_row=None):
    """(Record, the reader's meta: its time base and the units the file states) — the work of
    :func:`read_record`; ``crowdvib init`` (:mod:`crowdvib.io.draft`) reports the time base."""
    path = Path(path)
    kind = _format_of(path, format)
    require_file(path, "record")
    if sample_rate is not None:
        sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    if units is not None:
        _unit_key(units, "")
    # The one guard of every reader: whatever goes wrong in the file, the caller gets a
    # DataError naming it (a unit or sample rate stored in the file included).
    row = file_formats("record")[kind]
    options = {}
    if header_row is not None:
        if kind != "csv":
            raise ParameterError(f"header_row applies to CSV records only, got it for "
                                 f"{Path(path).name!r} read as {kind}")
        options["header_row"] = check_positive("header_row", header_row)
    with reading(path, row.description):
        columns, meta = row.reader(path, sample_rate=sample_rate, time_column=time_column,
                                   **options)
        unit = units if units is not None else (meta.get("units") or "m/s2")
        _unit_key(unit, f"{path.name}: ")
        record = _assemble(path, columns, sample_rate=meta.get("sample_rate"),
                           rate_source=meta.get("rate_source"), time=meta.get("time"),
                           time_name=meta.get("time_name"), units=unit,
                           start_time=meta.get("start_time", 0.0))
    return record, meta


def write_record(record: Record, path: str | os.PathLike, *, format: str | None = None,
                 dtype: str = "float64") -> Path:
    """Write a record atomically in one of the formats :func:`read_record` reads.

    Parameters
    ----------
    record : Record
    path : str or Path
    format : {"csv", "npz", "mat", "mat73", "uff"}, optional
        Default from the suffix; ``.mat`` is written as v5 unless ``format="mat73"``.
    dtype : {"float64", "float32"}
        Sample precision on disk (float32 halves the size; ~7 significant digits).

    Returns
    -------
    Path
    """
    if not isinstance(record, Record):
        raise ParameterError(f"record must be a Record, got {type(record).__name__}")
    if np.dtype(dtype) not in (np.float32, np.float64):
        raise ParameterError(f"dtype must be 'float32' or 'float64', got {dtype!r}")
    kind = _format_of(path, format)
    check_names(record.channel_names, kind)
    file_formats("record")[kind].writer(record, Path(path), np.dtype(dtype).type)
    return Path(path)
