"""Finite crossings: the load of walkers who stay on the deck for a crossing only (docs: theory,
Finite crossings).

One walker's modal force is their walking force times the envelope φ_j(x(t)) for the T_c = L/v
seconds of a crossing. Over a Poisson stream (Campbell's theorem) the modal-load PSD is the
narrow-band load spectrum s(f) convolved with the envelope's normalised energy spectrum
K_j(Δ) ∝ E_lane |∫ φ_j(vt) e^{−2πiΔt} dt|². The smeared model takes K_j as a delta (a crossing
long against 1/(r_c σ_fs)). K_j is even and, by Parseval, its variance is

    σ_K² = v² ⟨(∂φ_j/∂x)²⟩ / (4π² ⟨φ_j²⟩)      [Hz²],   ⟨·⟩ the walkway average,

1/(2 T_c) for a half sine. s varies on the scale r_c σ_fs ≫ σ_K, so the three-point rule that
keeps K_j's mass and variance is enough:

    (s ∗ K_j)(f) ≈ (2/3) s(f) + (1/6) [s(f + √3 σ_K) + s(|f − √3 σ_K|)]

(|·|: the one-sided spectrum mirrored at 0 Hz, where s vanishes anyway).
"""

from __future__ import annotations

import numpy as np

from ...errors import ParameterError
from ...models.structure import ModalModel


def crossing_spread(structure: ModalModel, walking_speed: float, mode: int) -> float:
    """σ_K [Hz]: the standard deviation of mode ``mode``'s crossing kernel at ``walking_speed``.

    ⟨(∂φ/∂x)²⟩ from the differences between stations, lane by lane, weighted like
    :meth:`ModalModel.influence_matrix`; the steps where the walkway starts and ends are not in
    it (a mode that does not vanish there spreads part of its load over a broad band instead).
    """
    shapes = structure.mode_shapes[..., mode]                   # (lane, station)
    slope_energy = lane_slope_energy(structure, shapes)
    energy = np.sum(structure._area_weights * shapes**2)
    if not energy > 0:
        raise ParameterError(f"mode {mode} carries no crowd (∫φ² dA = 0): it has no crossing "
                             "kernel")
    length_energy = energy / structure.width                    # lane-averaged ∫φ² dx
    return float(walking_speed / (2 * np.pi) * np.sqrt(slope_energy / length_energy))


def lane_slope_energy(structure: ModalModel, values: np.ndarray) -> float:
    """Lane-weighted ∫ (∂v/∂x)² dx of values (lane, station) along the walking direction, from
    the differences between stations (the walkway's ends excluded)."""
    lane_weights = structure._area_weights.sum(axis=1)
    lane_weights = lane_weights / lane_weights.sum()
    return float(lane_weights @ (np.diff(values, axis=1) ** 2
                                 / np.diff(structure.positions)).sum(axis=1))


def smoothed_load_spectrum(force, frequency: np.ndarray, crowd, spread: float) -> np.ndarray:
    """s ∗ K at ``frequency``: the three-point rule of the module docstring (spread = σ_K)."""
    if spread == 0:
        return force.load_spectrum(frequency, crowd)
    offset = np.sqrt(3.0) * spread
    # The three points in one call of the load spectrum (it is evaluated elementwise): a third
    # of its fixed cost, which dominates at the few frequencies of a pole's stencil.
    frequency = np.asarray(frequency, dtype=float)
    flat = frequency.ravel()
    at, above, below = np.asarray(force.load_spectrum(
        np.concatenate([flat, flat + offset, np.abs(flat - offset)]), crowd)).reshape(3, -1)
    return (2 / 3 * at + (above + below) / 6).reshape(frequency.shape)
