"""A walking person as a mass-spring-damper (MSD) coupled to the deck (docs: theory, Conventions, §3.1).

The body mass m_h splits into a sprung mass m_h1 = μ_h1·m_h on a spring k_h1 and damper c_h1,
and an unsprung mass m_h0 = (1 − μ_h1)·m_h that moves with the deck.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._plausibility import warn_if_implausible
from .._validation import (FieldsFromDict, check_damping_ratio, check_open_unit,
                           check_positive, check_scalar)

__all__ = ["MSDModel", "transmissibility", "MSD_DAMPING_LIMIT"]

#: The MSD's damping ratio ξ_h1 must stay below this (fractions; walkers are over-damped at most
#: a little): the estimator's bounds must too.
MSD_DAMPING_LIMIT = 2.0


def transmissibility(frequency_ratio: ArrayLike, damping_ratio: float) -> np.ndarray:
    """Displacement transmissibility T = (1 + 2iξr)/(1 − r² + 2iξr) of a base-excited SDOF [-].

    The motion of a sprung mass over that of its (moving) base, with r = f/f_n: the factor by
    which a sprung mass m₁ on the deck acts as the apparent mass m₁·T (docs: theory, Occupied receptance and FRFs). Shared by
    the walkers' MSD model and the tuned mass damper, which is the same oscillator.
    """
    two_xi_r = 2j * damping_ratio * np.asarray(frequency_ratio, dtype=float)
    return (1.0 + two_xi_r) / (1.0 - np.asarray(frequency_ratio, dtype=float) ** 2 + two_xi_r)


@dataclass(frozen=True)
class MSDModel(FieldsFromDict):
    """Single-degree-of-freedom mass-spring-damper model of a walking person.

    Parameters
    ----------
    frequency : float
        Natural frequency f_h1 = sqrt(k_h1/m_h1)/2π [Hz], > 0.
    damping_ratio : float
        Damping ratio ξ_h1 = c_h1/(2 m_h1 ω_h1) [-], a fraction in (0, 2); 2 and above is refused
        as a likely percent value (over-damped bodies beyond that are not physiological).
    mass_ratio : float
        μ_h1 = m_h1/m_h [-] in (0, 1); 0.95 after Matsumoto & Griffin (2003), as in the paper.

    See Also
    --------
    crowdvib.estimate_hsi : the MSD from measured PSDs.
    crowdvib.Crowd

    Notes
    -----
    Defaults (3.0 Hz, 0.30, 0.95) are the paper's numerical example (docs: theory, The paper's numerical example).

    References
    ----------
    K. Van Nimmen and P. Van den Broeck, "Using full-scale observations on footbridges to estimate
    the parameters governing human–structure interaction", *Journal of Bridge Engineering* 28(1),
    2023. The single-degree-of-freedom pedestrian (Eq. 1–4).

    K. Van Nimmen, G. Lombaert, G. De Roeck and P. Van den Broeck, "The impact of vertical
    human–structure interaction on the response of footbridges to pedestrian excitation", *Journal
    of Sound and Vibration* 402:104–121, 2017. The crowd–structure model with MSD pedestrians.

    The theory pages cite them (docs: theory, References).
    """

    frequency: float = 3.0
    damping_ratio: float = 0.30
    mass_ratio: float = 0.95

    def __post_init__(self):
        # One MSD: an array (several walkers' values) is refused, not broadcast through later.
        object.__setattr__(self, "frequency", check_positive(
            "frequency", check_scalar("frequency", self.frequency), unit="Hz"))
        object.__setattr__(self, "damping_ratio", check_damping_ratio(
            "damping_ratio", check_scalar("damping_ratio", self.damping_ratio),
            upper=MSD_DAMPING_LIMIT))
        object.__setattr__(self, "mass_ratio", check_open_unit("mass_ratio", self.mass_ratio))
        # Above 15 Hz only (docs: theory, Plausible ranges): the estimator searches down to
        # 0.001 Hz and must stay quiet there; rad/s is the mix-up, and it lands high.
        warn_if_implausible("msd_frequency", self.frequency, "frequency", stacklevel=3)

    @classmethod
    def _checked(cls, frequency: float, damping_ratio: float, mass_ratio: float) -> MSDModel:
        """An MSD of values the caller has checked against this class's rules (an optimiser's θ
        inside bounds checked when the fit began): the checks and the plausibility note cost
        more than a forward model's arithmetic for the few modes of a footbridge (issue 39)."""
        msd = object.__new__(cls)
        for name, value in (("frequency", frequency), ("damping_ratio", damping_ratio),
                            ("mass_ratio", mass_ratio)):
            object.__setattr__(msd, name, float(value))
        return msd

    def sprung_mass(self, body_mass: ArrayLike) -> np.ndarray | float:
        """m_h1 = μ_h1·m_h [kg].

        Parameters
        ----------
        body_mass : float or array_like
            Body mass m_h [kg].
        """
        return self.mass_ratio * body_mass

    def stiffness(self, body_mass: ArrayLike) -> np.ndarray | float:
        """k_h1 = m_h1 ω_h1² [N/m].

        Parameters
        ----------
        body_mass : float or array_like
            Body mass m_h [kg].
        """
        return self.sprung_mass(body_mass) * (2.0 * np.pi * self.frequency) ** 2

    def damping(self, body_mass: ArrayLike) -> np.ndarray | float:
        """c_h1 = 2 ξ_h1 m_h1 ω_h1 [N·s/m].

        Parameters
        ----------
        body_mass : float or array_like
            Body mass m_h [kg].
        """
        return 2.0 * self.damping_ratio * self.sprung_mass(body_mass) * 2.0 * np.pi * self.frequency

    def apparent_mass(self, frequency: ArrayLike, body_mass: ArrayLike) -> np.ndarray | complex:
        """Apparent (dynamic) mass M_app(f) [kg] of the person on a moving point (docs: theory, Occupied receptance and FRFs).

        M_app = m_h0 + m_h1 (k_h1 + iωc_h1)/(k_h1 − ω² m_h1 + iωc_h1); M_app(0) = m_h,
        M_app(∞) = m_h0. The force on the structure is ω² M_app U for a deck motion U.

        Parameters
        ----------
        frequency : array_like
            Frequencies [Hz].
        body_mass : float
            Total body mass m_h [kg].

        Returns
        -------
        ndarray of complex, shape of ``frequency``
        """
        # In the frequency ratio r = f/f_h1, T is the transmissibility of docs: theory, Occupied receptance and FRFs with k
        # and c divided by m_h1 ω_h1².
        ratio = np.asarray(frequency, dtype=float) / self.frequency
        return body_mass * ((1.0 - self.mass_ratio)
                            + self.mass_ratio * transmissibility(ratio, self.damping_ratio))

    def to_dict(self) -> dict[str, float]:
        """The parameters as a JSON-ready dict (keys as in ``results.json``)."""
        return {"frequency": self.frequency, "damping_ratio": self.damping_ratio,
                "mass_ratio": self.mass_ratio}
