"""Constants and load models of the footbridge design guides (vertical direction).

Sétra/AFGC (2006), "Footbridges – Assessment of vibrational behaviour of footbridges under
pedestrian loading", and HiVoSS (2008), "Design of footbridges – Guideline", share one resonant
load model: a harmonic pressure p = F·ψ(f_j)·n_eq/A applied with the sign of mode j at its natural
frequency, F = 280 N for the first and 70 N for the second walking harmonic per *equivalent*
pedestrian, n_eq = 10.8·sqrt(ξ_j n) below 1 person/m² and 1.85·sqrt(n) at or above it. EN 1990
Annex A2 gives the limit 0.7 m/s² but no load model; crowdvib checks it with the same load.

Provenance (docs: theory, Design checks, Defaults not verified against the guide): each constant
says whether it was read in a public source (SOURCED, with where: the guide and clause, and the
public text it was read in) or is RECALLED from the guides, whose text was not reachable here; a
RECALLED constant is a default to verify against the guide before a design relies on it, and
:data:`UNVERIFIED_DEFAULTS` lists them per code for the results and the report.
"""

import io
from collections.abc import Sequence
from functools import cache
from importlib import resources
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike
from scipy.interpolate import RegularGridInterpolator

from .._validation import check_non_negative, check_positive
from ..errors import ParameterError

if TYPE_CHECKING:
    from ..models.structure import ModalModel

__all__ = ["CODES", "UNVERIFIED_DEFAULTS", "TRAFFIC_CLASSES", "COMFORT_CLASSES", "EN1990_VERTICAL_LIMIT",
           "HARMONIC_FORCES", "reduction_factor", "equivalent_pedestrians", "class_density",
           "comfort_class", "comfort_limit", "UKNA_CLASSES", "UKNA_GROUPS", "ukna_k_factor",
           "ukna_gamma", "ukna_gamma_figure", "ukna_gamma_outside", "ukna_crowd_gamma",
           "ukna_limit", "effective_span", "UKNA_GAMMA_FIGURES", "UKNA_DEFAULT_GAMMA_FIGURE"]

#: Codes understood by :func:`crowdvib.design.design_check`.
CODES = ("setra", "hivoss", "en1990", "ukna")

#: Vertical force amplitude per equivalent pedestrian [N] of walking harmonic 1 and 2.
#: 280 N: SOURCED (HiVoSS 2008 Table 4-7, read in MEMAndersen/DynSys ped_dyn.py
#: HIVOSS.calc_load_intensity @5226de3; Sétra 2006 §3.2.1: 0.4 × 700 N, read in xcfem/xc
#: EC1_pedestrian_load_models.py). 70 N for the second harmonic: SOURCED (Sétra 2006 §3.2.1,
#: the single pedestrian's second coefficient 0.1 × 700 N, xcfem/xc; its use as load case 3
#: was not seen). HiVoSS folds the second harmonic into ψ with a plateau of 0.25 on 280 N, the
#: same 70 N: SOURCED (HiVoSS Table 4-6, DynSys calc_psi_HIVOSS).
HARMONIC_FORCES = {1: 280.0, 2: 70.0}

#: Frequency reduction factor ψ(f) [-] for the vertical direction: (frequency [Hz], ψ) corners
#: of the piecewise-linear curve, 0 outside: first harmonic 0 → 1 on 1.25–1.7 Hz, 1 to 2.1 Hz,
#: → 0 at 2.3 Hz; second harmonic 0 → 1 on 2.5–3.4 Hz, 1 to 4.2 Hz, → 0 at 4.6 Hz (HiVoSS:
#: × 0.25 with 280 N). SOURCED for HiVoSS (HiVoSS 2008 Table 4-6, f = [1.25, 1.7, 2.1, 2.3] and
#: [2.5, 3.4, 4.2, 4.6], read in DynSys calc_psi_HIVOSS @5226de3). RECALLED for Sétra, whose own
#: ψ figure was not seen (the same corners expected).
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
#: func.py get_d); TC5 = 1.5: SOURCED, indirectly (the HiVoSS/SYNPEX classes as quoted in
#: DETAIL Praxis "Fußgängerbrücken", p. 11; CSA S7 Table 7.1). Sétra classes I = 1.0, II = 0.8,
#: III = 0.5 P/m²: RECALLED (not found in a public text); class IV needs no check. EN 1990 has
#: no classes of its own: it takes HiVoSS's.
_HIVOSS_CLASSES = {"TC1": ("persons", 15.0), "TC2": 0.2, "TC3": 0.5, "TC4": 1.0, "TC5": 1.5}
TRAFFIC_CLASSES = {
    "setra": {"I": 1.0, "II": 0.8, "III": 0.5},
    "hivoss": _HIVOSS_CLASSES,
    "en1990": _HIVOSS_CLASSES,
}

#: Vertical comfort classes: (name, upper bound of the peak acceleration [m/s²]). HiVoSS CL1
#: maximum < 0.5, CL2 mean 0.5–1.0, CL3 minimum 1.0–2.5, CL4 unacceptable > 2.5. SOURCED (CSA S7
#: Table 7.2, as its public implementation's COMFORT_LEVELS_VERTICAL). Sétra's maximum/mean/
#: minimum comfort are taken to have the same ranges: RECALLED (Sétra's table was not seen).
COMFORT_CLASSES = (("CL1", 0.5), ("CL2", 1.0), ("CL3", 2.5), ("CL4", np.inf))

#: EN 1990 Annex A2 (A2.4.3.2(1)) recommended maximum vertical deck acceleration [m/s²] for
#: pedestrian comfort. SOURCED, indirectly (EN 1990:2002/A1:2005 A2.4.3.2(1): 0.7 m/s²
#: vertical, as quoted by public summaries of Annex A2 and by Shock and Vibration 2014,
#: 925437, Table 8; the Eurocode's own text was not reachable here).
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


# --- UK National Annex to BS EN 1991-2 (NA.2.44): walkers, joggers and crowds -----------------
#
# Provenance: the NA text itself was not reachable here, apart from three screenshots of it in
# DynSys. Values marked SOURCED were read in the public DynSys package (Richard Hollamby, COWI UK
# Bridge, MIT licence, MEMAndersen/DynSys @5226de3, modules ``ped_dyn``/``dyn_analysis``: Table
# NA.7 and NA.8 values, digitised Figures NA.8 and NA.9 and PD 6688-2 Figure 2, Figure NA.7's
# S_eff and λ, the screenshots of Figure NA.7, NA.2.44.4 and NA.2.44.5), which implements the
# NA; values marked RECALLED are from memory of the NA and must be checked against it
# (UNVERIFIED_DEFAULTS["ukna"]).

#: Table NA.7 (bridge usage class → walkers per group, joggers per group, crowd density
#: [persons/m²]). SOURCED (DynSys calc_N and get_crowd_density). Class A needs no crowd check
#: and no joggers (N = 0). Class D's 1.5 persons/m² loads the crowd case as 1.0
#: (UKNA_CROWD_MAX_DENSITY, NA.2.44.5(1)).
UKNA_CLASSES = {"A": (2, 0, 0.0), "B": (4, 1, 0.4), "C": (8, 2, 0.8), "D": (16, 4, 1.5)}

#: Table NA.8: reference force amplitude F0 [N] and speed [m/s] of a walker and of a jogger.
#: SOURCED (DynSys UKNA_BSEN1991_2_walkers_joggers_loading / get_load_velocity).
UKNA_GROUPS = {"walkers": (280.0, 1.7), "joggers": (910.0, 3.0)}

#: Figure NA.8: combined population and harmonic factor k(f_v) [-] against the mode frequency
#: f_v [Hz], as (f, k) points of the digitised curves; crowdvib interpolates linearly between
#: them (DynSys uses a cubic spline through the same points) and takes 0 outside. SOURCED
#: (DynSys UKNA_BSEN1991_2_Figure_NA_8 digitisation, walkers = curve A, joggers = curve B).
UKNA_K_CURVES = {
    "walkers": ((0.0, 0.0), (0.2, 0.0), (0.4, 0.01), (0.6, 0.03), (0.8, 0.08), (1.0, 0.24),
                (1.2, 0.44), (1.4, 0.72), (1.6, 0.93), (1.7, 0.98), (1.8, 1.0), (2.0, 0.997),
                (2.1, 0.97), (2.2, 0.9), (2.4, 0.65), (2.6, 0.4), (2.8, 0.25), (3.0, 0.28),
                (3.2, 0.32), (3.4, 0.34), (3.6, 0.36), (3.8, 0.36), (4.0, 0.35), (4.5, 0.28),
                (5.0, 0.18), (5.5, 0.13), (6.0, 0.115), (6.5, 0.098), (7.0, 0.08), (8.0, 0.02),
                (9.0, 0.0)),
    "joggers": ((0.0, 0.0), (0.8, 0.0), (1.0, 0.01), (1.2, 0.04), (1.4, 0.15), (1.6, 0.3),
                (1.7, 0.45), (1.8, 0.55), (2.0, 0.87), (2.1, 1.01), (2.2, 1.11), (2.4, 1.16),
                (2.6, 1.12), (2.8, 0.93), (3.0, 0.64), (3.2, 0.36), (3.4, 0.16), (3.6, 0.1),
                (3.8, 0.13), (4.0, 0.16), (4.5, 0.21), (5.0, 0.22), (5.5, 0.18), (6.0, 0.11),
                (6.5, 0.04), (7.0, 0.03), (8.0, 0.02), (9.0, 0.0)),
}

#: The two readings of the groups' reduction factor γ [-] (NA.2.44.4), name → (label, packaged
#: file). Each file (crowdvib/data, its first line the provenance) holds γ on a grid of the
#: logarithmic decrement δ = 2πξ = 0, 0.02, …, 0.20 and the effective span S_eff = 10, 12, 15,
#: 20, 30, 40, 60, 100, 200, 300 m, as digitised in MEMAndersen/DynSys (Richard Hollamby, MIT
#: licence; UKNA_BSEN1991_2_Figure_NA_9 @5226de3). SOURCED. "pd6688-2" (the default, as in
#: DynSys): PD 6688-2:2011 Figure 2, which replaces Figure NA.9 (PD 6688-2 cl. 3.20: the NA's
#: figure contains errors); "na9": Figure NA.9 as published, lower γ (0.1918 against 0.2678 for
#: a 2 Hz, 0.5 % beam of 50 m), kept to reproduce checks made with it.
UKNA_GAMMA_FIGURES = {
    "pd6688-2": ("PD 6688-2:2011 Figure 2 (the corrected Figure NA.9)",
                 "ukna_gamma_pd6688_2_fig2.csv"),
    "na9": ("Figure NA.9 of the UK NA as published (uncorrected; PD 6688-2:2011 cl. 3.20 "
            "replaces it)", "ukna_gamma_na9_uncorrected.csv"),
}
#: The γ figure of the UK NA checks unless ``gamma_figure`` says otherwise.
UKNA_DEFAULT_GAMMA_FIGURE = "pd6688-2"


@cache
def ukna_gamma_figure(gamma_figure: str = UKNA_DEFAULT_GAMMA_FIGURE) -> dict:
    """A γ figure read from its packaged file: "name", "label", "source" (the file's provenance
    line), "decrements" δ (n_δ,), "spans" S_eff [m] (n_S,) and "table" γ (n_δ, n_S).

    Parameters
    ----------
    gamma_figure : {"pd6688-2", "na9"}
        :data:`UKNA_GAMMA_FIGURES`.
    """
    if gamma_figure not in UKNA_GAMMA_FIGURES:
        raise ParameterError(f"gamma_figure must be one of {list(UKNA_GAMMA_FIGURES)}, got "
                             f"gamma_figure={gamma_figure!r}")
    label, name = UKNA_GAMMA_FIGURES[gamma_figure]
    text = resources.files("crowdvib").joinpath("data", name).read_text(encoding="utf-8")
    source = text.splitlines()[0].lstrip("# ").strip()
    rows = np.loadtxt(io.StringIO(text), delimiter=",", comments="#", skiprows=2, ndmin=2)
    decrements, spans = np.unique(rows[:, 0]), np.unique(rows[:, 1])
    table = np.full((decrements.size, spans.size), np.nan)
    table[np.searchsorted(decrements, rows[:, 0]), np.searchsorted(spans, rows[:, 1])] = rows[:, 2]
    if np.isnan(table).any() or rows.shape[0] != table.size:
        raise ParameterError(f"{name}: the γ figure must hold one value per (δ, S_eff) of a "
                             f"full grid, got {rows.shape[0]} rows for {table.size} points")
    for array in (decrements, spans, table):
        array.setflags(write=False)                 # cached: shared by every call
    return {"name": gamma_figure, "label": label, "source": source, "decrements": decrements,
            "spans": spans, "table": table}


def ukna_gamma_outside(log_decrement: ArrayLike, effective_span: ArrayLike,
                       gamma_figure: str = UKNA_DEFAULT_GAMMA_FIGURE) -> list[str]:
    """What lies outside the grid of a γ figure, one sentence per parameter and value (empty
    inside): the ParameterError of :func:`ukna_gamma`, or what a clamped reading states."""
    grid = ukna_gamma_figure(gamma_figure)
    notes = []
    for name, values, axis, unit in (("log_decrement", log_decrement, grid["decrements"], ""),
                                     ("effective_span", effective_span, grid["spans"], " m")):
        low, high = axis[0], axis[-1]
        for value in np.unique(np.atleast_1d(np.asarray(values, dtype=float))):
            if not low <= value <= high:
                edge = low if value < low else high
                notes.append(f"{name} must be within {low:g}–{high:g}{unit} (the grid of "
                             f"{grid['label']}), got {value:.4g}{unit}: read at {edge:g}{unit}")
    return notes


def ukna_gamma(log_decrement: ArrayLike, effective_span: ArrayLike,
               gamma_figure: str = UKNA_DEFAULT_GAMMA_FIGURE, *,
               clamp: bool = False) -> np.ndarray | float:
    """γ(δ, S_eff) [-] for groups (NA.2.44.4), read bilinearly on a figure's grid.

    Parameters
    ----------
    log_decrement : array_like
        δ = 2πξ [-].
    effective_span : array_like
        S_eff [m] (Figure NA.7, :func:`effective_span`).
    gamma_figure : {"pd6688-2", "na9"}
        PD 6688-2:2011 Figure 2 (default) or Figure NA.9 as published
        (:data:`UKNA_GAMMA_FIGURES`).
    clamp : bool
        Outside the grid (δ 0–0.20, S_eff 10–300 m) read γ at its nearest edge instead of
        refusing; :func:`ukna_gamma_outside` says what was clamped. The design check clamps and
        states it (S_eff below 10 m takes the larger γ of 10 m, conservative; δ above 0.2
        reads a smaller γ than the figure's trend, with a warning).

    Raises
    ------
    ParameterError
        A value outside the grid without ``clamp``, naming the parameter, the grid and the value.
    """
    grid = ukna_gamma_figure(gamma_figure)
    if not clamp:
        outside = ukna_gamma_outside(log_decrement, effective_span, gamma_figure)
        if outside:
            raise ParameterError(outside[0].split(": read at")[0] + " (clamp=True reads it at "
                                 "the grid's edge)")
    delta = np.clip(np.asarray(log_decrement, dtype=float), grid["decrements"][0],
                    grid["decrements"][-1])
    span = np.clip(np.asarray(effective_span, dtype=float), grid["spans"][0],
                   grid["spans"][-1])
    delta, span = np.broadcast_arrays(delta, span)
    interpolate = RegularGridInterpolator((grid["decrements"], grid["spans"]), grid["table"])
    values = interpolate(np.stack([delta.ravel(), span.ravel()], axis=-1)).reshape(delta.shape)
    return values if values.ndim else float(values)


#: Figure NA.9 (crowds): γ = 0.23 δ / 0.2 [-], a straight line through 0.23 at δ = 0.2.
#: SOURCED (DynSys UKNA_BSEN1991_2_Figure_NA_9, groupType "crowd").
UKNA_CROWD_GAMMA_SLOPE = 0.23 / 0.20

#: NA.2.44.5: crowd load w = CROWD_FACTOR (F0/A) k(f_v) sqrt(γ N / λ), F0 = 280 N (walkers),
#: N = ρ A, λ = 0.634 S_eff / S. SOURCED (DynSys UKNA_BSEN1991_2_crowd.calc_load_intensity).
UKNA_CROWD_FACTOR = 1.8
#: NA.2.44.5(1): ρ of the crowd load "is the required crowd density obtained from NA.2.44.2 but
#: with a maximum value of 1.0 persons/m²" (denser crowds slow down and respond less), so class
#: D's 1.5 persons/m² loads as 1.0 [persons/m²]. SOURCED (the NA's text, read in DynSys's
#: screenshot dynsys/img/UKNA_BSEN1991_2_Cl_2_44_5.PNG; DynSys's own code omits the cap).
UKNA_CROWD_MAX_DENSITY = 1.0
#: Figure NA.7: S_eff = ∫|φ| dx / (0.634 max|φ|), λ = 0.634 S_eff / S. SOURCED (DynSys Calc_Seff).
UKNA_SPAN_FACTOR = 0.634

#: NA.2.44.6: a_limit = 1.0 k1 k2 k3 k4 [m/s²], bounded to [0.5, 2.0]. RECALLED (not in DynSys,
#: and the NA's text was not reachable).
UKNA_BASE_LIMIT, UKNA_LIMIT_BOUNDS = 1.0, (0.5, 2.0)
#: Site factors (NA.2.44.6, Tables NA.9–NA.11), named choices → value. RECALLED (the tables were
#: not reachable here): k1 site usage, k2 route redundancy, k3 height of the structure; k4 the
#: exposure factor, 1.0 unless the designer justifies another value.
UKNA_SITE_FACTORS = {
    "k1": {"hospital": 0.6, "school": 0.8, "stadium": 0.8, "urban": 1.0, "suburban": 1.3,
           "rural": 1.6},
    "k2": {"sole": 0.7, "primary": 1.0, "alternative": 1.6},
    "k3": {"above_8m": 0.7, "4_to_8m": 1.0, "below_4m": 1.1},
    "k4": {"default": 1.0},
}


def ukna_k_factor(frequency: ArrayLike, group: str = "walkers") -> np.ndarray:
    """k(f_v) [-] of Figure NA.8 (digitised, linear between points, 0 outside), UK NA."""
    if group not in UKNA_K_CURVES:
        raise ParameterError(f"group must be one of {list(UKNA_K_CURVES)}, got {group!r}")
    f, k = np.array(UKNA_K_CURVES[group]).T
    return np.interp(np.asarray(frequency, dtype=float), f, k, left=0.0, right=0.0)


def ukna_crowd_gamma(log_decrement: ArrayLike) -> np.ndarray:
    """γ [-] of Figure NA.9 for crowds: 0.23 δ / 0.2."""
    return UKNA_CROWD_GAMMA_SLOPE * np.asarray(log_decrement, dtype=float)


def ukna_limit(site_factors: dict | Sequence | None = None) -> tuple[float, dict]:
    """Vertical acceleration limit [m/s²] of NA.2.44.6 and the factors used.

    Parameters
    ----------
    site_factors : dict or sequence of 4 floats, optional
        k1…k4 as numbers or as names of :data:`UKNA_SITE_FACTORS` (``{"k1": "urban", "k3":
        0.7}``); missing factors are 1.0.

    Returns
    -------
    (float, dict)
        clip(1.0 k1 k2 k3 k4, 0.5, 2.0) and the factors.
    """
    names = ("k1", "k2", "k3", "k4")
    if site_factors is None:
        site_factors = {}
    elif not isinstance(site_factors, dict):
        values = list(np.atleast_1d(np.asarray(site_factors, dtype=object)))
        if len(values) != 4:
            raise ParameterError(f"site_factors must hold 4 values (k1, k2, k3, k4), got "
                                 f"{len(values)}")
        site_factors = dict(zip(names, values))
    unknown = set(site_factors) - set(names)
    if unknown:
        raise ParameterError(f"site_factors keys must be among {list(names)}, got "
                             f"{sorted(unknown)}")
    factors = {}
    for name in names:
        value = site_factors.get(name, 1.0)
        if isinstance(value, str):
            if value not in UKNA_SITE_FACTORS[name]:
                raise ParameterError(f"site factor {name} must be a number or one of "
                                     f"{list(UKNA_SITE_FACTORS[name])}, got {value!r}")
            value = UKNA_SITE_FACTORS[name][value]
        factors[name] = float(check_positive(name, value))
    limit = UKNA_BASE_LIMIT * np.prod(list(factors.values()))
    return float(np.clip(limit, *UKNA_LIMIT_BOUNDS)), factors


def effective_span(structure: "ModalModel") -> tuple[np.ndarray, np.ndarray]:
    """Effective span S_eff [m] of each mode (Figure NA.7) and λ = 0.634 S_eff / S [-].

    S_eff = ∫_A |φ_j| dA / (B · 0.634 · max|φ_j|): the walkway integral of the absolute mode
    shape (averaged across the width) over its largest value on the walkway.
    """
    peak = np.abs(structure.mode_shapes).max(axis=(0, 1))
    span = structure.shape_integrals(absolute=True) / (structure.width * UKNA_SPAN_FACTOR
                                                       * peak)
    return span, UKNA_SPAN_FACTOR * span / structure.length


#: The defaults of each code that no public text could confirm (docs: theory, Design checks,
#: Defaults not verified against the guide, which lists these same entries): code → what, in
#: words, the constant's name in brackets. Each is marked RECALLED above; every check of the
#: code carries them in ``details["unverified_defaults"]`` and the report lists them with the
#: inputs. HiVoSS and EN 1990 use none (their constants are SOURCED).
UNVERIFIED_DEFAULTS = {
    "setra": ("traffic classes I/II/III = 1.0/0.8/0.5 persons/m² (TRAFFIC_CLASSES)",
              "the guide's own ψ figure: HiVoSS's corners are used (REDUCTION_FACTOR_CORNERS)",
              "the guide's own comfort ranges: CSA S7's CL1–CL4 are used (COMFORT_CLASSES)"),
    "hivoss": (),
    "en1990": (),
    "ukna": ("limit 1.0 k1 k2 k3 k4 within 0.5–2.0 m/s², NA.2.44.6 (UKNA_BASE_LIMIT, "
             "UKNA_LIMIT_BOUNDS)",
             "site factor k1, site usage, Table NA.9 (UKNA_SITE_FACTORS)",
             "site factor k2, route redundancy, Table NA.10 (UKNA_SITE_FACTORS)",
             "site factor k3, height of the structure, Table NA.11 (UKNA_SITE_FACTORS)",
             "exposure factor k4 = 1.0, NA.2.44.6 (UKNA_SITE_FACTORS)"),
}
