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
    Optional ``#`` comment lines (``# unit = g``, ``# sample_rate = 100``, ``# time_column =
    time``), one header line of column names (RFC 4180 quoting), one row per sample. Columns are
    separated by ``,``, or by ``;`` or tab, which allow decimal commas (``1,5``). The time column
    [s] is the one named by ``time_column`` or the comment, else ``time``, else the one usual time
    header (``t``, ``Time [s]``, ``time_s``, ``Zeit``, ``temps``, ``Tijd`` …); without one the
    sample rate must be given (case file ``measurement.sample_rate``), and with one a stated
    sample rate must agree with it. crowdvib writes a channel name a spreadsheet would take for
    a formula (first character ``= + - @``) behind a ``'``, which the reader takes off again.
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
from collections.abc import Callable
from pathlib import Path
from typing import NamedTuple

import numpy as np

from .._files import atomic_path
from .._resources import check_declared_size
from ..errors import DataError, ParameterError
from ._common import (MAX_CHANNELS, quote, refuse_transposed, sample_rate_from_time, stated_rate,
                      where)
from ._matv5 import check_mat_v5
from .csvformat import _read_csv, _write_csv, read_table_cells
from .headers import time_key

__all__ = ["FileFormat", "FORMATS", "register_format", "file_formats", "suffix_format",
           "check_names", "read_table_cells", "refuse_transposed", "MAX_CHANNELS"]

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


def _samples(path, key, value):
    """Accelerations as stored: integers are refused, they are a logger's raw ADC counts, and
    taking counts for m/s² would be silently wrong by the sensor's sensitivity (issue 24)."""
    dtype = np.asarray(value).dtype
    if dtype.kind in "iu":
        raise DataError(f"{where(path)}{key} holds {dtype.name} samples, the raw counts of a "
                        "logger rather than accelerations: scale them to m/s² (or g) with the "
                        "sensor's sensitivity and store them as floating point")
    return value


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


# --------------------------------------------------------------------------------- NPZ and MAT
def _read_npz(path, *, sample_rate, time_column):
    _check_npz_sizes(path)
    with np.load(path, allow_pickle=False) as archive:
        content = {key: archive[key] for key in archive.files}
    return _from_variables(path, content, sample_rate=sample_rate, time_column=time_column,
                           channels_last=False)


def _check_npz_sizes(path):
    """Every array of an NPZ file no larger than the file can hold, judged from the .npy headers
    before numpy allocates what they declare (a 2.5 KB file once declared 10.7 GB)."""
    import zipfile

    from numpy.lib import format as npy

    prefix, size, total = where(path), Path(path).stat().st_size, 0
    with zipfile.ZipFile(path) as archive:
        for info in archive.infolist():
            if not info.filename.endswith(".npy"):
                continue
            label = f"array {quote(info.filename[:-4])}"
            with archive.open(info) as member:
                version = npy.read_magic(member)
                if version not in ((1, 0), (2, 0)):
                    raise DataError(f"{prefix}{label} is a .npy of version {version}, not 1.0 "
                                    "or 2.0")
                read = npy.read_array_header_1_0 if version == (1, 0) \
                    else npy.read_array_header_2_0
                shape, _, dtype = read(member)
                header = member.tell()
            # What the member holds after its header: the zip's own size of it, and for a
            # member stored as it is, no more than the file itself.
            held = info.file_size - header
            if info.compress_type == zipfile.ZIP_STORED:
                held = min(held, size - header)
            total += check_declared_size(
                prefix, label, shape, dtype.itemsize, stored=held,
                compressed=None if info.compress_type == zipfile.ZIP_STORED
                else info.compress_size)
    check_declared_size(prefix, "its arrays together", (total,), 1)


def _from_variables(path, content, *, sample_rate, time_column, channels_last):
    """Channels and time base from a dict of variables (NPZ, MAT)."""
    units = _string(content.pop("unit")) if "unit" in content else None
    start = _scalar(path, "start_time", content.pop("start_time")) if "start_time" in content \
        else 0.0
    stored = content.pop("sample_rate", None)
    stored = None if stored is None else _scalar(path, "sample_rate", stored)
    rate, source = stated_rate(path, sample_rate, stored, "its variable 'sample_rate'")
    time_name = time_key(path, [k for k in content if not k.startswith("__")], time_column)
    time = None if time_name is None else _vector(path, time_name, content.pop(time_name))
    names = _names(content.pop("channel_names")) if "channel_names" in content else None
    if "data" in content:
        raw = _numbers(path, "data", _samples(path, "data", content.pop("data")), max_ndim=2)
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
            label = f"channel {quote(key)}"
            columns.append((key, _vector(path, label, _samples(path, label, value)), None))
    return columns, dict(time=time, time_name=time_name, sample_rate=rate, rate_source=source,
                         units=units, start_time=start)


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


def _install(name):
    """How to get a record format's optional dependency (the table's ``extra``)."""
    return f"pip install 'crowdvib[{FORMATS['record', name].extra}]'"


def _h5py():
    try:
        import h5py
    except ImportError:
        raise ImportError(f"MATLAB v7.3 files need h5py: {_install('mat73')}") from None
    return h5py


def _matlab_chars(value):
    return "".join(map(chr, np.ravel(np.asarray(value).T)))


def _read_mat73(path, *, sample_rate, time_column):
    h5py = _h5py()
    content = {}
    size = Path(path).stat().st_size
    with h5py.File(path, "r") as handle:
        for key, item in handle.items():
            if key.startswith("#") or not isinstance(item, h5py.Dataset):
                continue
            value = _dataset(path, key, item, size)
            kind = item.attrs.get("MATLAB_class", b"")
            kind = kind.decode() if isinstance(kind, bytes) else str(kind)
            if kind == "char":
                value = _matlab_chars(value)
            elif kind == "cell":  # cell array of char: object references
                value = np.array([_matlab_chars(_dataset(path, key, handle[ref], size))
                                  for ref in np.ravel(value.T)])
            else:
                # HDF5 holds MATLAB's column-major arrays transposed: (n_channels, n_samples)
                # for a MATLAB n_samples × n_channels matrix.
                value = np.asarray(value)
            content[key] = value
    return _from_variables(path, content, sample_rate=sample_rate, time_column=time_column,
                           channels_last=False)


def _dataset(path, key, item, size):
    """An HDF5 dataset's values, once its declared size is one the file can hold: the bytes
    stored for it (no more than the file), or with a filter (compression) what deflate expands
    them to. A dataset whose storage was never written reads as its fill value, as large as
    declared: refused too."""
    stored = min(item.id.get_storage_size(), size)
    filtered = item.id.get_create_plist().get_nfilters() > 0
    check_declared_size(where(path), f"variable {quote(key)}", item.shape or (),
                        item.dtype.itemsize, stored=None if filtered else stored,
                        compressed=stored if filtered else None)
    return item[()]


# ------------------------------------------------------------------------------------- UFF 58
def _pyuff():
    try:
        import pyuff
    except ImportError:
        raise ImportError(f"UFF files need pyuff: {_install('uff')}") from None
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
    return columns, dict(time=None, sample_rate=sample_rate, units=units, start_time=start,
                         rate_source="the given sample_rate (measurement.sample_rate)")




# ------------------------------------------------------------------------------------ writers
# ------------------------------------------------------------------------------------ writers
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


def check_names(names, kind):
    """Refuse, before writing, a channel name the format's reader could not give back."""
    for number, name in enumerate(names):
        if name != name.strip():
            rule = "must not start or end with blanks (the readers drop them)"
        elif kind == "mat73" and "," in name:
            rule = "must not hold a comma (a MATLAB v7.3 file keeps the names as one text)"
        elif kind in ("mat", "uff") and not name:
            rule = "must not be empty (MATLAB v5 stores it as [], UFF reads it as ch<n>)"
        elif kind == "uff" and (len(name) > 80 or "\n" in name or "\r" in name):
            rule = "must fit the 80 characters of one UFF ID line"
        else:
            continue
        raise ParameterError(f"channel_names[{number}] {rule} in {kind} format, got "
                             f"{quote(name)}: rename it, or write CSV or NPZ")


# ------------------------------------------------------------------------- the formats table
class FileFormat(NamedTuple):
    """One row of the table of file formats crowdvib reads and writes (issue 26 §3)."""

    #: What the format is called (``format=`` of read_record, ``measurement.format``).
    name: str
    #: What the file holds: "record" (acceleration channels) or "modes" (a modal model).
    data: str
    #: File suffixes, lower case; the first is the one written (empty: chosen by name only).
    suffixes: tuple
    #: How messages name a file of it ("a CSV").
    description: str
    #: The reader; for records ``reader(path, *, sample_rate, time_column)`` → (columns, meta).
    reader: Callable
    #: The writer, or None; for records ``writer(record, path, dtype)``.
    writer: Callable | None = None
    #: The pip extra the format needs (``pip install 'crowdvib[extra]'``), or None.
    extra: str | None = None


#: Every format, keyed by (data, name): records here, modal files registered by modalfiles.py.
FORMATS: dict[tuple[str, str], FileFormat] = {}


def register_format(row: FileFormat) -> FileFormat:
    """Add a row to :data:`FORMATS` (a format of the same data and name is replaced)."""
    FORMATS[row.data, row.name] = row
    return row


def file_formats(data: str) -> dict[str, FileFormat]:
    """The formats of one kind of data ("record" or "modes"), by name, in table order."""
    return {name: row for (kind, name), row in FORMATS.items() if kind == data}


def suffix_format(path, data: str) -> FileFormat | None:
    """The format of ``data`` whose suffixes hold ``path``'s suffix (case-blind), or None."""
    suffix = Path(path).suffix.lower()
    return next((row for row in file_formats(data).values() if suffix in row.suffixes), None)


for _row in (FileFormat("csv", "record", (".csv", ".txt"), "a CSV", _read_csv, _write_csv),
             FileFormat("npz", "record", (".npz",), "an NPZ", _read_npz, _write_npz),
             FileFormat("mat", "record", (".mat",), "a MATLAB", _read_mat, _write_mat),
             # v7.3 shares .mat with v5: read_record tells them apart by the header.
             FileFormat("mat73", "record", (), "a MATLAB v7.3", _read_mat73, _write_mat73,
                        "mat73"),
             FileFormat("uff", "record", (".uff", ".unv"), "a UFF 58", _read_uff, _write_uff,
                        "uff")):
    register_format(_row)
