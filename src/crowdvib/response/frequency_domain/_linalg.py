"""Compiled small dense solves for the spectral model (numba).

The occupied dynamic stiffness D(ω) = diag(k − ω²m + iωc) − Σ_s ω² M_app,s(ω) Ψ_s (a smeared
crowd of MSDs and any tuned mass dampers, each with its own influence matrix) changes with every
frequency, so a PSD on 6000 frequencies needs 6000 small complex solves. numpy's batched
``linalg.solve`` spends most of its time per call on overhead for 10–20-mode models; a plain
Gaussian elimination compiled with numba does the same work several times faster.
"""

import numpy as np
from numba import njit


@njit(cache=True)
def solve_occupied(diagonal, added, psi, rhs):
    """Solve [diag(diagonal[f]) − Σ_s added[f, s]·Ψ_s] X[f] = rhs for every frequency f.

    Parameters
    ----------
    diagonal : complex ndarray, shape (n_f, n)
    added : complex ndarray, shape (n_f, n_s)
    psi : float ndarray, shape (n_s, n, n)
    rhs : float ndarray, shape (n, k)

    Returns
    -------
    complex ndarray, shape (n_f, n, k)
    """
    n_f, n = diagonal.shape
    n_s = psi.shape[0]
    k = rhs.shape[1]
    out = np.empty((n_f, n, k), dtype=np.complex128)
    a = np.empty((n, n), dtype=np.complex128)
    b = np.empty((n, k), dtype=np.complex128)
    for f in range(n_f):
        for i in range(n):
            for j in range(n):
                total = 0j
                for s in range(n_s):
                    total -= added[f, s] * psi[s, i, j]
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
                    total -= a[row, j] * out[f, j, c]
                out[f, row, c] = total / a[row, row]
    return out
