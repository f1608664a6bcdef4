"""``crowdvib modes AMBIENT.toml``: the empty bridge's modes from an ambient record (OMA).

The ambient file (TOML, paths relative to it)::

    name = "my footbridge, ambient test"

    [record]                        # read_record: CSV, NPZ, MAT or UFF 58
    file = "ambient.csv"
    channels = ["s1", "s2", "s3"]   # optional: the sensors, in order (default all channels)
    sample_rate = 50.0              # optional: for a CSV without a time column [Hz]

    [identification]                # identify_modes (SSI-cov, pyOMA2)
    n_modes = 3                     # optional (default every consistently stable mode)
    frequency_band = [1.0, 9.0]     # optional [Hz]
    max_order = 40                  # optional

    [modal_model]                   # optional: the ModalModel to write (OMA gives no masses)
    fe_model = "bridge.uff"         #   an FE export (UFF 15 + 55) whose output_nodes are the
    output_nodes = { s1 = 101 }     #   sensors (identified f, ξ replace the paired FE modes), or
    # modal_masses = [5e4, 4e4]     #   stated masses [kg] with sensor_positions = [...] [m]
    # walkway = [0.0, 50.0]         #   and the walkway's ends [m] (coarse shapes)
    width = 3.0                     #   walkway width [m]

Writes ``modes.csv`` (f, ξ and their standard deviations per mode), ``mode_shapes.csv`` (at the
sensors), ``stabilisation.png``, the modal-model CSV files when ``[modal_model]`` is given,
``results.json`` and ``report.html``.
"""

import csv
import time
from pathlib import Path

from .. import __version__
from .._files import write_json
from ..reporting.report import write_report
from .common import add_output_arguments, say, say_verdict, staged_output, versions


def add_arguments(parser):
    parser.add_argument("ambient", type=Path, help="ambient-test file (TOML)")
    add_output_arguments(parser)


def read_ambient(path):
    """The ambient file's record, identification options and modal-model table (checked)."""
    from ..io._toml import Table, read_toml
    from ..io.records import read_record

    path = Path(path)
    root = Table(read_toml(path), "", path)
    name = root.string("name", path.stem)
    record_table = root.table("record", required=True)
    record = read_record(record_table.file("file"),
                         channels=record_table.strings("channels", None),
                         sample_rate=record_table.number("sample_rate", None, rule="positive"))
    record_table.finish()
    ident = root.table("identification")
    n_modes = ident.number("n_modes", None, rule="positive")
    options = {"n_modes": None if n_modes is None else int(n_modes),
               "frequency_band": ident.pair("frequency_band", None),
               "max_order": int(ident.number("max_order", 40.0, rule="positive"))}
    ident.finish()
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
    return name, record, options, spec


def _output_nodes(table):
    nodes = table.raw("output_nodes", None)
    if nodes is not None and not (isinstance(nodes, dict) and all(
            isinstance(v, int) and not isinstance(v, bool) for v in nodes.values())):
        raise table.error("output_nodes", "must be a table of sensor = node number", nodes)
    return nodes


def _modal_model(modes, spec):
    from ..io.modalfiles import read_modal_model

    if spec["fe_model"] is not None:
        fe = read_modal_model(spec["fe_model"], width=spec["width"],
                              output_nodes=spec["output_nodes"])
        return modes.modal_model(fe)
    return modes.modal_model(modal_masses=spec["modal_masses"],
                             sensor_positions=spec["sensor_positions"],
                             walkway=spec["walkway"], width=spec["width"])


def run(args):
    from ..identification.oma import identify_modes
    from ..io.modalfiles import write_modal_model
    from ..reporting.plotting import save_figure

    name, record, options, spec = read_ambient(args.ambient)
    say(f"crowdvib modes: {name}, {record.n_channels} sensor(s), {record.duration:g} s at "
        f"{record.sample_rate:g} Hz")
    with staged_output(args.out, args.force, command="modes",
                       inputs=[("the ambient file", args.ambient)]) as staging:
        started = time.perf_counter()
        modes = identify_modes(record.data, record.sample_rate,
                               sensor_names=record.channel_names, **options)
        elapsed = time.perf_counter() - started
        with open(staging / "modes.csv", "w", encoding="utf-8", newline="") as handle:
            writer = csv.writer(handle, lineterminator="\n")
            writer.writerow(["mode", "frequency", "frequency_std", "damping_ratio",
                             "damping_std"])
            for j in range(modes.n_modes):
                writer.writerow([f"mode_{j + 1}", f"{modes.frequencies[j]:.10g}",
                                 f"{modes.frequency_std[j]:.10g}",
                                 f"{modes.damping_ratios[j]:.10g}",
                                 f"{modes.damping_std[j]:.10g}"])
        with open(staging / "mode_shapes.csv", "w", encoding="utf-8", newline="") as handle:
            writer = csv.writer(handle, lineterminator="\n")
            writer.writerow(["sensor"] + [f"mode_{j + 1}" for j in range(modes.n_modes)])
            for sensor, row in zip(modes.sensor_names, modes.mode_shapes):
                writer.writerow([sensor] + [f"{v:.10g}" for v in row])
        figure = save_figure(modes.plot_stabilisation(), staging / "stabilisation.png").name
        files = ["modes.csv", "mode_shapes.csv"]
        if spec is not None:
            structure = _modal_model(modes, spec)
            write_modal_model(structure, staging / "modal_table.csv",
                              staging / "modal_shapes.csv", staging / "output_points.csv")
            files += ["modal_table.csv", "modal_shapes.csv", "output_points.csv"]
        results = {"command": "modes", "crowdvib_version": __version__, "versions": versions(),
                   "ambient": str(args.ambient), "name": name,
                   "modes": [{"frequency": float(modes.frequencies[j]),
                              "frequency_std": float(modes.frequency_std[j]),
                              "damping_ratio": float(modes.damping_ratios[j]),
                              "damping_std": float(modes.damping_std[j])}
                             for j in range(modes.n_modes)],
                   "files": files, "figures": [figure], "elapsed_s": elapsed}
        write_json(staging / "results.json", results)
        write_report(staging)
    for j in range(modes.n_modes):
        say(f"  mode {j + 1}: f = {modes.frequencies[j]:.4f} ± {modes.frequency_std[j]:.4f} Hz, "
            f"ξ = {modes.damping_ratios[j]:.4f} ± {modes.damping_std[j]:.4f}")
    say(f"  wrote {', '.join(files)} and results.json to {args.out} ({elapsed:.1f} s)")
    say_verdict(args.out)
    return 0
