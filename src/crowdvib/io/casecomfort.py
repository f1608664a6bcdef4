"""The ``[comfort]`` and ``[traffic]`` tables of a case file (``crowdvib comfort``, issue 37), and
the traffic CSV, parsed apart from the other tables; every key through
:class:`crowdvib.io._toml.Table`.

::

    [comfort]                      # all optional
    duration = 600.0               # the window [s]
    rms_window = 1.0               # τ of the running RMS [s]
    peak_model = "vanmarcke"       # or "davenport"
    output = "midspan"             # the output judged (default the loudest)
    crowd_model = "fluctuating"    # or "smeared"
    damper_mass_ratio = 0.02       # a damper tuned to the loudest mode (0: none; a
                                   # [design.damper] is used when the case has one)
    densities = 12                 # densities of the response table
    resamples = 200                # resamples of a season's windows (its sampling band)
    unmeasured = "hour"            # or "zero": the hours of the week no window measured
    simulate_below = 0.15          # [persons/m²]: below, simulated windows stand in (0: none;
                                   # default: a thin crowd, fewer than 100 effective walkers
                                   # on the walkway)
    simulated_windows = 100        # windows simulated per density there

    [traffic]                      # one of:
    table = "traffic.csv"          #   a CSV: density, hours_per_year; or hour, density
    density = [0.1, 0.4]           #   a design table …
    hours_per_year = [3000, 200]   #   … with its hours
    profile = [0.0, …]             #   24 densities, hours 0–23, every day
    days = 365                     #   days a year of a profile
    year_hours = 8760              #   the year's hours of a design table (the rest: no crowd)

The values are checked here (numbers, files, choices); the traffic itself is built by the comfort
layer (:class:`crowdvib.comfort.Traffic`): io imports no analysis layer.
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import DataError
from ._common import quote
from .csvtables import number_columns, read_csv_table

__all__ = ["ComfortSpec", "TrafficSpec", "read_traffic_table", "TRAFFIC_COLUMNS",
           "PEAK_CHOICES", "UNMEASURED_CHOICES"]

#: The columns of a traffic CSV: a design table, or a daily profile.
TRAFFIC_COLUMNS = {"table": ("density", "hours_per_year"), "profile": ("hour", "density")}
PEAK_CHOICES = ("vanmarcke", "davenport")
UNMEASURED_CHOICES = ("hour", "zero")


@dataclass(frozen=True)
class ComfortSpec:
    """``[comfort]``: how ``crowdvib comfort`` judges a window (module docstring)."""

    duration: float = 600.0
    rms_window: float = 1.0
    peak_model: str = "vanmarcke"
    output: str | None = None
    crowd_model: str | None = None
    damper_mass_ratio: float = 0.02
    densities: int = 12
    resamples: int = 200
    unmeasured: str = "hour"
    simulate_below: float | None = None
    simulated_windows: int = 100


@dataclass(frozen=True)
class TrafficSpec:
    """``[traffic]``: a design table (``density``, ``hours_per_year``) or a daily profile
    (``profile``, ``days``), given in the file or in a CSV (``table``)."""

    kind: str
    density: tuple
    hours_per_year: tuple = ()
    days: float = 365.0
    year_hours: float | None = None
    file: Path | None = None


def _comfort(table, path):
    """``[comfort]`` → :class:`ComfortSpec`."""
    spec = ComfortSpec(
        duration=table.number("duration", 600.0, rule="positive"),
        rms_window=table.number("rms_window", 1.0, rule="positive"),
        peak_model=table.string("peak_model", "vanmarcke", choices=PEAK_CHOICES),
        output=table.string("output", None),
        crowd_model=table.string("crowd_model", None, choices=("fluctuating", "smeared")),
        damper_mass_ratio=table.number("damper_mass_ratio", 0.02, rule="non_negative"),
        densities=table.count("densities", 12, minimum=2),
        resamples=table.count("resamples", 200, minimum=0),
        unmeasured=table.string("unmeasured", "hour", choices=UNMEASURED_CHOICES),
        simulate_below=table.number("simulate_below", None, rule="non_negative"),
        simulated_windows=table.count("simulated_windows", 100, minimum=1))
    if spec.damper_mass_ratio >= 1:
        raise table.error("damper_mass_ratio", "must be < 1 (a fraction of the modal mass)",
                          spec.damper_mass_ratio)
    table.finish()
    return spec


def _traffic(table, path):
    """``[traffic]`` → :class:`TrafficSpec` (exactly one of ``table``, ``density``,
    ``profile``)."""
    given = [key for key in ("table", "density", "profile") if table.has(key)]
    if len(given) != 1:
        raise DataError(f"{path.name}: [traffic] must give exactly one of 'table', 'density' "
                        f"(with 'hours_per_year') and 'profile', got {given or 'none'}")
    days = table.number("days", 365.0, rule="positive")
    year_hours = table.number("year_hours", None, rule="positive")
    if given[0] == "table":
        spec = read_traffic_table(table.file("table"), days=days, year_hours=year_hours)
    elif given[0] == "density":
        spec = TrafficSpec("table", _non_negative(table, "density", table.numbers("density")),
                           _non_negative(table, "hours_per_year",
                                         table.numbers("hours_per_year")),
                           year_hours=year_hours)
        if len(spec.density) != len(spec.hours_per_year):
            raise table.error("hours_per_year", f"must have one value per density "
                              f"({len(spec.density)})", list(spec.hours_per_year))
    else:
        spec = TrafficSpec("profile", _non_negative(table, "profile", table.numbers("profile")),
                           days=days)
        if len(spec.density) != 24:
            raise table.error("profile", "must hold 24 densities (hours 0–23)",
                              list(spec.density))
    table.finish()
    return spec


def _non_negative(table, name, values):
    """The numbers read from ``name`` (one number is a list of one), checked >= 0."""
    values = np.atleast_1d(values)
    if np.any(values < 0):
        raise table.error(name, "must be >= 0", values.tolist())
    return tuple(float(v) for v in values)


def read_traffic_table(path, *, days: float = 365.0,
                       year_hours: float | None = None) -> TrafficSpec:
    """A traffic CSV → :class:`TrafficSpec`: columns ``density, hours_per_year`` (a design
    table) or ``hour, density`` (a daily profile, hours 0–23 each once); ``#`` lines comments.

    Raises
    ------
    DataError
        Neither pair of columns, a cell that is not a finite number, a negative density or
        hours, or a profile whose hours are not 0–23 each once (file, row and column named).
    """
    header, rows = read_csv_table(path)
    name = Path(path).name
    kind = next((k for k, columns in TRAFFIC_COLUMNS.items() if set(columns) <= set(header)),
                None)
    if kind is None:
        raise DataError(f"{name}: a traffic table needs the columns 'density' and "
                        "'hours_per_year' (a design table) or 'hour' and 'density' (a daily "
                        f"profile), got {[quote(c) for c in header]}")
    values = number_columns(path, header, rows, TRAFFIC_COLUMNS[kind])
    for j, column in enumerate(TRAFFIC_COLUMNS[kind]):
        bad = np.flatnonzero(values[:, j] < 0)
        if bad.size:
            raise DataError(f"{name}: row {bad[0] + 1}, column {quote(column)} must be >= 0, "
                            f"got {values[bad[0], j]:g}")
    if kind == "table":
        return TrafficSpec("table", tuple(values[:, 0]), tuple(values[:, 1]),
                           year_hours=year_hours, file=Path(path))
    hours = values[:, 0]
    if sorted(hours.tolist()) != list(range(24)):
        raise DataError(f"{name}: column 'hour' must hold the hours 0 to 23 each once, got "
                        f"{hours.tolist()}")
    return TrafficSpec("profile", tuple(values[np.argsort(hours), 1]), days=days,
                       file=Path(path))
