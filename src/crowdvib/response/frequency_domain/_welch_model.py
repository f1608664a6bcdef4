"""The Welch-window expectation of the modelled PSD with few model points (docs: theory, Evaluating the Welch expectation).

E[Ĝ](f) = ∫ K(f − ν) G(ν) dν with the Hann kernel K (signals.welch_kernel). Sampling G densely
enough for a rectangle rule to resolve a lightly damped peak costs 16 points per bin of 1/T; here
G is sampled at a few points per bin, and the error that this coarse rule makes on each narrow
occupied peak is corrected exactly:

* the occupied response has the pole–residue form |Φ_o H B|² = 2 Re Σ_p β_p / (iω − λ_p)
  (:func:`power_coefficients`), so G = w(ν) · 2 Re Σ_p β_p u_p(ν) with the smooth weight
  w = ω⁴ s(f) |H_LP|⁴ and u_p = 1/(iω − λ_p);
* near a narrow pole p, w is replaced by its quadratic Taylor polynomial at ν_p, which makes the
  peak part S_p a pole term plus a polynomial: its convolution with K is closed-form
  (:func:`hann_pole_convolution`, the window's autocorrelation times e^{λt} integrated over
  [0, T]);
* for the output frequencies within reach of the pole, E += K∗S_p − rule(S_p): the coarse rule's
  error on the sharp part is replaced by the exact value, and what is left, G − Σ S_p, is smooth
  on the scale 1/T, where the coarse rule is accurate.
"""

import copy
import functools

import numpy as np
from scipy import sparse

from ...signals import welch_kernel

# Welch kernel support: ±8 bins of 1/T hold all but ~1e-5 of the Hann kernel's area.
KERNEL_HALF_WIDTH_BINS = 8
# The dense reference samples 16 points per bin; the corrected coarse rule 4.
DENSE_POINTS_PER_BIN = 16
COARSE_POINTS_PER_BIN = 4
# A pole narrower than this (γ T, γ = |Re λ|/2π) gets the exact correction: a rectangle rule of
# step 1/(nT) aliases a peak of half-width γ by ~exp(−2πγ(n − 1)T), 1e-7 at γ T = 0.85 for n = 4.
NARROW_POLE_WIDTH = 0.85
# Output frequencies within (half width + margin) bins of a narrow pole get its correction; beyond,
# the kernel's support stays 2 bins clear of the peak and the coarse rule is exact to round-off.
CORRECTION_MARGIN_BINS = 2
# Step [Hz] of the central differences that give w' and w'' at a pole (w varies on ≥ 0.05 Hz).
TAYLOR_STEP = 1e-3


class WelchRule:
    """A rectangle rule of the Welch kernel on a uniform grid covering ``frequency`` ± reach.

    ``matrix`` (sparse, n_f × n_grid) maps G on ``grid`` to the Welch expectation at
    ``frequency``; the same weights are kept banded (``start``, ``weights``: row i uses grid
    points start[i] … start[i] + L − 1) for the per-pole corrections.
    """

    def __init__(self, frequency, window_length, points_per_bin,
                 half_width_bins=KERNEL_HALF_WIDTH_BINS):
        bin_width = 1.0 / window_length
        step = bin_width / points_per_bin
        reach = half_width_bins * bin_width
        lower = max(frequency[0] - reach, 0.0)
        self.grid = lower + step * np.arange(
            int(np.ceil((frequency[-1] + reach - lower) / step)) + 1)
        half = round(reach / step)
        centre = np.rint((frequency - lower) / step).astype(int)
        index = centre[:, np.newaxis] + np.arange(-half, half + 1)
        inside = (index >= 0) & (index < self.grid.size)
        clipped = np.clip(index, 0, self.grid.size - 1)
        weights = welch_kernel(frequency[:, np.newaxis] - self.grid[clipped], window_length)
        self.weights = np.where(inside, weights * step, 0.0)
        self.index = clipped
        rows = np.broadcast_to(np.arange(frequency.size)[:, np.newaxis], index.shape)[inside]
        self.matrix = sparse.csr_matrix((self.weights[inside], (rows, index[inside])),
                                        shape=(frequency.size, self.grid.size))
        self.frequency = frequency
        self.window_length = window_length
        self.reach = reach
        self.row_sum = self.weights.sum(axis=1)

    def apply(self, values):
        """Welch expectation at ``frequency`` of values (n_outputs, n_grid) sampled on ``grid``."""
        return (self.matrix @ values.T).T


def cross_power_coefficients(poles, left, right):
    """β^{ab} with Σ_r P_ar conj(P_br) = Σ_p β^{ab}_p u_p + conj(Σ_p β^{ba}_p u_p), where
    P_ar = Σ_p left[a,p] right[p,r] / (s − λ_p), s = iω and u_p = 1/(s − λ_p).

    The cross-spectral generalisation of :func:`power_coefficients` (the same partial fractions,
    docs: theory, The cross-spectral matrix): β^{ab}_p = −Σ_q A_ap Ā_bq / (λ_p + λ̄_q), shape
    (n_outputs, n_outputs, n_poles); its diagonal is :func:`power_coefficients`.
    """
    mixed = (right @ _transposed(right.conj())) / _pole_sums(poles)
    # a matrix product: no einsum
    return -left[..., :, np.newaxis, :] * (left.conj() @ _transposed(mixed))[..., np.newaxis, :, :]


def power_coefficients(poles, left, right):
    """β with Σ_r |Σ_p left[o,p] right[p,r] / (s − λ_p)|² = 2 Re Σ_p β[o,p] / (s − λ_p), s = iω.

    Partial fractions of each product 1/((s − λ_p)(s̄ − λ̄_q)) on the imaginary axis:
    β_p = −Σ_q A_p Ā_q / (λ_p + λ̄_q) with A_p the residue row (docs: theory, Evaluating the
    Welch expectation). Shape (n_outputs, n_poles). Stacks of poles (the occupancy nodes of a
    mixture, ``spectral._pole_terms``) give stacks, here and in :func:`cross_power_coefficients`.
    """
    gram = right @ _transposed(right.conj())                         # (2N, 2N)
    mixed = gram / _pole_sums(poles)
    return -left * (left.conj() @ _transposed(mixed))                 # a matrix product: no einsum


def _transposed(matrices):
    return matrices.swapaxes(-1, -2)


def _pole_sums(poles):
    """λ_p + λ̄_q, shape (…, 2N, 2N)."""
    return poles[..., :, np.newaxis] + poles.conj()[..., np.newaxis, :]


def _ratio_series(z):
    """(e^z − 1 − z)/z², with its Taylor series where the closed form cancels."""
    small = np.abs(z) < 1e-2
    safe = np.where(small, 1.0, z)
    closed = (np.exp(safe) - 1.0 - safe) / safe**2
    series = 0.5 + z / 6.0 + z**2 / 24.0 + z**3 / 120.0
    return np.where(small, series, closed)


def hann_pole_convolution(poles, frequency, window_length):
    """(K ∗ u)(f) for u(ν) = 1/(2πiν − λ) and the Hann Welch kernel K, shape (n_f, n_poles).

    K is the Fourier transform of the window's normalised autocorrelation
    ρ(t) = ⅔(1 − t/T)(1 + ½ cos 2πt/T) + sin(2πt/T)/2π on |t| ≤ T and u that of e^{λt} on t ≥ 0,
    so K ∗ u = ∫₀ᵀ ρ(t) e^{(λ − 2πif)t} dt, in closed form (docs: theory, Evaluating the Welch
    expectation). Needs Re λ < 0.
    """
    return _pole_convolution(poles[np.newaxis] - 2j * np.pi * frequency[:, np.newaxis],
                             window_length)


def _pole_convolution(a, window_length):
    """:func:`hann_pole_convolution` from a = λ − 2πif, elementwise."""
    period = window_length
    kappa = 2 * np.pi / period

    def linear(c):
        # ∫₀ᵀ (1 − t/T) e^{ct} dt = T (e^{cT} − 1 − cT)/(cT)²
        return period * _ratio_series(c * period)

    growth = np.exp(a * period)
    sine = -(growth - 1.0) / (period * (a**2 + kappa**2))
    return 2.0 / 3.0 * linear(a) + (linear(a + 1j * kappa) + linear(a - 1j * kappa)) / 6.0 + sine


def _coarse_rule(frequency, window_length):
    """The coarse :class:`WelchRule` of a grid and window, shared by every model on them: an
    estimate builds a dozen models on one band (its objectives, their bins, the crowd-size
    term), and the rule is a quarter of each build (issue 39). Its arrays are read-only."""
    return _cached_rule(frequency.tobytes(), frequency.shape, window_length)


@functools.lru_cache(maxsize=16)
def _cached_rule(data, shape, window_length):
    rule = WelchRule(np.frombuffer(data, dtype=float).reshape(shape), window_length,
                     COARSE_POINTS_PER_BIN)
    for array in (rule.grid, rule.weights, rule.index, rule.row_sum, rule.matrix.data,
                  rule.matrix.indices, rule.matrix.indptr):
        array.flags.writeable = False
    return rule


class CorrectedWelch:
    """Welch expectation from a coarse rule plus exact corrections at the narrow poles.

    Parameters
    ----------
    frequency : ndarray
        Output frequencies [Hz].
    window_length : float
        T [s].
    weight : callable
        w(ν) = ω⁴ s(ν) |H_LP(ν)|⁴ for an array of frequencies.
    """

    def __init__(self, frequency, window_length, weight):
        self.rule = _coarse_rule(np.asarray(frequency, dtype=float), float(window_length))
        self.grid = self.rule.grid
        self._weight = weight
        self.grid_weight = weight(self.grid)
        self._reach = (KERNEL_HALF_WIDTH_BINS + CORRECTION_MARGIN_BINS) / window_length
        self._narrow = NARROW_POLE_WIDTH / window_length

    def with_weight(self, weight, grid_weight=None):
        """The same rule for another weight function (``grid_weight``: its values on the grid,
        when the caller has them): the rule depends on the grid and window only."""
        other = copy.copy(self)
        other._weight = weight
        other.grid_weight = weight(self.grid) if grid_weight is None else grid_weight
        return other

    def psd(self, poles, left, right):
        """Welch expectation (n_outputs, n_f) of w · Σ_r |Σ_p left right / (iω − λ_p)|²."""
        return self.psd_from(poles, *self.power_terms(poles, left, right))

    def _resolvent(self, poles):
        """u_p = 1/(iω − λ_p) on the grid, (…, n_grid, 2N)."""
        return 1.0 / (2j * np.pi * self.grid[:, np.newaxis] - poles[..., np.newaxis, :])

    def power_terms(self, poles, left, right):
        """(β, the unweighted power on the grid (n_grid, n_outputs)): with the narrow poles'
        part of the rule's error (:meth:`pole_parts`) what :meth:`psd` needs of the poles,
        independent of the weight w (kept by a model across step frequencies). Stacks of poles
        give stacks."""
        beta = power_coefficients(poles, left, right)
        resolvent = self._resolvent(poles)
        # Only the real part is wanted: two real products (a complex product of this skinny
        # shape took 11 ms in OpenBLAS against 0.04 ms for the real ones, measured).
        return beta, 2.0 * (resolvent.real @ _transposed(beta.real)
                            - resolvent.imag @ _transposed(beta.imag))

    def psd_from(self, poles, beta, power, parts=None):
        """:meth:`psd` from its :meth:`power_terms` and this rule's weight."""
        expected = self.rule.apply(power.T * self.grid_weight)
        chosen, errors = self._pole_errors(poles, parts)
        if chosen.size:
            expected += 2.0 * (beta[:, chosen] @ errors).real
        return expected

    def cross(self, poles, left, right):
        """Welch expectation (n_outputs, n_outputs, n_f) of the cross-spectral matrix
        w · Σ_r P_ar conj(P_br) (:func:`cross_power_coefficients`).

        The Welch estimate of a cross-spectrum averages X_a conj(X_b) of the windowed segments,
        whose expectation is the true cross-spectrum convolved with the same real kernel K as
        an auto-spectrum; K∗ is linear, so each pole term C_ab = K∗(w Σ_p β^{ab}_p u_p) gets the
        same coarse rule and exact pole corrections as :meth:`psd`, and the matrix is
        C_ab + conj(C_ba) (w and K real).
        """
        return self.cross_from(poles, *self.cross_terms(poles, left, right))

    def cross_terms(self, poles, left, right):
        """(β^{ab} flattened (n_outputs², n_poles), the unweighted cross power on the grid):
        what :meth:`cross` needs of the poles, with :meth:`pole_parts` independent of the
        weight w. Stacks of poles give stacks."""
        beta = cross_power_coefficients(poles, left, right)
        size = beta.shape[-2]
        flat = beta.reshape(beta.shape[:-3] + (size * size, -1))
        resolvent = self._resolvent(poles)
        # As in psd: real products (the complex product of this shape is ~100× slower).
        real, imag = resolvent.real, resolvent.imag
        real_flat, imag_flat = _transposed(flat.real), _transposed(flat.imag)
        return flat, ((real @ real_flat - imag @ imag_flat)
                      + 1j * (real @ imag_flat + imag @ real_flat))

    def cross_from(self, poles, flat, power, parts=None):
        """:meth:`cross` from its :meth:`cross_terms` and this rule's weight."""
        size = round(np.sqrt(flat.shape[0]))
        expected = self.rule.apply(power.T * self.grid_weight)
        chosen, errors = self._pole_errors(poles, parts)
        if chosen.size:
            expected += flat[:, chosen] @ errors
        expected = expected.reshape(size, size, -1)
        return expected + np.conj(np.swapaxes(expected, 0, 1))

    def _pole_errors(self, poles, parts=None):
        """(the narrow poles p, K∗u_p − rule(u_p) in Taylor form per unit β, (n_p, n_f)): the
        error of the coarse rule on the sharp part of each narrow peak at the output rows within
        its reach, zero beyond. Every (pole, row) pair at once: a loop over the poles cost more
        than their arithmetic (a 14-mode bridge has 14 narrow poles per occupancy node).
        ``parts``: :meth:`pole_parts` of these poles, when the caller keeps them."""
        frequency = self.rule.frequency
        chosen, stencil, which, rows, r, errors_u, errors_1, errors_delta = (
            self.pole_parts(poles) if parts is None else parts)
        errors = np.zeros((chosen.size, frequency.size), dtype=complex)
        if chosen.size == 0:
            return chosen, errors
        # Quadratic Taylor polynomials of w at the peaks, a0 + a1 Δ + a2 Δ² (Δ = ν − ν_p),
        # from one evaluation of w at every stencil point.
        w_minus, w_0, w_plus = self._weight(stencil).reshape(-1, 3).T
        taylor = (w_0, (w_plus - w_minus) / (2 * TAYLOR_STEP),
                  (w_plus - 2 * w_0 + w_minus) / (2 * TAYLOR_STEP**2))
        # (a0 + a1Δ + a2Δ²) u = b_u u + b_c + b_l Δ, from 2πiΔ u = 1 + Re(λ) u.
        q = 1.0 / (2j * np.pi)
        a0, a1, a2 = (coefficient[which] for coefficient in taylor)
        b_u = a0 + a1 * r * q + a2 * r**2 * q**2
        b_c = a1 * q + a2 * r * q**2
        b_l = a2 * q
        errors[which, rows] = b_u * errors_u + b_c * errors_1 + b_l * errors_delta
        return chosen, errors

    def pole_parts(self, poles):
        """What :meth:`_pole_errors` needs of the poles alone, independent of the weight w
        (kept with the pole terms across step frequencies, half a fit's Jacobian, issue 39):
        the narrow poles, the Taylor stencil's frequencies, the (pole, row) pairs within reach,
        Re λ per pair and the rule's errors on u, 1 and Δ there."""
        frequency = self.rule.frequency
        width = -poles.real / (2 * np.pi)
        centre = poles.imag / (2 * np.pi)
        # A pole below 10 Taylor steps is no resonance of the walking band (an over-damped
        # or slow pole; there w ∝ ω⁴ s vanishes) and its stencil would reach f < 0.
        narrow = ((centre > 10 * TAYLOR_STEP) & (width < self._narrow)
                  & (centre > frequency[0] - self._reach) & (centre < frequency[-1] + self._reach))
        chosen = np.flatnonzero(narrow)
        if chosen.size == 0:
            return (chosen,) + (None,) * 7
        stencil = (centre[chosen, np.newaxis] + TAYLOR_STEP * np.array([-1.0, 0.0, 1.0])).ravel()
        which, rows = np.nonzero(np.abs(frequency - centre[chosen, np.newaxis]) <= self._reach)
        pole, middle = poles[chosen][which], centre[chosen][which]
        weights = self.rule.weights[rows]
        nodes = self.grid[self.rule.index[rows]]
        rule_u = (weights / (2j * np.pi * nodes - pole[:, np.newaxis])).sum(axis=1)
        rule_1 = self.rule.row_sum[rows]
        rule_delta = (weights * (nodes - middle[:, np.newaxis])).sum(axis=1)
        exact_u = _pole_convolution(pole - 2j * np.pi * frequency[rows], self.rule.window_length)
        delta = frequency[rows] - middle
        return (chosen, stencil, which, rows, pole.real, exact_u - rule_u, 1.0 - rule_1,
                delta - rule_delta)
