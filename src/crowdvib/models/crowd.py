"""The crowd on the deck: density, body mass, walking speed and step frequencies (docs: theory, The crowd).

A :class:`Crowd` is the statistical description the paper assumes known: a uniform density d,
Poisson arrivals at rate λ = d·B·v, one walking speed, step frequencies f_s ~ N(μ_fs, σ_fs) and
one (average) body mass. Its density is a number (a stationary crowd) or a
:class:`~crowdvib.models.CrowdProfile` (a crowd whose density changes within a record, issue 34
§3): one value that the simulator, the record's model and the estimator read; the models of a
stationary crowd refuse a profile (:meth:`Crowd.check_stationary`).
"""

from __future__ import annotations

import copy

from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._plausibility import derived, implausibility, warn_notes
from .._validation import (FieldsFromDict, as_float_array, check_non_negative, check_positive,
                           fields_from_dict)
from ..errors import ParameterError
from .loading import STANDARD_GRAVITY
from .profile import JAM_DENSITY, CrowdProfile

__all__ = ["Crowd", "weidmann_speed", "bruno_venuti_step_frequency", "JAM_DENSITY"]

#: Free walking speed v_0 [m/s] of Weidmann's speed–density relation (docs: theory, The crowd, SOURCED).
FREE_SPEED = 1.34
#: Shape constant γ [persons/m²] of Weidmann's relation (docs: theory, The crowd, SOURCED).
WEIDMANN_GAMMA = 1.913
#: Standard deviation of step frequencies in unrestricted traffic [Hz] (AFGC 2006 via the paper).
UNRESTRICTED_STEP_FREQUENCY_STD = 0.175


def weidmann_speed(density: ArrayLike) -> np.ndarray:
    """Walking speed v(d) = v_0 [1 − exp(−γ (1/d − 1/d_max))] [m/s] (Weidmann 1993; docs: theory, The crowd).

    Check value: v(0.5) = 1.298 m/s, the paper's 1.30 m/s.

    Parameters
    ----------
    density : float or array_like
        Crowd density d [persons/m²], > 0 and below the jam density d_max.

    Returns
    -------
    ndarray
        Walking speed [m/s].

    See Also
    --------
    bruno_venuti_step_frequency : the mean step frequency at this speed.
    Crowd.from_density : a crowd with both relations applied.

    References
    ----------
    U. Weidmann, *Transporttechnik der Fussgänger*, IVT Nr. 90, ETH Zürich, 1993, in the form
    of L. Bruno and F. Venuti, *J. Sound Vib.* 323:475–493, 2009 (docs: theory, References).

    Examples
    --------
    >>> from crowdvib.models import weidmann_speed
    >>> round(float(weidmann_speed(0.5)), 3)
    1.298
    """
    density = check_positive("density", density, unit="persons/m²")
    if np.any(np.asarray(density) >= JAM_DENSITY):
        raise ParameterError(
            f"density must be < the jam density {JAM_DENSITY} persons/m² of the speed–density "
            f"model, got {np.max(density):g}")
    return FREE_SPEED * (1.0 - np.exp(-WEIDMANN_GAMMA * (1.0 / density - 1.0 / JAM_DENSITY)))


def bruno_venuti_step_frequency(speed: ArrayLike) -> np.ndarray:
    """Mean step frequency f_s(v) = 0.35 v³ − 1.59 v² + 2.93 v [Hz] (Bruno & Venuti 2009).

    SOURCED indirectly (docs: theory, The crowd: an independent public implementation has the
    same coefficients; the paper was not seen) and validated there: f_s(1.30) = 1.891 Hz, the
    paper's 1.89 Hz.

    Parameters
    ----------
    speed : float or array_like
        Walking speed v [m/s], > 0.

    Returns
    -------
    ndarray
        Mean step frequency [Hz].

    See Also
    --------
    weidmann_speed : the speed at a crowd density.

    References
    ----------
    L. Bruno and F. Venuti, "Crowd–structure interaction in footbridges: modelling, application
    to a real case-study and sensitivity analyses", *J. Sound Vib.* 323:475–493, 2009.

    Examples
    --------
    >>> from crowdvib.models import bruno_venuti_step_frequency
    >>> round(float(bruno_venuti_step_frequency(1.30)), 3)
    1.891
    """
    v = check_positive("speed", speed, unit="m/s")
    return 0.35 * v**3 - 1.59 * v**2 + 2.93 * v


@dataclass(frozen=True)
class Crowd(FieldsFromDict):
    """A stationary stream of pedestrians on the deck.

    Parameters
    ----------
    density : float or CrowdProfile
        Pedestrian density d [persons/m²], >= 0 (0 = empty deck), or a
        :class:`~crowdvib.models.CrowdProfile`, the density against the record's time (t = 0 its
        first sample; docs: theory, A crowd that changes), which :func:`crowdvib.simulate`,
        :func:`crowdvib.varying_response_psd` and :func:`crowdvib.estimate_hsi` follow and the
        models of a stationary crowd refuse (:meth:`check_stationary`).
    walking_speed : float
        Walking speed v [m/s], > 0, the same for all.
    step_frequency_mean : float
        Mean μ_fs of the step frequencies [Hz].
    step_frequency_std : float
        Standard deviation σ_fs [Hz], > 0.
    body_mass : float
        Body mass m_h [kg] of every pedestrian (the crowd's average, as in the paper).
    forward_fraction : float
        Fraction of pedestrians walking in the +x direction (the others walk back); used by the
        time-domain simulator, irrelevant to the spectral model.
    body_mass_std : float
        Standard deviation σ_m of the body masses [kg] (0: everybody weighs ``body_mass``, as
        in the paper). The simulator draws N(m_h, σ_m); the spectral load uses
        E[W²] = g² (m_h² + σ_m²) (docs: theory, Modal load PSD of a Poisson crowd), the apparent mass the mean m_h.

    See Also
    --------
    Crowd.from_density : speed and step frequency from the density (Weidmann, Bruno & Venuti).
    crowdvib.MSDModel : the pedestrians' mass-spring-damper model.
    crowdvib.response_psd : the response to the crowd.

    Examples
    --------
    The paper's crowd (docs: theory, The paper's numerical example), and its arrivals onto a
    3 m wide walkway, λ = d·B·v:

    >>> from crowdvib import Crowd
    >>> crowd = Crowd(density=0.5, walking_speed=1.30, step_frequency_mean=1.89,
    ...               step_frequency_std=0.175, body_mass=70.0)
    >>> round(crowd.arrival_rate(3.0), 3)                    # persons/s
    1.95

    A crowd that ramps from 0.2 to 1.0 persons/m² over an hour carries its profile:

    >>> from crowdvib import CrowdProfile
    >>> ramp = Crowd.from_density(CrowdProfile([0.0, 3600.0], [0.2, 1.0]))
    >>> ramp.profile.peak, round(ramp.walking_speed, 3)      # walkers of the mean, 0.6
    (1.0, 1.261)
    """

    # A union, not a float with a separate profile field: the constructor's keyword says what
    # it takes, and code that needs a number narrows it at its entry (check_stationary, or
    # ``profile``) rather than reading a placeholder density (issue 34 §3).
    density: float | CrowdProfile
    walking_speed: float
    step_frequency_mean: float
    step_frequency_std: float = UNRESTRICTED_STEP_FREQUENCY_STD
    body_mass: float = 70.0
    forward_fraction: float = 1.0
    body_mass_std: float = 0.0

    def __post_init__(self):
        # A profile checked its own densities (>= 0, below the jam density) when it was built.
        if not isinstance(self.density, CrowdProfile):
            if isinstance(self.density, dict) or np.ndim(self.density) != 0:
                raise ParameterError(f"density must be a number [persons/m²] or a CrowdProfile, "
                                     f"got {self.density!r:.60}")
            check_non_negative("density", self.density, unit="persons/m²")
            if self.density >= JAM_DENSITY:
                raise ParameterError(f"density must be < the jam density {JAM_DENSITY} "
                                     f"persons/m², got {self.density:g}")
            object.__setattr__(self, "density", float(self.density))
        check_positive("walking_speed", self.walking_speed, unit="m/s")
        check_positive("step_frequency_mean", self.step_frequency_mean, unit="Hz")
        check_positive("step_frequency_std", self.step_frequency_std, unit="Hz")
        check_positive("body_mass", self.body_mass, unit="kg")
        check_non_negative("body_mass_std", self.body_mass_std, unit="kg")
        if self.body_mass_std >= self.body_mass:
            raise ParameterError(
                f"body_mass_std must be < body_mass ({self.body_mass:g} kg), "
                f"got {self.body_mass_std:g} kg")
        fraction = float(as_float_array("forward_fraction", self.forward_fraction, ndim=0))
        if not 0.0 <= fraction <= 1.0:
            raise ParameterError(f"forward_fraction must lie in [0, 1], got {fraction:g}")
        for name in ("walking_speed", "step_frequency_mean", "step_frequency_std",
                     "body_mass", "forward_fraction", "body_mass_std"):
            object.__setattr__(self, name, float(getattr(self, name)))
        warn_notes(self.implausibilities(), stacklevel=3)

    def implausibilities(self) -> list[str]:
        """Legal but doubtful values, each with its likely unit mix-up and the value it would
        then be (docs: theory, Plausible ranges); the constructor warns with them.

        Walking speed (km/h?), mean and spread of the step frequencies (rad/s or steps per
        minute? — either puts the whole load spectrum above the modes: an all-zero response) and
        body mass (tonnes, grams or pounds?). The density has its error here (the jam density)
        and its design range in :func:`crowdvib.design.design_check`.
        """
        notes = [implausibility(name, getattr(self, name)) for name in (
            "walking_speed", "step_frequency_mean", "step_frequency_std", "body_mass")]
        return [note for note in notes if note is not None]

    @property
    def profile(self) -> CrowdProfile | None:
        """The density against time when it is a :class:`~crowdvib.models.CrowdProfile`, None
        for a stationary crowd (a number)."""
        return self.density if isinstance(self.density, CrowdProfile) else None

    def check_stationary(self, caller: str) -> Crowd:
        """This crowd if its density is a number, or a ParameterError naming ``caller``.

        The models of a stationary crowd (the spectral models, the design and comfort checks)
        have one density; a profile is followed by :func:`crowdvib.simulate`, the record's model
        (:func:`crowdvib.varying_response_psd`, :func:`crowdvib.response.record_model`) and
        :func:`crowdvib.estimate_hsi`, not reduced to a number silently.

        Parameters
        ----------
        caller : str
            The function or class that needs a number (for the message).
        """
        if isinstance(self.density, CrowdProfile):
            raise ParameterError(
                f"crowd.density must be a number [persons/m²] for {caller}, a model of a "
                "stationary crowd, got a CrowdProfile (a density that changes with time): "
                "crowdvib.varying_response_psd (or crowdvib.response.record_model) gives the "
                "expected PSD of a record whose crowd follows it, crowd.with_density(d) the "
                "stationary crowd of one density d")
        return self

    @classmethod
    def from_density(cls, density: float | CrowdProfile, *, body_mass: float = 70.0,
                     step_frequency_std: float = UNRESTRICTED_STEP_FREQUENCY_STD,
                     forward_fraction: float = 1.0, body_mass_std: float = 0.0) -> Crowd:
        """A crowd whose speed follows Weidmann and whose step frequency follows Bruno & Venuti.

        >>> crowd = Crowd.from_density(0.5)
        >>> round(crowd.walking_speed, 3), round(crowd.step_frequency_mean, 3)
        (1.298, 1.89)

        Parameters
        ----------
        density : float or CrowdProfile
            Crowd density d [persons/m²], > 0 and below the jam density, or its profile against
            time, whose mean over its table (:attr:`CrowdProfile.table_mean`) sets the walkers'
            speed and step frequency (as a case file's ``[crowd]`` without ``density``).
        body_mass, step_frequency_std, forward_fraction, body_mass_std
            As for :class:`Crowd`.

        Returns
        -------
        Crowd
            With ``walking_speed`` = :func:`~crowdvib.models.weidmann_speed` (d) and
            ``step_frequency_mean`` = :func:`~crowdvib.models.bruno_venuti_step_frequency` (v).
        """
        speed = float(weidmann_speed(density.table_mean if isinstance(density, CrowdProfile)
                                     else density))
        with derived():          # warned below, at the caller's line rather than here
            crowd = cls(density=density, walking_speed=speed,
                        step_frequency_mean=float(bruno_venuti_step_frequency(speed)),
                        step_frequency_std=step_frequency_std, body_mass=body_mass,
                        forward_fraction=forward_fraction, body_mass_std=body_mass_std)
        warn_notes(crowd.implausibilities(), stacklevel=2)
        return crowd

    def to_dict(self) -> dict[str, Any]:
        """The crowd as a JSON-ready dict (keys as the parameters; a profile density as
        :meth:`CrowdProfile.to_dict`)."""
        data = asdict(self)
        if isinstance(self.density, CrowdProfile):
            data["density"] = self.density.to_dict()
        return data

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Crowd:
        """The crowd of :meth:`to_dict`'s dict, as :meth:`FieldsFromDict.from_dict` reads one
        (a DataError for a missing field), its ``density`` a number or a profile's table
        (:meth:`CrowdProfile.from_dict`).

        Parameters
        ----------
        data : dict
            The crowd's fields by name, from JSON.
        """
        if isinstance(data, dict) and isinstance(data.get("density"), dict):
            return fields_from_dict(cls, data, density=CrowdProfile.from_dict(data["density"]))
        return fields_from_dict(cls, data)

    def with_density(self, density: float | CrowdProfile) -> Crowd:
        """The same walkers at another density (speed and step frequencies unchanged).

        The walkers were checked for plausibility when this crowd was built: no warning again.

        Parameters
        ----------
        density : float or CrowdProfile
            The new density [persons/m²], >= 0 and below the jam density, or a profile.
        """
        with derived():
            return replace(self, density=density)

    def _with_checked(self, **fields: float) -> Crowd:
        """This crowd with numeric ``fields`` set that the caller has checked against the rules
        of ``__post_init__`` (an optimiser's step frequencies inside bounds checked when the fit
        began; a mixture's node density, checked when its model was built): the checks cost a
        fifth of an evaluation of the model for other step frequencies (issue 39)."""
        other = copy.copy(self)
        for name, value in fields.items():
            object.__setattr__(other, name, float(value))
        return other

    def mean_square_weight(self) -> float:
        """E[W²] = g² (m_h² + σ_m²) [N²]: the weight factor of the crowd-load PSD (docs: theory, Modal load PSD of a Poisson crowd)."""
        return STANDARD_GRAVITY**2 * (self.body_mass**2 + self.body_mass_std**2)

    def arrival_rate(self, width: float) -> float:
        """Poisson arrival rate λ = d·B·v [persons/s] onto a walkway of width B (docs: theory, Poisson arrivals).

        Parameters
        ----------
        width : float
            Walkway width B [m].

        Returns
        -------
        float
            λ [persons/s].
        """
        density = self.check_stationary("Crowd.arrival_rate").density
        return density * check_positive("width", width, unit="m") * self.walking_speed

    def step_frequency_pdf(self, step_frequency: ArrayLike) -> np.ndarray:
        """Gaussian density p_fs of the step frequencies [1/Hz].

        Parameters
        ----------
        step_frequency : array_like
            Step frequencies f_s [Hz].

        Returns
        -------
        ndarray
            N(μ_fs, σ_fs) density at each step frequency [1/Hz].
        """
        z = (np.asarray(step_frequency, dtype=float) - self.step_frequency_mean) / self.step_frequency_std
        return np.exp(-0.5 * z * z) / (self.step_frequency_std * np.sqrt(2.0 * np.pi))

