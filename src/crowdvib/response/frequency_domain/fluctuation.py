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
quadrature of that law: a handful of :class:`~crowdvib.response.SpectralModel`
instances, each used as a black box (at a new MSD their poles are computed as one stack,
``spectral.expected_psds``). Their load spectrum is smoothed by the kernel of a walker's
finite crossing of the occupied mode (``_crossing.py``; docs: theory, Finite crossings).
"""

from __future__ import annotations

import copy
import dataclasses
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from ..._estimators import DEFAULT_CROWD_MODEL
from ..._validation import check_type
from ...errors import ParameterError
from ...models.crowd import Crowd
from ...models.loading import as_force_model
from ...models.pedestrian import MSDModel
from ...models.structure import ModalModel
from ...signals import ResponsePSD
from ._crossing import crossing_spread
from ._modulation import (OccupancyPath, drift_parameters, modulation_correction,
                          occupancy_rate_variance)
from .expected import model_psd
from .spectral import SpectralModel, _check_models, expected_psds

if TYPE_CHECKING:
    from ..._validation import ForceModel
    from ...models.damper import TunedMassDamper
    from ...signals.welch import LowPassFilter

__all__ = ["FluctuatingSpectralModel", "occupancy_quadrature", "occupancy_cumulants",
           "occupancy_law", "dominant_mode", "spectral_model", "CROWD_MODELS", "response_psd"]

#: Expected-PSD models of the crowd: the mean crowd, or the mixture over its occupancy.
CROWD_MODELS = ("smeared", "fluctuating")
#: Reference MSD for choosing the number of nodes (the paper's values): the mixture must be
#: resolved for a plausible crowd, whatever θ the estimator later tries.
_REFERENCE_MSD = MSDModel()
#: The drift correction is applied by default up to this κ (the occupied resonance's shift over
#: one standard deviation of the occupancy, in half-power half-widths): checked against the
#: simulator at κ = 0.40–0.42 (four densities and speeds on the paper's bridge, a 20 m bridge
#: with 48 light walkers), it overshoots at κ = 0.69–1.96 where the mixture alone holds
#: (docs: theory, Beyond the quasi-static mixture).
_SPREAD_LIMIT = 0.5
#: Corrections per unit load kept, by MSD (the memory is emptied when full).
_DRIFT_MEMORY = 64


def dominant_mode(structure: ModalModel, crowd: Crowd, frequency: np.ndarray, force=None,
                  outputs: Sequence[str] | None = None) -> int:
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


def occupancy_cumulants(structure: ModalModel, density: float, mode: int,
                        order: int = 6) -> np.ndarray:
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


#: Points of the discretised occupancy law (its characteristic function is inverted by FFT).
_LAW_POINTS = 4096
#: Node counts tried, and the change of the mixture (over its peak) below which a rule counts
#: as converged: the next rule moves the expected PSD by less than this.
_NODE_COUNTS = (3, 5, 7, 9, 13, 17, 25)
_NODE_TOLERANCE = 5e-3


def occupancy_law(structure: ModalModel, density: float,
                  mode: int) -> tuple[np.ndarray, np.ndarray]:
    """The law of λ = ψ_jj/E[ψ_jj] on a grid → (λ values, probabilities).

    Its characteristic function is exact for a Poisson field of walkers,
    E[e^{itψ}] = exp(d ∫_A (e^{itφ_j²} − 1) dA) (Campbell), with the area quadrature of
    :meth:`ModalModel.influence_matrix`; the FFT turns it into probabilities on an even grid
    reaching 15 standard deviations above the mean.

    It depends on the density, the area weights and the mode's shape only, not on the modal
    frequencies, damping or masses: the laws last computed are kept under those (a study's
    error cases and an estimate's objectives ask for the same law again; issue 39); each call
    returns copies.
    """
    key = (float(density), structure._area_weights.shape, structure._area_weights.tobytes(),
           structure.mode_shapes[..., mode].tobytes())
    if key not in _LAWS:
        if len(_LAWS) >= _LAW_MEMORY:
            _LAWS.pop(next(iter(_LAWS)))                       # the oldest
        values, probability = _occupancy_law(structure, density, mode)
        values.flags.writeable = probability.flags.writeable = False
        _LAWS[key] = (values, probability)
    return tuple(array.copy() for array in _LAWS[key])


#: Occupancy laws kept (occupancy_law): (density, area weights, mode shape) → (λ, p).
_LAWS: dict = {}
_LAW_MEMORY = 16


def _occupancy_law(structure, density, mode):
    """:func:`occupancy_law`, computed."""
    cumulants = occupancy_cumulants(structure, density, mode, order=2)
    area = density * structure._area_weights.ravel()
    share = (structure.mode_shapes[..., mode] ** 2).ravel()
    share = share / np.sum(area * share)            # each walker's λ contribution
    top = 1.0 + 15.0 * np.sqrt(cumulants[1]) + share.max()
    step = top / _LAW_POINTS
    # The exponent at the FFT's t_k = k Δt: ψ is real, so the exponent at −t is the conjugate
    # of that at t, and only k = 0 … n/2 are computed. With k = j + m b (m ≈ √(n/2)),
    # e^{i k Δt s} = e^{i j Δt s} e^{i m b Δt s}: 2√(n/2) exponentials per walker position
    # and one sum of products instead of n/2 exponentials (issue 39: 23 → 2.3 ms per law), to
    # a few units of round-off. einsum, not a matrix product: BLAS rounds a product of this
    # size differently with its thread count, and a study's tasks must give the same bits in
    # every process (a dask worker runs one thread).
    half = _LAW_POINTS // 2
    block = int(np.ceil(np.sqrt(half + 1)))
    rate = 2 * np.pi / (_LAW_POINTS * step)
    within = np.exp(1j * rate * np.outer(np.arange(block), share))
    across = np.exp(1j * rate * block * np.outer(np.arange(block), share))
    sums = np.einsum("ja,ba->bj", within, area * across).ravel()[:half + 1] - area.sum()
    exponent = np.concatenate([sums[:half], sums[half:].conj(), sums[half - 1:0:-1].conj()])
    probability = np.maximum(np.fft.fft(np.exp(exponent)).real / _LAW_POINTS, 0.0)
    return step * np.arange(_LAW_POINTS), probability / probability.sum()


def _gauss_rule(values: np.ndarray, probabilities: np.ndarray,
                n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """n-point Gauss rule of a discrete law: nodes and weights (E[g] ≈ Σ w_i g(x_i)).

    Lanczos on diag(x) from the vector √p (with full reorthogonalisation) gives the Jacobi matrix
    of the law's orthogonal polynomials; its eigenvalues are the nodes and the squared first
    components of its eigenvectors the weights (Golub & Welsch 1969). Unlike the moment route
    this stays accurate for many nodes.
    """
    basis = np.zeros((n_nodes, values.size))
    basis[0] = np.sqrt(probabilities)
    alpha, beta = np.zeros(n_nodes), np.zeros(max(n_nodes - 1, 0))
    for k in range(n_nodes):
        vector = values * basis[k]
        alpha[k] = vector @ basis[k]
        if k + 1 == n_nodes:
            break
        vector -= alpha[k] * basis[k] + (beta[k - 1] * basis[k - 1] if k else 0.0)
        vector -= basis[:k + 1].T @ (basis[:k + 1] @ vector)
        beta[k] = np.linalg.norm(vector)
        if not beta[k] > 1e-12:
            raise ParameterError(f"n_nodes = {n_nodes} is more than the occupancy law of this "
                                 "crowd supports; use fewer nodes")
        basis[k + 1] = vector / beta[k]
    nodes, vectors = np.linalg.eigh(np.diag(alpha) + np.diag(beta, 1) + np.diag(beta, -1))
    weights = vectors[0] ** 2
    return nodes, weights / weights.sum()


def occupancy_quadrature(structure: ModalModel, crowd: Crowd, mode: int,
                         n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss nodes λ_i and weights w_i of the occupancy λ = ψ/ψ̄: E[g(λ)] ≈ Σ w_i g(λ_i)."""
    if n_nodes == 1 or crowd.density == 0:
        return np.ones(1), np.ones(1)
    return _gauss_rule(*occupancy_law(structure, crowd.density, mode), n_nodes)


class FluctuatingSpectralModel:
    """Expected response PSD of a Poisson crowd whose occupancy fluctuates (quasi-static mixture).

    The drop-in counterpart of :class:`~crowdvib.response.SpectralModel` (same ``psd_array``,
    ``psd`` and attributes): the PSD is Σ_i w_i G(f; λ_i d), each term a smeared model with the
    crowd density scaled by the occupancy node λ_i (docs: theory, The fluctuating crowd).

    Parameters
    ----------
    structure, crowd, frequency
        As for :class:`~crowdvib.response.SpectralModel`.
    n_nodes : int, optional
        Quadrature nodes (1 gives the smeared model). Default: the fewest of 3, 5, 7, 9, 13, 17,
        25 whose mixture the next rule changes by less than 0.5 % of its peak, judged with the
        paper's MSD (3 Hz, 30 %, 0.95): 3 on the paper's example, more where the occupied
        frequency moves by more than the resonance width over the occupancy's spread.
    mode : int, optional
        The mode whose occupancy is modelled (default the one with the largest resonant
        response at the outputs within ``frequency``); the whole influence matrix is scaled by
        its λ.
    finite_crossing : bool, optional
        Smooth the load spectrum with that mode's crossing kernel (default True: walkers stay
        on the deck for a crossing only; docs: theory, Finite crossings).
    modulation : bool or None, optional
        The correction for an occupancy that moves within the occupied resonance's memory
        (docs: theory, Beyond the quasi-static mixture): the resonance drifts with the
        occupancy along its Gaussian path, to all orders in the rate. ``None`` (default)
        applies it where it has been checked against the simulator, κ ≤ 0.5 (see
        ``spread_parameter``; the paper's bridge has κ ≈ 0.4 at every density): beyond, on
        strongly coupled light bridges, it overshoots and the mixture alone is nearer the
        records. ``True`` applies it always, ``False`` never. Without HSI it vanishes.
    **options
        The keywords of :class:`~crowdvib.response.SpectralModel`: ``force``, ``outputs``,
        ``welch_window_length``, ``lowpass``, ``dampers``.

    Attributes
    ----------
    nodes, weights : ndarray
        The occupancy rule.
    crossing_spread : float
        σ_K [Hz] of the crossing kernel (0 without ``finite_crossing``).
    modulation_parameter : float
        ε = Var λ̇ / (Var λ Γ²) with the paper's MSD: the squared ratio of the occupied mode's
        memory to the occupancy's time scale (0 with ``modulation=False``).
    spread_parameter : float
        κ = σ_λ |Im p'| / Γ with the paper's MSD: how many half-power half-widths the occupied
        resonance moves over one standard deviation of the occupancy (0 with
        ``modulation=False``).
    rate_variance : float
        Var λ̇ [1/s²] of the occupancy (0 with ``modulation=False``).
    modulation : bool
        Whether the drift correction is applied.
    """

    def __init__(self, structure: ModalModel, crowd: Crowd, frequency: ArrayLike, *,
                 n_nodes: int | None = None, mode: int | None = None,
                 finite_crossing: bool = True, modulation: bool | None = None,
                 **options: Any) -> None:
        check_type("structure", structure, ModalModel)
        check_type("crowd", crowd, Crowd).check_stationary("FluctuatingSpectralModel")
        check_type("finite_crossing", finite_crossing, bool)
        if modulation is not None:
            check_type("modulation", modulation, bool)
        if n_nodes is not None and (not isinstance(n_nodes, (int, np.integer))
                                    or not 1 <= n_nodes <= 40):
            raise ParameterError(f"n_nodes must be an integer from 1 to 40, got {n_nodes!r}")
        if "crossing_spread" in options:
            raise ParameterError("crossing_spread is set from the mode shape here; use "
                                 "finite_crossing=False for the narrow-band load")
        base = SpectralModel(structure, crowd, frequency, **options)
        self.structure, self.crowd, self.frequency = base.structure, base.crowd, base.frequency
        self.force, self.output_names = base.force, base.output_names
        self.welch_window_length, self.lowpass = base.welch_window_length, base.lowpass
        self.mode = (dominant_mode(structure, crowd, base.frequency, options.get("force"),
                                   base.output_names) if mode is None else int(mode))
        self.crossing_spread = (crossing_spread(structure, crowd.walking_speed, self.mode)
                                if finite_crossing and crowd.density > 0 else 0.0)
        options = dict(options, crossing_spread=self.crossing_spread)
        self._base = SpectralModel(structure, crowd, frequency, **options)
        self.rate_variance = self.modulation_parameter = self.spread_parameter = 0.0
        self._path = None
        if modulation is not False and crowd.density > 0 and n_nodes != 1:
            path = OccupancyPath(
                structure, crowd.walking_speed, self.mode,
                variance=occupancy_cumulants(structure, crowd.density, self.mode, order=2)[1],
                rate_variance=occupancy_rate_variance(structure, crowd.density,
                                                      crowd.walking_speed, self.mode))
            self.rate_variance = path.rate_variance
            self.modulation_parameter, self.spread_parameter = drift_parameters(
                structure, self._base._attached(_REFERENCE_MSD), self.mode, path)
            if modulation or self.spread_parameter <= _SPREAD_LIMIT:
                self._path = path
        self.modulation = self._path is not None
        # The correction per unit load, by MSD: it does not depend on the step frequencies, so
        # the models of with_step_frequencies share it (a fit of μ_fs and σ_fs asks for the
        # same MSD again and again).
        self._drifts: dict = {}
        # The eigen-decompositions of its poles' tracks last computed (shared likewise): a
        # Jacobian's f_h1 and ξ_h1 columns update them (_linalg.eigen_decomposition).
        self._tracks: list = []
        if crowd.density == 0 or n_nodes == 1:
            self.nodes, self.weights, self._models = np.ones(1), np.ones(1), [self._base]
            return
        law = occupancy_law(structure, crowd.density, self.mode)

        weight = self._base._grid_weight                 # the same for every node: s(f) per ψ

        def rule(count):
            nodes, weights = _gauss_rule(*law, count)
            models = [self._base._for_crowd(crowd.with_density(crowd.density * node), weight)
                      for node in nodes]
            return nodes, weights, models

        if n_nodes is not None:
            self.nodes, self.weights, self._models = rule(n_nodes)
            return
        current = rule(_NODE_COUNTS[0])
        for count in _NODE_COUNTS[1:]:
            finer = rule(count)
            coarse = _mixture(current[1], current[2], _REFERENCE_MSD)
            fine = _mixture(finer[1], finer[2], _REFERENCE_MSD)
            if np.abs(coarse - fine).max() <= _NODE_TOLERANCE * fine.max():
                break
            current = finer
        self.nodes, self.weights, self._models = current

    def details(self) -> dict[str, Any]:
        """What this mixture is made of, for a report: occupied mode, occupancy nodes, crossing
        spread [Hz], whether the drift correction is applied, κ and ε."""
        return {"mode": self.mode, "occupancy_nodes": int(len(self.nodes)),
                "crossing_spread": float(self.crossing_spread),
                "drift_correction": bool(self.modulation),
                "spread_parameter": float(self.spread_parameter),
                "spread_limit": _SPREAD_LIMIT,
                "modulation_parameter": float(self.modulation_parameter)}

    def with_step_frequencies(self, crowd: Crowd) -> "FluctuatingSpectralModel":
        """The same mixture for a crowd that differs only in its step-frequency distribution.

        The occupancy law, hence the nodes and weights, depends on the density and the mode
        shape alone: it is kept, and only the smeared models are built again (an estimate that
        fits μ_fs and σ_fs builds hundreds of these).

        Parameters
        ----------
        crowd : Crowd
            The crowd with other step frequencies (same density, speed and body mass).
        """
        check_type("crowd", crowd, Crowd)
        # The occupancy law (density), its path (walking speed) and the drift correction per
        # unit load (body mass) are kept: nothing but the step frequencies may change.
        changed = [f"{field.name} {getattr(self.crowd, field.name)!r} → "
                   f"{getattr(crowd, field.name)!r}" for field in dataclasses.fields(Crowd)
                   if field.name not in ("step_frequency_mean", "step_frequency_std")
                   and getattr(crowd, field.name) != getattr(self.crowd, field.name)]
        if changed:
            raise ParameterError(f"crowd may differ from the model's in its step frequencies "
                                 f"only (the occupancy law and path are kept), got "
                                 f"{', '.join(changed)}")
        other = copy.copy(self)
        other.crowd = crowd
        other._base = self._base._for_crowd(crowd)
        weight = other._base._grid_weight           # the same for every node: s(f) per ψ
        other._models = [model._for_crowd(crowd._with_checked(density=model.crowd.density), weight)
                         for model in self._models]
        return other

    def psd_array(self, msd: MSDModel | None = None) -> np.ndarray:
        """Expected PSD [(m/s²)²/Hz], shape (n_outputs, n_frequencies).

        Parameters
        ----------
        msd : MSDModel, optional
            The pedestrians' MSD; None for the crowd as moving forces only (no HSI).
        """
        return _mixture(self.weights, self._models, msd) + self._modulation(msd, cross=False)

    def cross_psd_array(self, msd: MSDModel | None = None) -> np.ndarray:
        """Expected cross-spectral matrix, shape (n_outputs, n_outputs, n_frequencies): the
        same mixture Σ_i w_i S(f; λ_i d), each term linear in the occupancy state's record
        (docs: theory, The cross-spectral matrix).

        Parameters
        ----------
        msd : MSDModel, optional
            The pedestrians' MSD; None for the crowd as moving forces only (no HSI).
        """
        return _mixture(self.weights, self._models, msd, cross=True) + self._modulation(
            msd, cross=True)

    def _modulation(self, msd, cross):
        """The slow-modulation correction, as the Welch estimate sees it (0 without HSI, with
        one node or without ``modulation``)."""
        if msd is None or self._path is None:       # no HSI, no nodes or no correction
            return 0.0
        # On the base model's grid with its load weight (the Welch rule's, or the frequencies).
        welch = self._base._welch
        rule, grid = (None, self.frequency) if welch is None else (welch.rule, welch.grid)
        key = (msd, cross)
        if key not in self._drifts:
            if len(self._drifts) >= _DRIFT_MEMORY:
                self._drifts.clear()
            self._drifts[key] = modulation_correction(
                self.structure, self._base._attached(msd), self._base._shapes, self.mode,
                self.nodes, self.weights, self._path, grid, cross, self._tracks)
        delta = self._drifts[key] * self._base._grid_weight
        if rule is None:
            return delta
        if not cross:
            return rule.apply(delta)
        size = delta.shape[0]
        return rule.apply(delta.reshape(size * size, -1)).reshape(size, size, -1)

    def psd(self, msd: MSDModel | None = None) -> ResponsePSD:
        """Expected PSD at the outputs → :class:`ResponsePSD`.

        Parameters
        ----------
        msd : MSDModel, optional
            The pedestrians' MSD; None for the crowd as moving forces only (no HSI).
        """
        return model_psd(self, msd)


def _mixture(weights, models, msd, cross=False):
    """Σ_i w_i G_i(f; msd), or Σ_i w_i S_i(f; msd) with ``cross``."""
    # a new MSD's poles of the nodes together (one stacked computation: most of a node's cost
    # is numpy's overhead per call)
    terms = expected_psds(models, msd, cross)
    total = weights[0] * terms[0]
    for weight, term in zip(weights[1:], terms[1:]):
        total += weight * term
    return total


def spectral_model(structure: ModalModel, crowd: Crowd, frequency, *,
                   crowd_model: str = "smeared",
                   **options) -> SpectralModel | FluctuatingSpectralModel:
    """A :class:`SpectralModel` (``"smeared"``) or :class:`FluctuatingSpectralModel`."""
    if crowd_model not in CROWD_MODELS:
        raise ParameterError(f"crowd_model must be one of {list(CROWD_MODELS)}, got "
                             f"{crowd_model!r}")
    if crowd_model == "smeared":
        return SpectralModel(structure, crowd, frequency, **options)
    return FluctuatingSpectralModel(structure, crowd, frequency, **options)


def response_psd(structure: ModalModel, crowd: Crowd, frequency: ArrayLike, *,
                 msd: MSDModel | None = None, force: ForceModel | None = None,
                 outputs: str | Sequence[str] | None = None,
                 welch_window_length: float | None = None, lowpass: LowPassFilter | None = None,
                 dampers: Sequence[TunedMassDamper] | None = None,
                 crowd_model: str = DEFAULT_CROWD_MODEL) -> ResponsePSD:
    """One-sided acceleration PSD at the outputs of a crowd-loaded footbridge (docs: theory, Response PSD with HSI).

    G_ü(f) = ω⁴ Φ_o H(ω) G_QQ(f) H(ω)ᴴ Φ_oᵀ with the occupied receptance H (HSI, when ``msd`` is
    given) or the empty one (crowd as moving forces only, ``msd=None``): the smeared crowd's
    PSD, or by default its expectation over a Poisson crowd's fluctuating occupancy, the model
    the default estimator fits (``crowd_model``).

    Parameters
    ----------
    structure : ModalModel
        The empty footbridge.
    crowd : Crowd
        Density, walking speed, step-frequency distribution and body mass.
    frequency : array_like
        Frequencies [Hz], increasing, >= 0.
    msd : MSDModel, optional
        The pedestrians' mass-spring-damper model; None = no HSI.
    force : ZivanovicForce, YoungForce or any models.loading.ForceModel, optional
        Walking force model (default Živanović 2007; docs: theory, Your own model).
    outputs : sequence of str, optional
        Output names (default all).
    welch_window_length : float, optional
        Return the expectation of a Hann-window Welch estimate with segments of T [s] instead of
        the exact PSD (docs: theory, What a Welch estimate sees: the expectation kernel).
    lowpass : LowPassFilter, optional
        Zero-phase low-pass filter applied to the signal (PSD × |H_LP|⁴).
    dampers : sequence of TunedMassDamper, optional
        Tuned mass dampers fixed to the deck.
    crowd_model : {"fluctuating", "smeared"}
        The expected PSD of a Poisson crowd, the mixture over its fluctuating occupancy with
        the crossing-smoothed load (:class:`~crowdvib.response.FluctuatingSpectralModel`; docs:
        theory, The fluctuating crowd), or the paper's smeared mean crowd
        (:class:`SpectralModel`). The default is the one of :func:`crowdvib.estimate_hsi`
        (``crowdvib._estimators.DEFAULT_CROWD_MODEL``, the fluctuating crowd): a noise-free PSD
        made here with ``welch_window_length`` is what the default estimate recovers exactly.
        ``"smeared"`` is the paper's forward model, which the paper's estimator
        (``method="least_squares"``) fits.

    See Also
    --------
    crowdvib.simulate : the same crowd in the time domain.
    crowdvib.frf : the occupied structure's FRFs.
    crowdvib.welch_psd : the measured counterpart.
    crowdvib.estimate_hsi : the inverse problem.

    References
    ----------
    K. Van Nimmen and P. Van den Broeck, "Using full-scale observations on footbridges to estimate
    the parameters governing human–structure interaction", *Journal of Bridge Engineering* 28(1),
    2023. The spectral model with HSI.

    K. Van Nimmen, P. Van den Broeck, G. Lombaert and F. Tubino, "Pedestrian-induced vibrations of
    footbridges: an extended spectral approach", *Journal of Bridge Engineering*, 2020. The spectral
    load model.

    S. Živanović, A. Pavić and P. Reynolds, "Probability-based prediction of multi-mode vibration
    response to walking excitation", *Engineering Structures* 29(6):942–954, 2007. The walking force
    (default).

    J. S. Bendat and A. G. Piersol, *Random Data: Analysis and Measurement Procedures*, 4th ed.,
    Wiley, 2010. The PSD of a linear system's response.

    The theory pages cite them (docs: theory, References).

    Examples
    --------
    >>> import numpy as np
    >>> from crowdvib import Crowd, MSDModel, ModalModel, response_psd
    >>> bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    >>> psd = response_psd(bridge, Crowd.from_density(0.5), np.arange(1, 601) / 60, msd=MSDModel())
    >>> round(float(psd.peak_frequency()[0]), 2)
    1.93
    """
    _check_models(structure, crowd, msd, "response_psd", crowd_required=True)
    model = spectral_model(structure, crowd, frequency, crowd_model=crowd_model, force=force,
                           outputs=outputs, welch_window_length=welch_window_length,
                           lowpass=lowpass, dampers=dampers)
    return model.psd(msd)
