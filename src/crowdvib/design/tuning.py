"""Tuning a tuned mass damper to a mode, of the empty or of the occupied footbridge.

Den Hartog (1956) minimises the peak displacement of an undamped primary system under force,
Asami, Nishihara & Baz (2002) its peak acceleration (docs: theory, Why modes just above f_h1 feel the crowd most). Both are fixed-point
optima for an undamped primary; with a crowd on the deck the primary is the *occupied* mode,
whose frequency and engaged modal mass come from :func:`crowdvib.effective_modal_properties`:
a damper tuned to the empty bridge is detuned by the crowd's human–structure interaction.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .._plausibility import warn_if_implausible
from .._validation import check_positive, check_type
from ..errors import ParameterError
from ..models.crowd import Crowd
from ..models.damper import TunedMassDamper
from ..models.structure import ModalModel
from ..response.frequency_domain.spectral import effective_modal_properties

if TYPE_CHECKING:
    from ..models.pedestrian import MSDModel

__all__ = ["optimal_tuning", "tune_damper", "TUNING_CRITERIA"]

#: Criteria of :func:`optimal_tuning`: the output whose peak the damper minimises.
TUNING_CRITERIA = ("acceleration", "displacement")


def optimal_tuning(mass_ratio, criterion="acceleration"):
    """Optimal frequency ratio γ = f_d/f_j and damping ratio ζ of a damper (docs: theory, Why modes just above f_h1 feel the crowd most).

    * ``"displacement"`` (Den Hartog 1956): γ = 1/(1+μ), ζ = sqrt(3μ / (8 (1+μ))). Den Hartog
      tabulates (c/c_c)² = 3μ / (8 (1+μ)³) with c_c = 2 m_d ω_j, the *structure's* frequency;
      the damper's own ratio c/(2 m_d ω_d), ω_d = γ ω_j, is (1+μ) times that.
    * ``"acceleration"`` (Asami et al. 2002, fixed-point form DERIVED in docs: theory, Why modes
      just above f_h1 feel the crowd most): γ = 1/sqrt(1+μ), ζ = sqrt(3μ / (8 (1 + μ/2))),
      already the damper's own ratio.

    ζ is the damper's own damping ratio c/(2 m_d ω_d), as :class:`TunedMassDamper` takes it
    (both checked by the fixed-point construction in docs: theory, Design checks, Tuning).

    Parameters
    ----------
    mass_ratio : float
        μ = damper mass × φ² at the damper / modal mass [-], > 0.
    criterion : {"acceleration", "displacement"}

    Returns
    -------
    (float, float)
        γ [-] and ζ [-].

    See Also
    --------
    crowdvib.tune_damper

    References
    ----------
    J. P. Den Hartog, *Mechanical Vibrations*, 4th ed., McGraw-Hill, 1956, §3.3.

    T. Asami, O. Nishihara and A. M. Baz, "Analytical solutions to H∞ and H2 optimization of dynamic
    vibration absorbers attached to damped linear systems", *Journal of Vibration and Acoustics*
    124:284–295, 2002.

    The theory pages cite them (docs: theory, References).

    Examples
    --------
    >>> [round(v, 4) for v in optimal_tuning(0.05)]          # docs: theory, Inverse problem
    [0.9759, 0.1353]
    """
    mu = check_positive("mass_ratio", mass_ratio)
    if criterion == "displacement":
        return 1.0 / (1.0 + mu), float(np.sqrt(3 * mu / (8 * (1 + mu))))
    if criterion == "acceleration":
        return float(1.0 / np.sqrt(1.0 + mu)), float(np.sqrt(3 * mu / (8 * (1 + mu / 2))))
    raise ParameterError(f"criterion must be one of {list(TUNING_CRITERIA)}, got {criterion!r}")


def _antinode(structure, mode):
    """Position [m], lane [m] and shape value where |φ_mode| is largest on the walkway."""
    shapes = np.abs(structure.mode_shapes[:, :, mode])            # (lanes, positions)
    lane, station = np.unravel_index(np.argmax(shapes), shapes.shape)
    lanes = structure.lanes
    return (float(structure.positions[station]),
            None if lanes.size == 1 else float(lanes[lane]),
            float(structure.mode_shapes[lane, station, mode]))


def tune_damper(structure: ModalModel, mode: int, mass_ratio: float, *, crowd: Crowd | None = None,
                msd: MSDModel | None = None, criterion: str = "acceleration") -> TunedMassDamper:
    """A tuned mass damper at the antinode of a mode, tuned to the empty or occupied structure.

    The damper's mass is m_d = μ m_j / φ_j(x_d)² with m_j the *empty* modal mass, so one
    ``mass_ratio`` buys the same damper with and without crowd. Its frequency and damping follow
    :func:`optimal_tuning` for the targeted mode: the empty mode, or with ``crowd`` and ``msd``
    the occupied mode (effective frequency f_j,eff and engaged modal mass m_j,eff of
    :func:`crowdvib.effective_modal_properties`, so the tuning uses μ_eff = m_d φ² / m_j,eff).

    Parameters
    ----------
    structure : ModalModel
        The empty footbridge.
    mode : int
        Index of the mode to control (0-based).
    mass_ratio : float
        μ = m_d φ_j(x_d)² / m_j [-], > 0 (typically 0.01–0.05).
    crowd : Crowd, optional
        The design crowd; needed with ``msd``, and only with it (without an MSD the crowd
        changes nothing, so it is refused rather than ignored).
    msd : MSDModel, optional
        The pedestrians' MSD model; with it the damper is tuned to the occupied mode.
    criterion : {"acceleration", "displacement"}
        Asami et al. (2002) or Den Hartog (1956).

    Returns
    -------
    TunedMassDamper
        At the antinode of the mode (largest |φ_j| over the sampled walkway).

    See Also
    --------
    crowdvib.design.optimal_tuning : the tuning rule alone.
    crowdvib.design_check

    References
    ----------
    J. P. Den Hartog, *Mechanical Vibrations*, 4th ed., McGraw-Hill, 1956, §3.3. The optimum tuning
    of a damper on an undamped structure.

    T. Asami, O. Nishihara and A. M. Baz, "Analytical solutions to H∞ and H2 optimization of dynamic
    vibration absorbers attached to damped linear systems", *Journal of Vibration and Acoustics*
    124:284–295, 2002. The H∞ and H2 optima.

    The theory pages cite them (docs: theory, References).

    Examples
    --------
    >>> from crowdvib import ModalModel
    >>> bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    >>> damper = tune_damper(bridge, 0, 0.02)
    >>> round(damper.mass), round(damper.frequency, 4), damper.position
    (1000, 1.9803, 25.0)
    """
    check_type("structure", structure, ModalModel)
    if isinstance(mode, bool) or not isinstance(mode, (int, np.integer)) \
            or not 0 <= mode < structure.n_modes:
        raise ParameterError(
            f"mode must be an integer index in [0, {structure.n_modes - 1}], got {mode!r}")
    if crowd is not None:
        check_type("crowd", crowd, Crowd).check_stationary("tune_damper")
        if msd is None:
            raise ParameterError("msd must be given with crowd: the damper is tuned to the "
                                 "occupied mode of the crowd's MSDs, and a crowd without them "
                                 "would be ignored; give msd, or leave crowd out for the empty "
                                 "bridge")
    mu = check_positive("mass_ratio", mass_ratio)
    # 2 meant as 2 % would build a damper as heavy as the mode (docs: theory, Plausible ranges).
    warn_if_implausible("mass_ratio", mu, stacklevel=2)
    optimal_tuning(mu, criterion)                          # checks the criterion early
    position, lane, shape = _antinode(structure, mode)
    damper_mass = mu * structure.modal_masses[mode] / shape**2
    target = effective_modal_properties(structure, crowd, msd)
    effective_ratio = damper_mass * shape**2 / target.modal_masses[mode]
    gamma, zeta = optimal_tuning(effective_ratio, criterion)
    return TunedMassDamper(mass=damper_mass, frequency=gamma * target.frequencies[mode],
                           damping_ratio=zeta, position=position, lane=lane)
