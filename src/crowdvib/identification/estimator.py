"""The estimator as one value: every choice of the inverse problem written once (issue 34 §2).

:class:`Estimator` holds what :func:`~crowdvib.estimate_hsi` is asked besides the data: the
misfit (``method``), the band, the intervals, the crowd model, bounds, starts and which
parameters are free. Its defaults are the estimator a user gets without asking
(:mod:`crowdvib._estimators`, docs: theory, Calibration); ``estimate_hsi(...)`` is the same
call with the choices spelled out. A study, a case file (its ``[estimation]`` table) or a
notebook holds one value, changes it with :meth:`Estimator.replace`, and fits it with
:meth:`Estimator.fit` (one record) or :meth:`Estimator.fit_joint` (several). The studies
(:func:`~crowdvib.studies.modelling_error_study`, :func:`~crowdvib.studies.record_length_study`,
:func:`~crowdvib.studies.objective_map`, :func:`~crowdvib.studies.season_study`) take it
as ``estimator=``, and every command of a case file fits with the one
:func:`crowdvib.cases.case_estimator` makes of its ``[estimation]`` table. That the defaults of
every entry point agree with this one, and that no other entry point spells the choices out
again, is tested (tests/identification/test_estimator.py).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from .._estimators import DEFAULT_DENSITY_UNCERTAINTY, DEFAULT_METHOD, check_method
from ..errors import ParameterError
from .estimation import estimate_hsi, estimate_hsi_joint
from .objective import PSDObjective

if TYPE_CHECKING:
    from .._typing import ForceModel, Seed
    from ..models.crowd import Crowd
    from ..models.structure import ModalModel
    from ..signals.spectrum import ResponsePSD
    from .result import HSIEstimate

__all__ = ["Estimator"]

#: The choices that shape only the interval, or the check before the fit, not the point estimate.
_INTERVAL_CHOICES = ("interval", "level", "n_boot", "density_uncertainty", "check_level")
#: The choices of the misfit itself (:class:`~crowdvib.identification.PSDObjective`).
_OBJECTIVE_CHOICES = ("band", "force", "outputs", "output_weights", "frequency_weights",
                      "match_welch", "method", "crowd_model")


@dataclass(frozen=True)
class Estimator:
    """The choices of the inverse problem, with the defaults of :func:`~crowdvib.estimate_hsi`.

    Each choice in full is in :func:`~crowdvib.estimate_hsi`'s parameters.

    Parameters
    ----------
    band : (float, float)
        Analysis band [Hz] (the paper: 0–10 Hz for the numerical example, 2.5–8 Hz for Eeklo,
        2–6 Hz for Waalse Krook).
    method : {"likelihood", "least_squares"}
        The Whittle likelihood of the Welch ordinates (default) or the paper's least squares.
    interval : {"profile", "wald", "bootstrap", None}
        The statistical uncertainty (None: none, fastest).
    level : float
        Confidence level of the intervals.
    crowd_model : {"fluctuating", "smeared"}, optional
        The expected PSD's crowd (default: the method's).
    free_step_frequencies : bool, optional
        Fit the crowd's step-frequency distribution with the MSD (default: the method's).
    mass_ratio : float
        μ_h1 when held (paper: 0.95).
    free_mass_ratio : bool
        Estimate μ_h1 too.
    bounds, starts
        Search bounds (parameter → (lower, upper)) and starting points; default
        :data:`~crowdvib.identification.DEFAULT_BOUNDS` and four spread points.
    outputs, output_weights, frequency_weights
        Outputs to fit, their γ_l and the frequency weight (paper Eq. 6).
    force : ZivanovicForce or YoungForce, optional
        Walking force model (default Živanović 2007).
    match_welch : bool
        Compare with what a Welch estimate of the measured window length would see.
    n_boot : int
        Bootstrap replicates (``interval="bootstrap"``).
    density_uncertainty : float
        Relative standard uncertainty of the stated crowd density, carried by the intervals.
    check_level : bool
        Refuse a measured level no MSD explains (a unit mix-up) before any fit.

    Examples
    --------
    >>> from crowdvib.identification import Estimator
    >>> paper = Estimator(band=(0.0, 10.0), method="least_squares", interval=None)
    >>> paper.replace(interval="wald").interval
    'wald'
    """

    band: tuple[float, float] | None = None
    method: str = DEFAULT_METHOD
    interval: str | None = "profile"
    level: float = 0.95
    crowd_model: str | None = None
    free_step_frequencies: bool | None = None
    mass_ratio: float = 0.95
    free_mass_ratio: bool = False
    bounds: Mapping[str, tuple[float, float]] | None = None
    starts: Sequence[Sequence[float]] | None = None
    outputs: Sequence[str] | None = None
    output_weights: Sequence[float] | None = None
    frequency_weights: Callable | Any = None
    force: ForceModel | None = None
    match_welch: bool = True
    n_boot: int = 200
    density_uncertainty: float = DEFAULT_DENSITY_UNCERTAINTY
    check_level: bool = True

    def __post_init__(self):
        check_method(self.method)

    def replace(self, **changes: Any) -> Estimator:
        """The same estimator with some choices changed.

        Parameters
        ----------
        **changes
            Choice → new value (names as the parameters).
        """
        return dataclasses.replace(self, **changes)

    def options(self, *, point_only: bool = False) -> dict[str, Any]:
        """The choices as keyword arguments of :func:`~crowdvib.estimate_hsi`.

        Parameters
        ----------
        point_only : bool
            Only the choices that shape the point estimate: without ``interval``, ``level``,
            ``n_boot``, ``density_uncertainty`` and ``check_level`` (a study's tasks compare
            point estimates, and their keys then change only with what moves them).

        Raises
        ------
        ParameterError
            ``band`` is not given.
        """

        if self.band is None:
            raise ParameterError("band must be given: the analysis band [Hz] of the estimator "
                                 "(Estimator(band=(lower, upper)))")
        return {item.name: getattr(self, item.name) for item in dataclasses.fields(self)
                if not (point_only and item.name in _INTERVAL_CHOICES)}

    def objective(self, measured: ResponsePSD, structure: ModalModel,
                  crowd: Crowd) -> PSDObjective:
        """The misfit these choices minimise, at the crowd as given.

        Parameters
        ----------
        measured, structure, crowd
            As :meth:`fit`.

        Returns
        -------
        PSDObjective
        """

        given = self.options()
        return PSDObjective(measured, structure, crowd,
                            **{name: given[name] for name in _OBJECTIVE_CHOICES})

    def fit(self, measured: ResponsePSD, structure: ModalModel, crowd: Crowd, *,
            rng: Seed = None) -> HSIEstimate:
        """The MSD of one record: :func:`~crowdvib.estimate_hsi` with these choices.

        Parameters
        ----------
        measured : ResponsePSD
        structure : ModalModel
        crowd : Crowd
            Its density a number or a profile over the record (as :func:`~crowdvib.estimate_hsi`).
        rng : None, int or numpy.random.Generator
            Seed of the bootstrap replicates.
        """

        return estimate_hsi(measured, structure, crowd, rng=rng, **self.options())

    def fit_joint(self, measurements: Sequence[ResponsePSD], structure: ModalModel,
                  crowds: Sequence[Crowd], *, rng: Seed = None) -> HSIEstimate:
        """One MSD for several records, each with its crowd:
        :func:`~crowdvib.estimate_hsi_joint` with these choices (its ``method`` the one it
        states; the joint fit holds each record's crowd, so ``free_step_frequencies`` must not
        be True).

        Parameters
        ----------
        measurements, structure, crowds, rng
            As :func:`~crowdvib.estimate_hsi_joint`.
        """

        given = self.options()
        if given.pop("free_step_frequencies") is True:
            raise ParameterError("free_step_frequencies must not be True for a joint fit: it "
                                 "holds each record's crowd as given (Estimator.replace("
                                 "free_step_frequencies=None))")
        return estimate_hsi_joint(measurements, structure, crowds, rng=rng, **given)


def check_estimator(estimator: Any) -> Estimator:
    """``estimator`` if it is an :class:`Estimator`, else a ParameterError naming the rule
    (the studies take their estimator as one value)."""

    if not isinstance(estimator, Estimator):
        raise ParameterError(f"estimator must be a crowdvib.identification.Estimator (e.g. "
                             f"Estimator(band=(0.0, 10.0))), got {type(estimator).__name__}")
    return estimator
