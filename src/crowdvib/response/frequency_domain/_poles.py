"""The occupied structure's pole–residue form, and the direct solves that check it (docs: theory,
The smeared crowd and the occupied bridge).

Φ_o H(ω) B = Σ_p left_p right_p / (iω − λ_p) from one small eigen-decomposition of the reduced
model's state matrix per MSD, checked against a direct solve of the occupied dynamic stiffness
at a few frequencies. Everything here takes a crowd whose B carries leading axes, a stack of
crowds that differ in density only (the occupancy nodes of a mixture at one MSD,
:class:`._attached.Attached`): the nodes' expansions then come from one stacked computation
(one reduced model, state matrix, eigen-decomposition and check for all of them), which costs
little more than one node's (numpy's overhead per call dominates these small matrices).
"""

import numpy as np

from ._attached import reduced_matrices
from ._linalg import eigen_decomposition, solve_occupied


def _dynamic_stiffness_diagonal(structure, omega):
    """k_j − ω² m_j + iω c_j of the empty structure, shape (n_f, n_modes)."""
    wn = 2 * np.pi * structure.frequencies
    m = structure.modal_masses
    return (m * wn**2)[np.newaxis] - omega[:, np.newaxis] ** 2 * m + \
        1j * omega[:, np.newaxis] * (2 * structure.damping_ratios * m * wn)


def _occupied_solve(diagonal, attached, frequency, rhs):
    """Solve [diag(D0) − Σ_s ω² M_app,s Ψ_s] X = rhs at every frequency; rhs (n_modes, k)
    → X (…, n_f, n_modes, k), the leading axes those of a stack of crowds."""
    added = np.stack([part.added_stiffness(frequency) for part in attached], axis=-1)
    psi = np.stack(np.broadcast_arrays(*(part.influence for part in attached)), axis=-3)
    if diagonal.shape[1] == 1:
        occupied = diagonal[:, 0] - (psi[..., np.newaxis, :, 0, 0] * added).sum(axis=-1)
        return rhs / occupied[..., np.newaxis, np.newaxis]
    stack = psi.shape[:-3]
    solved = solve_occupied(np.ascontiguousarray(diagonal), np.ascontiguousarray(added),
                            np.ascontiguousarray(psi.reshape((-1,) + psi.shape[-3:])),
                            np.ascontiguousarray(rhs, dtype=float))
    return solved.reshape(stack + solved.shape[1:])


def _direct_projection(diagonal, attached, frequency, shapes, factor):
    """Φ_o H B by one solve per frequency; D is complex symmetric, so Φ_o H = solve(D, Φ_oᵀ)ᵀ."""
    solved = _occupied_solve(diagonal, attached, frequency, shapes.T)
    return np.swapaxes(solved, -1, -2) @ factor[..., np.newaxis, :, :]


def _state_matrix(mass, damping, stiffness):
    """The first-order form's A and M⁻¹ of (M, C, K), or of stacks of them (…, n, n)."""
    size = mass.shape[-1]
    inverse_mass = np.linalg.inv(mass)
    # set block by block (np.block's checks cost more than the matrix here)
    state = np.zeros(mass.shape[:-2] + (2 * size, 2 * size))
    state[..., :size, size:] = np.eye(size)
    state[..., size:, :size] = -inverse_mass @ stiffness
    state[..., size:, size:] = -inverse_mass @ damping
    return state, inverse_mass


# The modal expansion is checked against a direct solve at a few frequencies; beyond this
# relative mismatch (a nearly defective state matrix) the direct solve is used instead.
_MODAL_CHECK_TOLERANCE = 1e-7


def probe(structure, frequency):
    """The frequencies at which :func:`_pole_residue` checks an expansion (five spread over
    ``frequency``) and the empty structure's dynamic stiffness there: a model keeps them."""
    chosen = frequency[np.unique(np.linspace(0, frequency.size - 1, 5).astype(int))]
    return chosen, _dynamic_stiffness_diagonal(structure, 2 * np.pi * chosen)


def _expanded(resolvent, left, right):
    """Σ_p left[o,p] right[p,r] resolvent[f,p] → (…, n_f, n_outputs, rank), one output at a time
    (a product over all of them at once would hold n_f × n_outputs × 2N numbers)."""
    return np.stack([(resolvent * left[..., np.newaxis, row, :]) @ right
                     for row in range(left.shape[-2])], axis=-2)


def _pole_residue(structure, attached, factor, shapes, checked_at, kept=None):
    """(poles λ (…, 2N), left (…, n_out, 2N), right (…, 2N, rank), reliable (…)) with
    Φ_o H(ω) B = Σ_p left_p right_p / (iω − λ_p), ``reliable`` False where the expansion misses
    a direct solve at the frequencies ``checked_at`` (:func:`probe`); None when an
    eigenvector matrix is singular. The leading axes are those of a stack of crowds
    (``factor`` and the crowd's B, :class:`._attached.Attached`), none for one crowd.

    With A = V Λ V⁻¹ the state matrix of (M_r, C_r, K_r), z(ω) = Σ_p V_zp (V⁻¹ F)_p / (iω − λ_p):
    one small eigen-decomposition per MSD model replaces one LU solve per frequency. ``kept``:
    recent decompositions to update by perturbation (:func:`._linalg.eigen_decomposition`).
    """
    mass, damping, stiffness = reduced_matrices(structure, attached)
    state, inverse_mass = _state_matrix(mass, damping, stiffness)
    size, n_modes = mass.shape[-1], structure.n_modes
    try:
        poles, vectors, inverse_vectors = eigen_decomposition(
            state, kept, rows=slice(None, n_modes), columns=slice(size, None))
    except np.linalg.LinAlgError:
        return None
    left = shapes @ vectors                                                 # (…, n_out, 2N)
    right = inverse_vectors @ inverse_mass[..., :, :n_modes] @ factor       # (…, 2N, rank)
    # without the crowd's MSDs (no HSI) the nodes share their poles: a stack by its load alone
    stack = right.shape[:-2]
    poles = np.broadcast_to(poles, stack + poles.shape[-1:])
    left = np.broadcast_to(left, stack + left.shape[-2:])
    frequency, diagonal = checked_at
    resolvent = 1.0 / (2j * np.pi * frequency[:, np.newaxis] - poles[..., np.newaxis, :])
    expanded = _expanded(resolvent, left, right)                   # (…, n_probe, n_out, rank)
    if attached:
        direct = _direct_projection(diagonal, attached, frequency, shapes, factor)
    else:
        direct = (shapes[np.newaxis] / diagonal[:, np.newaxis, :]) @ factor[..., np.newaxis, :, :]
    direct = np.broadcast_to(direct, expanded.shape)
    scale = np.abs(direct).max(axis=(-3, -2, -1), initial=0.0)
    mismatch = np.abs(expanded - direct).max(axis=(-3, -2, -1), initial=0.0)
    return poles, left, right, ~((scale > 0) & (mismatch > _MODAL_CHECK_TOLERANCE * scale))


def _modal_projection(structure, attached, factor, shapes, frequency):
    """Φ_o H(ω) B by complex modal superposition of the reduced model, or None if unreliable."""
    expansion = _pole_residue(structure, attached, factor, shapes, probe(structure, frequency))
    if expansion is None or not expansion[3]:
        return None
    poles, left, right, _ = expansion
    resolvent = 1.0 / (2j * np.pi * frequency[:, np.newaxis] - poles)   # (n_f, 2N)
    return _expanded(resolvent, left, right)
