"""Serviceability checks to the design guides, with and without human–structure interaction.

:func:`design_check` applies the resonant crowd load of Sétra/HiVoSS (:mod:`.codes`) mode by mode
to three models of the structure, side by side:

* ``"empty"``: the empty structure's modal properties, as the guides do;
* ``"added_mass"``: the crowd's mass added to each mode (m_j + m_h Ψ_jj), so frequencies drop
  by sqrt(m_j / (m_j + m_h Ψ_jj)); the damping ratios are kept, as the guides tabulate them;
* ``"hsi"`` (with an ``msd``): the occupied mode of the crowd of MSDs, its frequency, damping
  ratio and engaged modal mass from :func:`crowdvib.effective_modal_properties`.

The ratio of the governing accelerations tells the engineer what the identified interaction is
worth.
"""

from dataclasses import dataclass

import numpy as np

from .._validation import check_non_negative, frozen_array
from ..errors import ParameterError
from ..models.crowd import Crowd
from ..models.pedestrian import MSDModel
from ..models.structure import ModalModel
from ..response.spectral import effective_modal_properties
from .codes import (CODES, HARMONIC_FORCES, class_density, comfort_class, comfort_limit,
                    equivalent_pedestrians, reduction_factor)

__all__ = ["DesignCheck", "design_check", "resonant_response"]


@dataclass(frozen=True, eq=False)
class DesignCheck:
    """Verdict of a design-code comfort check, for one or several models of the structure.

    Attributes
    ----------
    code : str
        "setra", "hivoss" or "en1990".
    traffic_class : str or None
        The class checked (None when only a density was given).
    density : float
        Crowd density d [persons/m²] of the check.
    limit : float
        Acceleration limit [m/s²]: the upper bound of the target comfort class, or EN 1990's.
    output_names : tuple of str
    models : tuple of str
        The structural models checked, in order: "empty", "added_mass" and, with an MSD, "hsi".
    frequencies, damping_ratios, modal_masses : ndarray, shape (n_models, n_modes)
        Modal properties each model uses [Hz], [-], [kg in the scaling of the mode shapes].
    modal_forces : ndarray, shape (n_models, n_modes)
        Amplitude |Q_j| of the resonant modal force [N × scaling].
    harmonics : ndarray of int, shape (n_models, n_modes)
        Walking harmonic (1 or 2) that loads each mode; 0 where ψ = 0 for both.
    peak_accelerations : ndarray, shape (n_models, n_outputs, n_modes)
        Steady-state resonant peak accelerations [m/s²] at each output, mode by mode.
    """

    code: str
    traffic_class: str
    density: float
    limit: float
    output_names: tuple
    models: tuple
    frequencies: np.ndarray
    damping_ratios: np.ndarray
    modal_masses: np.ndarray
    modal_forces: np.ndarray
    harmonics: np.ndarray
    peak_accelerations: np.ndarray

    def __post_init__(self):
        for name in ("frequencies", "damping_ratios", "modal_masses", "modal_forces",
                     "peak_accelerations"):
            object.__setattr__(self, name, frozen_array(getattr(self, name)))
        object.__setattr__(self, "harmonics", frozen_array(self.harmonics, int))

    @property
    def primary(self):
        """The model the verdict is given for: "hsi" when checked, else "empty" (the guides)."""
        return "hsi" if "hsi" in self.models else "empty"

    @property
    def peak_acceleration(self):
        """Peak accelerations [m/s²] of the primary model, shape (n_outputs, n_modes)."""
        return self.peak_accelerations[self.models.index(self.primary)]

    def governing_of(self, model):
        """Largest peak acceleration over the modes [m/s²] per output, for one model."""
        if model not in self.models:
            raise ParameterError(f"model must be one of {list(self.models)}, got {model!r}")
        return self.peak_accelerations[self.models.index(model)].max(axis=1)

    @property
    def governing(self):
        """Largest peak acceleration over the modes per output [m/s²] (primary model)."""
        return self.governing_of(self.primary)

    @property
    def utilisation(self):
        """governing / limit per output [-]: above 1 fails the check."""
        return self.governing / self.limit

    @property
    def comfort_class(self):
        """Comfort class ("CL1"…"CL4") per output, from the governing acceleration."""
        return comfort_class(self.governing)

    @property
    def ratios(self):
        """Governing accelerations of each model over each earlier one, per output [-]:
        keys "added_mass/empty", and with HSI "hsi/empty" and "hsi/added_mass"."""
        result = {}
        for later in range(1, len(self.models)):
            for earlier in range(later):
                top, bottom = self.models[later], self.models[earlier]
                with np.errstate(divide="ignore", invalid="ignore"):
                    result[f"{top}/{bottom}"] = self.governing_of(top) / self.governing_of(bottom)
        return result

    def to_dict(self):
        """JSON-ready dict: inputs, per-model modal data and accelerations, and the verdict."""
        return {
            "code": self.code, "traffic_class": self.traffic_class, "density": self.density,
            "limit": self.limit, "output_names": list(self.output_names),
            "models": list(self.models), "primary": self.primary,
            **{name: getattr(self, name).tolist() for name in
               ("frequencies", "damping_ratios", "modal_masses", "modal_forces", "harmonics",
                "peak_accelerations")},
            "governing": self.governing.tolist(), "utilisation": self.utilisation.tolist(),
            "comfort_class": list(self.comfort_class),
            "ratios": {key: value.tolist() for key, value in self.ratios.items()},
        }


def resonant_response(structure, density, frequencies, damping_ratios, modal_masses):
    """Steady-state resonant response of every mode to the Sétra/HiVoSS crowd load.

    Mode j is loaded at its frequency f_j by p = F_h ψ_h(f_j) n_eq / A applied with the sign of
    φ_j, for the harmonic h (1: 280 N, 2: 70 N) whose ψ is non-zero, so Q_j = p ∫_A |φ_j| dA; its
    modal acceleration is |Q_j| / (2 ξ_j m_j) and the output o sees |φ_o,j| times that.

    Parameters
    ----------
    structure : ModalModel
        Supplies the walkway, the mode shapes and the outputs.
    density : float
        d [persons/m²].
    frequencies, damping_ratios, modal_masses : array_like, shape (n_modes,)
        The modal properties to use [Hz], [-], [kg].

    Returns
    -------
    (ndarray, ndarray, ndarray)
        Modal forces |Q_j| (n_modes,), harmonics (n_modes,), peak accelerations
        (n_outputs, n_modes) [m/s²].
    """
    area = structure.area
    n_eq = equivalent_pedestrians(density, area, damping_ratios)
    amplitudes = np.stack([HARMONIC_FORCES[h] * reduction_factor(frequencies, h) for h in (1, 2)])
    harmonics = np.where(amplitudes.max(axis=0) > 0, amplitudes.argmax(axis=0) + 1, 0)
    forces = amplitudes.max(axis=0) * n_eq / area * structure.shape_integrals(absolute=True)
    modal = forces / (2 * np.asarray(damping_ratios) * np.asarray(modal_masses))
    return forces, harmonics, np.abs(structure.output_shapes) * modal


def _check_density(code, structure, traffic_class, density, crowd):
    if density is not None:
        density = check_non_negative("density", density, unit="persons/m²")
    elif traffic_class is not None:
        density = class_density(code, traffic_class, structure.area)
    elif crowd is not None:
        density = crowd.density
    else:
        raise ParameterError("a design check needs traffic_class, density or crowd: "
                             "all three are None")
    if density <= 0:
        raise ParameterError(f"density must be > 0 persons/m² for a design check, got "
                             f"{density:g}")
    return float(density)


def design_check(structure, code, *, traffic_class=None, density=None, crowd=None, msd=None,
                 comfort_class=None):
    """Comfort check of a footbridge to a design guide, without and with HSI.

    Parameters
    ----------
    structure : ModalModel
        The empty footbridge.
    code : {"setra", "hivoss", "en1990"}
        Sétra/AFGC 2006, HiVoSS 2008, or EN 1990 Annex A2's limit (0.7 m/s²) with the HiVoSS
        load and classes.
    traffic_class : str, optional
        "I", "II", "III" (Sétra) or "TC1"…"TC5" (HiVoSS, EN 1990).
    density : float, optional
        Crowd density [persons/m²]; overrides the class's density.
    crowd : Crowd, optional
        Body mass (and walkers) of the design crowd; its density is replaced by the class's
        (default ``Crowd.from_density``: 70 kg). Used for the added mass and with ``msd``.
    msd : MSDModel, optional
        The pedestrians' MSD model (identified or assumed): adds the "hsi" model.
    comfort_class : {"CL1", "CL2", "CL3"}, optional
        Target comfort class of Sétra/HiVoSS (default "CL2", mean comfort: 1.0 m/s²).

    Returns
    -------
    DesignCheck

    Examples
    --------
    >>> from crowdvib import ModalModel, MSDModel
    >>> bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    >>> check = design_check(bridge, "hivoss", traffic_class="TC3", msd=MSDModel())
    >>> check.comfort_class, round(float(check.ratios["hsi/empty"][0]), 2)
    (('CL3',), 0.58)
    """
    if not isinstance(structure, ModalModel):
        raise ParameterError(f"structure must be a ModalModel, got {type(structure).__name__}")
    if code not in CODES:
        raise ParameterError(f"code must be one of {list(CODES)}, got {code!r}")
    if crowd is not None and not isinstance(crowd, Crowd):
        raise ParameterError(f"crowd must be a Crowd or None, got {type(crowd).__name__}")
    if msd is not None and not isinstance(msd, MSDModel):
        raise ParameterError(f"msd must be an MSDModel or None, got {type(msd).__name__}")
    limit = comfort_limit(code, comfort_class)
    density = _check_density(code, structure, traffic_class, density, crowd)
    if np.any(structure.damping_ratios == 0):
        raise ParameterError("damping_ratios must be > 0 for a resonant design check, got "
                             f"{structure.damping_ratios.tolist()}")
    crowd = (Crowd.from_density(density) if crowd is None else crowd.with_density(density))

    m = structure.modal_masses
    loaded = m + crowd.body_mass * np.diag(structure.influence_matrix(density))
    properties = {"empty": (structure.frequencies, structure.damping_ratios, m),
                  "added_mass": (structure.frequencies * np.sqrt(m / loaded),
                                 structure.damping_ratios, loaded)}
    if msd is not None:
        occupied = effective_modal_properties(structure, crowd, msd)
        properties["hsi"] = (occupied.frequencies, occupied.damping_ratios,
                             occupied.modal_masses)
    columns = {name: [] for name in ("frequencies", "damping_ratios", "modal_masses",
                                     "modal_forces", "harmonics", "peak_accelerations")}
    for frequencies, ratios, masses in properties.values():
        forces, harmonics, peaks = resonant_response(structure, density, frequencies, ratios,
                                                     masses)
        for name, value in zip(columns, (frequencies, ratios, masses, forces, harmonics, peaks)):
            columns[name].append(value)
    return DesignCheck(code=code, traffic_class=traffic_class, density=density, limit=limit,
                       output_names=structure.output_names, models=tuple(properties),
                       **{name: np.array(value) for name, value in columns.items()})
