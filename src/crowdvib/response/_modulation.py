"""The slow-modulation correction to the quasi-static mixture (docs: theory, The fluctuating crowd,
Beyond the quasi-static mixture).

The mixture freezes the occupancy λ = ψ/ψ̄ over the occupied mode's memory. It moves: walkers at
speed v change it at the rate λ̇, Var λ̇ = d v² ∫(∂φ²/∂x)² dA / ψ̄² (Campbell). For a walker's force
entering at time s, the response at frequency ω is G(ω, s) = ∫₀^∞ C Φ(s+u, s) b e^{−iωu} du, with
Φ the state-transition matrix of the occupied structure (state matrix A(λ(t))). Expanding λ(s+u)
about s to second order and Laplace-transforming in u (R = (iω − A)⁻¹, A' = ∂A/∂λ):

    G ≈ C R b + λ̇ C R A' R² b + λ̇² C (R A' R² A' R² + 2 R A' R A' R³ + R A'' R³) b
        + λ̈ C R A' R³ b =: G₀ + λ̇ G₁ + λ̇² G₂ + λ̈ G₃.

The expected PSD weights |G|² by the load's intensity λ(s). Stationarity gives E[λ̇ g(λ)] = 0 and
E[λ̈ g(λ)] = −E[λ̇² g'(λ)]; with λ̇ independent of λ (its variance V) the correction to the
mixture Σ_i w_i λ_i |G₀(λ_i)|² is

    ΔG = V Σ_i w_i { λ_i (|G₁|² + 2 Re G₀* G₂) − ∂/∂λ [2 λ Re G₀* G₃] }   at λ = λ_i,

of order ε = (memory of the mode / time scale of λ)² against the mixture's own spread. It is
computed for the occupied mode alone with its crowd and dampers (the mode whose occupancy the
mixture models), where its terms, with three or more resolvents, are not negligible.
"""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np

from ..models.structure import ModalModel
from ._attached import reduced_matrices
from ._crossing import lane_slope_energy

#: Relative step in λ for the derivatives of the state matrix and of the λ̈ term.
_STEP = 1e-3
#: Poles with a damping ratio below this carry the correction (the MSD's own pole, heavily
#: damped, varies little with λ); it is computed within _REACH half-power half-widths of
#: them, and at least _MIN_REACH [Hz].
_LIGHT_DAMPING, _REACH, _MIN_REACH = 0.2, 40.0, 0.2
#: The largest expansion parameter ε at which the correction is applied: on the paper's
#: example it brings the damping estimated from 800 simulated hours at 0.25 P/m² (ε = 0.77)
#: from +1.8 % to +0.5 %, and at 3 m/s (ε = 3.9) it overshoots to −4.6 %.
MAX_PARAMETER = 1.0


def occupancy_rate_variance(structure: ModalModel, density: float, walking_speed: float,
                            mode: int) -> float:
    """Var λ̇ [1/s²] of the relative occupancy of mode ``mode`` (Campbell's theorem):
    d v² ∫(∂φ²/∂x)² dA / (d ∫φ² dA)²  (2π² v² / (d B L³) for a half sine)."""
    shapes = structure.mode_shapes[..., mode]
    energy = np.sum(structure._area_weights * shapes**2)                  # ∫ φ² dA
    gradient = structure.width * lane_slope_energy(structure, shapes**2)  # ∫ (∂φ²/∂x)² dA
    return float(walking_speed**2 * gradient / (density * energy**2))


class _OccupiedMode:
    """The occupied mode alone with its crowd and dampers, as a function of the occupancy λ.

    The mass, damping and stiffness of :func:`reduced_matrices` are polynomials in s = √λ
    (the crowd's coupling B scales with s, its Ψ with s²), so three evaluations give them at
    every λ. Other modes are left out: the correction is a property of the resonance whose
    occupancy fluctuates (as the crossing kernel is).
    """

    def __init__(self, structure, attached, mode):
        one = slice(mode, mode + 1)
        sub = SimpleNamespace(n_modes=1, frequencies=structure.frequencies[one],
                              damping_ratios=structure.damping_ratios[one],
                              modal_masses=structure.modal_masses[one])
        crowd, dampers = attached[0], attached[1:]
        self.coupling = np.sqrt(crowd.influence[mode, mode])
        dampers = tuple(dataclasses.replace(d, factor=d.factor[one]) for d in dampers)

        def matrices(s):
            scaled = dataclasses.replace(crowd, factor=np.array([[s * self.coupling]]))
            return np.array(reduced_matrices(sub, (scaled,) + dampers))

        at_zero, at_one, at_minus = matrices(0.0), matrices(1.0), matrices(-1.0)
        self.coefficients = (at_zero, (at_one - at_minus) / 2, (at_one + at_minus) / 2 - at_zero)

    def system(self, occupancy):
        """State matrices (…, 2n, 2n) and input columns (…, 2n, 1), the load's intensity λ in
        them, at the occupancies λ (a float or an array of any shape …)."""
        s = np.sqrt(np.asarray(occupancy, dtype=float))[..., np.newaxis, np.newaxis]
        mass, damping, stiffness = (c0 + s * c1 + s**2 * c2 for c0, c1, c2
                                    in zip(*self.coefficients))
        size = mass.shape[-1]
        inverse_mass = np.linalg.inv(mass)
        state = np.zeros(s.shape[:-2] + (2 * size, 2 * size))
        state[..., :size, size:] = np.eye(size)
        state[..., size:, :size] = -inverse_mass @ stiffness
        state[..., size:, size:] = -inverse_mass @ damping
        load = np.zeros(s.shape[:-2] + (2 * size, 1))
        load[..., size:, :] = inverse_mass[..., :, :1] * s * self.coupling
        return state, load


def _power(a, b, cross):
    """Σ_k a_ok conj(b_ok) over (…, n_f, n_out, rank) → (…, n_out, n_f), or the
    (…, n_out, n_out, n_f) matrix with ``cross``."""
    if cross:
        return np.einsum("...fak,...fbk->...abf", a, b.conj())
    return np.einsum("...fak,...fak->...af", a, b.conj())


def _real_part(product, cross):
    """2 Re of a product, for a PSD or (Hermitian part) a cross-spectral matrix."""
    return product + np.swapaxes(product.conj(), -3, -2) if cross else 2 * product.real


def expansion(occupied: _OccupiedMode, mode_shape: np.ndarray, nodes: np.ndarray,
              frequency: np.ndarray):
    """G₀ and G₃ of the module docstring at λ = node + k h for k = −1, 0, 1 (h = _STEP node),
    shape (n_nodes, 3, n_f, n_out, 1), G₁ and G₂ at k = 0 only, shape (n_nodes, 1, n_f,
    n_out, 1) (the λ̈ term is differentiated in λ, the others are not).

    In the eigenbasis of A every resolvent R = (iω − A)⁻¹ is diagonal, so the products are
    built left to right as row vectors C R X R^k …: n² operations per output and frequency.
    """
    step = _STEP * np.asarray(nodes, dtype=float)[:, np.newaxis]
    states, loads = occupied.system(nodes[:, np.newaxis] + np.arange(-2, 3) * step)
    h = step[..., np.newaxis, np.newaxis]
    first = (states[:, 2:] - states[:, :-2]) / (2 * h)          # A' at k = −1, 0, 1
    second = (states[:, 2:] - 2 * states[:, 1:-1] + states[:, :-2]) / h**2
    poles, vectors = np.linalg.eig(states[:, 1:-1])
    inverse = np.linalg.inv(vectors)
    right = (inverse @ loads[:, 1:-1])[:, :, np.newaxis]        # (n, 3, 1, 2m, 1)
    a1 = (inverse @ first @ vectors)[:, :, np.newaxis]
    a2 = (inverse @ second @ vectors)[:, :, np.newaxis]
    d = 1.0 / (2j * np.pi * frequency[:, np.newaxis] - poles[:, :, np.newaxis, :])
    d = d[..., np.newaxis, :]                                   # (n, 3, f, 1, 2m)
    start = mode_shape[:, np.newaxis] * vectors[:, :, np.newaxis, :1, :] * d   # C R
    row_a1 = start @ a1                                                      # C R A'
    g0 = start @ right
    g3 = (row_a1 * d**3) @ right
    # G₁ and G₂ at k = 0 only.
    start, row_a1, d, a1, right = (x[:, 1:2] for x in (start, row_a1, d, a1, right))
    g1 = (row_a1 * d**2) @ right
    g2 = (((row_a1 * d**2) @ a1) * d**2 + 2 * ((row_a1 * d) @ a1) * d**3
          + (start @ a2[:, 1:2]) * d**3) @ right
    return g0, g1, g2, g3


def modulation_correction(structure: ModalModel, attached: tuple, shapes: np.ndarray,
                          mode: int, nodes: np.ndarray, weights: np.ndarray,
                          rate_variance: float, frequency: np.ndarray,
                          cross: bool = False) -> np.ndarray:
    """ΔG of the module docstring for the displacements at the outputs (shapes (n_out,
    n_modes)): shape (n_out, n_f), or (n_out, n_out, n_f) with ``cross``; multiply by ω⁴ s(f)
    for accelerations. ``attached`` holds the crowd first, at the mean occupancy, then the
    dampers; ``nodes``, ``weights`` are the occupancy rule of mode ``mode``. Zero without a
    crowd of MSDs.
    """
    shape = (len(shapes),) * (2 if cross else 1) + (len(frequency),)
    result = np.zeros(shape, dtype=complex if cross else float)
    if not attached or rate_variance == 0:
        return result
    occupied = _OccupiedMode(structure, attached, mode)
    nodes = np.asarray(nodes, dtype=float)
    near = _near_resonances(occupied, nodes, frequency)
    g0, g1, g2, g3 = expansion(occupied, shapes[:, mode], nodes, frequency[near])
    lam_g3 = _real_part(_power(g0, g3, cross), cross)          # (n, 3, …, f)
    h = (_STEP * nodes).reshape((-1,) + (1,) * (lam_g3.ndim - 2))
    slope = (lam_g3[:, 2] - lam_g3[:, 0]) / (2 * h)
    terms = (_power(g1[:, 0], g1[:, 0], cross)
             + _real_part(_power(g0[:, 1], g2[:, 0], cross), cross) - slope)
    total = np.tensordot(np.asarray(weights, dtype=float), terms, axes=1)
    result[..., near] = rate_variance * (total if cross else total.real)
    return result


def modulation_parameter(structure: ModalModel, attached: tuple, mode: int,
                         occupancy_variance: float, rate_variance: float) -> float:
    """ε = Var λ̇ / (Var λ · Γ²): the squared ratio of the occupied mode's memory 1/Γ (Γ = −Re p
    of its pole at the mean occupancy) to the occupancy's time scale σ_λ/σ_λ̇. The expansion
    holds for ε small; beyond MAX_PARAMETER it overshoots (docs: theory, Beyond the
    quasi-static mixture)."""
    poles = np.linalg.eigvals(_OccupiedMode(structure, attached, mode).system(1.0)[0])
    light = _light_poles(poles)
    decay = -(light if light.size else poles).real.min()
    return float(rate_variance / (occupancy_variance * decay**2))


def _light_poles(poles):
    """The poles with Im > 0 and a damping ratio below _LIGHT_DAMPING (the resonances that
    carry the correction; the MSD's own, heavily damped pole varies little with λ)."""
    return poles[(poles.imag > 0) & (-poles.real < _LIGHT_DAMPING * np.abs(poles))]


def _near_resonances(occupied, nodes, frequency):
    """Where the correction is computed: within _REACH half-power widths (at least
    _MIN_REACH Hz) of a lightly damped pole at any node. Its terms carry three or more
    resolvents where the mixture carries one, so beyond this it is below 1e-3 of the PSD."""
    light = _light_poles(np.linalg.eigvals(occupied.system(nodes)[0]).ravel())
    reach = np.maximum(_REACH * -light.real, 2 * np.pi * _MIN_REACH) / (2 * np.pi)
    return (np.abs(frequency[:, np.newaxis] - light.imag / (2 * np.pi)) < reach).any(axis=1)
