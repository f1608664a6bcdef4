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
import functools
from types import SimpleNamespace

import numpy as np
from numba import njit

from ...models.structure import ModalModel
from ._attached import reduced_matrices
from ._linalg import eigen_decomposition
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
#: Poles whose memories differ by more than this factor are computed on separate grids
#: (_memory_groups); within it they share the grid of the longest memory, as they always did:
#: on the paper's bridge the occupied mode's poles at the nodes differ by < 1.2, and with a
#: lightly damped MSD (ξ_h = 0.1) its own pole by 20–26 from the bridge's. From a factor of
#: about 1600 the shared grid's step makes Filon's weights overflow (e^{Re zh} below rounding).
_MEMORY_SPAN = 100.0


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
        """ρ at ``lags`` [s] (the stations' φ² interpolated linearly, zero off the walkway).

        Each station's term is linear in the lag between the lags (x_j − x_i)/v at which the
        shifted station crosses another: ρ is piecewise linear with those knots, and where φ²
        vanishes at both ends of the walkway (no jump where a walker leaves it) it is
        interpolated from its values there, kept (_knots), to rounding: the grid in u changes
        with every MSD (a tenth of the drift correction's time, issue 39)."""
        lags = np.abs(np.asarray(lags, float))
        if self._knots is not None:
            knots, values = self._knots
            return np.interp(lags, knots, values, right=0.0)
        return self._correlation(lags)

    @functools.cached_property
    def _knots(self):
        """(the lags where ρ bends, ρ there), or None where φ² jumps at an end of the walkway."""
        square = self.structure.mode_shapes[..., self.mode] ** 2
        # sin(π) of a half-sine is 1e-16, not 0: a jump below rounding is none
        if np.any(square[:, [0, -1]] > 1e-15 * square.max()) or not self.walking_speed > 0:
            return None
        positions = self.structure.positions
        knots = np.unique(np.maximum(positions - positions[:, np.newaxis], 0.0)) / self.walking_speed
        return knots, self._correlation(knots)

    def _correlation(self, lags):
        """ρ at lags ≥ 0, summed station by station."""
        structure = self.structure
        square = structure.mode_shapes[..., self.mode] ** 2         # (lane, station)
        positions = structure.positions
        ahead = positions + self.walking_speed * lags[:, np.newaxis]
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

        # Only the mode's coupling to the crowd's coordinate (entries (0, 1) and (1, 0)) is odd
        # in s; every other entry is even (the crowd's Ψ = s² c² on the mode, the rest constant):
        # two evaluations give the three coefficients, the values the central differences at
        # s = ±1 gave (a third of building this, once per MSD).
        at_zero, at_one = matrices(0.0), matrices(1.0)
        odd = np.zeros(at_one.shape[1:], dtype=bool)
        odd[0, 1] = odd[1, 0] = True
        self.coefficients = (at_zero, np.where(odd, at_one, 0.0),
                             np.where(odd, 0.0, at_one - at_zero))
        # The mass is diagonal (one mode, the crowd's and the dampers' own coordinates; only
        # stiffness and damping couple them): its inverse is the reciprocals, what LAPACK's
        # inverse of a diagonal matrix gives, without a batched inverse of 150 small matrices
        # (a sixth of the correction's time, issue 39).
        masses = np.stack([c[0] for c in self.coefficients])
        self._diagonal_mass = not np.any(masses - masses * np.eye(masses.shape[-1]))

    def system(self, occupancy):
        """State matrices (…, 2n, 2n) and input columns (…, 2n, 1), the load's intensity λ in
        them, at the occupancies λ (a float or an array of any shape …)."""
        s = np.sqrt(np.asarray(occupancy, dtype=float))[..., np.newaxis, np.newaxis]
        c0, c1, c2 = self.coefficients          # (mass, damping, stiffness) of each power of s
        mass, damping, stiffness = np.moveaxis(c0 + s[..., np.newaxis] * c1
                                               + s[..., np.newaxis]**2 * c2, -3, 0)
        size = mass.shape[-1]
        state = np.zeros(s.shape[:-2] + (2 * size, 2 * size))
        state[..., :size, size:] = np.eye(size)
        load = np.zeros(s.shape[:-2] + (2 * size, 1))
        if self._diagonal_mass:
            # M⁻¹X for a diagonal M: each row of X times its reciprocal mass, the product
            # M⁻¹'s matrix gave, without a batched product per matrix
            inverse = 1.0 / np.einsum("...ii->...i", mass)[..., np.newaxis]   # (…, n, 1)
            state[..., size:, :size] = -(inverse * stiffness)
            state[..., size:, size:] = -(inverse * damping)
            load[..., size, :] = inverse[..., 0, :] * s[..., 0, :] * self.coupling
            return state, load
        inverse_mass = np.linalg.inv(mass)
        state[..., size:, :size] = -inverse_mass @ stiffness
        state[..., size:, size:] = -inverse_mass @ damping
        load[..., size:, :] = inverse_mass[..., :, :1] * s * self.coupling
        return state, load

    def drifting_poles(self, nodes, kept=None):
        """The lightly damped poles at each node λ₀, followed along the occupancy's mean path
        λ₀ + (1 − λ₀) t for t on _TRACK (back to the mean, 1), with their slope dp/dλ there,
        and |residue|² at λ₀ (modal displacement per unit load, the load's intensity in it)
        → track (n_p, n_t), slope (n_p, n_t), residue (n_p,) and the node of each pole.
        ``kept``: recent eigen-decompositions of the track's states, which those of a nearby
        MSD (a Jacobian's column) update by perturbation (:func:`._linalg.eigen_decomposition`).
        """
        nodes = np.asarray(nodes, dtype=float)
        levels = nodes[:, np.newaxis] + (1.0 - nodes[:, np.newaxis]) * _TRACK   # (n, n_t)
        step = _STEP * np.maximum(levels, _STEP)
        states, loads = self.system(levels[..., np.newaxis]
                                    + np.array([-1, 0, 1]) * step[..., np.newaxis])
        poles, vectors, inverse = eigen_decomposition(states[:, :, 1], kept)  # (n, n_t, 2m), …
        # dp/dλ of every pole: first-order perturbation w_p (dA/dλ) v_p (w_p the rows of V⁻¹),
        # dA/dλ by central differences (one eigen-decomposition per level, not three)
        change = (states[:, :, 2] - states[:, :, 0]) / (2 * step[..., np.newaxis, np.newaxis])
        slopes = np.einsum("...pi,...ij,...jp->...p", inverse, change, vectors)
        node, which = np.nonzero(_is_light(poles[:, 0]))
        modal = (inverse[node, 0] @ loads[node, 0, 1])[np.arange(node.size), which, 0]
        residue = np.abs(vectors[node, 0, 0, which] * modal) ** 2
        poles, slopes = poles[node], slopes[node]
        # each pole follows its nearest successor: the successor of every pole at each step at
        # once, then the chain from the light pole at λ₀
        successor = np.abs(poles[:, 1:, np.newaxis, :]
                           - poles[:, :-1, :, np.newaxis]).argmin(axis=-1)
        rows, columns = np.arange(node.size), np.arange(_TRACK.size)
        if np.all(successor == np.arange(poles.shape[-1])):
            # the usual case: eig keeps the poles' order along the path (no chain to follow)
            chosen = np.broadcast_to(which[:, np.newaxis], (node.size, _TRACK.size))
        else:
            chosen = np.empty((node.size, _TRACK.size), dtype=int)
            chosen[:, 0] = which
            for k in range(1, _TRACK.size):
                chosen[:, k] = successor[rows, k - 1, chosen[:, k - 1]]
        rows = rows[:, np.newaxis]
        return poles[rows, columns, chosen], slopes[rows, columns, chosen], residue, node


def _is_light(poles):
    """Im p > 0 and a damping ratio below _LIGHT_DAMPING: the resonances that carry the
    correction (the MSD's own, heavily damped pole varies little with λ)."""
    return (poles.imag > 0) & (-poles.real < _LIGHT_DAMPING * np.abs(poles))


def _path_grid(path: OccupancyPath, decay: float):
    """The grid in u (an odd number of points) and ρ on it: the correlation of the path about
    its mean given λ₀ is σ⁻² Cov(δλ(u), δλ(u')) = ρ(u − u') − ρ(u) ρ(u') (the linear
    prediction's error), formed where it is used (_lag_sums)."""
    step = min(path.time_scale, 1.0 / decay) / _PER_SCALE
    # The count from the ratio of the scales, not from the step: for a memory shorter than the
    # time scale, _MEMORIES / (2 Γ h) is the integer _MEMORIES _PER_SCALE / 2 give or take a
    # rounding, and its ceiling added two points or not by the last bit of Γ (two MSDs a
    # Jacobian's step apart then differed by 2e-4 of the correction).
    half = _MEMORIES * _PER_SCALE / (2 * min(path.time_scale * decay, 1.0))
    count = min(2 * int(np.ceil(half)) + 1, _MAX_POINTS)
    step = max(step, _MEMORIES / (decay * (count - 1)))
    u = step * np.arange(count)
    return u, path.correlation(u)


def _powers(base, count):
    """base^k for k = 0 … count − 1 along a new first axis, by doubling (log₂ count products of
    blocks: numpy's complex running product is slow; rounding grows as log k ε)."""
    powers = np.empty((count,) + np.shape(base), dtype=complex)
    powers[0] = 1.0
    filled, factor = 1, base
    while filled < count:
        block = min(filled, count - filled)
        np.multiply(powers[:block], factor, out=powers[filled:filled + block])
        filled, factor = filled + block, factor * factor
    return powers


def drift_spectrum(track, slope, path: OccupancyPath, omega):
    """S − S_frozen of the module docstring per unit |r|², for poles followed along the mean
    path (``track``, ``slope``: (n_p, n_t) on _TRACK, the first column at λ₀)
    at angular frequencies ``omega`` → (n_p, n_f)."""
    track, slope = np.asarray(track, dtype=complex), np.asarray(slope, dtype=complex)
    omega = np.asarray(omega, dtype=float)
    decay = float(-track.real.max())                # the longest memory along the mean path
    u, rho = _path_grid(path, decay)
    step, pole = u[1], track[:, :1]
    # the pole and its slope where the mean path λ₀ + (1 − λ₀)(1 − ρ(u)) is at u (_TRACK is
    # even: one interpolation weight for every pole)
    position = np.clip(1.0 - rho, 0.0, 1.0) * (_TRACK.size - 1)
    below = np.minimum(position.astype(int), _TRACK.size - 2)
    fraction = position - below
    along, rate = (np.take(rows, below, axis=1) * (1.0 - fraction)
                   + np.take(rows, below + 1, axis=1) * fraction for rows in (track, slope))
    # e^{iΩu} and e^{−iωu} on the fine grid; the coarse grid (2h) takes every other power
    spin = _powers(np.exp(1j * pole[:, 0].imag * step), u.size).T     # (n_p, N)
    rotation = _powers(np.exp(-1j * omega * step), u.size)            # (N, n_f)
    zh = (pole - 1j * omega) * step
    growth = np.expm1(zh)                                   # e^{zh} − 1; doubled: e(e + 2)
    fine = _drift_on_grid(pole, along, rate, rho, path.variance, step, spin, rotation,
                          _filon(zh, growth, step))
    coarse = _drift_on_grid(pole, np.ascontiguousarray(along[:, ::2]),
                            np.ascontiguousarray(rate[:, ::2]), np.ascontiguousarray(rho[::2]),
                            path.variance, 2 * step, spin[:, ::2], rotation[::2],
                            _filon(2 * zh, growth * (growth + 2), 2 * step))
    return (4 * fine - coarse) / 3


@njit(cache=True, nogil=True)
def _lag_sums(pole, along, rate, rho, variance, step):
    """The lag sums L(δ) = Σ_k K(u_k + δ, u_k) of the integrand K (module docstring) and its
    first column K(u_k, 0), per pole → two (n_p, N) arrays: the O(N²) part of _drift_on_grid,
    compiled (numba), as numpy's N × N temporaries cost more than the sums (issue 39).

    Z(u) = ∫₀^u p₁ δλ = X + iY (X the damping's part, Y the frequency's). The Gaussian
    cumulant of Z(u) + Z̄(u') less Var(X(u) + X(u'))/2: the damping's fluctuation enters to
    first order (with the frequency's, as a phase); its square would let rare paths of a
    linearised pole go undamped. Left: −Var(Y(u) − Y(u'))/2 + i Cov(X(u) + X(u'), Y(u) − Y(u')).
    M(u, u') = E[X(u) Y(u')] + i E[Y(u) Y(u')] in one: the double integral of p₁(u) Cov Im p₁(u'),
    over u' first (shared by both), then over u, by trapezoids. K is Hermitian in (u, u'): only
    u ≥ u' is evaluated, where its exponent is E(u) + Ē(u') − i M(u, u') + i Re M(u', u) with
    E(u) = ∫₀^u p(λ̄) − iΩu + i Re M(u, u) − Im M(u, u)/2; its real part,
    Re ∫p + Re ∫p' − Var(Y(u) − Y(u'))/2, cannot overflow.
    """
    size, count = along.shape
    half = 0.5 * step
    sums = np.zeros((size, count), dtype=np.complex128)
    column = np.empty((size, count), dtype=np.complex128)
    inner = np.empty((count, count))
    moments = np.empty((count, count), dtype=np.complex128)
    exponent = np.empty(count, dtype=np.complex128)
    for p in range(size):
        # ∫₀^{u'} Cov(δλ(u), δλ(s)) Im p₁(s) ds on the grid, Cov = σ² (ρ(u − s) − ρ(u) ρ(s))
        for j in range(count):
            inner[j, 0] = 0.0
            previous = variance * (rho[j] - rho[j] * rho[0]) * rate[p, 0].imag
            for k in range(1, count):
                current = variance * (rho[abs(j - k)] - rho[j] * rho[k]) * rate[p, k].imag
                inner[j, k] = inner[j, k - 1] + half * (previous + current)
                previous = current
        for k in range(count):
            moments[0, k] = 0.0
        for j in range(1, count):
            for k in range(count):
                moments[j, k] = moments[j - 1, k] + half * (rate[p, j - 1] * inner[j - 1, k]
                                                            + rate[p, j] * inner[j, k])
        integral = 0.0j
        for j in range(count):
            if j:
                integral += half * (along[p, j - 1] + along[p, j])
            own = moments[j, j]
            exponent[j] = (integral - 1j * pole[p, 0].imag * step * j + 1j * own.real
                           - 0.5 * own.imag)
        for j in range(count):
            for k in range(j + 1):
                value = np.exp(exponent[j] + np.conj(exponent[k]) - 1j * moments[j, k]
                               + 1j * moments[k, j].real)
                sums[p, j - k] += value
                if k == 0:
                    column[p, j] = value
    return sums, column


def _drift_on_grid(pole, along, rate, rho, variance, step, spin, rotation, filon):
    """drift_spectrum on one grid of ``step``: the pole at λ₀ (n_p, 1), the pole and its slope
    along the mean path (n_p, N), ρ (N,) and Var λ, e^{iΩu} (n_p, N), e^{−iωu} (N, n_f) and
    Filon's weights (n_p, n_f) on it."""
    size, count = along.shape
    moving, first_column = _lag_sums(pole, along, rate, rho, variance, step)
    # less the frozen envelope e^{γ(u + u')}, γ = Re p, whose lag sums are geometric series:
    # Σ_{k < N−δ} e^{γh(2k + δ)} = e^{γhδ} (e^{2γh(N−δ)} − 1)/(e^{2γh} − 1)
    decay, lags = pole.real * step, np.arange(count)
    envelope = np.exp(decay * lags)
    frozen = envelope * np.expm1(2 * decay * (count - lags)) / np.expm1(2 * decay)
    sums = (moving - frozen) * spin                             # L(δ) e^{iΩδ}, δ ≥ 0
    sums[:, 0] /= 2                                              # L(0) is real: 2 Re once
    first_column = (first_column - envelope) * spin             # K(u_k, 0) e^{iΩu_k}
    # Σ_δ (…) e^{−iωδ}, the ω part shared by all poles: one real product (complex products of
    # this skinny shape are slow in OpenBLAS); its columns alternate real and imaginary parts
    products = (np.concatenate([sums.real, sums.imag, first_column.real, first_column.imag])
                @ rotation.view(float))
    rr, ri = products[:, ::2], products[:, 1::2]
    total = 2 * (rr[:size] - ri[size:2 * size])                  # 2 Re Σ_δ L(δ) e^{i(Ω−ω)δ}
    # the first row Σ_k K(0, u_k) e^{−i(Ω−ω)u_k}, the conjugate of the first column's sum
    row_sum = ((rr[2 * size:3 * size] - ri[3 * size:])
               - 1j * (ri[2 * size:3 * size] + rr[3 * size:]))
    hat, first = filon
    total = total + 2 * ((first / hat - 1.0) * row_sum).real
    return np.abs(hat) ** 2 * total


def _filon(zh, growth, step):
    """Filon's weights for K piecewise linear on a grid of ``step``: ∫ hat_j(u) e^{zu} du =
    e^{z u_j} h(z) inside, b₀(z) at u = 0, from zh and e^{zh} − 1 (``growth``):
    h = step (sinh(zh/2)/(zh/2))² = step (e^{zh} − 1)²/(e^{zh} (zh)²), b₀ = step (e^{zh} − 1 − zh)/(zh)²."""
    scale = step / zh**2
    return scale * growth**2 / (1.0 + growth), scale * (growth - zh)


def modulation_correction(structure: ModalModel, attached: tuple, shapes: np.ndarray,
                          mode: int, nodes: np.ndarray, weights: np.ndarray,
                          path: OccupancyPath, frequency: np.ndarray,
                          cross: bool = False, kept: list | None = None) -> np.ndarray:
    """The module docstring's correction for the displacements at the outputs (shapes (n_out,
    n_modes)): shape (n_out, n_f), or (n_out, n_out, n_f) with ``cross``; multiply by ω⁴ s(f)
    for accelerations. ``attached`` holds the crowd first, at the mean occupancy, then the
    dampers; ``nodes``, ``weights`` are the occupancy rule of mode ``mode``. Zero without a
    crowd of MSDs. ``kept``: as for :meth:`_OccupiedMode.drifting_poles`.
    """
    outputs = shapes[:, mode]
    result = np.zeros(len(frequency))
    if attached and path.rate_variance > 0:
        occupied = _OccupiedMode(structure, attached, mode)
        track, slope, residue, node = occupied.drifting_poles(nodes, kept)
        if node.size:           # none where every pole is heavily damped: nothing drifts to ring
            near = _near_resonances(track[:, 0], frequency)
            spectra = np.empty((len(track), int(near.sum())))
            for group in _memory_groups(track):
                spectra[group] = drift_spectrum(track[group], slope[group], path,
                                                2 * np.pi * frequency[near])
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


def _memory_groups(track):
    """The drifting poles in groups whose memories 1/Γ lie within _MEMORY_SPAN of each other,
    each computed on its own grid in u. One grid sized by the longest memory would step over
    the short ones: a walker's pole that an estimate's bounds put at 1 mHz (a memory of two
    days) made the grid's step an hour, and the bridge's pole then overflowed Filon's weights
    (NaN in the PSD). Poles of comparable memory (the occupied mode's at each occupancy node)
    stay on one grid, as before."""
    decay = -track.real.max(axis=1)                      # each pole's longest memory's Γ
    order = np.argsort(decay)
    groups, start = [], 0
    for k in range(1, order.size + 1):
        if k == order.size or decay[order[k]] > _MEMORY_SPAN * decay[order[start]]:
            groups.append(order[start:k])
            start = k
    return groups


def _near_resonances(poles, frequency):
    """Where the correction is computed: within _REACH half-power widths (at least
    _MIN_REACH Hz) of a drifting pole. Beyond, it is below 1e-3 of the PSD."""
    reach = np.maximum(_REACH * -poles.real, 2 * np.pi * _MIN_REACH) / (2 * np.pi)
    return (np.abs(frequency[:, np.newaxis] - poles.imag / (2 * np.pi)) < reach).any(axis=1)
