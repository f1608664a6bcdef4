"""A case file's models: ``[structure]`` (a modal model from files, or a beam), ``[crowd]``
(with its counts or density profile, and the density's uncertainty) and ``[hsi]`` (the MSD),
each table read and checked into the model of :mod:`crowdvib.models` (the case as a whole is
read by :func:`crowdvib.io.casefile.load_case`)."""

from .._estimators import DEFAULT_DENSITY_UNCERTAINTY, check_density_uncertainty
from ..errors import ParameterError
from ..models.crowd import Crowd, bruno_venuti_step_frequency, weidmann_speed
from ..models.pedestrian import MSDModel
from ..models.profile import PROFILE_KINDS, CrowdProfile
from ..models.structure import ModalModel
from ._common import quote
from ._toml import wrap
from .csvtables import number_columns, read_csv_table, require_columns
from .modalfiles import read_modal_model


def _outputs(table, path, *, pairs):
    """``structure.outputs``: a table name = position x [m] (or [x, y] when ``pairs``), checked
    here so that a text position is named as such (not a ValueError deep in the model)."""
    outputs = table.raw("outputs", None)
    if outputs is None:
        return None
    rule = "a position x [m]" + (" or [x, y]" if pairs else "")
    if not isinstance(outputs, dict):
        raise table.error("outputs", f"must be a table name = {rule}", outputs)

    def number(value):
        return isinstance(value, (int, float)) and not isinstance(value, bool)

    for label, where in outputs.items():
        if not (number(where) or (pairs and isinstance(where, list) and len(where) == 2
                                  and all(map(number, where)))):
            raise ParameterError(f"{path.name}: {table.key('outputs')}[{label!r}] must be "
                                 f"{rule}, got {quote(where)}")
    return outputs


def _structure(table, path):
    kind = table.string("type", "modal_files", choices=("modal_files", "simply_supported_beam"))
    name = table.string("name", path.stem)
    width = table.number("width", rule="positive")
    try:
        if kind == "simply_supported_beam":
            span = table.number("span", rule="positive")
            frequency = table.numbers("frequency", rule="positive")
            damping = table.numbers("damping_ratio")
            mass = table.numbers("modal_mass", rule="positive")
            n_modes = table.count("n_modes", 1)
            outputs = _outputs(table, path, pairs=False)
            structure = ModalModel.simply_supported_beam(span, width, frequency, damping, mass,
                                                         n_modes, outputs=outputs, name=name)
        else:
            outputs = _outputs(table, path, pairs=True)
            points = table.file("output_points", None)
            # An FE export (UFF 15 + 55) holds the shapes itself: mode_shapes is then left out.
            fe = {key: value for key, value in (
                ("output_nodes", _output_nodes(table)),
                ("damping_ratios", table.numbers("damping_ratios", None))) if value is not None}
            structure = read_modal_model(table.file("modal_table"),
                                         table.file("mode_shapes", None), width=width,
                                         outputs=outputs, output_points=points, name=name, **fe)
    except ParameterError as exc:
        if str(exc).startswith(path.name):
            raise
        raise wrap(path, "structure", exc) from None
    table.finish()
    return structure


def _output_nodes(table):
    """``output_nodes = { name = node number }`` of an FE export, or None."""
    nodes = table.raw("output_nodes", None)
    if nodes is None:
        return None
    if not isinstance(nodes, dict) or not all(
            isinstance(v, int) and not isinstance(v, bool) for v in nodes.values()):
        raise table.error("output_nodes", "must be a table output_name = node number (integer)",
                          nodes)
    return nodes


def _crowd_profile(table, path, structure):
    """``[crowd] counts`` (a CSV of ``time`` [s] and ``count``, people on the deck from each
    time to the next) or ``density_profile`` (``time``, ``density`` [persons/m²]): the crowd's
    density against the record's time, piecewise constant or linear (``profile_kind``; default
    "step" for counts, "linear" for densities; docs: theory, A crowd that changes)."""
    counts = table.file("counts", None)
    densities = table.file("density_profile", None)
    if counts is None and densities is None:
        return None
    if counts is not None and densities is not None:
        raise ParameterError(f"{path.name}: crowd.counts and crowd.density_profile must not "
                             "both be given (one density against time), got both")
    kind = table.string("profile_kind", None, choices=PROFILE_KINDS)
    source, column = (counts, "count") if counts is not None else (densities, "density")
    header, rows = read_csv_table(source)
    require_columns(source, header, ["time", column])
    values = number_columns(source, header, rows, ["time", column])
    key = "counts" if counts is not None else "density_profile"
    try:
        if counts is not None:
            return CrowdProfile.from_counts(values[:, 0], values[:, 1], structure.area,
                                            kind=kind or "step")
        return CrowdProfile(values[:, 0], values[:, 1], kind or "linear")
    except ParameterError as exc:
        raise ParameterError(f"{path.name}: crowd.{key} ({source.name}): {exc}") from None


def _crowd(table, path, profile=None):
    """``[crowd]`` → (the crowd, its density the number or ``profile``; the walkers' reference
    density: the number, or with a profile the table's ``density`` or the profile's mean)."""
    if profile is not None and not table.has("density"):
        # The walkers' reference density (their speed and step frequency by default): the
        # profile's mean over its table.
        table.defaulted.add(table.key("density"))
        density = profile.table_mean
    else:
        density = table.number("density", rule="positive")
    speed = table.number("walking_speed", None, rule="positive")
    mean = table.number("step_frequency_mean", None, rule="positive")
    std = table.number("step_frequency_std", 0.175, rule="positive")
    mass = table.number("body_mass", 70.0, rule="positive")
    fraction = table.number("forward_fraction", 1.0, rule="non_negative")
    mass_std = table.number("body_mass_std", 0.0, rule="non_negative")
    table.finish()
    try:
        speed = float(weidmann_speed(density)) if speed is None else speed
        mean = float(bruno_venuti_step_frequency(speed)) if mean is None else mean
        crowd = Crowd(density=density, walking_speed=speed, step_frequency_mean=mean,
                      step_frequency_std=std, body_mass=mass, forward_fraction=fraction,
                      body_mass_std=mass_std)
        return (crowd if profile is None else crowd.with_density(profile)), density
    except ParameterError as exc:
        raise wrap(path, "crowd", exc) from None


def _density_uncertainty(table, path):
    """``[crowd] density_uncertainty``: the relative standard uncertainty of the stated density
    (or of the counts), which the estimate's intervals carry (docs: theory, The crowd density's
    uncertainty)."""
    value = table.number("density_uncertainty", DEFAULT_DENSITY_UNCERTAINTY)
    try:
        return check_density_uncertainty(value)
    except ParameterError as exc:
        raise ParameterError(f"{path.name}: crowd.{exc}") from None


def _msd(table, path):
    frequency = table.number("frequency", 3.0, rule="positive")
    damping = table.number("damping_ratio", 0.30, rule="positive")
    mass_ratio = table.number("mass_ratio", 0.95, rule="fraction")
    table.finish()
    try:
        return MSDModel(frequency, damping, mass_ratio)
    except ParameterError as exc:
        raise wrap(path, table.prefix, exc) from None    # "hsi" or "design.msd"

