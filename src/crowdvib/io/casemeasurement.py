"""A case file's ``[measurement]`` table: how its records are read and processed (issue 36 §2
added where the header row is, ``header_row``/``skip_rows``, and what to do with a dropout,
``gaps``/``max_gap``); or its ``[[measurement]]`` blocks, each with its own name and crowd, of
a joint fit of one MSD."""

from ..errors import ParameterError
from ._toml import Table
from .casemodels import _crowd, _crowd_profile
from .casespecs import MeasurementBlock, MeasurementSpec
from .gaps import GAP_MODES
from .records import RECORD_FORMATS
from .units import _unit_key

__all__ = ["measurement_spec", "header_row_of"]


def header_row_of(table):
    """``header_row`` (the header's line number, from 1) or ``skip_rows`` (the lines above it)
    of a record's table, as the line number; None (the reader finds it) when neither is set."""
    header_row = table.count("header_row", None)
    skip_rows = table.count("skip_rows", None, minimum=0)
    if header_row is not None and skip_rows is not None:
        raise table.error("skip_rows", "must not be given with header_row (both say where the "
                          "header row is: header_row = skip_rows + 1)", skip_rows)
    return header_row if skip_rows is None else skip_rows + 1


def measurement_spec(table, path):
    """``[measurement]`` (or one ``[[measurement]]`` block's keys) → :class:`MeasurementSpec`."""
    files = table.strings("files", ())
    # Existence is checked when the records are read (load_measurement): `crowdvib simulate`
    # writes them from the same case file.
    resolved = [(path.parent / name).resolve() for name in files]
    channels = table.raw("channels", None)
    if channels is not None and (not isinstance(channels, dict) or not all(
            isinstance(v, str) for v in channels.values())):
        raise table.error("channels", "must be a table output_name = \"channel in file\"",
                          channels)
    units = table.string("units", None)
    if units is not None:
        _unit_key(units, f"{path.name}: measurement.")
    # Where a logger's header row is, below its metadata lines (default: found in the file).
    header_row = header_row_of(table)
    gaps = table.string("gaps", None, choices=GAP_MODES)
    max_gap = table.number("max_gap", 0.1, rule="positive")
    frame = table.raw("time_frame", None)
    if frame is not None and frame != "stationary" and frame != "all":
        frame = table.pair("time_frame")
        if frame[0] < 0:
            raise table.error("time_frame", "must start at t >= 0 s", list(frame))
    frame = None if frame == "all" else frame
    filter_table = table.table("filter")
    cutoff = filter_table.raw("cutoff", 10.0)
    cutoff = None if cutoff is False else filter_table.number("cutoff", 10.0, rule="positive")
    order = filter_table.number("order", 4.0, rule="positive")
    if int(order) != order:
        raise filter_table.error("order", "must be an integer", order)
    filter_table.finish()
    overlap = table.number("overlap", 0.5, rule="non_negative")
    if not overlap < 1:
        raise table.error("overlap", "must lie in [0, 1)", overlap)
    spec = MeasurementSpec(
        files=tuple(resolved), format=table.string("format", None, choices=tuple(RECORD_FORMATS)),
        channels=channels, units=units,
        sample_rate=table.number("sample_rate", None, rule="positive"),
        time_column=table.string("time_column", "time"), time_frame=frame,
        lowpass_cutoff=cutoff, lowpass_order=int(order),
        resample=table.number("resample", None, rule="positive"),
        window_length=table.number("window_length", 60.0, rule="positive"), overlap=overlap,
        detrend=table.string("detrend", "constant", choices=("constant", "linear")),
        header_row=header_row, gaps=gaps, max_gap=max_gap)
    table.finish()
    return spec


# -------------------------------------------------------- several measurements (joint fit)
def _measurement_block(table, path, crowd, number, structure):
    """One ``[[measurement]]`` block: its name, its own crowd (default the case's, stationary),
    with its counts or density profile if it has them, and the keys of ``[measurement]``."""
    name = table.string("name", f"record {number}")
    profile, reference = None, crowd.density
    if table.has("crowd"):
        crowd_table = table.table("crowd")
        profile = _crowd_profile(crowd_table, path, structure)
        crowd, reference = _crowd(crowd_table, path, profile)
    measurement = measurement_spec(table, path)
    _check_profile_frame(profile, measurement, path, f"measurement[{number}].crowd",
                         "its [[measurement]] block")
    return MeasurementBlock(name=name, measurement=measurement, crowd=crowd,
                            reference_density=reference)


def _check_profile_frame(profile, measurement, path, where, measured_by):
    """A crowd profile is on its record's time, and the estimator places Welch windows at
    overlap 0.5 over it: refuse a stationary time frame or another overlap."""
    if profile is not None and (measurement.time_frame == "stationary"
                                or measurement.overlap != 0.5):
        raise ParameterError(
            f"{path.name}: {where}.counts or {where}.density_profile must come with "
            f"{measured_by} whose time_frame is the whole record or [start, end] (the profile "
            "is on the record's time) and Welch windows at overlap 0.5 (as the estimator "
            "places them), got " + ('time_frame = "stationary"'
                                    if measurement.time_frame == "stationary"
                                    else f"overlap = {measurement.overlap:g}"))


def _measurements(root, path, crowd, structure):
    """``[measurement]`` → (spec, ()); ``[[measurement]]`` blocks → (first spec, blocks)."""
    blocks = root.raw("measurement", {})
    if not isinstance(blocks, list):
        return measurement_spec(root.table("measurement"), path), ()
    if not blocks:
        raise root.error("measurement", "must hold at least one [[measurement]] block", blocks)
    records = tuple(_measurement_block(Table(block, f"measurement[{i}]", path), path, crowd, i,
                                       structure)
                    for i, block in enumerate(blocks, start=1))
    names = [block.name for block in records]
    if len(set(names)) != len(names):
        raise root.error("measurement", "blocks must have distinct names", names)
    return records[0].measurement, records
