"""The expected PSD of a fluctuating crowd (docs: theory, The fluctuating crowd).

The smeared model puts the mean crowd on the deck for ever. A Poisson stream is not the mean
crowd: the number and the positions of the walkers change on the time scale of a crossing, and
with them the crowd influence ψ(t) = Σ_k φ²(x_k(t)) that sets both the walkers' load and the mass
they add. A record of an hour averages over these states. When ψ changes slowly against the
memory of the occupied mode, the expected PSD is the mixture

    E[G(f)] = E_λ[ G(f; λ Ψ̄) ],   λ = ψ/ψ̄,

of smeared-crowd PSDs, each with the crowd scaled by λ (load and added mass together). λ is a
compound-Poisson variable whose cumulants follow from the mode shape (Campbell's theorem):
κ_r(ψ) = d ∫ φ^{2r} dA. :class:`FluctuatingSpectralModel` evaluates the mixture with a Gauss
quadrature built from these moments: a handful of :class:`~crowdvib.response.SpectralModel`
instances, each used as a black box.
"""

from math import comb

import numpy as np

from .._validation import check_type
from ..errors import ParameterError
from ..models.crowd import Crowd
from ..models.loading import as_force_model
from ..models.structure import ModalModel
from ..signals import ResponsePSD
from .spectral import SpectralModel

__all__ = ["FluctuatingSpectralModel", "occupancy_quadrature", "occupancy_cumulants",
           "CROWD_MODELS"]

#: Expected-PSD models of the crowd: the mean crowd, or the mixture over its occupancy.
CROWD_MODELS = ("smeared", "fluctuating")
#: Quadrature nodes: 3 integrate polynomials of degree 5 in λ exactly, enough for a relative
#: occupancy spread up to ~30 % (docs: theory, The fluctuating crowd).
DEFAULT_NODES = 3


def dominant_mode(structure, crowd, frequency, force=None, outputs=None):
    """Index of the mode with the largest resonant response at the outputs within ``frequency``.

    Peak of mode j alone without HSI, Σ_o φ_oj² Ψ_jj s(f_j) / (4 ξ_j² m_j²) (acceleration PSD at
    resonance), over the modes whose natural frequency lies in the grid (all modes if none does).
    """
    force = as_force_model(force)
    names = structure.output_names if outputs is None else outputs
    shapes = structure.output_shapes[structure.output_index(names)]
    psi = np.diag(structure.influence_matrix(crowd.density))
    peak = ((shapes**2).sum(axis=0) * psi * force.load_spectrum(structure.frequencies, crowd)
            / (4 * structure.damping_ratios**2 * structure.modal_masses**2))
    inside = (structure.frequencies >= frequency[0]) & (structure.frequencies <= frequency[-1])
    if inside.any():
        peak = np.where(inside, peak, -np.inf)
    return int(np.argmax(peak))


def occupancy_cumulants(structure, density, mode, order=6):
    """Cumulants κ_1 … κ_order of λ = ψ_jj/E[ψ_jj] for a Poisson crowd of ``density`` [-].

    A Poisson field of walkers of intensity d gives ψ = Σ_k φ_j²(x_k) the cumulants
    κ_r(ψ) = d ∫_A φ_j^{2r} dA (Campbell); dividing by the mean ψ̄ = d ∫ φ_j² dA scales κ_r by ψ̄^{-r}.
    Same trapezoidal quadrature as :meth:`ModalModel.influence_matrix`.
    """
    weights = structure._area_weights
    square = structure.mode_shapes[..., mode] ** 2
    mean = density * np.sum(weights * square)
    if not mean > 0:
        raise ParameterError(f"mode {mode} carries no crowd (∫φ² dA = 0 or density 0): the "
                             "occupancy of the walkway does not reach it")
    return np.array([density * np.sum(weights * square**r) / mean**r
                     for r in range(1, order + 1)])


def _moments(cumulants):
    """Raw moments m_0 … m_n from cumulants κ_1 … κ_n (m_n = Σ C(n−1, k−1) κ_k m_{n−k})."""
    moments = [1.0]
    for n in range(1, cumulants.size + 1):
        moments.append(sum(comb(n - 1, k - 1) * cumulants[k - 1] * moments[n - k]
                           for k in range(1, n + 1)))
    return np.array(moments)


def _gauss_rule(moments, n_nodes):
    """Nodes and weights of the n-point Gauss rule of a law with raw moments m_0 … m_2n.

    Golub & Welsch (1969): the Cholesky factor R of the Hankel matrix [m_{i+j}] gives the
    three-term recurrence, whose Jacobi matrix has the nodes as eigenvalues and the squared first
    components of its eigenvectors as weights.
    """
    hankel = np.array([[moments[i + j] for j in range(n_nodes + 1)] for i in range(n_nodes + 1)])
    try:
        upper = np.linalg.cholesky(hankel).T
    except np.linalg.LinAlgError:
        raise ParameterError(f"n_nodes = {n_nodes} is too many for the occupancy law of this "
                             "crowd (its moment matrix is singular); use fewer nodes")
    diagonal = [upper[j, j + 1] / upper[j, j] - (upper[j - 1, j] / upper[j - 1, j - 1] if j else 0)
                for j in range(n_nodes)]
    off = [upper[j + 1, j + 1] / upper[j, j] for j in range(n_nodes - 1)]
    nodes, vectors = np.linalg.eigh(np.diag(diagonal) + np.diag(off, 1) + np.diag(off, -1))
    weights = vectors[0] ** 2
    return nodes, weights / weights.sum()


def occupancy_quadrature(structure, crowd, mode, n_nodes=DEFAULT_NODES, variance_factor=1.0):
    """Gauss nodes λ_i and weights w_i of the occupancy λ = ψ/ψ̄: E[g(λ)] ≈ Σ w_i g(λ_i).

    The quadrature of the compound-Poisson law of λ from its first 2n moments (Golub–Welsch on
    the standardised variable). ``variance_factor`` < 1 scales the spread (all cumulants of order
    r by its r/2 power), for an occupancy seen through the mode's memory.
    """
    if n_nodes == 1:
        return np.ones(1), np.ones(1)
    cumulants = occupancy_cumulants(structure, crowd.density, mode, order=2 * n_nodes)
    spread = np.sqrt(cumulants[1] * variance_factor)
    if not spread > 0:
        return np.ones(1), np.ones(1)
    # Standardised z = (λ − 1)/σ: κ_1 = 0, κ_r(z) = κ_r(λ) v^{r/2} / σ^r (v: variance factor).
    order = np.arange(1, cumulants.size + 1)
    standard = cumulants * variance_factor ** (order / 2) / spread**order
    standard[0] = 0.0
    nodes, weights = _gauss_rule(_moments(standard), n_nodes)
    return 1.0 + spread * nodes, weights


class FluctuatingSpectralModel:
    """Expected response PSD of a Poisson crowd whose occupancy fluctuates (quasi-static mixture).

    The drop-in counterpart of :class:`~crowdvib.response.SpectralModel` (same ``psd_array``,
    ``psd`` and attributes): the PSD is Σ_i w_i G(f; λ_i d), each term a smeared model with the
    crowd density scaled by the occupancy node λ_i (docs: theory, The fluctuating crowd).

    Parameters
    ----------
    structure, crowd, frequency, force, outputs, welch_window_length, lowpass, dampers
        As for :class:`~crowdvib.response.SpectralModel`.
    n_nodes : int
        Quadrature nodes (default 3; 1 gives the smeared model).
    mode : int, optional
        The mode whose occupancy is modelled (default the one with the largest resonant
        response at the outputs within ``frequency``); the whole influence matrix is scaled by
        its λ.
    """

    def __init__(self, structure, crowd, frequency, *, n_nodes=DEFAULT_NODES, mode=None,
                 **options):
        check_type("structure", structure, ModalModel)
        check_type("crowd", crowd, Crowd)
        if not isinstance(n_nodes, (int, np.integer)) or not 1 <= n_nodes <= 8:
            raise ParameterError(f"n_nodes must be an integer from 1 to 8, got {n_nodes!r}")
        base = SpectralModel(structure, crowd, frequency, **options)
        self.mode = (dominant_mode(structure, crowd, base.frequency, options.get("force"),
                                   base.output_names) if mode is None else int(mode))
        if crowd.density > 0 and n_nodes > 1:
            self.nodes, self.weights = occupancy_quadrature(structure, crowd, self.mode, n_nodes)
        else:
            self.nodes, self.weights = np.ones(1), np.ones(1)
        self._models = [base if node == 1.0 else
                        SpectralModel(structure, crowd.with_density(crowd.density * node),
                                      frequency, **options) for node in self.nodes]
        for name in ("structure", "crowd", "frequency", "force", "output_names",
                     "welch_window_length", "lowpass"):
            setattr(self, name, getattr(base, name))

    def psd_array(self, msd=None):
        """Expected PSD [(m/s²)²/Hz], shape (n_outputs, n_frequencies)."""
        total = self.weights[0] * self._models[0].psd_array(msd)
        for weight, model in zip(self.weights[1:], self._models[1:]):
            total += weight * model.psd_array(msd)
        return total

    def psd(self, msd=None):
        """Expected PSD at the outputs → :class:`ResponsePSD`."""
        return ResponsePSD(frequency=self.frequency, psd=self.psd_array(msd),
                           output_names=self.output_names,
                           window_length=self.welch_window_length, lowpass=self.lowpass,
                           source="model")


def spectral_model(structure, crowd, frequency, *, crowd_model="smeared", **options):
    """A :class:`SpectralModel` (``"smeared"``) or :class:`FluctuatingSpectralModel`."""
    if crowd_model not in CROWD_MODELS:
        raise ParameterError(f"crowd_model must be one of {list(CROWD_MODELS)}, got "
                             f"{crowd_model!r}")
    if crowd_model == "smeared":
        return SpectralModel(structure, crowd, frequency, **options)
    return FluctuatingSpectralModel(structure, crowd, frequency, **options)
