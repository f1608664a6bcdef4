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
        """State matrix and input column (the load's intensity λ in it) at occupancy λ."""
        s = np.sqrt(occupancy)
        mass, damping, stiffness = sum(c * s**k for k, c in enumerate(self.coefficients))
        size = mass.shape[0]
        inverse_mass = np.linalg.inv(mass)
        state = np.zeros((2 * size, 2 * size))
        state[:size, size:] = np.eye(size)
        state[size:, :size] = -inverse_mass @ stiffness
        state[size:, size:] = -inverse_mass @ damping
        load = np.zeros((2 * size, 1))
        load[size:, 0] = inverse_mass[:, 0] * s * self.coupling
        return state, load


def _power(a, b, cross):
    """Σ_k a_ok conj(b_ok) → (n_out, n_f), or the (n_out, n_out, n_f) matrix with ``cross``."""
    if cross:
        return np.einsum("fak,fbk->abf", a, b.conj())
    return np.einsum("fak,fak->af", a, b.conj())


def _real_part(product, cross):
    """2 Re of a product, for a PSD or (Hermitian part) a cross-spectral matrix."""
    return product + np.swapaxes(product.conj(), 0, 1) if cross else 2 * product.real


class _Resolvents:
    """Row vectors C R X R^k … at every frequency, built left to right in the eigenbasis of
    the state matrix (R = (iω − A)⁻¹ is diagonal there), so each product costs n² per output
    and frequency."""

    def __init__(self, mode_shape, state, load, omega):
        poles, vectors = np.linalg.eig(state)
        self.inverse, self.vectors = np.linalg.inv(vectors), vectors
        self.right = self.inverse @ load                                  # (2n, 1)
        self.d = 1.0 / (omega - poles)                                    # (n_f, 2n)
        self.start = mode_shape[:, np.newaxis] * vectors[0] * self.d[:, np.newaxis, :]

    def basis(self, matrix):
        return self.inverse @ matrix @ self.vectors

    def then(self, rows, matrix, power):
        """rows · X R^power for rows (n_f, n_out, 2n) and X in the eigenbasis."""
        return (rows @ matrix) * self.d[:, np.newaxis, :] ** power

    def close(self, rows):
        """rows · b → (n_f, n_out, 1)."""
        return rows @ self.right


def expansion(occupied: _OccupiedMode, mode_shape: np.ndarray, node: float,
              omega: np.ndarray):
    """G₀, G₁, G₂ of the module docstring at λ = node (each (n_f, n_out, 1)) and, for the λ̈
    term differentiated in λ, {k: (G₀, G₃)} at λ = node + k h, k = ±1 (h = _STEP node)."""
    h = _STEP * node
    systems = {k: occupied.system(node + k * h) for k in range(-2, 3)}

    def at(k):
        """Resolvents, A' and A'' at λ = node + k h."""
        (minus, _), (state, load), (plus, _) = (systems[k + j] for j in (-1, 0, 1))
        r = _Resolvents(mode_shape, state, load, omega)
        return r, r.basis((plus - minus) / (2 * h)), r.basis((plus - 2 * state + minus) / h**2)

    g3 = {}
    for k in (-1, 1):
        r, a1, _ = at(k)
        g3[k] = (r.close(r.start), r.close(r.then(r.start, a1, 3)))
    r, a1, a2 = at(0)
    row_a1 = r.start @ a1                                                 # C R A'
    g0 = r.close(r.start)
    g1 = r.close(row_a1 * r.d[:, np.newaxis, :] ** 2)
    g2 = r.close(r.then(row_a1 * r.d[:, np.newaxis, :] ** 2, a1, 2)
                 + 2 * r.then(row_a1 * r.d[:, np.newaxis, :], a1, 3)
                 + r.then(r.start, a2, 3))
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
    mode_shape = shapes[:, mode]
    near = _near_resonances(occupied, nodes, frequency)
    omega = 2j * np.pi * frequency[near, np.newaxis]

    total = 0.0
    for node, weight in zip(nodes, weights):
        g0, g1, g2, g3 = expansion(occupied, mode_shape, node, omega)
        h = _STEP * node
        (g0_plus, g3_plus), (g0_minus, g3_minus) = g3[1], g3[-1]
        slope = (_real_part(_power(g0_plus, g3_plus, cross), cross)
                 - _real_part(_power(g0_minus, g3_minus, cross), cross)) / (2 * h)
        total = total + weight * (_power(g1, g1, cross)
                                  + _real_part(_power(g0, g2, cross), cross) - slope)
    result[..., near] = rate_variance * (total if cross else total.real)
    return result


def modulation_parameter(structure: ModalModel, attached: tuple, mode: int,
                         occupancy_variance: float, rate_variance: float) -> float:
    """ε = Var λ̇ / (Var λ · Γ²): the squared ratio of the occupied mode's memory 1/Γ (Γ = −Re p
    of its pole at the mean occupancy) to the occupancy's time scale σ_λ/σ_λ̇. The expansion
    holds for ε small; beyond MAX_PARAMETER it overshoots (docs: theory, Beyond the
    quasi-static mixture)."""
    poles = np.linalg.eigvals(_OccupiedMode(structure, attached, mode).system(1.0)[0])
    light = poles[(poles.imag > 0) & (-poles.real < _LIGHT_DAMPING * np.abs(poles))]
    decay = -(light if light.size else poles).real.min()
    return float(rate_variance / (occupancy_variance * decay**2))


def _near_resonances(occupied, nodes, frequency):
    """Where the correction is computed: within _REACH half-power widths (at least
    _MIN_REACH Hz) of a lightly damped pole at any node. Its terms carry three or more
    resolvents where the mixture carries one, so beyond this it is below 1e-3 of the PSD."""
    near = np.zeros(frequency.shape, dtype=bool)
    for node in nodes:
        poles = np.linalg.eigvals(occupied.system(node)[0])
        for pole in poles[(poles.imag > 0) & (-poles.real < _LIGHT_DAMPING * np.abs(poles))]:
            reach = max(_REACH * -pole.real, 2 * np.pi * _MIN_REACH) / (2 * np.pi)
            near |= np.abs(frequency - pole.imag / (2 * np.pi)) < reach
    return near
