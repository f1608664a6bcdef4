"""A year's crowd as a distribution: crowd states, each a density and the hours a year it stands
for (docs: theory, A year of comfort).

Three sources (:class:`Traffic`):

- a design table ``density, hours_per_year`` (:meth:`Traffic.from_table`);
- a daily profile (the density in each hour of the day) times the days of a year
  (:meth:`Traffic.from_profile`);
- a season of measured windows, each with its density, start time and length
  (:meth:`Traffic.from_windows`, :meth:`Traffic.from_season` for a ``crowdvib season`` folder).
  The year is cut into the 168 hours of the week; each hour of the week stands for
  ``year_hours / 168`` hours and takes the windows measured in it, weighted by their lengths.
  An hour of the week nobody measured is filled by a rule (``unmeasured``): ``"hour"`` takes the
  windows of the same hour on the days of the same kind (Monday–Friday or the weekend), else on
  any day, else of the nearest measured hour of such a day; ``"zero"`` puts no crowd on the
  deck in it.

Every state keeps the window it comes from (``group``), so that the season's sampling can be
carried by resampling its windows (:meth:`Traffic.resample`).
"""

from __future__ import annotations

import datetime
from dataclasses import dataclass

import numpy as np

from .._validation import FieldsFromDict, as_float_array, check_positive, frozen_array
from ..errors import DataError, ParameterError

__all__ = ["Traffic", "HOURS_PER_YEAR", "WEEK_HOURS", "UNMEASURED_RULES"]

#: The hours of a year of 365 days.
HOURS_PER_YEAR = 8760.0
#: Hours of the week: a state's ``cell`` is weekday × 24 + hour (Monday 0–23, …, Sunday).
WEEK_HOURS = 168
#: Rules for the hours of the week that no window measured.
UNMEASURED_RULES = ("hour", "zero")
#: Days of the week counted as the weekend (Python's weekday(): Saturday 5, Sunday 6).
_WEEKEND = (5, 6)


@dataclass(frozen=True, eq=False)
class Traffic(FieldsFromDict):
    """A year's crowd: crowd states with the hours a year each stands for.

    Attributes
    ----------
    density : ndarray
        Density of each state [persons/m²].
    hours : ndarray
        Hours a year each state stands for [h]; their sum is the year's hours.
    cell : ndarray of int
        The hour of the week (weekday × 24 + hour, Monday 0) of each state, −1 for none.
    group : ndarray of int
        The measured window each state comes from (its index in the season), −1 for none.
    source : str
        ``"table"``, ``"profile"`` or ``"season"``.
    filled : tuple of int
        The hours of the week no window measured, filled by the ``unmeasured`` rule.
    unmeasured : str or None
        That rule (a season only).
    _windows : tuple or None
        A season's windows (density, hour of the week, length, year's hours), kept to resample
        them; None otherwise. Not in :meth:`to_dict` (``from_dict`` gives None).
    """

    density: np.ndarray
    hours: np.ndarray
    cell: np.ndarray
    group: np.ndarray
    source: str
    filled: tuple = ()
    unmeasured: str | None = None
    #: A season's windows (density, cell, weight), kept to resample them.
    _windows: tuple | None = None

    def __post_init__(self):
        object.__setattr__(self, "density", frozen_array(self.density))
        object.__setattr__(self, "hours", frozen_array(self.hours))
        object.__setattr__(self, "cell", frozen_array(self.cell, int))
        object.__setattr__(self, "group", frozen_array(self.group, int))

    @property
    def total_hours(self) -> float:
        """The year's hours [h]: the sum of the states' hours."""
        return float(self.hours.sum())

    @property
    def has_week(self) -> bool:
        """Whether every state has its hour of the week (a profile or a dated season)."""
        return bool(self.cell.size and np.all(self.cell >= 0))

    def __eq__(self, other):
        if not isinstance(other, Traffic):
            return NotImplemented
        return self.to_dict() == other.to_dict()

    def to_dict(self) -> dict:
        """JSON-ready: the states and where they come from."""
        return {"source": self.source, "density": self.density.tolist(),
                "hours": self.hours.tolist(), "cell": self.cell.tolist(),
                "group": self.group.tolist(), "filled": list(self.filled),
                "unmeasured": self.unmeasured, "total_hours": self.total_hours}

    # ---------------------------------------------------------------------- constructors
    @classmethod
    def from_table(cls, density, hours_per_year, *, year_hours: float | None = None) -> Traffic:
        """A design table: densities and the hours a year each stands for.

        Parameters
        ----------
        density : array_like
            [persons/m²], ≥ 0.
        hours_per_year : array_like
            [h] of each density, ≥ 0, not all 0.
        year_hours : float, optional
            The year's hours [h]: the hours the table does not cover are added with no crowd on
            the deck (default: the table's sum is the year).
        """
        density = _densities(density)
        hours = as_float_array("hours_per_year", hours_per_year, ndim=1)
        if hours.shape != density.shape:
            raise ParameterError(f"hours_per_year must have one value per density "
                                 f"({density.size}), got {hours.size}")
        if np.any(~np.isfinite(hours) | (hours < 0)) or not hours.sum() > 0:
            raise ParameterError(f"hours_per_year must be finite, >= 0 and not all 0, got "
                                 f"{hours.tolist()}")
        if year_hours is not None:
            year_hours = check_positive("year_hours", year_hours, unit="h")
            rest = year_hours - hours.sum()
            if rest < -1e-9 * year_hours:
                raise ParameterError(f"year_hours must be at least the table's "
                                     f"{hours.sum():g} h, got {year_hours:g}")
            if rest > 0:
                density, hours = np.append(density, 0.0), np.append(hours, rest)
        none = np.full(density.size, -1)
        return cls(density, hours, none, none, "table")

    @classmethod
    def from_profile(cls, density_by_hour, *, days: float = 365.0) -> Traffic:
        """A daily profile (the density in each hour of the day, 0–23) repeated every day.

        Parameters
        ----------
        density_by_hour : array_like, 24 values
            [persons/m²] in hour 0 (00:00–01:00) … 23.
        days : float
            Days a year the profile holds (each weekday ``days/7`` of them).
        """
        density = _densities(density_by_hour, "density_by_hour")
        if density.size != 24:
            raise ParameterError(f"density_by_hour must have 24 values (hours 0–23), got "
                                 f"{density.size}")
        days = check_positive("days", days, unit="days")
        cells = np.arange(WEEK_HOURS)
        return cls(density[cells % 24], np.full(WEEK_HOURS, days / 7), cells,
                   np.full(WEEK_HOURS, -1), "profile")

    @classmethod
    def from_windows(cls, density, times=None, durations=None, *, unmeasured: str = "hour",
                     year_hours: float = HOURS_PER_YEAR) -> Traffic:
        """A season of measured windows, each standing for its hour of the week.

        Parameters
        ----------
        density : array_like
            Each window's density [persons/m²].
        times : sequence of str or datetime, optional
            Each window's start (ISO 8601). Without any, every window stands for the whole
            week alike, weighted by its length (no week heat map).
        durations : array_like, optional
            Each window's length [s] (default: all alike).
        unmeasured : {"hour", "zero"}
            The rule for the hours of the week no window measured (module docstring).
        year_hours : float
            The year's hours [h] (default 365 days).
        """
        density = _densities(density)
        weight = (np.ones(density.size) if durations is None
                  else as_float_array("durations", durations, ndim=1))
        if weight.shape != density.shape or np.any(~np.isfinite(weight) | (weight <= 0)):
            raise ParameterError(f"durations must be {density.size} lengths > 0 s, got "
                                 f"{weight.tolist()}")
        if unmeasured not in UNMEASURED_RULES:
            raise ParameterError(f"unmeasured must be one of {list(UNMEASURED_RULES)}, got "
                                 f"{unmeasured!r}")
        year_hours = check_positive("year_hours", year_hours, unit="h")
        cells = (np.full(density.size, -1) if times is None
                 else np.array([_cell(t, i) for i, t in enumerate(times)], dtype=int))
        if cells.shape != density.shape:
            raise ParameterError(f"times must have one value per window ({density.size}), got "
                                 f"{cells.size}")
        return _states(density, cells, weight, unmeasured, year_hours)

    @classmethod
    def from_season(cls, results: dict, *, unmeasured: str = "hour",
                    year_hours: float = HOURS_PER_YEAR, area: float | None = None) -> Traffic:
        """The windows of a ``crowdvib season`` results.json (its ``records`` table): each row's
        density, ``time`` and length (``end − start``, else its ``duration``; else the median
        of the known lengths, or all alike).

        Parameters
        ----------
        results : dict
            The season's results.json.
        unmeasured, year_hours
            As :meth:`from_windows`.
        area : float, optional
            The walkway's area [m²], for rows that give a count and no density.
        """
        rows = [row for row in results.get("records") or [] if isinstance(row, dict)]
        if not rows:
            raise DataError("the season's results.json holds no records (its 'records' table "
                            "is empty or missing)")
        density, times, lengths = [], [], []
        for number, row in enumerate(rows, start=1):
            value = row.get("density")
            if value is None and row.get("count") is not None and area:
                value = row["count"] / area
            if not isinstance(value, (int, float)) or isinstance(value, bool):
                raise DataError(f"the season's record {number} ({row.get('name')!r}) has no "
                                f"density, got {value!r}")
            density.append(float(value))
            times.append(row.get("time"))
            start, end, length = row.get("start"), row.get("end"), row.get("duration")
            if isinstance(start, (int, float)) and isinstance(end, (int, float)):
                length = end - start
            lengths.append(length if isinstance(length, (int, float)) and length > 0 else None)
        dated = [t is not None for t in times]
        if any(dated) and not all(dated):
            first = dated.index(False) + 1
            raise DataError(f"the season's record {first} ({rows[first - 1].get('name')!r}) has "
                            "no time while others have: every window needs its time (the crowd "
                            "table's 'time' column) to stand for its hour of the week")
        known = [length for length in lengths if length is not None]
        fill = float(np.median(known)) if known else 1.0
        return cls.from_windows(density, times if all(dated) else None,
                                [fill if length is None else length for length in lengths],
                                unmeasured=unmeasured, year_hours=year_hours)

    # ---------------------------------------------------------------------- sampling
    def resample(self, rng) -> Traffic:
        """The season again from its windows drawn with replacement (a bootstrap of the
        season's sampling); the same traffic for a table or a profile.

        Parameters
        ----------
        rng : numpy.random.Generator
        """
        if self._windows is None:
            return self
        density, cells, weight, year_hours = self._windows
        pick = rng.integers(0, density.size, density.size)
        return _states(density[pick], cells[pick], weight[pick], self.unmeasured, year_hours,
                       groups=pick)

    def week_hours(self) -> np.ndarray:
        """Hours a year in each hour of the week, shape (168,) (all 0 without a week)."""
        found = np.zeros(WEEK_HOURS)
        if self.has_week:
            np.add.at(found, self.cell, self.hours)
        return found


def _densities(value, name="density"):
    density = as_float_array(name, value, ndim=1)
    if density.size == 0 or np.any(~np.isfinite(density) | (density < 0)):
        raise ParameterError(f"{name} must be finite and >= 0 persons/m², at least one, got "
                             f"{density.tolist()}")
    return density


def _cell(time, index):
    """Hour of the week of a window's start."""
    if isinstance(time, str):
        try:
            time = datetime.datetime.fromisoformat(time)
        except ValueError:
            raise DataError(f"times[{index}] must be ISO 8601 (2026-05-04T08:00), got "
                            f"{time!r}") from None
    if not isinstance(time, datetime.datetime):
        raise ParameterError(f"times[{index}] must be a datetime or an ISO 8601 string, got "
                             f"{type(time).__name__}")
    return time.weekday() * 24 + time.hour


def _pool(cell, measured):
    """The measured hours of the week that stand in for ``cell`` (rule "hour")."""
    day, hour = divmod(cell, 24)
    weekend = day in _WEEKEND
    same_kind = [c for c in measured if (c // 24 in _WEEKEND) == weekend]
    for group in (same_kind, measured):
        found = [c for c in group if c % 24 == hour]
        if found:
            return found
        if group:
            gaps = {c: min(abs(c % 24 - hour), 24 - abs(c % 24 - hour)) for c in group}
            nearest = min(gaps.values())
            return [c for c in group if gaps[c] == nearest]
    return []


def _states(density, cells, weight, unmeasured, year_hours, groups=None):
    """The traffic of windows: per hour of the week, its windows' share of its hours."""
    groups = np.arange(density.size) if groups is None else groups
    windows = (density, cells, weight, year_hours)
    if np.all(cells < 0):                   # no times: every window stands for the year
        hours = year_hours * weight / weight.sum()
        return Traffic(density, hours, cells, groups, "season", (), unmeasured, windows)
    share = year_hours / WEEK_HOURS
    by_cell: dict[int, list] = {}
    for index, cell in enumerate(cells.tolist()):
        by_cell.setdefault(cell, []).append(index)
    measured = sorted(by_cell)
    parts, filled = [], []
    for cell in range(WEEK_HOURS):
        if cell in by_cell:
            inside = np.array(by_cell[cell])
        else:
            filled.append(cell)
            if unmeasured == "zero":
                parts.append((np.zeros(1), np.full(1, share), np.full(1, cell), np.full(1, -1)))
                continue
            inside = np.array([i for source in _pool(cell, measured) for i in by_cell[source]])
        parts.append((density[inside], share * weight[inside] / weight[inside].sum(),
                      np.full(inside.size, cell), groups[inside]))
    d, h, c, g = (np.concatenate(column) for column in zip(*parts))
    return Traffic(d, h, c, g, "season", tuple(filled), unmeasured, windows)
