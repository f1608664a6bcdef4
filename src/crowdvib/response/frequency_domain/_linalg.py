"""Small dense linear algebra for the spectral model: compiled solves (numba) and eigen-decompositions
updated by perturbation.

The occupied dynamic stiffness D(ω) = diag(k − ω²m + iωc) − Σ_s ω² M_app,s(ω) Ψ_s (a smeared
crowd of MSDs and any tuned mass dampers, each with its own influence matrix) changes with every
frequency, so a PSD on 6000 frequencies needs 6000 small complex solves. numpy's batched
``linalg.solve`` spends most of its time per call on overhead for 10–20-mode models; a plain
Gaussian elimination compiled with numba does the same work several times faster.

The pole–residue form needs the eigen-decomposition of the occupied state matrix at every MSD
the optimiser tries; its finite-difference Jacobian moves f_h1 and ξ_h1 by ~1e-8, and a
first-order update of the decomposition at the column's base point is then as accurate as a
new one at a third of its cost on a 14-mode bridge (:func:`eigen_decomposition`; issue 39).
"""

import numpy as np
from numba import njit


@njit(cache=True)
def solve_occupied(diagonal, added, psi, rhs):
    """Solve [diag(diagonal[f]) − Σ_s added[f, s]·Ψ_gs] X[g, f] = rhs for every frequency f and
    every group g of influence matrices (the occupancy nodes of a mixture: one structure and
    MSD, so the same ``diagonal`` and ``added``, and their own Ψ).

    Parameters
    ----------
    diagonal : complex ndarray, shape (n_f, n)
    added : complex ndarray, shape (n_f, n_s)
    psi : float ndarray, shape (n_g, n_s, n, n)
    rhs : float ndarray, shape (n, k)

    Returns
    -------
    complex ndarray, shape (n_g, n_f, n, k)
    """
    n_f, n = diagonal.shape
    n_g, n_s = psi.shape[0], psi.shape[1]
    k = rhs.shape[1]
    out = np.empty((n_g, n_f, n, k), dtype=np.complex128)
    a = np.empty((n, n), dtype=np.complex128)
    b = np.empty((n, k), dtype=np.complex128)
    for g in range(n_g):
        for f in range(n_f):
            for i in range(n):
                for j in range(n):
                    total = 0j
                    for s in range(n_s):
                        total -= added[f, s] * psi[g, s, i, j]
                    a[i, j] = total
                a[i, i] += diagonal[f, i]
                for c in range(k):
                    b[i, c] = rhs[i, c]
            # Gaussian elimination with partial pivoting.
            for col in range(n):
                pivot = col
                # |Re| + |Im| ranks pivots as well as |z| without a square root.
                best = abs(a[col, col].real) + abs(a[col, col].imag)
                for row in range(col + 1, n):
                    size = abs(a[row, col].real) + abs(a[row, col].imag)
                    if size > best:
                        best, pivot = size, row
                if pivot != col:
                    for j in range(n):
                        swap = a[col, j]
                        a[col, j] = a[pivot, j]
                        a[pivot, j] = swap
                    for c in range(k):
                        swap = b[col, c]
                        b[col, c] = b[pivot, c]
                        b[pivot, c] = swap
                inverse = 1.0 / a[col, col]
                for row in range(col + 1, n):
                    factor = a[row, col] * inverse
                    for j in range(col + 1, n):
                        a[row, j] -= factor * a[col, j]
                    for c in range(k):
                        b[row, c] -= factor * b[col, c]
            for row in range(n - 1, -1, -1):
                for c in range(k):
                    total = b[row, c]
                    for j in range(row + 1, n):
                        total -= a[row, j] * out[g, f, j, c]
                    out[g, f, row, c] = total / a[row, row]
    return out


#: State matrices of at least this many entries (all of a stack together) get their
#: eigen-decomposition by perturbation from a nearby one when they can
#: (:func:`eigen_decomposition`); below it numpy's eig costs no more than the perturbation's
#: products (a one-mode bridge's 4 × 4: 40 µs against 95 µs).
PERTURBED_ENTRIES = 256
#: A state matrix within this relative distance (Frobenius) of a kept one is a perturbation of
#: it: a finite-difference column of the optimiser's Jacobian (a relative step of ~1.5e-8 in
#: f_h1 or ξ_h1).
_NEARBY = 1e-6
#: The first-order update is taken when its rotation C (below) is this small (Frobenius). The
#: Jacobian's columns on the Eeklo-like bridge (14 modes, three occupancy nodes, f_h1 2–5 Hz,
#: ξ_h1 0.05–0.6) have ‖C‖ = 1e-7 to 3e-6, and their expansions lie 2e-14 to 2e-13 (relative)
#: from those of a new eig, its own rounding; near ξ_h1 = 1 the MSD's two poles meet, ‖C‖
#: reaches 4e-5 to 2e-4 and the update errs by 3e-11 to 2e-9: such a matrix is decomposed afresh.
_ROTATION = 3e-6
#: Decompositions kept per model family: each is the stack of a mixture's occupancy nodes at
#: one θ (spectral._pole_terms), or one model's alone.
_KEPT = 8


def eigen_decomposition(state, kept=None, rows=slice(None), columns=slice(None)):
    """(λ, V[rows], V⁻¹[:, columns]) of a real state matrix A, or of a stack of them (…, n, n),
    V's columns the eigenvectors (numpy's eig).

    ``kept``: a list of recent (A, ‖A‖, λ, V, V⁻¹) computed by eig, shared by the caller's
    models.
    A state within _NEARBY of one of them (each matrix of a stack), A + ΔA, is decomposed by
    first-order perturbation of a non-defective matrix (Golub & Van Loan, Matrix Computations,
    §7.2, the rows of V⁻¹ its left eigenvectors): G = V⁻¹ ΔA V, λ' = λ + diag G,
    V' = V (I + C), V'⁻¹ = (I − C) V⁻¹ with C_qp = G_qp / (λ_p − λ_q) (q ≠ p), taken when
    every ‖C‖ ≤ _ROTATION; otherwise by eig (and kept). Only the rows and columns asked for
    are formed.
    Raises numpy.linalg.LinAlgError when V is singular.
    """
    kept = kept if state.size >= PERTURBED_ENTRIES else None
    if kept is not None:
        scale = np.linalg.norm(state, axis=(-2, -1))
        for base, size, poles, vectors, inverse in reversed(kept):      # the newest first
            # |‖A‖ − ‖B‖| ≤ ‖A − B‖: a kept matrix of another norm is not near (no difference
            # formed for it: an estimate's other MSDs differ by far more than _NEARBY)
            if base.shape != state.shape or np.any(np.abs(size - scale) > _NEARBY * scale):
                continue
            change = state - base
            if np.all(np.linalg.norm(change, axis=(-2, -1)) <= _NEARBY * scale):
                update = _perturbed(change, poles, vectors, inverse, rows, columns)
                if update is not None:
                    return update
                break
    poles, vectors = np.linalg.eig(state)
    inverse = np.linalg.inv(vectors)
    if kept is not None:
        if len(kept) >= _KEPT:
            kept.pop(0)                                   # the oldest
        kept.append((state, scale, poles, vectors, inverse))
    return poles, vectors[..., rows, :], inverse[..., :, columns]


def _perturbed(change, poles, vectors, inverse, rows, columns):
    """The first-order update of (λ, V[rows], V⁻¹[:, columns]) for A + ΔA, or None when its
    rotation is too large for the first order to hold."""
    others = tuple(axis for axis in range(change.ndim) if axis != change.ndim - 2)
    changed = np.flatnonzero(np.any(change != 0.0, axis=others))   # the rows ΔA moves
    moved = change[..., changed, :] @ vectors                      # real @ complex
    mixed = inverse[..., :, changed] @ moved
    diagonal = np.arange(poles.shape[-1])
    gaps = poles[..., np.newaxis, :] - poles[..., :, np.newaxis]
    gaps[..., diagonal, diagonal] = 1.0
    rotation = mixed / gaps
    rotation[..., diagonal, diagonal] = 0.0
    if not np.all(np.linalg.norm(rotation, axis=(-2, -1)) <= _ROTATION):
        return None
    part, inverse_part = vectors[..., rows, :], inverse[..., :, columns]
    return (poles + mixed[..., diagonal, diagonal], part + part @ rotation,
            inverse_part - rotation @ inverse_part)
