"""The correction to the quasi-static mixture for an occupancy that moves within the occupied
resonance's memory (docs: theory, The fluctuating crowd, Beyond the quasi-static mixture).

The mixture freezes the occupancy λ = ψ/ψ̄. Walkers at speed v move it: by Campbell's theorem its
autocorrelation is ρ(u) = ∫ φ²(x) φ²(x + vu) dA / ∫ φ⁴ dA (walkers on the walkway only), its
variance σ² = Var λ, and its rate Var λ̇ = −σ² ρ''(0) = d v² ∫(∂φ²/∂x)² dA / ψ̄².

Each lightly damped pole p(λ) of the occupied mode with its crowd (and dampers) drifts with λ.
A walker's force entering at s, when λ(s) = λ₀, drives that pole's coordinate; at frequency ω the
response is r ∫₀^∞ exp(∫₀^u p(λ(s+τ)) dτ − iωu) du, with the pole's residue r (which carries the
load's intensity) taken at entry. Given λ₀ the path is its linear prediction, the mean path
λ̄(τ) = λ₀ + (1 − λ₀)(1 − ρ(τ)), plus a Gaussian error δ of covariance σ²[ρ(τ − τ') − ρ(τ)ρ(τ')];
the pole is followed exactly along λ̄ and linearly about it, p ≈ p(λ̄) + p'(λ̄) δ. With
P(u) = ∫₀^u p(λ̄) and Z(u) = ∫₀^u p'(λ̄) δ = X + iY (damping and frequency parts) the exponent is
Gaussian, and its expectation is its cumulant (Kubo), with no expansion in the rate of change:

    S(ω | λ₀) = |r|² ∫∫ e^{P(u) + P̄(u') − iω(u − u')}
                 · exp(−Var(Y(u) − Y(u'))/2 + i Cov(X(u) + X(u'), Y(u) − Y(u'))) du du'.

The cumulant's +Var(X(u) + X(u'))/2, the damping's squared fluctuation, is left out: for a
linearised pole it lets rare paths ring undamped and diverge, which a passive structure's pole
never does; without it the integrand is bounded by the mean path's decay. The correction is
Σ_i w_i (S − S_frozen) at the occupancy nodes λ_i, S_frozen = |r|²/|iω − p(λ₀)|², per lightly
damped pole. The integrand over e^{z u + z̄ u'} (z = p(λ₀) − iω) varies slowly: it is sampled on
an even grid in u and taken piecewise linear, and the exponentials are integrated exactly
(Filon), so the grid follows the path, not the oscillation at ω.
"""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np
from scipy.integrate import cumulative_trapezoid

from ..models.structure import ModalModel
from ._attached import reduced_matrices
from ._crossing import lane_slope_energy

#: Relative step in λ for the pole's slope; the points of the mean path λ₀ → 1 where the pole
#: and its slope are computed (linear between them).
_STEP, _TRACK = 1e-3, np.linspace(0.0, 1.0, 17)
#: Poles with a damping ratio below this carry the correction (the MSD's own pole, heavily
#: damped, varies little with λ); it is computed within _REACH half-power half-widths of
#: them, and at least _MIN_REACH [Hz].
_LIGHT_DAMPING, _REACH, _MIN_REACH = 0.2, 40.0, 0.2
#: The grid in u: _PER_SCALE steps over the shorter of the occupancy's time scale σ/σ_λ̇ and the
#: memory 1/Γ, out to _MEMORIES memories (e^{−12} of the amplitude); at most _MAX_POINTS. The
#: piecewise-linear quadrature errs as h²: the result on this grid and on every other point of
#: it are extrapolated (Richardson), which leaves 7e-4 of the correction against ten times the
#: points and 16 memories, at a third of the cost of 12 steps per scale without it.
_PER_SCALE, _MEMORIES, _MAX_POINTS = 6, 12.0, 1025


def occupancy_rate_variance(structure: ModalModel, density: float, walking_speed: float,
                            mode: int) -> float:
    """Var λ̇ [1/s²] of the relative occupancy of mode ``mode`` (Campbell's theorem):
    d v² ∫(∂φ²/∂x)² dA / (d ∫φ² dA)²  (2π² v² / (d B L³) for a half sine)."""
    shapes = structure.mode_shapes[..., mode]
    energy = np.sum(structure._area_weights * shapes**2)                  # ∫ φ² dA
    gradient = structure.width * lane_slope_energy(structure, shapes**2)  # ∫ (∂φ²/∂x)² dA
    return float(walking_speed**2 * gradient / (density * energy**2))


@dataclasses.dataclass(frozen=True)
class OccupancyPath:
    """How the occupancy λ of one mode moves: σ² = Var λ, Var λ̇ and the autocorrelation ρ(u).

    ρ(u) = ∫ φ²(x) φ²(x + v|u|) dA / ∫ φ⁴ dA: a Poisson stream's walkers at speed v, each
    contributing φ² of their position while on the walkway (Campbell); the same whichever way
    they walk.
    """

    structure: ModalModel
    walking_speed: float
    mode: int
    variance: float
    rate_variance: float

    def correlation(self, lags: np.ndarray) -> np.ndarray:
        """ρ at ``lags`` [s] (the stations' φ² interpolated linearly, zero off the walkway)."""
        structure = self.structure
        square = structure.mode_shapes[..., self.mode] ** 2         # (lane, station)
        positions = structure.positions
        ahead = positions + self.walking_speed * np.abs(np.asarray(lags, float))[:, np.newaxis]
        total = sum((np.interp(ahead, positions, lane, right=0.0) * lane * weights).sum(axis=1)
                    for lane, weights in zip(square, structure._area_weights))
        return total / np.sum(structure._area_weights * square**2)

    @property
    def time_scale(self) -> float:
        """σ/σ_λ̇ [s]: how long the occupancy takes to change by its own spread."""
        return float(np.sqrt(self.variance / self.rate_variance))


class _OccupiedMode:
    """The occupied mode alone with its crowd and dampers, as a function of the occupancy λ.

    The mass, damping and stiffness of :func:`reduced_matrices` are polynomials in s = √λ
    (the crowd's coupling B scales with s, its Ψ with s²), so three evaluations give them at
    every λ. Other modes are left out: the correction is a property of the resonance whose
    occupancy fluctuates (as the crossing kernel is). ``reduced_matrices`` gets a one-mode
    stand-in with the four attributes it reads (cheaper than slicing a ModalModel).
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

    def drifting_poles(self, nodes):
        """The lightly damped poles at each node λ₀, followed along the occupancy's mean path
        λ₀ + (1 − λ₀) t for t on _TRACK (back to the mean, 1), with their slope dp/dλ there,
        and |residue|² at λ₀ (modal displacement per unit load, the load's intensity in it)
        → track (n_p, n_t), slope (n_p, n_t), residue (n_p,) and the node of each pole."""
        nodes = np.asarray(nodes, dtype=float)
        levels = nodes[:, np.newaxis] + (1.0 - nodes[:, np.newaxis]) * _TRACK   # (n, n_t)
        step = _STEP * np.maximum(levels, _STEP)[..., np.newaxis]
        states, loads = self.system(levels[..., np.newaxis] + np.array([-1, 0, 1]) * step)
        poles = np.linalg.eigvals(states)                           # (n, n_t, 3, 2m)
        centre, vectors = np.linalg.eig(states[:, 0, 1])
        node, which = np.nonzero(_is_light(centre))
        modal = (np.linalg.inv(vectors[node]) @ loads[node, 0, 1])[np.arange(node.size), which, 0]
        residue = np.abs(vectors[node, 0, which] * modal) ** 2
        track, slope = [], []
        current = centre[node, which]
        for k in range(_TRACK.size):                # each pole follows its nearest successor
            near = np.abs(poles[node, k] - current[:, np.newaxis, np.newaxis]).argmin(axis=-1)
            below, current, above = (poles[node, k, j, near[:, j]] for j in range(3))
            track.append(current)
            slope.append((above - below) / (2 * step[node, k, 0]))
        return np.array(track).T, np.array(slope).T, residue, node


def _is_light(poles):
    """Im p > 0 and a damping ratio below _LIGHT_DAMPING: the resonances that carry the
    correction (the MSD's own, heavily damped pole varies little with λ)."""
    return (poles.imag > 0) & (-poles.real < _LIGHT_DAMPING * np.abs(poles))


def _cumulative(values, step):
    """∫₀^u of samples on an even grid (trapezoids), along the last axis."""
    return cumulative_trapezoid(values, dx=step, axis=-1, initial=0)


def _path_grid(path: OccupancyPath, decay: float):
    """The grid in u (an odd number of points), ρ on it and the correlation of the path about
    its mean given λ₀: σ⁻² Cov(δλ(u), δλ(u')) = ρ(u − u') − ρ(u) ρ(u') (the linear
    prediction's error)."""
    step = min(path.time_scale, 1.0 / decay) / _PER_SCALE
    count = min(2 * int(np.ceil(_MEMORIES / (2 * decay * step))) + 1, _MAX_POINTS)
    step = max(step, _MEMORIES / (decay * (count - 1)))
    u = step * np.arange(count)
    rho = path.correlation(u)
    lag = np.abs(np.subtract.outer(np.arange(count), np.arange(count)))
    return u, rho, rho[lag] - np.multiply.outer(rho, rho)


def _powers(base, count):
    """base^k for k = 0 … count − 1 along a new last axis (a running product: no exponentials,
    rounding grows as k ε)."""
    factors = np.repeat(base[:, np.newaxis], count, axis=-1)
    factors[:, 0] = 1.0
    return np.cumprod(factors, axis=-1)


def _lag_sums(matrix):
    """L(δ) = Σ_k A[k + δ, k] for δ = −(N−1) … N−1 of (…, N, N) matrices → (…, 2N − 1)."""
    count = matrix.shape[-1]
    padded = np.zeros(matrix.shape[:-1] + (2 * count,), dtype=matrix.dtype)
    padded[..., :count] = matrix[..., ::-1]      # A[j, k] lands in column (j − k) + N − 1
    skew = padded.reshape(matrix.shape[:-2] + (-1,))[..., :count * (2 * count - 1)]
    return skew.reshape(matrix.shape[:-2] + (count, 2 * count - 1)).sum(axis=-2)


def _cumulative_square(matrix, step):
    """∫₀^u ∫₀^u' of samples (…, N, N) on an even grid, for every (u, u')."""
    return _cumulative(np.swapaxes(_cumulative(matrix, step), -1, -2), step).swapaxes(-1, -2)


def drift_spectrum(track, slope, path: OccupancyPath, omega):
    """S − S_frozen of the module docstring per unit |r|², for poles followed along the mean
    path (``track``, ``slope``: (n_p, n_t) on _TRACK, the first column at λ₀)
    at angular frequencies ``omega`` → (n_p, n_f)."""
    track, slope = np.asarray(track, dtype=complex), np.asarray(slope, dtype=complex)
    decay = float(-track.real.max())                # the longest memory along the mean path
    u, rho, covariance = _path_grid(path, decay)
    fine = _drift_on_grid(track, slope, path, omega, u, rho, covariance)
    coarse = _drift_on_grid(track, slope, path, omega, u[::2], rho[::2], covariance[::2, ::2])
    return (4 * fine - coarse) / 3


def _drift_on_grid(track, slope, path, omega, u, rho, covariance):
    """drift_spectrum on one grid (u, ρ(u), the path's correlation on it)."""
    pole = track[:, :1]
    step, count = u[1], u.size
    # the pole and its slope where the mean path λ₀ + (1 − λ₀)(1 − ρ(u)) is at u
    share = 1.0 - rho
    along, rate = (np.array([np.interp(share, _TRACK, x.real)
                             + 1j * np.interp(share, _TRACK, x.imag) for x in rows])
                   for rows in (track, slope))
    # Z(u) = ∫₀^u p₁ δλ = X + iY (X the damping's part, Y the frequency's). The Gaussian
    # cumulant of Z(u) + Z̄(u') less Var(X(u) + X(u'))/2: the damping's fluctuation enters to
    # first order (with the frequency's, as a phase); its square would let rare paths of a
    # linearised pole go undamped. Left: −Var(Y(u) − Y(u'))/2 + i Cov(X(u) + X(u'), Y(u) − Y(u')).
    weighted_covariance = path.variance * covariance

    def moment(left, right):                                    # E[left(u) right(u')]
        return _cumulative_square(left[:, :, np.newaxis] * weighted_covariance
                                  * right[:, np.newaxis, :], step)

    yy, xy = moment(rate.imag, rate.imag), moment(rate.real, rate.imag)
    diagonal = np.diagonal(2j * xy - yy, axis1=-2, axis2=-1) / 2
    exponent = _cumulative(along, step) - 1j * pole.imag * u + diagonal
    cross = yy + 1j * (np.swapaxes(xy, -1, -2) - xy)
    envelope = np.exp(pole.real * u)
    # one exponential: its real part, Re ∫p + Re ∫p' − Var(Y(u) − Y(u'))/2, cannot overflow
    weighted = (np.exp(exponent[:, :, np.newaxis] + exponent.conj()[:, np.newaxis, :] + cross)
                - envelope[:, :, np.newaxis] * envelope[:, np.newaxis, :])
    sums = _lag_sums(weighted)[:, count - 1:]                   # δ ≥ 0 (Hermitian)
    # e^{i(Ω − ω) δ}: the ω part shared by all poles, so one matrix product each
    rotation = _powers(np.exp(-1j * omega * step), count)      # e^{−iωu}, (n_f, N)
    spin = _powers(np.exp(1j * pole.imag[:, 0] * step), count)  # e^{iΩu}, (n_p, N)
    total = (sums[:, :1].real
             + 2 * ((sums[:, 1:] * spin[:, 1:]) @ rotation[:, 1:].T).real)
    # Filon: K piecewise linear, ∫ hat_j(u) e^{zu} du = e^{z u_j} h(z) inside, b₀ at u = 0.
    z = pole - 1j * omega
    y = z * step / 2
    hat = step * (np.sinh(y) / y) ** 2
    first = (np.expm1(z * step) - z * step) / (z**2 * step)
    row = (weighted[:, 0, :] * spin.conj()) @ rotation.conj().T   # Σ_k P₀ₖ e^{−i(Ω−ω) u_k}
    total = total + 2 * ((first / hat - 1.0) * row).real
    return np.abs(hat) ** 2 * total


def modulation_correction(structure: ModalModel, attached: tuple, shapes: np.ndarray,
                          mode: int, nodes: np.ndarray, weights: np.ndarray,
                          path: OccupancyPath, frequency: np.ndarray,
                          cross: bool = False) -> np.ndarray:
    """The module docstring's correction for the displacements at the outputs (shapes (n_out,
    n_modes)): shape (n_out, n_f), or (n_out, n_out, n_f) with ``cross``; multiply by ω⁴ s(f)
    for accelerations. ``attached`` holds the crowd first, at the mean occupancy, then the
    dampers; ``nodes``, ``weights`` are the occupancy rule of mode ``mode``. Zero without a
    crowd of MSDs.
    """
    outputs = shapes[:, mode]
    result = np.zeros(len(frequency))
    if attached and path.rate_variance > 0:
        occupied = _OccupiedMode(structure, attached, mode)
        track, slope, residue, node = occupied.drifting_poles(nodes)
        if node.size:           # none where every pole is heavily damped: nothing drifts to ring
            near = _near_resonances(track[:, 0], frequency)
            spectra = drift_spectrum(track, slope, path, 2 * np.pi * frequency[near])
            result[near] = (np.asarray(weights)[node] * residue) @ spectra
    if cross:
        return np.multiply.outer(np.outer(outputs, outputs), result).astype(complex)
    return np.multiply.outer(outputs**2, result)


def drift_parameters(structure: ModalModel, attached: tuple, mode: int,
                     path: OccupancyPath) -> tuple[float, float]:
    """(ε, κ) of the occupied mode's lightly damped pole p at the mean occupancy (the one with
    the shortest memory 1/Γ, Γ = −Re p; docs: theory, Beyond the quasi-static mixture):

    * ε = Var λ̇ / (Var λ Γ²), the squared ratio of the memory to the occupancy's time scale
      σ/σ_λ̇: where it is small the mixture alone holds, the correction matters from about 1;
    * κ = σ_λ |Im p'| / Γ, how many half-power half-widths the resonance moves over one
      standard deviation of the occupancy: the correction is checked against the simulator up
      to κ = 0.42 and overshoots from κ = 0.69.

    Where no pole is lightly damped ε takes the largest decay of all poles and κ is 0.
    """
    occupied = _OccupiedMode(structure, attached, mode)
    track, slope, _, _ = occupied.drifting_poles(np.ones(1))
    if not track.size:
        decay = float(-np.linalg.eigvals(occupied.system(1.0)[0]).real.min())
        return float(path.rate_variance / (path.variance * decay**2)), 0.0
    pole = np.argmax(-track[:, 0].real)
    decay = float(-track[pole, 0].real)
    return (float(path.rate_variance / (path.variance * decay**2)),
            float(np.sqrt(path.variance) * abs(slope[pole, 0].imag) / decay))


def _near_resonances(poles, frequency):
    """Where the correction is computed: within _REACH half-power widths (at least
    _MIN_REACH Hz) of a drifting pole. Beyond, it is below 1e-3 of the PSD."""
    reach = np.maximum(_REACH * -poles.real, 2 * np.pi * _MIN_REACH) / (2 * np.pi)
    return (np.abs(frequency[:, np.newaxis] - poles.imag / (2 * np.pi)) < reach).any(axis=1)
