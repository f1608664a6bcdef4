"""A crowd whose density changes within a record (issue 28 §1; docs: theory, A crowd that changes).

A :class:`CrowdProfile` is a table time → density d(t) [persons/m²], piecewise linear between its
points or piecewise constant from each point to the next, held at its first value before the
first point and at its last value after the last. It is the density of the stream: walkers
enter at the rate λ(t) = d(t)·B·v (a non-homogeneous Poisson stream), so the crowd *on the deck*
is its average over the last crossing, d_deck(t) = (1/τ) ∫_{t−τ}^{t} d(s) ds with τ = L/v
(:meth:`CrowdProfile.deck_density`); the two agree when d changes slowly over a crossing.
Time 0 is a record's first sample. The walkers themselves (speed, step frequencies, body masses)
are a :class:`~crowdvib.models.Crowd`'s.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._validation import as_float_array
from ..errors import DataError, ParameterError

__all__ = ["CrowdProfile", "PROFILE_KINDS", "JAM_DENSITY"]

#: Jam density d_max [persons/m²] at which Weidmann's speed falls to zero (docs: theory, The crowd,
#: SOURCED): no density, stationary or in a profile, reaches it.
JAM_DENSITY = 5.4

#: How a profile runs between its points: straight lines, or each value held to the next point.
PROFILE_KINDS = ("linear", "step")


@dataclass(frozen=True, eq=False)
class CrowdProfile:
    """The density of a crowd's stream against time (module docstring).

    Parameters
    ----------
    time : array_like
        Times t_i [s], strictly increasing (t = 0: the record's first sample; negative times
        reach into the warm-up).
    density : array_like
        Densities d_i [persons/m²] at ``time``, >= 0 and below the jam density.
    kind : {"linear", "step"}
        ``"linear"``: d(t) interpolates linearly between the points; ``"step"``: d(t) = d_i on
        [t_i, t_(i+1)) (counts per interval). Either way d is held constant outside the table.

    Examples
    --------
    >>> ramp = CrowdProfile([0.0, 3600.0], [0.2, 1.0])
    >>> round(float(ramp.density_at(1800.0)), 12), round(ramp.mean(0.0, 3600.0), 12)
    (0.6, 0.6)
    """

    time: np.ndarray
    density: np.ndarray
    kind: str = "linear"
    #: ∫ d dt at each point [persons·s/m²], set once in __post_init__ (not an argument).
    _knots: np.ndarray = field(init=False, repr=False)

    def __post_init__(self):
        time = as_float_array("time", self.time, ndim=1)
        density = as_float_array("density", self.density, ndim=1)
        if time.size == 0:
            raise ParameterError("time must hold at least one point, got an empty table")
        if density.shape != time.shape:
            raise ParameterError(f"density must have one value per time ({time.size}), got "
                                 f"{density.size}")
        if not (np.all(np.isfinite(time)) and np.all(np.diff(time) > 0)):
            raise ParameterError(f"time must be finite and strictly increasing [s], got "
                                 f"{time.tolist()[:6]}{' …' if time.size > 6 else ''}")
        if not np.all(np.isfinite(density)) or np.any(density < 0):
            bad = density[~(np.isfinite(density) & (density >= 0))][0]
            raise ParameterError(f"density must be finite and >= 0 persons/m², got {bad:g}")
        if np.any(density >= JAM_DENSITY):
            raise ParameterError(
                f"density must be < the jam density {JAM_DENSITY} persons/m², got "
                f"{density.max():g} (a count per interval? CrowdProfile.from_counts divides "
                "by the walkway area)")
        if self.kind not in PROFILE_KINDS:
            raise ParameterError(f"kind must be one of {list(PROFILE_KINDS)}, got {self.kind!r}")
        time.flags.writeable = density.flags.writeable = False
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "density", density)
        # ∫ d from time[0] to each point: the stream's cumulative rate per B·v.
        widths = np.diff(time)
        heights = (density[:-1] + density[1:]) / 2 if self.kind == "linear" else density[:-1]
        knots = np.concatenate([[0.0], np.cumsum(heights * widths)])
        knots.flags.writeable = False
        object.__setattr__(self, "_knots", knots)

    def __eq__(self, other: object) -> bool:
        # By value (its table), so that a crowd carrying it compares and hashes by value too
        # (Crowd.from_dict(crowd.to_dict()) == crowd).
        if not isinstance(other, CrowdProfile):
            return NotImplemented
        return (self.kind == other.kind and np.array_equal(self.time, other.time)
                and np.array_equal(self.density, other.density))

    def __hash__(self) -> int:
        return hash((self.kind, self.time.tobytes(), self.density.tobytes()))

    def to_dict(self) -> dict[str, Any]:
        """The profile as a JSON-ready dict: ``kind``, ``time`` [s], ``density`` [persons/m²]
        (the ``profile`` every command's inputs show with a case's crowd)."""
        return {"kind": self.kind, "time": self.time.tolist(), "density": self.density.tolist()}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> CrowdProfile:
        """The profile of :meth:`to_dict`'s dict.

        Parameters
        ----------
        data : dict
            ``kind``, ``time`` and ``density``, as :meth:`to_dict` wrote them.

        Raises
        ------
        DataError
            ``data`` is not a dict or lacks one of them.
        """
        if not isinstance(data, dict) or not {"time", "density"} <= set(data):
            raise DataError(f"a crowd profile must be a dict with 'time' and 'density' (and "
                            f"'kind'), got {data!r:.80}")
        return cls(data["time"], data["density"], data.get("kind", "linear"))

    @classmethod
    def constant(cls, density: float) -> CrowdProfile:
        """The stationary crowd of one density (a simulation with it is bit-identical to one
        with ``crowd.with_density(density)``).

        Parameters
        ----------
        density : float
            The density [persons/m²], >= 0.
        """
        return cls([0.0], [density])

    @classmethod
    def from_counts(cls, time: ArrayLike, count: ArrayLike, area: float, *,
                    kind: str = "step") -> CrowdProfile:
        """People counted on the deck per interval → densities count/area.

        Parameters
        ----------
        time : array_like
            Start of each counting interval [s] (an interval runs to the next time; the last
            one to the end of the record).
        count : array_like
            People on the deck in each interval (a mean may be fractional), >= 0.
        area : float
            Walkway area L·B [m²] (``ModalModel.area``).
        kind : {"step", "linear"}
            Default ``"step"``: a count holds over its interval.
        """
        area = float(as_float_array("area", area, ndim=0))
        if not area > 0:
            raise ParameterError(f"area must be > 0 m² (the walkway's L·B), got {area:g}")
        count = as_float_array("count", count, ndim=1)
        if np.any(~np.isfinite(count)) or np.any(count < 0):
            raise ParameterError(f"count must be finite and >= 0 people, got "
                                 f"{float(count[~(np.isfinite(count) & (count >= 0))][0]):g}")
        if count.size and count.max() / area >= JAM_DENSITY:
            raise ParameterError(
                f"count must stay below the jam density × area = {JAM_DENSITY * area:g} people "
                f"on {area:g} m², got {count.max():g}")
        return cls(time, count / area, kind)

    @property
    def is_constant(self) -> bool:
        """Whether d(t) is one value at all times."""
        return bool(np.all(self.density == self.density[0]))

    @property
    def table_mean(self) -> float:
        """The mean density over the table's span [persons/m²] (its one value for a one-point
        table): the walkers' reference density, which sets their speed and step frequency by
        default (:meth:`crowdvib.Crowd.from_density`, a case file's ``[crowd]``)."""
        return self.mean(self.time[0], self.time[-1]) if self.time.size > 1 else self.peak

    @property
    def peak(self) -> float:
        """The largest density [persons/m²]."""
        return float(self.density.max())

    def scaled(self, factor: float) -> CrowdProfile:
        """The same profile with every density times ``factor`` (>= 0).

        Parameters
        ----------
        factor : float
            The factor, >= 0.
        """
        return CrowdProfile(self.time, self.density * float(factor), self.kind)

    def implausibilities(self, duration: float) -> list[str]:
        """Doubts about this profile for a record of ``duration`` [s].

        A table whose times end within the first thirtieth of the record but would span it in
        minutes or hours is likely in those units (docs: theory, A crowd that changes).

        Parameters
        ----------
        duration : float
            The record's length [s].

        Returns
        -------
        list of str
            One sentence per doubt (empty: none).
        """
        if self.time[0] >= duration:    # issue 35 §3: read as its first value, silently
            return [f"crowd profile times start at {self.time[0]:g} s, after the {duration:g} s "
                    f"record ends: the table describes another stretch (its times on another "
                    f"axis, or the record's time_frame?); the whole record gets its first "
                    f"density {self.density[0]:g} persons/m²"]
        span = float(self.time[-1] - self.time[0])
        if self.time.size < 2 or not 0 < self.time[-1] <= duration / 30:
            return []
        for unit, factor in (("minutes", 60.0), ("hours", 3600.0)):
            if 0.5 * duration <= span * factor <= 2 * duration:
                return [f"crowd profile times end at {self.time[-1]:g} s of a {duration:g} s "
                        f"record: in {unit}? (they would span {span * factor:g} s)"]
        return []

    def shifted(self, offset: float) -> CrowdProfile:
        """The same profile on a time axis that starts ``offset`` [s] later (t → t − offset):
        for a record cut from ``offset`` on.

        Parameters
        ----------
        offset : float
            The shift of the time axis [s].
        """
        return CrowdProfile(self.time - float(offset), self.density, self.kind)

    def density_at(self, t: ArrayLike) -> np.ndarray:
        """d(t) [persons/m²] at times ``t`` [s].

        Parameters
        ----------
        t : array_like
            Times [s].
        """
        t = np.asarray(t, dtype=float)
        if self.kind == "linear":
            return np.interp(t, self.time, self.density)
        index = np.clip(np.searchsorted(self.time, t, "right") - 1, 0, self.time.size - 1)
        return self.density[index]

    def cumulative(self, t: ArrayLike) -> np.ndarray:
        """C(t) = ∫_{time[0]}^{t} d(s) ds [persons·s/m²] (negative before the first point).

        Parameters
        ----------
        t : array_like
            Times [s].
        """
        t = np.asarray(t, dtype=float)
        i = np.clip(np.searchsorted(self.time, t, "right") - 1, 0, self.time.size - 1)
        s = t - self.time[i]
        value = self._knots[i] + self.density[i] * s
        if self.kind == "linear" and self.time.size > 1:
            inside = (t >= self.time[0]) & (t < self.time[-1])
            j = np.minimum(i, self.time.size - 2)
            slope = (self.density[j + 1] - self.density[j]) / (self.time[j + 1] - self.time[j])
            value = value + np.where(inside, slope * s * s / 2, 0.0)
        return value

    def inverse_cumulative(self, c: ArrayLike) -> np.ndarray:
        """The time t with C(t) = c [s]: turns uniform draws of the cumulative rate into the
        arrival times of the non-homogeneous Poisson stream (inversion).

        Parameters
        ----------
        c : array_like
            Values of the cumulative density C [persons·s/m²].
        """
        c = np.asarray(c, dtype=float)
        knots, time, density = self._knots, self.time, self.density
        i = np.clip(np.searchsorted(knots, c, "right") - 1, 0, time.size - 1)
        rest = c - knots[i]
        slope = np.zeros_like(rest)
        if self.kind == "linear" and time.size > 1:
            j = np.minimum(i, time.size - 2)
            inside = (c >= knots[0]) & (c < knots[-1])
            slope = np.where(inside, (density[j + 1] - density[j]) / (time[j + 1] - time[j]),
                             0.0)
        # d_i s + slope s²/2 = rest, in the form that stays exact when slope → 0.
        root = np.sqrt(np.maximum(density[i] ** 2 + 2 * slope * rest, 0.0))
        denominator = density[i] + root
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.where(denominator > 0, 2 * rest / denominator, 0.0)
        return time[i] + s

    def mean(self, start: float, end: float) -> float:
        """The mean density over [start, end] [persons/m²].

        Parameters
        ----------
        start, end : float
            The interval [s].
        """
        if not end > start:
            raise ParameterError(f"end must be > start, got [{start:g}, {end:g}] s")
        return float((self.cumulative(end) - self.cumulative(start)) / (end - start))

    def deck_density(self, t: ArrayLike, crossing_time: float) -> np.ndarray:
        """The mean density on the deck at ``t`` [persons/m²]: the stream's density averaged
        over the last crossing, (C(t) − C(t − τ))/τ with τ = L/v [s] (module docstring).

        Parameters
        ----------
        t : array_like
            Times [s].
        crossing_time : float
            τ = L/v, the time a walker spends on the deck [s].
        """
        t = np.asarray(t, dtype=float)
        if not crossing_time > 0:
            return self.density_at(t)
        return (self.cumulative(t) - self.cumulative(t - crossing_time)) / crossing_time
