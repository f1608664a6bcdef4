"""The likelihood of several outputs: the complex-Wishart deviance of a Welch cross-spectral
matrix (docs: theory, The likelihood of several outputs).

For a long record of a stationary Gaussian process the Welch cross-spectral matrix Ŝ of p outputs
is, per bin, complex Wishart around its expectation S (Yuen, Katafygiotis & Beck 2002):
n Ŝ ~ CW_p(n, S) with n = ν/2 complex degrees of freedom, ν the equivalent degrees of freedom of
one ordinate (:func:`crowdvib.signals.welch.welch_degrees_of_freedom`), so that each diagonal entry
is S_aa χ²_ν/ν as the per-output (Whittle) likelihood has it. Twice the negative log-likelihood,
up to terms free of S, is the deviance

    D(θ) = Σ_k w_k ν [tr(S_k⁻¹ Ŝ_k) − ln det(S_k⁻¹ Ŝ_k) − p] = Σ_k Σ_i w_k ν (λ_ki − 1 − ln λ_ki),

λ_ki the eigenvalues of S_k⁻¹ Ŝ_k; for p = 1 it is the Whittle deviance. Its residuals are the
per-eigenvalue deviance residuals sign(λ − 1) sqrt(w ν (λ − 1 − ln λ)).

Rank: when one mode rules a bin, S_k has rank ≈ 1 and the deviance is ill-conditioned. Each bin
is therefore reduced to the principal directions of the model *without HSI* (fixed, like the
bins the Whittle likelihood uses: neither θ nor the data choose them) whose eigenvalue is within
``WISHART_RANK_TOLERANCE`` of the bin's largest and within the likelihood's dynamic range of the
band's largest. The projection U_kᴴ Ŝ_k U_k of a complex Wishart matrix on fixed directions is
again complex Wishart around U_kᴴ S_k U_k, so the reduced deviance is an exact likelihood of the
projected data; it needs no noise model.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from .uncertainty import score_variance

__all__ = ["WishartTerms", "WISHART_RANK_TOLERANCE"]

#: A principal direction of the model (without HSI) is kept in a bin when its eigenvalue is at
#: least this fraction of the bin's largest (20 dB): a gain or mode-shape error of a few per
#: cent between channels puts ~1e-3 of the dominant power into the other directions, which
#: would rule a weaker direction instead of the model.
WISHART_RANK_TOLERANCE = 1e-2


def _mask_identity(matrices, keep, fill):
    """Matrices (K, p, p) with the rows and columns of dropped directions (keep False) set to
    those of ``fill`` × identity: a dropped direction then adds nothing to the deviance."""
    out = matrices * (keep[:, :, np.newaxis] & keep[:, np.newaxis, :])
    index = np.arange(keep.shape[1])
    out[:, index, index] += np.where(keep, 0.0, fill)
    return out


def _components(matrices):
    """Real coordinates c(B) of Hermitian B (K, p, p, …) with c(B)·c(B') = tr(B B'): the
    diagonal entries, and √2 Re and √2 Im of the entries above it → (p², K, …)."""
    size = matrices.shape[1]
    rows, cols = np.triu_indices(size, k=1)
    diagonal = np.stack([matrices[:, i, i].real for i in range(size)])
    upper = matrices[:, rows, cols]
    return np.concatenate([diagonal, np.sqrt(2) * np.moveaxis(upper.real, 1, 0),
                           np.sqrt(2) * np.moveaxis(upper.imag, 1, 0)])


class WishartTerms:
    """The complex-Wishart deviance of one record for :class:`PSDObjective` (module docstring).

    Parameters
    ----------
    target : ndarray of complex, shape (p, p, K)
        Measured Welch cross-spectral matrix on the objective's bins, in its normalised units.
    reference : ndarray of complex, shape (p, p, K)
        The model's cross-spectral matrix without HSI, same units: it fixes the directions kept.
    scale : ndarray, shape (K,)
        w_k ν per bin.
    dynamic_range : float
        A kept direction's eigenvalue must reach this fraction of the band's largest.
    """

    def __init__(self, target, reference, scale, dynamic_range):
        values, vectors = np.linalg.eigh(np.moveaxis(reference, -1, 0))
        values, vectors = values[:, ::-1], vectors[:, :, ::-1]        # largest first
        self.keep = ((values >= WISHART_RANK_TOLERANCE * values[:, :1])
                     & (values >= dynamic_range * values[:, 0].max()))
        self.basis = vectors
        self.scale = np.asarray(scale, dtype=float)
        self.set_target(target)

    def set_target(self, target):
        """Use another measured cross-spectral matrix (a bootstrap draw), same shape and units."""
        projected = self.project(target)
        self.target = _mask_identity(projected, self.keep, 1.0)
        eigen = np.linalg.eigvalsh(self.target)
        if not np.all(eigen > 0):
            k = int(np.argwhere(~(eigen > 0).all(axis=1))[0, 0])
            raise ParameterError(
                f"the measured cross-spectral matrix must be positive definite on the directions "
                f"the model resolves (a Welch average of at least as many segments as outputs, "
                f"no two channels identical), got a singular one at bin {k}")

    def project(self, matrices):
        """U_kᴴ M_k U_k for M (p, p, K) → (K, p, p), in the fixed principal directions."""
        stacked = np.moveaxis(matrices, -1, 0)
        return np.conj(np.swapaxes(self.basis, 1, 2)) @ stacked @ self.basis

    def _whitened(self, model):
        """Cholesky factors C (C Cᴴ = reduced model) and C⁻¹ Ŝ C⁻ᴴ, both (K, p, p)."""
        reduced = _mask_identity(self.project(model), self.keep, 1.0)
        factor = np.linalg.cholesky(reduced)
        half = np.linalg.solve(factor, self.target)                  # C⁻¹ Ŝ
        return factor, np.linalg.solve(factor, np.conj(np.swapaxes(half, 1, 2)))

    def residuals(self, model):
        """Deviance residuals (K·p,) of the model cross-spectral matrix (p, p, K)."""
        try:
            _, whitened = self._whitened(model)
        except np.linalg.LinAlgError:
            # A model matrix not positive definite on the kept directions (a θ so far off that
            # a kept direction carries no power): a large but finite deviance.
            return np.full(self.keep.size, 1e150)
        ratio = np.maximum(np.linalg.eigvalsh(whitened), 1e-300)
        deviance = np.maximum(ratio - 1.0 - np.log(ratio), 0.0)
        return (np.sign(ratio - 1.0) * np.sqrt(deviance * self.scale[:, np.newaxis])).ravel()

    def information(self, model, gradient, degrees_of_freedom, correlation, dispersion,
                    occupancy=None):
        """Score variance and expected Hessian of D about the fitted model (sandwich parts).

        On the kept directions the score is g = Σ_k tr(A_k (Ŝ_k − S_k)) with
        A_k = −s_k S⁻¹ ∂S S⁻¹ and the expected Hessian H = Σ_k s_k tr(S⁻¹ ∂_p S S⁻¹ ∂_q S).
        Writing Ŝ − S = C E Cᴴ (C Cᴴ = S), the whitened E has independent entries of
        variance 1/n = 2/ν, so tr(A ΔŜ) = tr(B E) with B = Cᴴ A C, whose real coordinates
        (:func:`_components`) are independent score terms; neighbouring bins correlate each
        coordinate by ρ(d) as they do the ordinates of one output
        (:func:`~crowdvib.identification.uncertainty.score_variance`, ``coherent=False``).
        For that, E must mean the same at neighbouring bins: A is taken back to the outputs'
        coordinates (the principal directions' phases and order change from bin to bin) and
        C is the Cholesky factor of the full model matrix there, which varies smoothly with f
        (a ridge of 1e-10 of its trace lets a rank-deficient S be factored; B is confined to the
        kept directions, so it changes B by as little).

        Parameters
        ----------
        model : ndarray of complex, shape (p, p, K)
            S(θ̂).
        gradient : ndarray of complex, shape (p, p, K, n_parameters)
            ∂S/∂θ at θ̂.
        degrees_of_freedom : float
            ν of the Welch ordinates.
        correlation : array_like
            ρ(0) = 1, ρ(1), … of ordinates 0, 1, … bins apart.
        dispersion : ndarray, shape (K,)
            Measured dispersion of the ordinates, averaged over the outputs (1: Gaussian).
        occupancy : (ndarray, float), optional
            ∂S/∂ln n (shape of ``model``) and the relative variance of the crowd size.

        Returns
        -------
        variance, hessian : ndarray, shape (n_parameters, n_parameters)
        shift : ndarray, shape (n_parameters,), or None
            The score's move per unit of ln n (None without ``occupancy``).
        """
        factor, _ = self._whitened(model)
        inverse = np.linalg.inv(factor @ np.conj(np.swapaxes(factor, 1, 2)))   # S_r⁻¹

        def reduced(derivative):
            return _mask_identity(self.project(derivative), self.keep, 0.0)

        def whiten(matrices):
            half = np.linalg.solve(factor, matrices)
            return np.linalg.solve(factor, np.conj(np.swapaxes(half, 1, 2)))

        derivatives = [reduced(gradient[..., i]) for i in range(gradient.shape[-1])]
        # H from the whitened derivatives C⁻¹ ∂S C⁻ᴴ: tr(S⁻¹∂_pS S⁻¹∂_qS) = c(W_p)·c(W_q).
        whitened = np.stack([_components(whiten(d)) for d in derivatives], axis=-1)
        hessian = np.einsum("k,ckp,ckq->pq", self.scale, whitened, whitened)
        # A_k on the kept directions, taken back to the outputs' coordinates: U A Uᴴ.
        scores = [-self.scale[:, np.newaxis, np.newaxis] * (inverse @ d @ inverse)
                  for d in derivatives]
        adjoint = np.conj(np.swapaxes(self.basis, 1, 2))
        full = np.moveaxis(model, -1, 0)
        ridge = 1e-10 * np.trace(full, axis1=1, axis2=2).real / full.shape[-1]
        smooth = np.linalg.cholesky(full + ridge[:, np.newaxis, np.newaxis] * np.eye(full.shape[-1]))
        q = np.stack([_components(np.conj(np.swapaxes(smooth, 1, 2)) @ self.basis @ a @ adjoint
                                  @ smooth) for a in scores], axis=-1)           # (p², K, P)
        spread = np.broadcast_to(np.sqrt(dispersion), q.shape[:2])
        variance = score_variance(q, spread, degrees_of_freedom, correlation, coherent=False)
        shift = None
        if occupancy is not None:
            # A crowd larger than its mean moves every matrix along ∂S/∂ln n: the score moves
            # by Σ_k tr(A_k ∂S_k/∂ln n) (docs: theory, Sandwich covariance).
            derivative, relative_variance = occupancy
            along = reduced(derivative)
            shift = np.array([np.einsum("kij,kji->", a, along).real for a in scores])
            variance = variance + relative_variance * np.outer(shift, shift)
        return variance, hessian, shift
