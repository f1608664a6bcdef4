"""Mass-spring-dampers attached to the modes: the crowd's MSDs and tuned mass dampers.

Both are sprung masses coupled to the structural modes through an influence matrix Ψ = B Bᵀ
(docs: theory, The smeared crowd and the occupied bridge): the smeared crowd through the crowd-influence matrix, a damper through its
mode-shape row (Ψ = φ_d φ_dᵀ). One representation, :class:`Attached`, serves the
frequency-domain solve (apparent masses, §3.1) and the reduced eigen-model (§2.7) of
:mod:`.spectral`, so the algebra is written once for both.
"""

from dataclasses import dataclass

import numpy as np

from ...models.damper import as_dampers
from ...models.pedestrian import transmissibility


@dataclass(frozen=True, eq=False)
class Attached:
    """Identical mass-spring-dampers coupled to the modes through Ψ = B Bᵀ (docs: theory, The smeared crowd and the occupied bridge).

    The smeared crowd (per unit of Ψ: unsprung m_h0, sprung m_h1 on k_h1, c_h1; B from Ψ's
    eigen-decomposition) and a tuned mass damper (no unsprung mass; B = φ_d, its mode-shape row)
    are the same object, so the frequency-domain solve and the reduced eigen-model below are
    written once for both.
    """

    unsprung_mass: float       # [kg] per unit of Ψ
    sprung_mass: float         # [kg]
    frequency: float           # [Hz] of the sprung mass on a fixed base
    damping_ratio: float       # [-]
    stiffness: float           # [N/m], from the model's own method
    damping: float             # [N·s/m], likewise
    factor: np.ndarray         # B, shape (n_modes, rank), or (…, n_modes, rank): see below

    # A crowd's B may carry leading axes, a stack of crowds that differ in density only (the
    # occupancy nodes of a mixture at one MSD): Ψ and the reduced matrices then carry them too,
    # and one stacked computation serves every node (spectral._pole_terms).

    @property
    def influence(self):
        return self.factor @ self.factor.swapaxes(-1, -2)

    def added_stiffness(self, frequency):
        """ω² M_app(ω) [kg/s²]: multiply by Ψ to get the dynamic stiffness it removes."""
        apparent = self.unsprung_mass + self.sprung_mass * transmissibility(
            np.asarray(frequency) / self.frequency, self.damping_ratio)
        return (2 * np.pi * frequency) ** 2 * apparent


def crowd_attachment(crowd, msd, factor):
    """The smeared crowd of MSDs as an :class:`Attached`, or None (no HSI or empty deck).
    ``factor``: B with Ψ = B Bᵀ (:func:`psd_factor`), which a model keeps for every MSD."""
    if msd is None or crowd is None or crowd.density == 0:
        return None
    body = crowd.body_mass
    sprung = msd.sprung_mass(body)
    return Attached(body - sprung, sprung, msd.frequency, msd.damping_ratio,
                     msd.stiffness(body), msd.damping(body), factor)


def damper_attachments(structure, dampers):
    """Each tuned mass damper as an :class:`Attached` on its mode-shape row."""
    return tuple(Attached(0.0, damper.mass, damper.frequency, damper.damping_ratio,
                           damper.stiffness(), damper.damping(),
                           damper.shape_row(structure)[:, np.newaxis])
                 for damper in as_dampers(dampers))


def attachments(structure, crowd, msd, dampers):
    """Everything attached to the modes: the crowd's MSDs (if HSI) and the dampers."""
    factor = (None if msd is None or crowd is None
              else psd_factor(structure.influence_matrix(crowd.density)))
    crowd_part = crowd_attachment(crowd, msd, factor)
    return ((crowd_part,) if crowd_part is not None else ()) + \
        damper_attachments(structure, dampers)


def psd_factor(psi):
    """B with Ψ = B Bᵀ (B: n_modes × rank), from the eigen-decomposition of the PSD matrix Ψ."""
    if psi.shape == (1, 1):     # one mode: what eigh gives, without its overhead
        return np.sqrt(psi) if psi[0, 0] > 0 else np.zeros((1, 0))
    values, vectors = np.linalg.eigh(psi)
    keep = values > values.max(initial=0.0) * 1e-12
    return vectors[:, keep] * np.sqrt(values[keep])


def reduced_matrices(structure, attached):
    """Mass, damping and stiffness of the structure with its attached MSDs (docs: theory, The smeared crowd and the occupied bridge).

    Coordinates: structural modes z (n_modes), then for each attachment its coordinates η
    (rank of Ψ = B Bᵀ; 1 for a damper): M_r = diag(M_s + Σ m_0 Ψ, m_1 I, …),
    K_r = [[K_s + Σ k_1 Ψ, −k_1 B, …], [−k_1 Bᵀ, k_1 I, …], …], C_r alike. Eliminating η at
    frequency ω gives back D(ω) = K_s − ω²(M_s + Σ M_app Ψ) + iωC_s (§3.1). A stack of B
    (:class:`Attached`) gives a stack of matrices, (…, size, size) each.
    """
    n_modes = structure.n_modes
    size = n_modes + sum(part.factor.shape[-1] for part in attached)
    # the axes of a stack of B (only a crowd's has them) ahead of the three matrices'
    stack = max((part.factor.shape[:-2] for part in attached), key=len, default=())
    wn = 2 * np.pi * structure.frequencies
    m = structure.modal_masses
    # mass, damping and stiffness as one array (…, 3, size, size): each block is set for the
    # three at once
    matrices = np.zeros(stack + (3, size, size))
    modes = np.arange(n_modes)
    matrices[..., modes, modes] = (m, 2 * structure.damping_ratios * m * wn, m * wn**2)
    start = n_modes
    for part in attached:
        rank = part.factor.shape[-1]
        block, own = slice(start, start + rank), np.arange(start, start + rank)
        influence, factor = part.influence, part.factor
        if stack:       # (3, 1, 1) against (…, 1, n_modes, n_modes)
            influence, factor = influence[..., np.newaxis, :, :], factor[..., np.newaxis, :, :]
        coupling = np.array([0.0, -part.damping, -part.stiffness])[:, np.newaxis, np.newaxis]
        matrices[..., :n_modes, :n_modes] += (np.array([part.unsprung_mass, part.damping,
                                                        part.stiffness])[:, np.newaxis, np.newaxis]
                                              * influence)
        matrices[..., own, own] = np.array([part.sprung_mass, part.damping,
                                            part.stiffness])[:, np.newaxis]
        matrices[..., :n_modes, block] = coupling * factor
        matrices[..., block, :n_modes] = coupling * factor.swapaxes(-1, -2)
        start = block.stop
    return matrices[..., 0, :, :], matrices[..., 1, :, :], matrices[..., 2, :, :]
