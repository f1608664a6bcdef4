"""Constants and load models of the footbridge design guides (vertical direction).

Sétra/AFGC (2006), "Footbridges – Assessment of vibrational behaviour of footbridges under
pedestrian loading", and HiVoSS (2008), "Design of footbridges – Guideline", share one resonant
load model: a harmonic pressure p = F·ψ(f_j)·n_eq/A applied with the sign of mode j at its natural
frequency, F = 280 N for the first and 70 N for the second walking harmonic per *equivalent*
pedestrian, n_eq = 10.8·sqrt(ξ_j n) below 1 person/m² and 1.85·sqrt(n) at or above it. EN 1990
Annex A2 gives the limit 0.7 m/s² but no load model; crowdvib checks it with the same load.

Provenance (docs: theory, Design-guide load models, §1.5, §10): each constant says whether it was read in a public
source (SOURCED, with where) or is RECALLED from the guides, which were not reachable here; a
RECALLED constant is a default to verify against the guide before a design relies on it.
"""

import numpy as np

from .._validation import check_non_negative
from ..errors import ParameterError

__all__ = ["CODES", "TRAFFIC_CLASSES", "COMFORT_CLASSES", "EN1990_VERTICAL_LIMIT",
           "HARMONIC_FORCES", "reduction_factor", "equivalent_pedestrians", "class_density",
           "comfort_class", "comfort_limit"]

#: Codes understood by :func:`crowdvib.design.design_check`.
CODES = ("setra", "hivoss", "en1990")

#: Vertical force amplitude per equivalent pedestrian [N] of walking harmonic 1 and 2.
#: 280 N: SOURCED (public Sétra/HiVoSS implementations, docs: theory, Design-guide load models: the CSA S7 code
#: "equivalent_number_of_pedestrians", NEY-DPI/Footbridge-Vibrations func.py). 70 N for the
#: second harmonic: RECALLED (Sétra 2006 load case 3). HiVoSS folds the second harmonic into ψ
#: with a plateau of 0.25 on 280 N (RECALLED), the same 70 N.
HARMONIC_FORCES = {1: 280.0, 2: 70.0}

#: Frequency reduction factor ψ(f) [-] for the vertical direction: (frequency [Hz], ψ) corners
#: of the piecewise-linear curve, 0 outside. RECALLED (the ψ figures of Sétra 2006 and HiVoSS
#: 2008 for vertical vibrations; docs: theory, Design-guide load models): first harmonic 0 → 1 on 1.25–1.7 Hz, 1 to
#: 2.1 Hz, → 0 at 2.3 Hz; second harmonic 0 → 1 on 2.5–3.4 Hz, 1 to 4.2 Hz, → 0 at 4.6 Hz
#: (HiVoSS: × 0.25 with 280 N).
REDUCTION_FACTOR_CORNERS = {
    1: ((1.25, 0.0), (1.7, 1.0), (2.1, 1.0), (2.3, 0.0)),
    2: ((2.5, 0.0), (3.4, 1.0), (4.2, 1.0), (4.6, 0.0)),
}

#: Equivalent synchronised pedestrians n_eq = SPARSE·sqrt(ξ n) (d < 1 P/m²) or DENSE·sqrt(n)
#: (d >= 1 P/m²). SOURCED (CSA S7 implementation and NEY-DPI/Footbridge-Vibrations get_N_eq,
#: docs: theory, The walking force).
SPARSE_FACTOR, DENSE_FACTOR, DENSE_FROM = 10.8, 1.85, 1.0

#: Traffic classes: density [persons/m²], or ("persons", n) for a fixed number on the deck.
#: HiVoSS TC1 = 15 persons, TC2 0.2, TC3 0.5, TC4 1.0: SOURCED (NEY-DPI/Footbridge-Vibrations
#: func.py get_d); TC5 = 1.5: RECALLED for HiVoSS (the CSA S7 implementation has 1.5).
#: Sétra classes I = 1.0, II = 0.8, III = 0.5 P/m²: RECALLED (docs: theory, Design-guide load models); class IV needs
#: no check. EN 1990 has no classes of its own: it takes HiVoSS's.
_HIVOSS_CLASSES = {"TC1": ("persons", 15.0), "TC2": 0.2, "TC3": 0.5, "TC4": 1.0, "TC5": 1.5}
TRAFFIC_CLASSES = {
    "setra": {"I": 1.0, "II": 0.8, "III": 0.5},
    "hivoss": _HIVOSS_CLASSES,
    "en1990": _HIVOSS_CLASSES,
}

#: Vertical comfort classes: (name, upper bound of the peak acceleration [m/s²]). HiVoSS CL1
#: maximum < 0.5, CL2 mean 0.5–1.0, CL3 minimum 1.0–2.5, CL4 unacceptable > 2.5; Sétra's
#: maximum/mean/minimum comfort have the same ranges. SOURCED (CSA S7 implementation
#: COMFORT_LEVELS_VERTICAL, the same ranges; docs: theory, Design-guide load models recalls the Sétra ones).
COMFORT_CLASSES = (("CL1", 0.5), ("CL2", 1.0), ("CL3", 2.5), ("CL4", np.inf))

#: EN 1990 Annex A2 (A2.4.3.2) recommended maximum vertical deck acceleration [m/s²] for
#: pedestrian comfort. RECALLED (the Eurocode text was not reachable here).
EN1990_VERTICAL_LIMIT = 0.7


def reduction_factor(frequency, harmonic):
    """Frequency reduction factor ψ [-] of walking harmonic 1 or 2 (vertical).

    Parameters
    ----------
    frequency : array_like
        Natural frequency of the mode [Hz].
    harmonic : {1, 2}

    Returns
    -------
    ndarray, shape of ``frequency``
    """
    if harmonic not in REDUCTION_FACTOR_CORNERS:
        raise ParameterError(f"harmonic must be 1 or 2, got {harmonic!r}")
    corners, values = np.array(REDUCTION_FACTOR_CORNERS[harmonic]).T
    return np.interp(np.asarray(frequency, dtype=float), corners, values, left=0.0, right=0.0)


def equivalent_pedestrians(density, area, damping_ratio):
    """Equivalent number of synchronised pedestrians n_eq [-] (Sétra 2006, HiVoSS 2008).

    n_eq = 10.8·sqrt(ξ n) for d < 1 person/m², 1.85·sqrt(n) for d >= 1, with n = d·A.

    Parameters
    ----------
    density : float
        d [persons/m²].
    area : float
        Walkway area A [m²].
    damping_ratio : array_like
        ξ_j [-] of each mode.

    Returns
    -------
    ndarray, shape of ``damping_ratio``
    """
    n = density * area
    ratio = np.asarray(damping_ratio, dtype=float)
    if density >= DENSE_FROM:
        return np.full(ratio.shape, DENSE_FACTOR * np.sqrt(n))
    return SPARSE_FACTOR * np.sqrt(ratio * n)


def class_density(code, traffic_class, area):
    """Density [persons/m²] of a traffic class of ``code`` on a walkway of ``area`` [m²]."""
    classes = TRAFFIC_CLASSES[code]
    if code == "setra" and traffic_class == "IV":
        raise ParameterError(
            "traffic_class 'IV' of Sétra (seldom used footbridge) requires no comfort check; "
            "give density= to check it anyway")
    if traffic_class not in classes:
        raise ParameterError(
            f"traffic_class must be one of {list(classes)} for code {code!r}, "
            f"got {traffic_class!r}")
    value = classes[traffic_class]
    if isinstance(value, tuple):                        # a fixed number of persons
        return value[1] / area
    return value


def comfort_class(acceleration):
    """Comfort class name ("CL1"…"CL4") of peak accelerations [m/s²] (upper bounds included)."""
    acceleration = check_non_negative("acceleration", acceleration, unit="m/s²")
    bounds = np.array([bound for _, bound in COMFORT_CLASSES])
    index = np.searchsorted(bounds, np.atleast_1d(acceleration), side="left")
    names = tuple(COMFORT_CLASSES[i][0] for i in index)
    return names if np.ndim(acceleration) else names[0]


def comfort_limit(code, target_class):
    """Acceleration limit [m/s²] of ``code``: EN 1990's 0.7, or the upper bound of a class."""
    if code == "en1990":
        if target_class is not None:
            raise ParameterError(
                f"comfort_class applies to 'setra' and 'hivoss'; EN 1990 has one limit "
                f"({EN1990_VERTICAL_LIMIT} m/s²), got comfort_class={target_class!r}")
        return EN1990_VERTICAL_LIMIT
    names = [name for name, bound in COMFORT_CLASSES if np.isfinite(bound)]
    target_class = "CL2" if target_class is None else target_class
    if target_class not in names:
        raise ParameterError(f"comfort_class must be one of {names}, got {target_class!r}")
    return dict(COMFORT_CLASSES)[target_class]
