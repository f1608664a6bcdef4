"""The ambient-test file of ``crowdvib modes`` (its format: docs, Case files, Ambient-test
files, whose key table is generated from this module's reads): the records, one per setup, the
identification options and the modal-model table, every key checked through
:class:`crowdvib.io._toml.Table` and refused with the file and key named."""

from pathlib import Path

from ..errors import ParameterError

from ._toml import Table, read_toml
from .casemeasurement import header_row_of
from .units import unit_key
from .records import RECORD_FORMATS, read_record

__all__ = ["read_ambient"]


def _records(root):
    """One ``[record]`` table, or several ``[[record]]`` blocks (setups)."""
    blocks = root.raw("record")
    tables = ([Table(b, f"record[{i}]", root.path) for i, b in enumerate(blocks, start=1)]
              if isinstance(blocks, list) else [root.table("record", required=True)])
    if not tables:
        raise root.error("record", "must hold at least one [[record]] block", blocks)
    records = []
    for table in tables:
        channels = table.raw("channels", None)
        if channels is not None and not isinstance(channels, dict):
            channels = table.strings("channels", None)
        elif channels is not None and not all(isinstance(v, str) for v in channels.values()):
            raise table.error("channels", "must be a list of channels or a table sensor = "
                                          "\"channel in file\"", channels)
        # The reader of a case file's [measurement], with its keys: format, units, time column.
        units = table.string("units", None)
        if units is not None and unit_key(units) is None:
            raise table.error("units", "must be 'm/s2', 'g', 'mg' or 'mm/s2'", units)
        records.append(read_record(
            table.file("file"), format=table.string("format", None,
                                                    choices=tuple(RECORD_FORMATS)),
            channels=channels, units=units,
            sample_rate=table.number("sample_rate", None, rule="positive"),
            time_column=table.string("time_column", "time"), header_row=header_row_of(table)))
        table.finish()
    return records


def read_ambient(path):
    """The ambient file's records (one per setup), identification options and modal-model
    table (checked); the keys are those of docs, Case files, Ambient-test files."""
    path = Path(path)
    root = Table(read_toml(path), "", path)
    _refuse_case_file(root, path)
    name = root.string("name", path.stem)
    records = _records(root)
    ident = root.table("identification")
    options = {"n_modes": _count(ident, "n_modes", None, 1),
               "frequency_band": ident.pair("frequency_band", None),
               # SSI-cov's order and block rows: chosen from n_modes and the band unless given
               "max_order": _count(ident, "max_order", None, 2),
               "block_rows": _count(ident, "block_rows", None, 2),
               "method": ident.string("method", "ssi-cov", choices=("ssi-cov", "efdd")),
               "cross_check": ident.boolean("cross_check", False),
               "segment_length": _count(ident, "segment_length", None, 64)}
    references = ident.strings("reference_channels", None)
    if len(records) > 1:
        if references is None:
            raise ident.error("reference_channels", "is required with several [[record]] "
                                                    "blocks (the channels they share)", None)
        options["reference_sensors"] = _reference_rows(records, references, ident)
    elif references is not None:
        raise ident.error("reference_channels", "needs several [[record]] blocks", references)
    ident.finish()
    if len({r.sample_rate for r in records}) > 1:
        raise root.error("record", "blocks must share one sample rate",
                         [r.sample_rate for r in records])
    model = root.table("modal_model")
    spec = None
    if model.data:
        spec = {"width": model.number("width", rule="positive"),
                "fe_model": model.file("fe_model", None),
                "output_nodes": _output_nodes(model),
                "modal_masses": model.numbers("modal_masses", None, rule="positive"),
                "sensor_positions": model.numbers("sensor_positions", None),
                "walkway": model.pair("walkway", None)}
        model.finish()
    root.finish()
    return name, records, options, spec


#: Tables of a case file that an ambient-test file never holds.
_CASE_TABLES = ("structure", "crowd", "measurement", "hsi", "estimation", "design", "simulation")


def _refuse_case_file(root, path):
    """A case file given for an ambient-test file is named as one (issue 36 §3: its tables were
    answered key by key, "record is required", "found 'report': misspelt?")."""
    found = [key for key in _CASE_TABLES if root.has(key)]
    if found and not root.has("record"):
        raise ParameterError(
            f"{path.name}: is a case file ({', '.join(f'[{key}]' for key in found)}), not an "
            "ambient-test file: crowdvib modes reads an ambient record's [record] and "
            "[identification] (docs: Case files, Ambient-test files); a case file goes to "
            "crowdvib estimate, check, simulate or season")


def _count(table, name, default, least):
    """A count of the file as int: 2.5 modes is refused, not cut to 2."""
    value = table.number(name, default)
    if value is not None and (int(value) != value or value < least):
        raise table.error(name, f"must be an integer >= {least}", value)
    return None if value is None else int(value)


def _reference_rows(records, references, table):
    rows = []
    for s, record in enumerate(records, start=1):
        missing = [c for c in references if c not in record.channel_names]
        if missing:
            raise table.error("reference_channels", f"must name channels of every record; "
                                                    f"record {s} lacks {missing}", references)
        rows.append([record.channel_names.index(c) for c in references])
    return rows


def _output_nodes(table):
    nodes = table.raw("output_nodes", None)
    if nodes is not None and not (isinstance(nodes, dict) and all(
            isinstance(v, int) and not isinstance(v, bool) for v in nodes.values())):
        raise table.error("output_nodes", "must be a table of sensor = node number", nodes)
    return nodes
