"""One reader and one writer per record file format (architecture §1; issue 9).

A reader returns the file's channels as ``(name, samples, sample_rate or None)`` and a dict of
its time base (``time`` or ``sample_rate``, ``units``, ``start_time``);
:func:`crowdvib.io.records.read_record` turns them into a checked :class:`Record`, inside one guard
that makes every failure a :class:`DataError` naming the file. The readers refuse what they
would otherwise have to guess: arrays of rank above 2, text where numbers belong, UFF data sets
cut short.

File layouts written (and read) by crowdvib
-------------------------------------------
CSV
    Optional ``#`` comment lines (``# unit = g``, ``# sample_rate = 100``), one header line of
    column names, one row per sample. A ``time`` column [s] gives the time stamps; without it the
    sample rate must be given (case file ``measurement.sample_rate``).
NPZ
    ``data`` (n_channels, n_samples) with ``channel_names``, or one array per channel;
    ``sample_rate`` [Hz] or ``time`` [s]; optional ``unit`` and ``start_time`` [s].
MAT (v5 and v7.3)
    The same variables; ``data`` is n_samples × n_channels in MATLAB (one column per channel);
    ``channel_names`` is a comma-separated char row (v7.3) or a cell array / char matrix (v5).
UFF 58
    One function-at-nodal-DOF data set per channel (function type 1, time response), the channel
    name in ID line 1, even abscissa spacing (Δt) and the unit in the ordinate-axis label.
"""

import re
import warnings
from pathlib import Path

import numpy as np

from .._files import atomic_path
from ..errors import DataError
from ._common import quote, sample_rate_from_time, where
from ._matv5 import check_mat_v5

__all__ = ["READERS", "WRITERS"]

_MAT73_HEADER = b"MATLAB 7.3 MAT-file, Platform: crowdvib, Created by: crowdvib HDF5 schema 1.00 ."
# A UFF data set starts and ends with the tag "    -1" closing a line (binary data run up to the
# end tag); pyuff pairs the tags as it finds them and drops an unpaired last one.
_UFF_TAG = re.compile(rb"    -1(?=[\r\n]|\Z| {74})")


# ------------------------------------------------------------------------- values of variables
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


def _numbers(path, key, value, *, max_ndim):
    """A variable as a float array; text, complex or boolean values and ranks above
    ``max_ndim`` are refused rather than reinterpreted."""
    array = np.asarray(value)
    if array.dtype.kind not in "fiu":
        raise DataError(f"{where(path)}{key} must hold real numbers, got {array.dtype.name} "
                        f"values of shape {array.shape}")
    if array.ndim > max_ndim:
        raise DataError(f"{where(path)}{key} must have at most {max_ndim} dimension(s), got shape "
                        f"{array.shape}: refusing to guess how it holds channels and samples")
    return array.astype(float)


def _vector(path, key, value):
    """A 1-D series: 1 × n and n × 1 matrices (MATLAB vectors) are flattened, others refused."""
    array = _numbers(path, key, value, max_ndim=2)
    if array.ndim == 2 and min(array.shape) > 1:
        raise DataError(f"{where(path)}{key} must be a vector, got shape {array.shape}")
    return array.ravel()


def _scalar(path, key, value):
    array = _numbers(path, key, value, max_ndim=2)
    if array.size != 1:
        raise DataError(f"{where(path)}{key} must be one number, got shape {array.shape}")
    return float(array.ravel()[0])


# ---------------------------------------------------------------------------------------- CSV
def _first_bad_line(path, skip, header):
    """Why the rows below the header are not a table of numbers (only run after a failure)."""
    with open(path, encoding="utf-8") as handle:
        row = -1
        for number, line in enumerate(handle, start=1):
            text = line.split("#", 1)[0].strip()
            if number <= skip or not text:
                continue
            row += 1
            cells = text.split(",")
            if len(cells) != len(header):
                return (f"line {number} (sample index {row}) has {len(cells)} field(s), the header "
                        f"names {len(header)} column(s)")
            for name, cell in zip(header, cells):
                try:
                    float(cell)
                except ValueError:
                    return (f"line {number} (sample index {row}), column {quote(name)}: "
                            f"{quote(cell.strip())} is not a number")
    return "its rows are not all numbers"


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
        raise DataError(f"{where(path)}has no header line of column names")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")   # numpy warns on a table without rows: refused below
            values = np.loadtxt(path, delimiter=",", skiprows=skip, ndmin=2, comments="#",
                                dtype=float, encoding="utf-8")
    except ValueError as exc:
        # numpy's message quotes the whole offending row: name the line and cell instead.
        raise DataError(f"{where(path)}cannot be read as a table of numbers: "
                        f"{_first_bad_line(path, skip, header)}") from exc
    if values.size == 0:
        raise DataError(f"{where(path)}has no rows of numbers below its header line")
    if values.shape[1] != len(header):
        raise DataError(f"{where(path)}has {values.shape[1]} columns of data but {len(header)} "
                        "names in its header line")
    time = None
    if time_column in header:
        time = values[:, header.index(time_column)]
    columns = [(name, values[:, i], None) for i, name in enumerate(header) if name != time_column]
    rate = sample_rate
    if rate is None and time is None and "sample_rate" in meta:
        try:
            rate = float(meta["sample_rate"])
        except ValueError:
            raise DataError(f"{where(path)}comment 'sample_rate' must be a number, got "
                            f"{quote(meta['sample_rate'])}") from None
    return columns, dict(time=None if rate is not None and time is None else time,
                         sample_rate=rate if time is None else None,
                         units=meta.get("unit"))


# --------------------------------------------------------------------------------- NPZ and MAT
def _read_npz(path, *, sample_rate, time_column):
    with np.load(path, allow_pickle=False) as archive:
        content = {key: archive[key] for key in archive.files}
    return _from_variables(path, content, sample_rate=sample_rate, time_column=time_column,
                           channels_last=False)


def _from_variables(path, content, *, sample_rate, time_column, channels_last):
    """Channels and time base from a dict of variables (NPZ, MAT)."""
    units = _string(content.pop("unit")) if "unit" in content else None
    start = _scalar(path, "start_time", content.pop("start_time")) if "start_time" in content \
        else 0.0
    rate = content.pop("sample_rate", None)
    rate = _scalar(path, "sample_rate", rate) if rate is not None else sample_rate
    time = content.pop(time_column, None)
    time = None if time is None else _vector(path, time_column, time)
    names = _names(content.pop("channel_names")) if "channel_names" in content else None
    if "data" in content:
        raw = _numbers(path, "data", content.pop("data"), max_ndim=2)
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
            raise DataError(f"{where(path)}channel_names has {len(names)} names for "
                            f"{data.shape[0]} channels of data {data.shape}")
        columns = [(name, row, None) for name, row in zip(names, data)]
    else:
        keys = names if names is not None else [k for k in content if not k.startswith("__")]
        columns = []
        for key in keys:
            if key not in content:
                raise DataError(f"{where(path)}channel {quote(key)} listed in channel_names has "
                                "no variable")
            value = np.asarray(content[key])
            if names is None and value.dtype.kind not in "fiu":
                continue   # other variables (text, structs) are not channels
            columns.append((key, _vector(path, f"channel {quote(key)}", value), None))
    return columns, dict(time=time if rate is None or time is not None else None,
                         sample_rate=rate if time is None else None, units=units,
                         start_time=start)


def _read_mat(path, *, sample_rate, time_column):
    with open(path, "rb") as handle:
        head = handle.read(128)
    if head.startswith(b"MATLAB 7.3") or head.startswith(b"\x89HDF"):
        return _read_mat73(path, sample_rate=sample_rate, time_column=time_column)
    from scipy.io import loadmat

    # scipy may crash the interpreter on a damaged file: walk it first, read what passed.
    names = check_mat_v5(path)
    content = loadmat(path, squeeze_me=True, chars_as_strings=True, variable_names=names)
    content = {k: v for k, v in content.items() if not k.startswith("__")}
    return _from_variables(path, content, sample_rate=sample_rate, time_column=time_column,
                           channels_last=True)


def _h5py():
    try:
        import h5py
    except ImportError:
        raise ImportError("MATLAB v7.3 files need h5py: pip install 'crowdvib[mat73]'") from None
    return h5py


def _matlab_chars(value):
    return "".join(map(chr, np.ravel(np.asarray(value).T)))


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
                value = _matlab_chars(value)
            elif kind == "cell":  # cell array of char: object references
                value = np.array([_matlab_chars(handle[ref][()]) for ref in np.ravel(value.T)])
            else:
                # HDF5 holds MATLAB's column-major arrays transposed: (n_channels, n_samples)
                # for a MATLAB n_samples × n_channels matrix.
                value = np.asarray(value)
            content[key] = value
    return _from_variables(path, content, sample_rate=sample_rate, time_column=time_column,
                           channels_last=False)


# ------------------------------------------------------------------------------------- UFF 58
def _pyuff():
    try:
        import pyuff
    except ImportError:
        raise ImportError("UFF files need pyuff: pip install 'crowdvib[uff]'") from None
    return pyuff


def _check_uff_complete(path):
    """Refuse a file whose last data set has no end tag: pyuff would silently drop it (a
    truncated file would lose its last channel, issue 9)."""
    content = Path(path).read_bytes()
    tags = list(_UFF_TAG.finditer(content))
    if len(tags) % 2:
        lines = content[tags[-1].end():].lstrip(b"\r\n").splitlines()
        name = lines[1].decode("utf-8", "replace").strip() if len(lines) > 1 else "?"
        raise DataError(f"{where(path)}data set {len(tags) // 2 + 1} (channel {quote(name)}) is "
                        "incomplete: the file ends before its end tag (truncated file?)")


def _read_uff(path, *, sample_rate, time_column):
    _check_uff_complete(path)       # before pyuff, which may fail less clearly on it
    sets = _pyuff().UFF(str(path)).read_sets()
    sets = [sets] if isinstance(sets, dict) else list(sets)
    sets = [s for s in sets if s.get("type") == 58]
    if not sets:
        raise DataError(f"{where(path)}holds no UFF type-58 data set")
    columns, units, start = [], None, 0.0
    for number, dset in enumerate(sets):
        name = str(dset.get("id1", "")).strip() or f"ch{number}"
        if dset.get("ord_data_type") not in (2, 4):
            raise DataError(f"{where(path, name)}ordinate data type {dset.get('ord_data_type')} "
                            "is not real (2 or 4): not an acceleration time series")
        samples = np.asarray(dset["data"], dtype=float)
        declared = dset.get("num_pts")
        if declared != samples.size:
            raise DataError(f"{where(path, name)}the header declares {declared} samples, the data "
                            f"set holds {samples.size} (truncated or damaged file?)")
        if dset.get("abscissa_spacing", 1) == 1 and dset.get("abscissa_inc", 0) > 0:
            columns.append((name, samples, 1.0 / float(dset["abscissa_inc"])))
            start = float(dset.get("abscissa_min", 0.0))
        else:  # uneven abscissa: check the stamps themselves
            rate = sample_rate_from_time(dset["x"], path, name)
            columns.append((name, samples, rate))
            start = float(np.ravel(dset["x"])[0])
        label = str(dset.get("ordinate_axis_units_lab", "")).strip()
        if label:
            units = label
    return columns, dict(time=None, sample_rate=sample_rate, units=units, start_time=start)


READERS = {"csv": _read_csv, "npz": _read_npz, "mat": _read_mat, "mat73": _read_mat73,
           "uff": _read_uff}


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
    pyuff = _pyuff()
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


WRITERS = {"csv": _write_csv, "npz": _write_npz, "mat": _write_mat, "mat73": _write_mat73,
           "uff": _write_uff}
