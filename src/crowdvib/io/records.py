"""Measured acceleration records: readers, writers and checks (physics.md §6; architecture §1).

A :class:`Record` holds uniformly sampled accelerations [m/s²] of named channels, time on the last
axis. Records come from, and go to, CSV, NPZ, MATLAB v5 (``scipy.io``), MATLAB v7.3 (HDF5, needs
the ``mat73`` extra: ``h5py``) and UFF type 58 (needs the ``uff`` extra: ``pyuff``) files; every
writer's output reads back to the same record.

Checks raise a :class:`DataError` naming the file, the channel and the sample index for what makes a
record unusable (NaN or infinite samples, non-uniform, decreasing or gapped time stamps, channels of
different length or sample rate, a sample rate too low for the analysis band) and warn with a
:class:`DataWarning` for what is doubtful but usable (flat or clipped stretches).

File layouts written (and read) by crowdvib
-------------------------------------------
CSV
    Optional ``#`` comment lines (``# unit = g``, ``# sample_rate = 100``), one header line of
    column names, one row per sample. A ``time`` column [s] gives the time stamps; without it the
    sample rate must be given (case file ``measurement.sample_rate``).
NPZ
    ``data`` (n_channels, n_samples) with ``channel_names``, or one array per channel; ``sample_rate``
    [Hz] or ``time`` [s]; optional ``unit`` and ``start_time`` [s].
MAT (v5 and v7.3)
    The same variables; ``data`` is n_samples × n_channels in MATLAB (one column per channel);
    ``channel_names`` is a comma-separated char row (v7.3) or a cell array / char matrix (v5).
UFF 58
    One function-at-nodal-DOF data set per channel (function type 1, time response), the channel
    name in ID line 1, even abscissa spacing (Δt) and the unit in the ordinate-axis label.
"""

import re
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._files import atomic_path
from .._validation import check_positive
from ..errors import DataError, DataWarning, ParameterError
from ..models.loading import STANDARD_GRAVITY

__all__ = ["Record", "read_record", "write_record", "check_record", "merge_records",
           "RECORD_FORMATS", "convert_units"]

#: File formats by name → file suffixes.
RECORD_FORMATS = {"csv": (".csv", ".txt"), "npz": (".npz",), "mat": (".mat",),
                  "mat73": (), "uff": (".uff", ".unv")}
_UNIT_ALIASES = {"m/s2": "m/s2", "m/s^2": "m/s2", "m/s²": "m/s2", "m s-2": "m/s2", "mps2": "m/s2",
                 "g": "g", "g0": "g"}
# Time stamps whose step differs from the median step by more than this fraction are non-uniform;
# a step of more than _GAP_FACTOR median steps is a gap (missing samples).
_JITTER_TOLERANCE = 1e-3
_GAP_FACTOR = 1.5
_MAT73_HEADER = b"MATLAB 7.3 MAT-file, Platform: crowdvib, Created by: crowdvib HDF5 schema 1.00 ."


def _unit_key(units, where):
    key = _UNIT_ALIASES.get(str(units).strip().lower().replace(" ", ""))
    if key is None:
        raise ParameterError(f"{where}units must be 'm/s2' or 'g', got {units!r}")
    return key


def convert_units(data, units):
    """Accelerations in ``units`` ("g" or "m/s2") → m/s² (g = 9.81 m/s², physics.md §0)."""
    return np.asarray(data, dtype=float) * (STANDARD_GRAVITY if _unit_key(units, "") == "g" else 1.0)


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

    Notes
    -----
    The constructor checks shapes and names only; :func:`check_record` checks the samples.
    """

    data: np.ndarray
    sample_rate: float
    channel_names: tuple
    start_time: float = 0.0
    source: str = ""

    def __post_init__(self):
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

    @property
    def n_channels(self):
        """Number of channels."""
        return self.data.shape[0]

    @property
    def n_samples(self):
        """Number of samples per channel."""
        return self.data.shape[1]

    @property
    def duration(self):
        """Record length n_samples / f_samp [s]."""
        return self.n_samples / self.sample_rate

    @property
    def time(self):
        """Time stamps [s] of the samples."""
        return self.start_time + np.arange(self.n_samples) / self.sample_rate

    def select(self, channels):
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
        for new, old in mapping.items():
            if old not in self.channel_names:
                raise DataError(f"{self._where()}channel {old!r} (for {new!r}) is not in the "
                                f"record; its channels are {list(self.channel_names)}")
            rows.append(self.channel_names.index(old))
        return self.replace(data=self.data[rows], channel_names=tuple(mapping))

    def frame(self, start=None, end=None):
        """The samples with start <= t < end [s] (times as in :attr:`time`)."""
        first = 0 if start is None else int(np.ceil((start - self.start_time) * self.sample_rate
                                                    - 1e-9))
        last = self.n_samples if end is None else int(np.ceil((end - self.start_time)
                                                              * self.sample_rate - 1e-9))
        first, last = max(first, 0), min(last, self.n_samples)
        if last - first < 2:
            raise DataError(f"{self._where()}time frame [{start}, {end}] s holds {max(last - first, 0)}"
                            f" sample(s) of a record spanning [{self.start_time:g}, "
                            f"{self.start_time + self.duration:g}] s")
        return self.replace(data=self.data[:, first:last],
                            start_time=self.start_time + first / self.sample_rate)

    def replace(self, **changes):
        """A copy with some fields changed (validated again)."""
        fields = dict(data=self.data, sample_rate=self.sample_rate,
                      channel_names=self.channel_names, start_time=self.start_time,
                      source=self.source)
        fields.update(changes)
        return Record(**fields)

    def _where(self):
        return f"{Path(self.source).name}: " if self.source else ""

    def to_dict(self):
        """Metadata as a JSON-ready dict (no samples)."""
        return {"source": self.source, "channel_names": list(self.channel_names),
                "sample_rate": self.sample_rate, "n_samples": self.n_samples,
                "start_time": self.start_time, "duration": self.duration}


# ------------------------------------------------------------------------------------ checks
def _where(source, channel=None):
    name = Path(source).name if source else "record"
    return f"{name}: " + ("" if channel is None else f"channel {channel!r}: ")


def _sample_rate_from_time(time, source, channel=None):
    """Sample rate [Hz] of uniform, increasing time stamps; DataError naming the first bad step."""
    time = np.asarray(time, dtype=float)
    where = _where(source, channel)
    if time.ndim != 1 or time.size < 2:
        raise DataError(f"{where}time must hold at least 2 stamps, got shape {time.shape}")
    bad = np.flatnonzero(~np.isfinite(time))
    if bad.size:
        raise DataError(f"{where}time stamp at sample index {bad[0]} is {time[bad[0]]}")
    step = np.diff(time)
    bad = np.flatnonzero(step <= 0)
    if bad.size:
        i = bad[0] + 1
        raise DataError(f"{where}time stamps must increase: sample index {i} has t = "
                        f"{time[i]:.9g} s after t = {time[i - 1]:.9g} s")
    median = float(np.median(step))
    bad = np.flatnonzero(step > _GAP_FACTOR * median)
    if bad.size:
        i = bad[0] + 1
        raise DataError(f"{where}gap in the time stamps before sample index {i}: "
                        f"{step[bad[0]]:.6g} s between samples, the median step is {median:.6g} s "
                        f"(about {int(round(step[bad[0]] / median)) - 1} sample(s) missing)")
    bad = np.flatnonzero(np.abs(step - median) > _JITTER_TOLERANCE * median)
    if bad.size:
        i = bad[0] + 1
        raise DataError(f"{where}time stamps must be uniform: the step before sample index {i} is "
                        f"{step[bad[0]]:.9g} s, the median step is {median:.9g} s")
    # The mean step over the record is more accurate than any single difference.
    return (time.size - 1) / (time[-1] - time[0])


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


def check_record(record, *, band=None, flat_duration=1.0, clip_samples=5):
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
    finite = np.isfinite(record.data)
    if not finite.all():
        channel, index = np.argwhere(~finite)[0]
        value = record.data[channel, index]
        kind = "NaN" if np.isnan(value) else "infinite"
        raise DataError(f"{_where(source, record.channel_names[channel])}{kind} sample at sample "
                        f"index {index} (t = {record.start_time + index / record.sample_rate:.6g} s)")
    if band is not None:
        upper = float(band[1])
        nyquist = record.sample_rate / 2
        if nyquist <= upper:
            raise DataError(f"{_where(source)}sample rate {record.sample_rate:g} Hz is too low for "
                            f"the band up to {upper:g} Hz: the Nyquist frequency "
                            f"{nyquist:g} Hz must exceed it")
    min_flat = max(int(round(flat_duration * record.sample_rate)), 2)
    for name, row in zip(record.channel_names, record.data):
        run = _flat_runs(row, min_flat)
        if run is not None:
            warnings.warn(f"{_where(source, name)}flat stretch of {run[1]} identical samples "
                          f"({run[1] / record.sample_rate:.3g} s, value {row[run[0]]:.6g}) from "
                          f"sample index {run[0]}", DataWarning, stacklevel=2)
            continue
        peak = np.max(np.abs(row))
        if peak > 0 and clip_samples >= 2:
            at_peak = np.abs(row) == peak
            run = _flat_runs(np.where(at_peak, 1.0, np.arange(row.size) + 2.0), clip_samples)
            if run is not None:
                warnings.warn(f"{_where(source, name)}looks clipped: {run[1]} consecutive samples "
                              f"at the extreme {row[run[0]]:.6g} m/s² from sample index {run[0]}",
                              DataWarning, stacklevel=2)
    return record


def merge_records(records):
    """Channels of several records side by side; they must share sample rate and length."""
    records = list(records)
    if not records:
        raise ParameterError("records must hold at least one Record")
    first = records[0]
    names = []
    for record in records:
        if abs(record.sample_rate - first.sample_rate) > 1e-9 * first.sample_rate:
            raise DataError(f"{_where(record.source, record.channel_names[0])}sample rate "
                            f"{record.sample_rate:g} Hz differs from {first.sample_rate:g} Hz of "
                            f"channel {first.channel_names[0]!r} in {_where(first.source)[:-2]}")
        if record.n_samples != first.n_samples:
            raise DataError(f"{_where(record.source, record.channel_names[0])}has "
                            f"{record.n_samples} samples, channel {first.channel_names[0]!r} in "
                            f"{_where(first.source)[:-2]} has {first.n_samples}: channels must "
                            "have the same length")
        names.extend(record.channel_names)
    sources = sorted({r.source for r in records})
    return Record(data=np.concatenate([r.data for r in records]), sample_rate=first.sample_rate,
                  channel_names=tuple(names), start_time=first.start_time,
                  source=sources[0] if len(sources) == 1 else ", ".join(sources))


def _assemble(source, channels, *, sample_rate=None, time=None, units="m/s2", start_time=0.0):
    """A Record from per-channel arrays; checks their lengths and the time base.

    ``channels`` is a list of (name, samples, channel_sample_rate or None).
    """
    if not channels:
        raise DataError(f"{_where(source)}holds no channels")
    if time is not None:
        rate = _sample_rate_from_time(time, source)
        start_time = float(np.asarray(time, dtype=float)[0])
    elif sample_rate is not None:
        rate = float(sample_rate)
    else:
        rates = [r for _, _, r in channels if r is not None]
        if not rates:
            raise DataError(f"{_where(source)}has no time stamps and no sample rate: give "
                            "measurement.sample_rate [Hz]")
        rate = rates[0]
    first_name, first, _ = channels[0]
    for name, samples, channel_rate in channels:
        if channel_rate is not None and abs(channel_rate - rate) > 1e-6 * rate:
            raise DataError(f"{_where(source, name)}sample rate {channel_rate:.9g} Hz differs "
                            f"from {rate:.9g} Hz of channel {first_name!r}")
        if np.size(samples) != np.size(first):
            raise DataError(f"{_where(source, name)}has {np.size(samples)} samples, channel "
                            f"{first_name!r} has {np.size(first)}: channels must have the same "
                            f"length (they differ from sample index "
                            f"{min(np.size(samples), np.size(first))})")
    if time is not None and np.size(time) != np.size(first):
        raise DataError(f"{_where(source)}has {np.size(time)} time stamps but {np.size(first)} "
                        "samples per channel")
    data = convert_units(np.stack([np.asarray(s, dtype=float).ravel() for _, s, _ in channels]),
                         units)
    return Record(data=data, sample_rate=rate, channel_names=[n for n, _, _ in channels],
                  start_time=start_time, source=str(source))


# ------------------------------------------------------------------------------------ formats
def _format_of(path, format):
    if format is not None:
        if format not in RECORD_FORMATS:
            raise ParameterError(f"format must be one of {list(RECORD_FORMATS)}, got {format!r}")
        return format
    suffix = Path(path).suffix.lower()
    for name, suffixes in RECORD_FORMATS.items():
        if suffix in suffixes:
            return name
    raise ParameterError(f"cannot tell the format of {Path(path).name!r} from its suffix: "
                         f"give format= one of {list(RECORD_FORMATS)}")


def _string(value):
    """A text value from numpy/MATLAB containers (0-d arrays, char arrays, bytes)."""
    value = np.asarray(value)
    if value.dtype.kind in "SU" or value.dtype == object:
        value = value.ravel()[0] if value.size == 1 else value
        value = value.item() if isinstance(value, np.ndarray) and value.ndim == 0 else value
    return value.decode() if isinstance(value, bytes) else str(value)


def _names(value):
    """Channel names from a string array, a cell array or a comma-separated string."""
    array = np.asarray(value)
    if array.ndim == 0 or (array.dtype.kind in "SU" and array.size == 1):
        text = _string(array)
        return [n.strip() for n in text.split(",")]
    return [_string(v).strip() for v in array.ravel()]


def _read_csv(path, *, sample_rate, time_column):
    meta = {}
    header = None
    with open(path, encoding="utf-8") as handle:
        skip = 0
        for line in handle:
            skip += 1
            stripped = line.strip()
            if not stripped:
                continue
            if stripped.startswith("#"):
                match = re.match(r"#\s*([\w ]+?)\s*[=:]\s*(.+)$", stripped)
                if match:
                    meta[match.group(1).strip().lower()] = match.group(2).strip()
                continue
            header = [h.strip() for h in stripped.split(",")]
            break
    if header is None:
        raise DataError(f"{_where(path)}has no header line of column names")
    try:
        values = np.loadtxt(path, delimiter=",", skiprows=skip, ndmin=2, comments="#",
                            dtype=float)
    except ValueError as exc:
        raise DataError(f"{_where(path)}cannot be read as a table of numbers "
                        f"({len(header)} columns: {header}): {exc}") from None
    if values.shape[1] != len(header):
        raise DataError(f"{_where(path)}has {values.shape[1]} columns of data but {len(header)} "
                        f"names in the header {header}")
    time = None
    if time_column in header:
        time = values[:, header.index(time_column)]
    columns = [(name, values[:, i], None) for i, name in enumerate(header) if name != time_column]
    rate = sample_rate if sample_rate is not None else (
        float(meta["sample_rate"]) if "sample_rate" in meta and time is None else None)
    return columns, dict(time=None if rate is not None and time is None else time,
                         sample_rate=rate if time is None else None,
                         units=meta.get("unit"))


def _read_npz(path, *, sample_rate, time_column):
    with np.load(path, allow_pickle=False) as archive:
        content = {key: archive[key] for key in archive.files}
    return _from_variables(path, content, sample_rate=sample_rate, time_column=time_column,
                           channels_last=False)


def _from_variables(path, content, *, sample_rate, time_column, channels_last):
    """Channels and time base from a dict of variables (NPZ, MAT)."""
    units = _string(content.pop("unit")) if "unit" in content else None
    start = float(np.ravel(content.pop("start_time"))[0]) if "start_time" in content else 0.0
    rate = content.pop("sample_rate", None)
    rate = float(np.ravel(rate)[0]) if rate is not None else sample_rate
    time = content.pop(time_column, None)
    time = None if time is None else np.ravel(np.asarray(time, dtype=float))
    names = _names(content.pop("channel_names")) if "channel_names" in content else None
    if "data" in content:
        raw = np.asarray(content.pop("data"), dtype=float)
        data = np.atleast_2d(raw)
        n = len(names) if names is not None else None
        # MATLAB users keep one column per channel (n_samples × n_channels); NPZ and the HDF5
        # view of a v7.3 file hold (n_channels, n_samples). The channel count decides when known.
        if n is not None:
            if data.shape[0] != n and data.shape[1] == n:
                data = data.T
        elif channels_last and raw.ndim == 2:
            data = data.T
        if names is None:
            names = [f"ch{i}" for i in range(data.shape[0])]
        if len(names) != data.shape[0]:
            raise DataError(f"{_where(path)}channel_names has {len(names)} names for "
                            f"{data.shape[0]} channels of data {data.shape}")
        columns = [(name, row, None) for name, row in zip(names, data)]
    else:
        keys = names if names is not None else [k for k in content if not k.startswith("__")]
        columns = []
        for key in keys:
            if key not in content:
                raise DataError(f"{_where(path)}channel {key!r} listed in channel_names has no "
                                "variable")
            value = np.asarray(content[key])
            if value.dtype.kind not in "fiu":
                continue
            columns.append((key, np.ravel(value), None))
    return columns, dict(time=time if rate is None or time is not None else None,
                         sample_rate=rate if time is None else None, units=units,
                         start_time=start)


def _read_mat(path, *, sample_rate, time_column):
    with open(path, "rb") as handle:
        head = handle.read(128)
    if head.startswith(b"MATLAB 7.3") or head.startswith(b"\x89HDF"):
        return _read_mat73(path, sample_rate=sample_rate, time_column=time_column)
    from scipy.io import loadmat

    try:
        content = loadmat(path, squeeze_me=True, chars_as_strings=True)
    except (ValueError, TypeError, OSError, NotImplementedError) as exc:
        raise DataError(f"{_where(path)}cannot be read as a MATLAB file: {exc}") from None
    content = {k: v for k, v in content.items() if not k.startswith("__")}
    return _from_variables(path, content, sample_rate=sample_rate, time_column=time_column,
                           channels_last=True)


def _h5py():
    try:
        import h5py
    except ImportError:
        raise ImportError("MATLAB v7.3 files need h5py: pip install 'crowdvib[mat73]'") from None
    return h5py


def _read_mat73(path, *, sample_rate, time_column):
    h5py = _h5py()
    content = {}
    with h5py.File(path, "r") as handle:
        for key, item in handle.items():
            if key.startswith("#") or not isinstance(item, h5py.Dataset):
                continue
            value = item[()]
            kind = item.attrs.get("MATLAB_class", b"")
            kind = kind.decode() if isinstance(kind, bytes) else str(kind)
            if kind == "char":
                value = "".join(map(chr, np.ravel(value.T)))
            elif kind == "cell":  # cell array of char: object references
                value = np.array(["".join(map(chr, np.ravel(handle[ref][()].T)))
                                  for ref in np.ravel(value.T)])
            else:
                # HDF5 holds MATLAB's column-major arrays transposed: (n_channels, n_samples)
                # for a MATLAB n_samples × n_channels matrix.
                value = np.asarray(value)
            content[key] = value
    return _from_variables(path, content, sample_rate=sample_rate, time_column=time_column,
                           channels_last=False)


def _read_uff(path, *, sample_rate, time_column):
    try:
        import pyuff
    except ImportError:
        raise ImportError("UFF files need pyuff: pip install 'crowdvib[uff]'") from None
    try:
        sets = pyuff.UFF(str(path)).read_sets()
    except Exception as exc:  # pyuff raises bare Exceptions on malformed files
        raise DataError(f"{_where(path)}cannot be read as a UFF file: {exc}") from None
    sets = [sets] if isinstance(sets, dict) else list(sets)
    sets = [s for s in sets if s.get("type") == 58]
    if not sets:
        raise DataError(f"{_where(path)}holds no UFF type-58 data set")
    columns, units, start = [], None, 0.0
    for number, dset in enumerate(sets):
        name = str(dset.get("id1", "")).strip() or f"ch{number}"
        if dset.get("abscissa_spacing", 1) == 1 and dset.get("abscissa_inc", 0) > 0:
            columns.append((name, np.asarray(dset["data"], dtype=float),
                            1.0 / float(dset["abscissa_inc"])))
            start = float(dset.get("abscissa_min", 0.0))
        else:  # uneven abscissa: check the stamps themselves
            rate = _sample_rate_from_time(dset["x"], path, name)
            columns.append((name, np.asarray(dset["data"], dtype=float), rate))
            start = float(np.ravel(dset["x"])[0])
        label = str(dset.get("ordinate_axis_units_lab", "")).strip()
        if label:
            units = label
    return columns, dict(time=None, sample_rate=sample_rate, units=units, start_time=start)


_READERS = {"csv": _read_csv, "npz": _read_npz, "mat": _read_mat, "mat73": _read_mat73,
            "uff": _read_uff}


def read_record(path, *, format=None, channels=None, units=None, sample_rate=None,
                time_column="time"):
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
    units : {"m/s2", "g"}, optional
        Units of the samples; default the unit stored in the file, else m/s². g → 9.81 m/s².
    sample_rate : float, optional
        Sample rate [Hz] for files without time stamps (CSV without a time column).
    time_column : str
        Name of the time column/variable [s].

    Returns
    -------
    Record
        In m/s²; time stamps are checked (uniform, increasing, no gaps), the samples are not —
        call :func:`check_record`.
    """
    path = Path(path)
    kind = _format_of(path, format)
    if not path.is_file():
        raise DataError(f"{path}: record file not found")
    if sample_rate is not None:
        sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    columns, meta = _READERS[kind](path, sample_rate=sample_rate, time_column=time_column)
    unit = units if units is not None else (meta.get("units") or "m/s2")
    _unit_key(unit, f"{path.name}: ")
    record = _assemble(path, columns, sample_rate=meta.get("sample_rate"), time=meta.get("time"),
                       units=unit, start_time=meta.get("start_time", 0.0))
    return record if channels is None else record.select(channels)


# ------------------------------------------------------------------------------------ writers
def _write_csv(record, path, dtype):
    digits = 8 if np.dtype(dtype) == np.float32 else 17
    columns = np.vstack([record.time, record.data]).T
    with atomic_path(path) as temporary:
        with open(temporary, "w", encoding="utf-8", newline="\n") as handle:
            handle.write(f"# crowdvib record\n# unit = m/s2\n"
                         f"# sample_rate = {record.sample_rate!r}\n")
            handle.write(",".join(("time",) + record.channel_names) + "\n")
            np.savetxt(handle, columns, delimiter=",", fmt=f"%.{digits}g")


def _write_npz(record, path, dtype):
    with atomic_path(path) as temporary:
        with open(temporary, "wb") as handle:
            np.savez_compressed(handle, data=record.data.astype(dtype),
                                channel_names=np.array(record.channel_names),
                                sample_rate=np.float64(record.sample_rate),
                                start_time=np.float64(record.start_time), unit=np.array("m/s2"))


def _write_mat(record, path, dtype):
    from scipy.io import savemat

    with atomic_path(path) as temporary:
        with open(temporary, "wb") as handle:
            savemat(handle, {"data": record.data.T.astype(dtype),
                             "channel_names": np.array(record.channel_names, dtype=object),
                             "sample_rate": record.sample_rate, "start_time": record.start_time,
                             "unit": "m/s2"}, do_compression=True)


def _write_mat73(record, path, dtype):
    h5py = _h5py()

    def char(text):
        # MATLAB stores a char row as uint16 codes in an (n_chars, 1) dataset (column-major).
        return np.array([[ord(c)] for c in text], dtype=np.uint16)

    with atomic_path(path) as temporary:
        with h5py.File(temporary, "w", userblock_size=512) as handle:
            for key, value, kind in (
                    ("data", record.data.astype(dtype), np.dtype(dtype).name),
                    ("channel_names", char(",".join(record.channel_names)), "char"),
                    ("sample_rate", np.array([[record.sample_rate]]), "double"),
                    ("start_time", np.array([[record.start_time]]), "double"),
                    ("unit", char("m/s2"), "char")):
                dataset = handle.create_dataset(key, data=value)
                dataset.attrs["MATLAB_class"] = np.bytes_("single" if kind == "float32" else
                                                          "double" if kind == "float64" else kind)
        # The 512-byte user block carries MATLAB's text header, which tells MATLAB (and us) the
        # file is a v7.3 MAT-file rather than plain HDF5.
        with open(temporary, "r+b") as handle:
            handle.write(_MAT73_HEADER.ljust(116) + b"\x00" * 8 + b"\x00\x02IM")


def _write_uff(record, path, dtype):
    try:
        import pyuff
    except ImportError:
        raise ImportError("UFF files need pyuff: pip install 'crowdvib[uff]'") from None
    step = 1.0 / record.sample_rate
    with atomic_path(path) as temporary:
        writer = pyuff.UFF(str(temporary))
        for number, (name, row) in enumerate(zip(record.channel_names, record.data)):
            dset = pyuff.prepare_58(
                binary=1, id1=name, id2="crowdvib record", func_type=1, rsp_node=number + 1,
                rsp_dir=3, ref_node=0, ref_dir=0, ord_data_type=4,
                abscissa_spacing=1, abscissa_min=record.start_time, abscissa_inc=step,
                z_axis_value=0.0, abscissa_spec_data_type=17, abscissa_len_unit_exp=0,
                abscissa_force_unit_exp=0, abscissa_temp_unit_exp=0, abscissa_axis_units_lab="s",
                ordinate_spec_data_type=12, ordinate_len_unit_exp=1, ordinate_force_unit_exp=0,
                ordinate_temp_unit_exp=0, ordinate_axis_units_lab="m/s2",
                orddenom_spec_data_type=0, orddenom_len_unit_exp=0, orddenom_force_unit_exp=0,
                orddenom_temp_unit_exp=0, orddenom_axis_units_lab="", z_axis_spec_data_type=0,
                z_axis_len_unit_exp=0, z_axis_force_unit_exp=0, z_axis_temp_unit_exp=0,
                z_axis_axis_units_lab="",
                # Always stored as double (pyuff's single-precision path is unreliable); float32
                # records are rounded first, so they read back exactly as written.
                data=np.asarray(row, dtype=dtype).astype(float),
                x=record.start_time + np.arange(row.size) * step)
            writer.write_sets(dset, mode="add")


_WRITERS = {"csv": _write_csv, "npz": _write_npz, "mat": _write_mat, "mat73": _write_mat73,
            "uff": _write_uff}


def write_record(record, path, *, format=None, dtype="float64"):
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
    _WRITERS[kind](record, Path(path), np.dtype(dtype).type)
    return Path(path)
