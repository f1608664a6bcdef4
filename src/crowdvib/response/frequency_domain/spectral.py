"""Frequency-domain crowd–structure model with HSI (docs: theory, The smeared crowd and the occupied bridge, §3).

The crowd is smeared over the walkway: its autonomous walking forces give the modal-load
cross-PSD G_QQ(f) = Ψ s(f) (§3.2) and its bodies, as MSDs, add the apparent mass M_app(f) Ψ to
the structure (§3.1). The occupied receptance is H(ω) = [K_s − ω²(M_s + M_app(ω) Ψ) + iωC_s]⁻¹ and
the output accelerations have G_ü(f) = ω⁴ Φ_o H G_QQ Hᴴ Φ_oᵀ (§3.3).

A tuned mass damper is one more mass-spring-damper, fixed at one point: it enters the same algebra
as the crowd with its own apparent mass and the influence matrix φ_d φ_dᵀ of its mode-shape row
(:mod:`._attached`), so every function here takes ``dampers=`` at no extra code path.

:class:`SpectralModel` precomputes everything that does not depend on the MSD parameters, so the
estimator can call it many times; :func:`response_psd` is the one-shot front door.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import linear_sum_assignment

from ..._validation import (check_frequency_grid, check_names, check_non_negative, check_optional,
                           check_positive, check_type)
from ...errors import ParameterError
from ...models.crowd import Crowd
from ...models.loading import as_force_model
from ...models.pedestrian import MSDModel
from ...models.structure import ModalModel
from ...signals import ResponsePSD
from .expected import model_psd
from ._attached import (
    attachments,
    crowd_attachment,
    damper_attachments,
    psd_factor,
    reduced_matrices,
)
from ._crossing import smoothed_load_spectrum
from ._poles import (_direct_projection, _dynamic_stiffness_diagonal, _modal_projection,
                     _occupied_solve, _pole_residue, _state_matrix, probe)
from ._welch_model import DENSE_POINTS_PER_BIN, CorrectedWelch, WelchRule
from .results import FRF, EffectiveModalProperties
from ...signals.welch import LowPassFilter

if TYPE_CHECKING:
    from ..._validation import ForceModel
    from ...models.damper import TunedMassDamper
    from ...signals.welch import LowPassFilter

__all__ = ["SpectralModel", "frf", "effective_modal_properties", "modal_accelerance"]


def _check_models(structure, crowd, msd, caller, *, crowd_required=False):
    """The model objects of the public entry point ``caller``: a clear error for None, a dict or
    a string where a model is expected (not an AttributeError deep inside), or for a crowd whose
    density is a profile (these are models of a stationary crowd)."""
    check_type("structure", structure, ModalModel)
    if crowd is not None or crowd_required:
        check_type("crowd", crowd, Crowd).check_stationary(caller)
    _check_msd_inputs(crowd, msd)


def _check_msd_inputs(crowd, msd):
    if msd is not None and not isinstance(msd, MSDModel):
        raise ParameterError(f"msd must be an MSDModel or None, got {type(msd).__name__}")
    if msd is not None and crowd is None:
        raise ParameterError("crowd must be given when msd is given: HSI needs the crowd's mass")


class SpectralModel:
    """Response PSD of a crowd-loaded footbridge, precomputed for repeated MSD parameters.

    Parameters
    ----------
    structure : ModalModel
    crowd : Crowd
    frequency : array_like
        Frequencies [Hz] at which the PSD is wanted, increasing, >= 0.
    force : ZivanovicForce, YoungForce or any models.loading.ForceModel, optional
        Walking force model (default Živanović 2007; docs: theory, Your own model).
    outputs : sequence of str, optional
        Output names (default all outputs of ``structure``).
    welch_window_length : float, optional
        If given, return what a Hann-window Welch estimate with segments of T seconds would see
        on average: the exact PSD convolved with the Welch kernel (docs: theory, What a Welch estimate sees: the expectation kernel),
        evaluated at 4 points per bin with the narrow peaks convolved in closed form (docs:
        theory, Evaluating the Welch expectation).
    lowpass : LowPassFilter, optional
        Zero-phase low-pass filter applied to the modelled signal: the PSD is multiplied by
        |H_LP|⁴ before the Welch smoothing (docs: theory, What a Welch estimate sees: the expectation kernel).
    dampers : sequence of TunedMassDamper, optional
        Tuned mass dampers fixed to the deck (part of the structure for every ``msd``).
    crossing_spread : float, optional
        σ_K [Hz] of the finite-crossing kernel that smooths the load spectrum (docs: theory,
        Finite crossings); 0 (default) keeps the narrow-band load of the paper.
        :class:`FluctuatingSpectralModel` sets it from the occupied mode's shape.
    """

    def __init__(self, structure: ModalModel, crowd: Crowd, frequency: ArrayLike, *,
                 force: ForceModel | None = None, outputs: str | Sequence[str] | None = None,
                 welch_window_length: float | None = None, lowpass: LowPassFilter | None = None,
                 dampers: Sequence[TunedMassDamper] | None = None,
                 crossing_spread: float = 0.0) -> None:
        _check_models(structure, crowd, None, "SpectralModel", crowd_required=True)
        self.structure = structure
        self.crowd = crowd
        self.frequency = check_frequency_grid(frequency)
        self.force = as_force_model(force)
        self.output_names = (structure.output_names if outputs is None
                             else check_names("outputs", outputs))
        shapes = structure.output_shapes[structure.output_index(self.output_names)]
        self.welch_window_length = welch_window_length

        self.lowpass = check_optional("lowpass", lowpass, LowPassFilter)
        self.crossing_spread = check_non_negative("crossing_spread", crossing_spread, unit="Hz")
        # B with Ψ = B Bᵀ: the crowd's load and its MSDs' coupling, kept for every MSD
        self._load_factor = psd_factor(structure.influence_matrix(crowd.density))
        self._shapes = shapes
        self._dampers = damper_attachments(structure, dampers)
        self._dense = None
        # (MSD, cross, density, body mass) → the poles' terms of the Welch rule (_expected).
        self._expansions: dict = {}
        # Recent eigen-decompositions of its state matrices, shared likewise: the Jacobian's
        # f_h1 and ξ_h1 columns update them by perturbation (_linalg.eigen_decomposition).
        self._decompositions: list = []
        if welch_window_length is None:
            self._welch = None
            self._grid = self._model_grid(self.frequency)
        else:
            window = check_positive("welch_window_length", welch_window_length, unit="s")
            self._welch = CorrectedWelch(self.frequency, window, self._weight_at)
            # where the pole expansions are checked (_pole_residue), for every MSD
            self._probe = probe(structure, self._welch.grid)

    def _for_crowd(self, crowd, weight=None):
        """This model for another crowd on the same structure, grid and options: only the
        crowd's parts are computed again (the Welch rule, the dampers and the empty structure's
        stiffness are kept). ``weight``: the load weight on the model's grid when the caller
        has it (it depends on the step frequencies and the body mass, not on the density)."""
        other = copy.copy(self)
        other.crowd = crowd
        if crowd.density != self.crowd.density:
            # Ψ's factor depends on the density alone: kept for other step frequencies
            # (their fits build hundreds of these)
            other._load_factor = psd_factor(self.structure.influence_matrix(crowd.density))
        other._dense = None
        if self._welch is None:
            frequency, _, diagonal = self._grid
            other._grid = (frequency, other._weight_at(frequency) if weight is None else weight,
                           diagonal)
        else:
            other._welch = self._welch.with_weight(other._weight_at, weight)
        return other

    @property
    def _grid_weight(self):
        """The load weight on the model's grid (the Welch rule's, or the frequencies)."""
        return self._grid[1] if self._welch is None else self._welch.grid_weight

    def _weight_at(self, frequency):
        """ω⁴ s(f) |H_LP|⁴: the load spectrum (and filter gain) with ω⁴ for accelerations."""
        spectrum = smoothed_load_spectrum(self.force, frequency, self.crowd,
                                          self.crossing_spread)
        if self.lowpass is not None:
            spectrum = spectrum * self.lowpass.power_gain(frequency)
        return (2 * np.pi * frequency) ** 4 * spectrum

    def _model_grid(self, frequency):
        """Frequencies, weight and empty dynamic stiffness for the exact PSD on a grid."""
        return (frequency, self._weight_at(frequency),
                _dynamic_stiffness_diagonal(self.structure, 2 * np.pi * frequency))

    def _attached(self, msd, factor=None):
        """The crowd's MSDs and the dampers; ``factor``: a stack of B for the crowd's
        (_pole_terms), instead of this model's."""
        _check_msd_inputs(self.crowd, msd)
        crowd_part = crowd_attachment(self.crowd, msd,
                                      self._load_factor if factor is None else factor)
        return ((crowd_part,) if crowd_part is not None else ()) + self._dampers

    def psd_array(self, msd: MSDModel | None = None) -> np.ndarray:
        """PSD [(m/s²)²/Hz] as an array of shape (n_outputs, n_frequencies).

        Parameters
        ----------
        msd : MSDModel, optional
            The pedestrians' MSD; None for the crowd as moving forces only (no HSI).
        """
        return self._expected(msd, cross=False)

    def cross_psd_array(self, msd: MSDModel | None = None) -> np.ndarray:
        """Cross-spectral matrix S_ab(f) = E[X_a conj(X_b)] [(m/s²)²/Hz] of the outputs, shape
        (n_outputs, n_outputs, n_frequencies), Hermitian in (a, b), its diagonal the PSD
        (docs: theory, The cross-spectral matrix); with the same Welch kernel and filter.

        Parameters
        ----------
        msd : MSDModel, optional
            The pedestrians' MSD; None for the crowd as moving forces only (no HSI).
        """
        return self._expected(msd, cross=True)

    def _expected(self, msd, cross):
        if self._welch is None:
            return self._exact_psd(self._grid, self._attached(msd), cross)
        return self._welch_psd(_pole_terms([self], msd, cross)[0], msd, cross)

    def _welch_psd(self, terms, msd, cross):
        """The Welch expectation at ``msd`` from this model's pole terms there
        (:func:`_pole_terms`)."""
        if not terms:
            return self._dense_welch_psd(self._attached(msd), cross)
        return self._welch.cross_from(*terms) if cross else self._welch.psd_from(*terms)

    def _exact_psd(self, grid, attached, cross=False):
        """The exact PSD (no Welch smoothing) on a model grid, shape (n_outputs, n_f), or the
        cross-spectral matrix, shape (n_outputs, n_outputs, n_f)."""
        frequency, weight, diagonal = grid
        if not attached:
            # Φ_o H with H diagonal: no solve needed.
            transfer = self._shapes[np.newaxis] / diagonal[:, np.newaxis, :]
            projected = transfer @ self._load_factor            # (n_f, n_out, rank)
        else:
            projected = None
            if self.structure.n_modes > 1:
                projected = _modal_projection(self.structure, attached, self._load_factor,
                                              self._shapes, frequency)
            if projected is None:
                projected = _direct_projection(diagonal, attached, frequency, self._shapes,
                                               self._load_factor)
        if cross:
            return np.einsum("fak,fbk->abf", projected, projected.conj()) * weight
        return (np.abs(projected) ** 2).sum(axis=-1).T * weight

    def _dense_welch_psd(self, attached, cross=False):
        """Reference Welch expectation: the exact PSD at 16 points per bin, rectangle rule."""
        if self._dense is None:
            rule = WelchRule(self.frequency, self.welch_window_length, DENSE_POINTS_PER_BIN)
            self._dense = (rule, self._model_grid(rule.grid))
        rule, grid = self._dense
        exact = self._exact_psd(grid, attached, cross)
        if not cross:
            return rule.apply(exact)
        size = exact.shape[0]
        return rule.apply(exact.reshape(size * size, -1)).reshape(size, size, -1)

    def psd(self, msd: MSDModel | None = None) -> ResponsePSD:
        """PSD at the outputs → :class:`ResponsePSD`.

        Parameters
        ----------
        msd : MSDModel, optional
            The pedestrians' MSD; None for the crowd as moving forces only (no HSI).
        """
        return model_psd(self, msd)

    def with_step_frequencies(self, crowd: Crowd) -> SpectralModel:
        """The same model for walkers that differ only in their step-frequency distribution
        (the structure, grid, Welch rule and dampers are kept).

        Parameters
        ----------
        crowd : Crowd
            The walkers with other step frequencies.
        """
        check_type("crowd", crowd, Crowd)
        return self._for_crowd(crowd)

    def details(self) -> dict[str, Any]:
        """What the model is made of, for a report: nothing beyond its crowd (the smeared
        crowd of the paper)."""
        return {}


#: Pole expansions a model and its copies for other step frequencies keep (_pole_terms): the
#: nodes of a fluctuating mixture at the MSDs of one Jacobian with room to spare.
_EXPANSION_MEMORY = 128


def _pole_terms(models, msd, cross):
    """Each model's pole terms of its Welch rule at ``msd`` (``()`` where it takes the dense rule
    instead): those its memory keeps, the others computed together.

    ``models``: Welch-rule models that are one model and its copies for crowds of other
    densities or step frequencies (:meth:`SpectralModel._for_crowd`; one body mass): the
    occupancy nodes of a fluctuating mixture (:func:`expected_psds`), or one model alone. They
    share the structure, outputs, dampers, rule, probe and memory.

    The poles and their unweighted power depend on the MSD and on the crowd's density and body
    mass, not on its step frequencies (the weight w only): kept for the models of other step
    frequencies, whose evaluations at the same MSD — half the Jacobian of a fit of the step
    frequencies — then cost the weight alone. The nodes not kept are computed as one stack of
    crowds (:mod:`._poles`, one numpy call for all where each node took its own; numpy's
    overhead per call is most of the cost of these small matrices): the same arithmetic,
    node by node, as computed alone.
    """
    first = models[0]
    _check_msd_inputs(first.crowd, msd)
    memory = first._expansions
    keys = [(msd, cross, model.crowd.density, model.crowd.body_mass, model.crowd.body_mass_std)
            for model in models]
    terms = [memory.get(key) for key in keys]
    missing = [index for index, found in enumerate(terms) if found is None]
    if not missing:
        return terms
    factor = np.stack([models[index]._load_factor for index in missing])
    expansion = _pole_residue(first.structure, first._attached(msd, factor), factor,
                              first._shapes, first._probe, first._decompositions)
    if expansion is None and len(missing) > 1:
        # an eigenvector matrix of the stack is singular: each node alone, so that only its
        # own falls back to the dense rule
        for index in missing:
            terms[index] = _pole_terms([models[index]], msd, cross)[0]
        return terms
    # A nearly defective state matrix, or an undamped pole (ξ = 0 and no HSI: the closed form
    # needs Re λ < 0): the dense rule instead (terms empty).
    usable = (np.zeros(len(missing), dtype=bool) if expansion is None
              else expansion[3] & np.all(expansion[0].real < 0, axis=-1))
    welch, found = first._welch, iter(())
    if usable.any():
        poles, left, right = (expansion[:3] if usable.all()
                              else (part[usable] for part in expansion[:3]))
        found = zip(poles, *(welch.cross_terms if cross else welch.power_terms)(poles, left,
                                                                                right))
    for index, kept in zip(missing, usable):
        terms[index] = ()
        if kept:
            node_poles, coefficients, power = next(found)
            terms[index] = (node_poles, coefficients, power, welch.pole_parts(node_poles))
        if len(memory) >= _EXPANSION_MEMORY:
            memory.pop(next(iter(memory)))      # the oldest
        memory[keys[index]] = terms[index]
    return terms


def expected_psds(models, msd, cross=False):
    """Each model's ``psd_array(msd)``, or ``cross_psd_array(msd)`` with ``cross``: the pole terms
    of a mixture's occupancy nodes together (:func:`_pole_terms`) when the models are one
    model's copies for crowds of other densities, each model on its own otherwise."""
    first = models[0]
    if len(models) > 1 and all(
            isinstance(model, SpectralModel) and model._welch is not None
            and model._expansions is first._expansions and model.crowd.density > 0
            and model.crowd.body_mass == first.crowd.body_mass
            and model._load_factor.shape == first._load_factor.shape for model in models):
        return [model._welch_psd(terms, msd, cross)
                for model, terms in zip(models, _pole_terms(models, msd, cross))]
    return [model.cross_psd_array(msd) if cross else model.psd_array(msd) for model in models]


def frf(structure: ModalModel, frequency: ArrayLike, *, crowd: Crowd | None = None,
        msd: MSDModel | None = None, outputs: str | Sequence[str] | None = None,
        inputs: str | Sequence[str] | None = None,
        dampers: Sequence[TunedMassDamper] | None = None) -> FRF:
    """Accelerance FRFs between deck points, empty or occupied (docs: theory, Occupied receptance and FRFs).

    H_oi(ω) = −ω² φ_oᵀ H(ω) φ_i with H the empty receptance, or the occupied one when ``crowd``
    and ``msd`` are given (the crowd's apparent mass smeared over the walkway). Tuned mass
    dampers add their apparent masses at their points in the same way.

    Parameters
    ----------
    structure : ModalModel
    frequency : array_like
        Frequencies [Hz].
    crowd : Crowd, optional
        Needed with ``msd``.
    msd : MSDModel, optional
        Pedestrian MSD model; None = empty structure.
    outputs, inputs : sequence of str, optional
        Output and input points by name (default all outputs, and inputs = outputs).
    dampers : sequence of TunedMassDamper, optional
        Tuned mass dampers fixed to the deck.

    Returns
    -------
    FRF
        ``values`` of shape (n_outputs, n_inputs, n_frequencies) [(m/s²)/N]; ``occupied`` is
        True when the crowd's MSDs are included.

    See Also
    --------
    crowdvib.effective_modal_properties : the occupied structure's modes.
    crowdvib.response_psd

    References
    ----------
    K. Van Nimmen and P. Van den Broeck, "Using full-scale observations on footbridges to estimate
    the parameters governing human–structure interaction", *Journal of Bridge Engineering* 28(1),
    2023. The occupied receptance.

    R. W. Clough and J. Penzien, *Dynamics of Structures*, 3rd ed., Computers & Structures, 2003.
    Modal FRFs.

    The theory pages cite them (docs: theory, References).
    """
    _check_models(structure, crowd, msd, "frf")
    frequency = check_frequency_grid(frequency)
    outputs = structure.output_names if outputs is None else tuple(outputs)
    inputs = outputs if inputs is None else tuple(inputs)
    out_shapes = structure.output_shapes[structure.output_index(outputs)]
    in_shapes = structure.output_shapes[structure.output_index(inputs)]
    occupied = msd is not None and crowd.density > 0
    values = _accelerance(structure, frequency, attachments(structure, crowd, msd, dampers),
                          out_shapes, in_shapes.T)
    return FRF(frequency=frequency, values=values, output_names=outputs,
               input_names=inputs, occupied=occupied)


def _accelerance(structure, frequency, attached, out_shapes, loads):
    """−ω² Φ_o H(ω) L for modal loads L (n_modes, k) → shape (n_outputs, k, n_f)."""
    omega = 2 * np.pi * frequency
    diagonal = _dynamic_stiffness_diagonal(structure, omega)
    if attached:
        response = _occupied_solve(diagonal, attached, frequency, loads)   # (n_f, n_modes, k)
    else:
        response = loads[np.newaxis] / diagonal[:, :, np.newaxis]
    values = -(omega**2)[:, np.newaxis, np.newaxis] * (out_shapes @ response)
    return np.moveaxis(values, 0, -1)


def modal_accelerance(structure: ModalModel, frequency: ArrayLike, *, crowd: Crowd | None = None,
                      msd: MSDModel | None = None,
                      dampers: Sequence[TunedMassDamper] | None = None,
                      outputs: str | Sequence[str] | None = None) -> np.ndarray:
    """Accelerations at the outputs per unit modal force, −ω² Φ_o H(ω) (docs: theory, Occupied receptance and FRFs).

    Column j is the response to a unit harmonic force in mode j alone (as a design code loads
    one mode at a time), through the empty or occupied receptance, dampers included.

    Parameters
    ----------
    structure : ModalModel
    frequency : array_like
        Frequencies [Hz].
    crowd, msd : Crowd, MSDModel, optional
        The crowd's MSDs (HSI); None = empty structure.
    dampers : sequence of TunedMassDamper, optional
    outputs : sequence of str, optional
        Output names (default all).

    Returns
    -------
    ndarray of complex, shape (n_outputs, n_modes, n_frequencies)
        [(m/s²) per unit modal force, in the scaling of the mode shapes].
    """
    _check_models(structure, crowd, msd, "modal_accelerance")
    frequency = check_frequency_grid(frequency)
    outputs = structure.output_names if outputs is None else tuple(outputs)
    return _accelerance(structure, frequency, attachments(structure, crowd, msd, dampers),
                        structure.output_shapes[structure.output_index(outputs)],
                        np.eye(structure.n_modes))


def effective_modal_properties(structure: ModalModel, crowd: Crowd | None = None,
                               msd: MSDModel | None = None, *,
                               dampers: Sequence[TunedMassDamper] | None = None
                               ) -> EffectiveModalProperties:
    """Natural frequencies, damping ratios and engaged modal masses of the occupied structure
    (docs: theory, The smeared crowd and the occupied bridge).

    The smeared crowd of identical MSDs reduces exactly to a model with the structural modes z and
    MSD coordinates η ∈ R^r (r = rank Ψ, Ψ = B Bᵀ):
    M_r = diag(M_s + m_h0 Ψ, m_h1 I), K_r = [[K_s + k_h1 Ψ, −k_h1 B], [−k_h1 Bᵀ, k_h1 I]] and C_r
    alike; each tuned mass damper adds one coordinate coupled through its mode-shape row. The
    complex poles λ give f = |λ|/2π and ξ = −Re λ/|λ|. Each structural mode is paired with the
    pole whose eigenvector carries most of its kinetic energy; the other poles (the crowd's, the
    dampers') are returned apart.

    The engaged modal mass of mode j is the mass of the single-degree-of-freedom oscillator with
    the same pole and the same residue R of the modal receptance H_jj there:
    m_j,eff = 1/(2 Im λ |R|) (= m_j for the empty structure, whose residue is 1/(2i m_j ω_d)).
    With it, a resonant modal force Q gives the modal acceleration ≈ |Q|/(2 ξ m_j,eff).

    Parameters
    ----------
    structure : ModalModel
    crowd : Crowd, optional
        Needed with ``msd``.
    msd : MSDModel or None
        None (or a density of 0) leaves the crowd out (the empty structure's own properties
        when there are no dampers either).
    dampers : sequence of TunedMassDamper, optional
        Tuned mass dampers fixed to the deck.

    Returns
    -------
    EffectiveModalProperties

    See Also
    --------
    crowdvib.frf
    crowdvib.response_psd

    References
    ----------
    K. Van Nimmen and P. Van den Broeck, "Using full-scale observations on footbridges to estimate
    the parameters governing human–structure interaction", *Journal of Bridge Engineering* 28(1),
    2023.

    K. Van Nimmen, G. Lombaert, G. De Roeck and P. Van den Broeck, "The impact of vertical
    human–structure interaction on the response of footbridges to pedestrian excitation", *Journal
    of Sound and Vibration* 402:104–121, 2017. The crowd–structure model with MSD pedestrians.

    The theory pages cite them (docs: theory, References).
    """
    _check_models(structure, crowd, msd, "effective_modal_properties")
    n_modes = structure.n_modes
    attached = attachments(structure, crowd, msd, dampers)
    if not attached:
        empty = np.array([])
        return EffectiveModalProperties(
            frequencies=structure.frequencies.copy(),
            damping_ratios=structure.damping_ratios.copy(),
            participation=np.ones(n_modes), interaction_frequencies=empty,
            interaction_damping_ratios=empty, modal_masses=structure.modal_masses.copy())
    mass, damping, stiffness = reduced_matrices(structure, attached)
    size = mass.shape[0]
    state, inverse_mass = _state_matrix(mass, damping, stiffness)
    poles, vectors = np.linalg.eig(state)
    # Residue of H_jj at pole p: V[j, p] · (V⁻¹[:, velocities] M⁻¹)[p, j] (modal expansion as in
    # _modal_projection).
    gain = np.linalg.solve(vectors, np.vstack([np.zeros((size, n_modes)),
                                               inverse_mass[:, :n_modes]]))   # (2N, n_modes)
    # One pole of each conjugate pair (over-damped real poles are kept once each).
    keep = (poles.imag > 0) | ((poles.imag == 0) & (np.abs(poles.real) > 0))
    poles, displacement, gain = poles[keep], vectors[:size, keep], gain[keep]
    energy = np.abs(displacement) ** 2 * np.diag(mass)[:, np.newaxis]
    share = energy / energy.sum(axis=0)
    rows, cols = linear_sum_assignment(-share[:n_modes])
    order = np.empty(n_modes, dtype=int)
    order[rows] = cols
    magnitude = np.abs(poles)
    frequencies = magnitude / (2 * np.pi)
    ratios = -poles.real / magnitude
    residues = displacement[np.arange(n_modes), order] * gain[order, np.arange(n_modes)]
    with np.errstate(divide="ignore"):   # an over-damped structural pole engages no mass
        engaged = 1.0 / (2 * np.abs(poles[order].imag) * np.abs(residues))
    others = np.setdiff1d(np.arange(poles.size), order)
    others = others[np.argsort(frequencies[others])]
    return EffectiveModalProperties(
        frequencies=frequencies[order], damping_ratios=ratios[order],
        participation=share[np.arange(n_modes), order],
        interaction_frequencies=frequencies[others], interaction_damping_ratios=ratios[others],
        modal_masses=engaged)
