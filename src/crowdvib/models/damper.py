"""A tuned mass damper (TMD) attached to one point of the deck.

A TMD is the walker's mass-spring-damper without the unsprung part: a mass on a spring and a
dashpot, fixed at one point of the walkway. The response models couple it to the modes exactly as
they couple the crowd's MSDs (docs: theory, The smeared crowd and the occupied bridge, §3.1), through the mode-shape row at its position.
It lives beside :class:`~crowdvib.models.MSDModel` because the response layer reads it; the
design layer (:mod:`crowdvib.design`) tunes it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from .._plausibility import warn_if_implausible
from .._validation import (FieldsFromDict, as_float_array, check_damping_ratio,
                           check_non_negative, check_positive)
from ..errors import ParameterError
from .pedestrian import transmissibility

if TYPE_CHECKING:
    from .structure import ModalModel

__all__ = ["TunedMassDamper", "as_dampers"]


@dataclass(frozen=True)
class TunedMassDamper(FieldsFromDict):
    """A tuned mass damper fixed to the deck.

    Parameters
    ----------
    mass : float
        Moving mass m_d [kg], > 0.
    frequency : float
        Natural frequency f_d = sqrt(k_d/m_d)/2π of the damper on a fixed base [Hz], > 0.
    damping_ratio : float
        ξ_d = c_d/(2 m_d ω_d) [-], a fraction in (0, 1).
    position : float
        Position along the walkway [m], in the coordinates of ``ModalModel.positions``.
    lane : float, optional
        Lateral position across the walkway [m]; None = mid-width (as
        :meth:`ModalModel.shapes_at`). Matters only for models with several lanes.
    """

    mass: float
    frequency: float
    damping_ratio: float
    position: float
    lane: float = None

    def __post_init__(self):
        object.__setattr__(self, "mass", check_positive("mass", self.mass, unit="kg"))
        object.__setattr__(self, "frequency",
                           check_positive("frequency", self.frequency, unit="Hz"))
        object.__setattr__(self, "damping_ratio",
                           check_damping_ratio("damping_ratio", self.damping_ratio))
        object.__setattr__(self, "position",
                           float(as_float_array("position", self.position, ndim=0)))
        if self.lane is not None:
            object.__setattr__(self, "lane", check_non_negative("lane", self.lane, unit="m"))
        warn_if_implausible("damper_frequency", self.frequency, "frequency", stacklevel=3)
        warn_if_implausible("damper_mass", self.mass, "mass", stacklevel=3)

    def stiffness(self) -> float:
        """k_d = m_d ω_d² [N/m]."""
        return self.mass * (2.0 * np.pi * self.frequency) ** 2

    def damping(self) -> float:
        """c_d = 2 ξ_d m_d ω_d [N·s/m]."""
        return 2.0 * self.damping_ratio * self.mass * 2.0 * np.pi * self.frequency

    def apparent_mass(self, frequency: ArrayLike) -> np.ndarray:
        """Apparent mass m_d·T(f/f_d) [kg] the damper adds at its point (docs: theory, Occupied receptance and FRFs).

        Parameters
        ----------
        frequency : array_like
            Frequencies [Hz].

        Returns
        -------
        ndarray of complex, shape of ``frequency``
        """
        ratio = np.asarray(frequency, dtype=float) / self.frequency
        return self.mass * transmissibility(ratio, self.damping_ratio)

    def shape_row(self, structure: ModalModel) -> np.ndarray:
        """Mode-shape row φ(x_d, y_d) of ``structure`` at the damper [scaling of the model].

        Parameters
        ----------
        structure : ModalModel
            The structure the damper is fixed to.

        Raises
        ------
        ParameterError
            If the damper lies off the walkway.
        """
        low, high = structure.positions[0], structure.positions[-1]
        if not low <= self.position <= high:
            raise ParameterError(
                f"damper position must lie on the walkway [{low:g}, {high:g}] m, "
                f"got {self.position:g} m")
        if self.lane is not None and self.lane > structure.width:
            raise ParameterError(
                f"damper lane must lie within [0, width={structure.width:g}] m, "
                f"got {self.lane:g} m")
        return structure.shapes_at(np.array([self.position]),
                                   None if self.lane is None else np.array([self.lane]))[0]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict of the parameters."""
        return {"mass": self.mass, "frequency": self.frequency,
                "damping_ratio": self.damping_ratio, "position": self.position,
                "lane": self.lane}


def as_dampers(dampers):
    """Check a ``dampers=`` argument: None or a sequence of :class:`TunedMassDamper` → tuple."""
    if dampers is None:
        return ()
    if isinstance(dampers, TunedMassDamper):
        return (dampers,)
    try:
        dampers = tuple(dampers)
    except TypeError:
        raise ParameterError(
            f"dampers must be a sequence of TunedMassDamper or None, got "
            f"{type(dampers).__name__}") from None
    for index, damper in enumerate(dampers):
        if not isinstance(damper, TunedMassDamper):
            raise ParameterError(
                f"dampers[{index}] must be a TunedMassDamper, got {type(damper).__name__}")
    return dampers
