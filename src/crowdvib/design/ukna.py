"""UK National Annex to BS EN 1991-2 (NA.2.44) on a modal model: walkers, joggers and crowds.

Two load cases per bridge class (docs: theory, Design checks to the UK National Annex):

* a group of N walkers (joggers) as ONE pulsating point force
  F(t) = F0 k(f_v) sqrt(1 + γ (N − 1)) sin(2π f_v t) crossing the walkway at 1.7 (3.0) m/s, with
  the sign of the mode it is tuned to (the force is flipped where φ_v < 0, so it always drives
  that mode), integrated in the time domain mode by mode from rest; the peak of the modal
  acceleration over the crossing, both directions, times |φ_o| at each output; γ is read from
  PD 6688-2:2011 Figure 2 (the corrected Figure NA.9), or from Figure NA.9 as published with
  ``gamma_figure="na9"``;
* the steady-state crowd, a pressure w = 1.8 (F0/A) k(f_v) sqrt(γ N / λ) applied with the sign
  of the mode, resonant response Q / (2 ξ m), N = ρA with ρ at most 1.0 persons/m²
  (NA.2.44.5(1)).

Each load case is applied to the models of :mod:`.check`: the empty structure, the structure with
the group's (crowd's) mass added, and with HSI the occupied effective mode of
:func:`crowdvib.effective_modal_properties` (its frequency, damping ratio and engaged modal mass:
an SDOF per mode, as the NA treats the empty structure). The forcing frequency f_v, k(f_v) and the
logarithmic decrement δ = 2πξ of γ are those of each model's mode.
"""

import warnings

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.signal import cont2discrete, lfilter, ss2tf

from .._plausibility import warn_if_implausible
from .._validation import check_non_negative
from ..errors import ParameterError, ResolutionWarning
from ..models.crowd import Crowd
from ..models.pedestrian import MSDModel
from ..models.structure import ModalModel
from ..response.frequency_domain.spectral import effective_modal_properties
from ..signals.weighting import running_rms, weight_wb
from .check import DesignCheck, structure_models
from .codes import (UKNA_CLASSES, UKNA_CROWD_FACTOR, UKNA_CROWD_MAX_DENSITY,
                    UKNA_DEFAULT_GAMMA_FIGURE, UKNA_GROUPS, UNVERIFIED_DEFAULTS, effective_span,
                    ukna_crowd_gamma, ukna_gamma, ukna_gamma_figure, ukna_gamma_outside,
                    ukna_k_factor, ukna_limit)
from .registry import DesignCode, register_code

__all__ = ["sdof_acceleration", "group_response", "crowd_response", "ukna_cases", "ukna_check",
           "UKNACode"]

#: Samples per period of the loading frequency: the force is linear between samples (exact
#: first-order-hold discretisation), whose fundamental is sinc²(π/64) ≈ 1 − 8e-4 of the sine, and
#: the sampled peak of the response is within 1 − cos(π/64) ≈ 1.2e-3 of the true one.
SAMPLES_PER_PERIOD = 64


def sdof_acceleration(frequency: float, damping_ratio: float, modal_mass: float,
                      force: np.ndarray, dt: float) -> np.ndarray:
    """Acceleration q̈(t) [m/s² × scaling] of m q̈ + 2ξωm q̇ + ω²m q = Q(t) from rest.

    Q is taken linear between its samples (first-order hold), for which the discretisation is
    exact; the filter is applied with :func:`scipy.signal.lfilter`.

    Parameters
    ----------
    frequency, damping_ratio, modal_mass : float
        f [Hz], ξ [-], m [kg].
    force : ndarray
        Q at t = 0, dt, 2dt, … [N].
    dt : float
        Sample interval [s].
    """
    omega = 2 * np.pi * frequency
    a = np.array([[0.0, 1.0], [-omega**2, -2 * damping_ratio * omega]])
    b = np.array([[0.0], [1.0 / modal_mass]])
    c = a[1:2]
    d = np.array([[1.0 / modal_mass]])
    ad, bd, cd, dd, _ = cont2discrete((a, b, c, d), dt, method="foh")
    numerator, denominator = ss2tf(ad, bd, cd, dd)
    return lfilter(numerator[0], denominator, force)


def _path_shapes(structure, speed, top_frequency):
    """Time grid of a crossing and the mode shapes under the load, both directions.

    Returns (dt, shapes): shapes of shape (2, n_t, n_modes), forward then backward crossing.
    """
    dt = 1.0 / (SAMPLES_PER_PERIOD * top_frequency)
    time = np.arange(int(np.ceil(structure.length / speed / dt)) + 1) * dt
    x = structure.positions[0] + np.minimum(speed * time, structure.length)
    forward = structure.shapes_at(x)
    backward = structure.shapes_at(structure.positions[0] + structure.positions[-1] - x)
    return dt, np.stack([forward, backward])


def group_response(structure: ModalModel, group: str, size: int, frequencies: ArrayLike,
                   damping_ratios: ArrayLike, modal_masses: ArrayLike, *,
                   effective_spans: ArrayLike | None = None,
                   gamma_figure: str = UKNA_DEFAULT_GAMMA_FIGURE) -> dict:
    """Peak accelerations of every mode under a crossing group of walkers or joggers (NA.2.44.4).

    Parameters
    ----------
    structure : ModalModel
        Supplies the walkway, the shapes along it and the outputs.
    group : {"walkers", "joggers"}
    size : int
        N, persons in the group (Table NA.7), >= 1.
    frequencies, damping_ratios, modal_masses : array_like, shape (n_modes,)
        The model's modes [Hz], [-], [kg].
    effective_spans : array_like, optional
        S_eff per mode [m] (default from the mode shapes, Figure NA.7).
    gamma_figure : {"pd6688-2", "na9"}
        The γ figure (:data:`~crowdvib.design.codes.UKNA_GAMMA_FIGURES`): PD 6688-2:2011
        Figure 2 (default) or Figure NA.9 as published. Outside its grid γ is read at the
        grid's edge, and "gamma_outside" says so.

    Returns
    -------
    dict
        "force" (amplitude F per mode [N]), "k", "gamma" (per mode), "gamma_outside" (what of
        the loaded modes' δ and S_eff lay outside the figure's grid, in words), "modal" (peak
        modal acceleration per mode), "peak" (n_outputs, n_modes) [m/s²], and the time
        histories' step "dt" with the modal accelerations "history" (n_modes, n_t) of the
        governing direction (for running RMS).
    """
    f0, speed = UKNA_GROUPS[group]
    frequencies = np.asarray(frequencies, dtype=float)
    damping_ratios = np.asarray(damping_ratios, dtype=float)
    masses = np.asarray(modal_masses, dtype=float)
    spans = effective_span(structure)[0] if effective_spans is None else effective_spans
    decrement = 2 * np.pi * damping_ratios
    k = ukna_k_factor(frequencies, group)
    gamma = np.atleast_1d(ukna_gamma(decrement, spans, gamma_figure, clamp=True))
    amplitude = f0 * k * np.sqrt(1.0 + gamma * (size - 1))
    # Only the loaded modes' γ matters; a clamp of S_eff (below 10 m: the 10 m curve's larger
    # γ, conservative) is stated in the result, one of δ (above 0.2: a smaller γ than the
    # figure's trend) also warned of.
    outside = ukna_gamma_outside(decrement[k > 0], np.broadcast_to(spans, k.shape)[k > 0],
                                 gamma_figure)
    if any(note.startswith("log_decrement") for note in outside):
        warnings.warn(ResolutionWarning(
            f"logarithmic decrements up to {decrement[k > 0].max():.3g} exceed the 0.2 of "
            f"{ukna_gamma_figure(gamma_figure)['label']}: γ is read at 0.2, which underestimates "
            "it for the more damped modes"), stacklevel=3)
    loaded = np.flatnonzero(amplitude > 0)
    n_modes = frequencies.size
    modal = np.zeros(n_modes)
    if loaded.size == 0:
        return {"force": amplitude, "k": k, "gamma": gamma, "gamma_outside": outside,
                "modal": modal, "peak": np.zeros((structure.n_outputs, n_modes)), "dt": None,
                "history": None}
    dt, shapes = _path_shapes(structure, speed, frequencies[loaded].max())
    time = np.arange(shapes.shape[1]) * dt
    history = np.zeros((n_modes, time.size))
    for j in loaded:
        wave = amplitude[j] * np.sin(2 * np.pi * frequencies[j] * time)
        for direction in range(2):
            # |φ_j| under the load: the force flips with the shape, driving mode j throughout.
            response = sdof_acceleration(frequencies[j], damping_ratios[j], masses[j],
                                         wave * np.abs(shapes[direction, :, j]), dt)
            peak = np.abs(response).max()
            if peak > modal[j]:
                modal[j], history[j] = peak, response
    return {"force": amplitude, "k": k, "gamma": gamma, "gamma_outside": outside,
            "modal": modal, "peak": np.abs(structure.output_shapes) * modal, "dt": dt,
            "history": history}


def crowd_response(structure: ModalModel, density: float, frequencies: ArrayLike,
                   damping_ratios: ArrayLike, modal_masses: ArrayLike) -> dict:
    """Steady-state resonant response of every mode to the NA.2.44.5 crowd load.

    w = 1.8 (F0/A) k(f_v) sqrt(γ N / λ) [N/m²], N = ρ A, γ = 0.23 δ/0.2, λ = 0.634 S_eff/S,
    applied with the sign of mode j: Q_j = w ∫_A |φ_j| dA, modal acceleration Q_j / (2 ξ_j m_j).
    ρ is ``density`` capped at 1.0 persons/m² (NA.2.44.5(1): "the required crowd density
    obtained from NA.2.44.2 but with a maximum value of 1.0 persons/m²").

    Returns
    -------
    dict
        "load_density" ρ [persons/m²], "pressure" w per mode [N/m²], "force" Q_j [N], "k",
        "gamma", "lambda", "peak" (n_outputs, n_modes) [m/s²].
    """
    f0 = UKNA_GROUPS["walkers"][0]
    area = structure.area
    frequencies = np.asarray(frequencies, dtype=float)
    damping_ratios = np.asarray(damping_ratios, dtype=float)
    k = ukna_k_factor(frequencies, "walkers")
    gamma = ukna_crowd_gamma(2 * np.pi * damping_ratios)
    lam = effective_span(structure)[1]
    load_density = min(float(density), UKNA_CROWD_MAX_DENSITY)          # NA.2.44.5(1)
    pressure = UKNA_CROWD_FACTOR * f0 / area * k * np.sqrt(gamma * load_density * area / lam)
    force = pressure * structure.shape_integrals(absolute=True)
    modal = force / (2 * damping_ratios * np.asarray(modal_masses, dtype=float))
    return {"load_density": load_density, "pressure": pressure, "force": force, "k": k,
            "gamma": gamma, "lambda": lam, "peak": np.abs(structure.output_shapes) * modal}


def ukna_cases(traffic_class: str | None, density: float | None) -> list[tuple]:
    """The load cases of a bridge class: (name, kind, size or density) with a non-zero load.

    ``density`` (persons/m²) overrides the class's crowd density; without a class only the
    crowd case is checked.
    """
    cases: list[tuple] = []
    if traffic_class is not None:
        if traffic_class not in UKNA_CLASSES:
            raise ParameterError(f"traffic_class must be one of {list(UKNA_CLASSES)} for code "
                                 f"'ukna', got {traffic_class!r}")
        walkers, joggers, crowd_density = UKNA_CLASSES[traffic_class]
        cases += [(name, name, size) for name, size in (("walkers", walkers),
                                                        ("joggers", joggers)) if size > 0]
        density = crowd_density if density is None else density
    if density:
        cases.append(("crowd", "crowd", float(density)))
    if not cases:
        raise ParameterError("code 'ukna' needs traffic_class ('A'…'D') or density > 0: got "
                             f"traffic_class={traffic_class!r}, density={density!r}")
    return cases


def _occupancy(kind, size_or_density, area):
    """Persons/m² on the deck during a load case: the group smeared over the walkway, or ρ."""
    return size_or_density / area if kind != "crowd" else size_or_density


def ukna_check(structure: ModalModel, *, traffic_class: str | None, density: float | None,
               crowd: Crowd | None, msd: MSDModel | None, dampers: Sequence,
               site_factors: dict | Sequence | None, weighting: str | None,
               gamma_figure: str | None = None) -> DesignCheck:
    """UK NA check of :func:`crowdvib.design.design_check` (inputs already validated there)."""
    figure = ukna_gamma_figure(UKNA_DEFAULT_GAMMA_FIGURE if gamma_figure is None
                               else gamma_figure)
    if density is not None:
        density = float(check_non_negative("density", density, unit="persons/m²"))
        warn_if_implausible("density", density, stacklevel=3)
    if weighting not in (None, "Wb"):
        raise ParameterError(f"weighting must be None or 'Wb', got {weighting!r}")
    limit, factors = ukna_limit(site_factors)
    cases = ukna_cases(traffic_class, density)
    spans, lam = effective_span(structure)
    base_crowd = Crowd.from_density(1.0) if crowd is None else crowd
    n_modes = structure.n_modes
    model_names: tuple = ()
    peak_rows, prop_rows, force_rows = [], [], []
    per_case: dict[str, dict] = {}
    running: dict[str, list] = {}
    outside: list[str] = []
    for name, kind, value in cases:
        occupancy = _occupancy(kind, value, structure.area)
        models = structure_models(structure, base_crowd, occupancy, msd)
        model_names = tuple(models)
        peaks, props, forces = [], [], []
        info: dict[str, Any] = {"k": [], "gamma": []}
        for model_name, (model, model_crowd, model_msd) in models.items():
            modal = effective_modal_properties(model, model_crowd, model_msd, dampers=dampers)
            args = (modal.frequencies, modal.damping_ratios, modal.modal_masses)
            if kind == "crowd":
                result = crowd_response(structure, value, *args)
                info["load_density"] = result["load_density"]
            else:
                result = group_response(structure, kind, value, *args, effective_spans=spans,
                                        gamma_figure=figure["name"])
                # a note for readers: the model in words ("added mass"), not its key
                outside += [f"{name}, {model_name.replace('_', ' ')}: {note}"
                            for note in result["gamma_outside"]]
                if weighting is not None and result["history"] is not None:
                    running.setdefault(name, []).append(
                        _largest_running_rms(structure, result))
            peaks.append(result["peak"])
            props.append(np.stack(args))
            forces.append(result["force"])
            info["k"].append(np.asarray(result["k"]).tolist())
            info["gamma"].append(np.atleast_1d(result["gamma"]).tolist())
        peak_rows.append(peaks)
        prop_rows.append(props)
        force_rows.append(forces)
        per_case[name] = {"kind": kind, ("group_size" if kind != "crowd" else "density"): value,
                          "occupancy_density": occupancy,
                          "frequencies": [p[0].tolist() for p in props],
                          "damping_ratios": [p[1].tolist() for p in props],
                          "modal_masses": [p[2].tolist() for p in props], **info}
    case_peaks = np.array(peak_rows)                   # (n_cases, n_models, n_outputs, n_modes)
    case_props = np.array(prop_rows)                   # (n_cases, n_models, 3, n_modes)
    case_forces = np.array(force_rows)                 # (n_cases, n_models, n_modes)
    # The case that governs each model's mode (largest over the outputs) supplies its row.
    governing = case_peaks.max(axis=2).argmax(axis=0)  # (n_models, n_modes)
    models_idx, modes_idx = np.indices(governing.shape)
    chosen = case_props[governing, models_idx, :, modes_idx]         # (n_models, n_modes, 3)
    details = {"effective_span": spans.tolist(), "lambda": lam.tolist(),
               "site_factors": factors, "cases": per_case, "gamma_figure": figure["name"],
               "gamma_figure_label": figure["label"], "gamma_figure_source": figure["source"],
               "gamma_outside_grid": outside,
               "governing_case": [[cases[i][0] for i in row] for row in governing]}
    if running:
        details["running_rms"] = {"weighting": weighting, "window": RUNNING_RMS_WINDOW,
                                  **{name: np.array(v).tolist() for name, v in running.items()}}
    crowd_density = next((value for _, kind, value in cases if kind == "crowd"), 0.0)
    return DesignCheck(
        code="ukna", traffic_class=traffic_class, density=crowd_density, limit=limit,
        output_names=structure.output_names, models=model_names,
        frequencies=chosen[..., 0], damping_ratios=chosen[..., 1], modal_masses=chosen[..., 2],
        modal_forces=case_forces[governing, models_idx, modes_idx],
        harmonics=np.zeros((len(model_names), n_modes), dtype=int),
        peak_accelerations=case_peaks.max(axis=0),
        cases=tuple(name for name, _, _ in cases), case_accelerations=case_peaks,
        details=details)


#: Window of the running RMS [s] (ISO 2631-1's "slow" integration time).
RUNNING_RMS_WINDOW = 1.0


def _largest_running_rms(structure, result):
    """Largest 1-s running RMS of the W_b-weighted output accelerations, mode by mode
    (n_outputs, n_modes) [m/s²], from a group crossing's modal acceleration histories."""
    rate = 1.0 / result["dt"]
    weighted = weight_wb(result["history"], rate)               # (n_modes, n_t)
    largest = running_rms(weighted, rate, RUNNING_RMS_WINDOW).max(axis=-1, initial=0.0)
    return np.abs(structure.output_shapes) * largest


class UKNACode(DesignCode):
    """The UK National Annex to BS EN 1991-2 (NA.2.44) as a design code: :func:`ukna_check`."""

    name = "ukna"
    label = "UK NA"
    options = frozenset({"site_factors", "weighting", "gamma_figure"})
    unverified_defaults = UNVERIFIED_DEFAULTS["ukna"]

    def check(self, structure, *, traffic_class, density, crowd, msd, dampers,  # type: ignore[override]
              site_factors=None, weighting=None, gamma_figure=None) -> DesignCheck:
        """The comfort check of :func:`crowdvib.design.design_check` to the UK NA.

        Parameters
        ----------
        structure, traffic_class, density, crowd, msd, dampers
            As for :meth:`DesignCode.check`.
        site_factors : dict, optional
            The UK NA's site factors (:func:`~crowdvib.design.design_check`).
        weighting : str, optional
            As for :func:`~crowdvib.design.design_check`.
        gamma_figure : {"pd6688-2", "na9"}, optional
            γ of the groups from PD 6688-2:2011 Figure 2 (default) or Figure NA.9 as published.

        Returns
        -------
        DesignCheck
        """
        return ukna_check(structure, traffic_class=traffic_class, density=density, crowd=crowd,
                          msd=msd, dampers=dampers, site_factors=site_factors,
                          weighting=weighting, gamma_figure=gamma_figure)


register_code(UKNACode())
