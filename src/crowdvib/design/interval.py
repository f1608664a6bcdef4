"""Design checks across the box of f_h1 and ξ_h1 an estimate allows (docs: theory, design,
"The estimate's interval in the design check").

An identified MSD is uncertain; a design check with it is a range, not a point. :class:`MSDBox`
is the box of f_h1 and ξ_h1 (μ_h1 held at its estimate, as the paper does): an estimate's
statistical interval (:meth:`MSDBox.from_estimate`), or that widened by the modelling bound of a
sensitivity study (:meth:`MSDBox.around` with ``widened=True``). :func:`check_over_box` evaluates any check's
utilisation on a grid over the box and says, per code and model, its range and the verdict at
the conservative end. The box is wider than the joint confidence region, so the range is on
the safe side.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import DataError, ParameterError
from ..models.pedestrian import MSDModel

if TYPE_CHECKING:
    from ..identification.result import HSIEstimate

__all__ = ["MSDBox", "check_over_box", "check_grid", "SPANNED"]

#: The MSD parameters the box spans (μ_h1 is held at its estimate, as the paper does).
SPANNED = ("frequency", "damping_ratio")


@dataclass(frozen=True)
class MSDBox:
    """The box of f_h1 and ξ_h1 an estimate allows, around its point estimate.

    Attributes
    ----------
    msd : MSDModel
        The point estimate (μ_h1 held at it across the box).
    frequency, damping_ratio : tuple of float
        (low, high) of f_h1 [Hz] and ξ_h1 [-]; a parameter without an interval (held in the
        estimation, or an interval cut by a search bound) is its estimate at both ends.
    level : float
        The confidence level of the statistical interval.
    interval : str
        What the box is: ``"estimate 95 %"`` or ``"estimate 95 % + modelling bound"``.
    """

    msd: MSDModel
    frequency: tuple[float, float]
    damping_ratio: tuple[float, float]
    level: float = 0.95
    interval: str = "estimate 95 %"

    @classmethod
    def from_estimate(cls, estimate: HSIEstimate) -> MSDBox | None:
        """The box of an estimate's statistical interval (its profile interval, else its Wald
        interval, at its ``interval_level``), or None if it carries none.

        Parameters
        ----------
        estimate : HSIEstimate
        """
        if estimate.covariance is None and not estimate.intervals:
            return None
        level = estimate.interval_level
        return cls.around(estimate.msd, {name: estimate.interval(name, level) for name in SPANNED
                                         if name in estimate.free_parameters}, level)

    @classmethod
    def around(cls, msd: MSDModel, ends: Mapping, level: float = 0.95, *,
               widened: bool = False) -> MSDBox | None:
        """The box of the interval ``ends`` around ``msd``, or None if they hold none.

        Parameters
        ----------
        msd : MSDModel
            The point estimate.
        ends : dict
            Parameter → (low, high); a parameter missing, or with an end that is not a finite
            number, stays at its estimate.
        level : float
            The confidence level of the statistical interval.
        widened : bool
            The interval is a sensitivity study's, widened by its modelling bound
            (:meth:`crowdvib.studies.SensitivityResult.combined`).
        """
        pairs = {name: _pair(ends.get(name)) for name in SPANNED}
        if not any(pairs.values()):
            return None
        box = {name: pairs[name] or (float(getattr(msd, name)),) * 2 for name in SPANNED}
        level = float(level) if isinstance(level, (int, float)) else 0.95
        return cls(msd, box["frequency"], box["damping_ratio"], level,
                   f"estimate {100 * level:g} %{' + modelling bound' if widened else ''}")

    def grid(self, points: int) -> tuple[np.ndarray, np.ndarray]:
        """(f_h1 values, ξ_h1 values): ``points`` evenly spaced over each side, ends included.

        Parameters
        ----------
        points : int
            At least 2 (the corners).
        """
        return tuple(np.linspace(*getattr(self, name), points) for name in SPANNED)

    def to_dict(self) -> dict:
        """JSON-ready: ``frequency`` and ``damping_ratio`` [low, high], ``level``, ``interval``
        and the point estimate ``msd``."""
        return {"frequency": list(self.frequency), "damping_ratio": list(self.damping_ratio),
                "level": self.level, "interval": self.interval, "msd": self.msd.to_dict()}

    @classmethod
    def from_dict(cls, data: dict) -> MSDBox:
        """The box of :meth:`to_dict`.

        Parameters
        ----------
        data : dict
            What :meth:`to_dict` wrote (as read back from JSON).

        Raises
        ------
        DataError
            ``data`` is not such a dict.
        """
        try:
            return cls(MSDModel.from_dict(data["msd"]), tuple(data["frequency"]),
                       tuple(data["damping_ratio"]), data["level"], data["interval"])
        except (KeyError, TypeError) as error:
            raise DataError(f"MSDBox.from_dict: not a box's dict ({type(error).__name__}: "
                            f"{error})") from None


def _pair(value):
    """(low, high) as floats if ``value`` holds two finite numbers, else None."""
    try:
        low, high = (float(v) for v in value)
    except (TypeError, ValueError):
        return None
    return (low, high) if math.isfinite(low) and math.isfinite(high) else None


def check_grid(grid: int) -> int:
    """``grid`` (points per side of the box) if it is an integer of at least 2, the corners;
    else a ParameterError naming the rule and the value.

    Parameters
    ----------
    grid : int
        Points per parameter.
    """
    if not (isinstance(grid, (int, np.integer)) and not isinstance(grid, bool) and grid >= 2):
        raise ParameterError(f"grid must be an integer of at least 2 (the corners), got {grid!r}")
    return int(grid)


def check_over_box(utilisations: Callable[[MSDModel], Mapping[tuple, float]], box: MSDBox, *,
                   grid: int = 3) -> list[dict]:
    """The checks of ``utilisations`` at the point estimate and on a ``grid × grid`` grid over
    ``box``: per key, the range of the utilisation and the verdict at the conservative end.

    Parameters
    ----------
    utilisations : callable
        MSD → {key: utilisation}: the largest utilisation over the outputs per check (e.g.
        key = (code, model)), the same keys for every MSD.
    box : MSDBox
    grid : int
        Points per parameter, at least 2 (the corners). A utilisation monotone in each
        parameter is bounded by the corners; 3 also checks the monotony.

    Returns
    -------
    list of dict
        Per key: ``key``, ``utilisation`` at the point estimate, ``low``/``high`` over the grid
        and the point, ``conservative_end`` (the f_h1 and ξ_h1 of ``high``), ``monotone`` (the
        grid's utilisation is monotone along each parameter), ``passes`` (``high`` ≤ 1) and
        ``verdict`` (``"passes"``, ``"FAILS"`` or ``"FAILS at the conservative end"``: the
        interval decides).
    """
    grid = check_grid(grid)
    msd = box.msd
    at_point = utilisations(msd)
    frequencies, damping_ratios = box.grid(grid)
    cells = [[utilisations(MSDModel(f, xi, msd.mass_ratio)) for f in frequencies]
             for xi in damping_ratios]
    rows = []
    for key, utilisation in at_point.items():
        values = np.array([[cell[key] for cell in row] for row in cells])   # [ξ, f]
        low, high = min(values.min(), utilisation), max(values.max(), utilisation)
        # Where the high end is: the MSD the verdict at the conservative end is for.
        i, j = np.unravel_index(values.argmax(), values.shape)
        end = ((damping_ratios[i], frequencies[j]) if values.max() >= utilisation
               else (msd.damping_ratio, msd.frequency))
        rows.append({"key": key, "utilisation": utilisation, "low": float(low),
                     "high": float(high),
                     "conservative_end": {"frequency": float(end[1]),
                                          "damping_ratio": float(end[0])},
                     "monotone": bool(_monotone(values, 0) and _monotone(values, 1)),
                     "passes": bool(high <= 1.0),
                     "verdict": ("passes" if high <= 1.0 else "FAILS" if low > 1.0
                                 else "FAILS at the conservative end")})
    return rows


def _monotone(values, axis):
    """Whether every line of ``values`` along ``axis`` is monotone (to rounding)."""
    steps = np.diff(values, axis=axis)
    tolerance = 1e-9 * np.abs(values).max()
    lines = np.moveaxis(steps, axis, -1)
    return bool(np.all((lines >= -tolerance).all(-1) | (lines <= tolerance).all(-1)))
