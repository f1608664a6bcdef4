"""The misfit between a measured and a modelled PSD, as a residual vector (docs: theory, The estimator).

Two misfits share one interface, a residual vector r(θ) with Σ r² the objective:

* ``"least_squares"`` — paper Eq. (6): J(θ) = Σ_l γ_l ‖G̃_l − G_l(θ)‖₂² / ‖G̃_l‖₂², with
  r_{l,k} = sqrt(γ_l w_k) (G̃_l(f_k) − G_l(f_k; θ)) / ‖G̃_l‖₂.
* ``"likelihood"`` — the Whittle (gamma) likelihood of Welch ordinates: Ĝ = G·χ²_ν/ν per bin, so
  −2 log L = Σ ν (x − 1 − ln x) + const with x = Ĝ/G, the deviance D(θ); its deviance residuals
  r_{l,k} = sign(x − 1) sqrt(L γ_l w_k ν (x − 1 − ln x)). Neighbouring bins and coherent outputs
  are not independent: the composite likelihood keeps the estimate consistent, and
  :mod:`crowdvib.identification.uncertainty` corrects its curvature (sandwich) for the intervals.
  When the record carries its cross-spectral matrix (``welch_psd(..., cross=True)``) and two or
  more outputs are fitted, the likelihood is the complex-Wishart deviance of that matrix
  instead (:mod:`crowdvib.identification.wishart`): coherent outputs then count once.
"""

import copy

import numpy as np

from .._estimators import DEFAULT_METHOD, METHOD_DEFAULTS, estimator_defaults
from .._validation import as_float_array, check_flag, check_names, check_positive, check_type
from ..errors import ParameterError
from ..models.crowd import Crowd
from ..models.structure import ModalModel
from ..response.frequency_domain.fluctuation import spectral_model
from ..response.frequency_domain.varying import record_model
from ..signals.spectrum import ResponsePSD
from ..signals.welch import welch_bin_correlation, welch_degrees_of_freedom
from .uncertainty import occupancy_shift, score_variance
from .wishart import WishartTerms

__all__ = ["PSDObjective", "METHODS"]

#: The misfits :class:`PSDObjective` offers.
METHODS = tuple(METHOD_DEFAULTS)
#: The likelihood uses the bins where the modelled response (without HSI) lies within this
#: fraction of its peak in the band (40 dB): there the model, not noise or leakage, rules.
LIKELIHOOD_DYNAMIC_RANGE = 1e-4


def _check_band(band, frequency):
    try:
        lower, upper = (float(b) for b in band)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"band must be a pair (lower, upper) in Hz, got {band!r}") from exc
    if not lower < upper:
        raise ParameterError(f"band must have lower < upper, got ({lower:g}, {upper:g}) Hz")
    if lower < frequency[0] - 1e-12 or upper > frequency[-1] + 1e-12:
        raise ParameterError(
            f"band must lie within the measured frequency grid [{frequency[0]:g}, "
            f"{frequency[-1]:g}] Hz, got ({lower:g}, {upper:g}) Hz")
    keep = (frequency >= lower) & (frequency <= upper)
    if keep.sum() < 3:
        raise ParameterError(
            f"band ({lower:g}, {upper:g}) Hz must hold at least 3 frequencies of the measured "
            f"grid, got {int(keep.sum())}")
    return (lower, upper), keep


def _check_length(name, array, size):
    if array.shape != (size,):
        raise ParameterError(f"{name} must have {size} entries, got {array.size}")


def _normalised_weights(name, weights, size):
    if weights is None:
        return np.full(size, 1.0 / size)
    weights = as_float_array(name, weights, ndim=1)
    _check_length(name, weights, size)
    check_positive(name, weights)
    return weights / weights.sum()


def _read_only(value):
    """``value``, an array as a read-only view (the objective's arrays are its state too; the
    caller's own array stays writeable)."""
    if isinstance(value, np.ndarray):
        value = value.view()
        value.flags.writeable = False
    return value


class PSDObjective:
    """Residuals of paper Equation (6) for a measured PSD and a spectral forward model.

    The objective is immutable: its state is fixed at construction, and an objective for other
    step frequencies (:meth:`with_step_frequencies`) or another measured PSD
    (:meth:`with_target`) is a new object, so an estimate's steps can share one without
    one step changing what the next sees.

    Parameters
    ----------
    measured : ResponsePSD
        Measured (or synthetic) PSDs, one row per output.
    structure, crowd, force
        The model assumed known. A crowd whose density is a
        :class:`~crowdvib.models.CrowdProfile` (t = 0 the record's first sample) makes the model
        the average over the Welch windows of each window's expectation (docs: theory, A crowd
        that changes), the windows placed as a Welch estimate of ``measured.n_windows`` windows
        at 50 % overlap places them from t = 0.
    band : (float, float)
        Analysis band [Hz].
    outputs : sequence of str, optional
        Outputs used (default all of ``measured``); each must exist in ``structure``.
    output_weights : array_like, optional
        γ_l > 0, normalised to sum 1 (default equal).
    frequency_weights : callable or array_like, optional
        w(f) > 0 on the band frequencies (a function of f [Hz] or an array).
    match_welch : bool
        Model what a Welch estimate with the measured window length (and low-pass filter) sees
        (docs: theory, What a Welch estimate sees: the expectation kernel); only when ``measured.window_length`` is known.
    method : {"likelihood", "least_squares"}
        The misfit (module docstring); by default the one :func:`crowdvib.estimate_hsi`
        minimises by default (``crowdvib._estimators.DEFAULT_METHOD``). The likelihood leaves
        out the 0 Hz bin, whose ordinate is not a χ²_ν variable (and is removed by
        detrending). With ``measured.cross`` and two
        or more outputs it is the complex-Wishart likelihood of the cross-spectral matrix
        (which weighs the outputs by their statistics: no ``output_weights`` then); drop the
        cross-spectra (``dataclasses.replace(measured, cross=None)``) for the per-output sum.
    crowd_model : {"smeared", "fluctuating"}, optional
        The expected PSD of the mean crowd, or the mixture over the Poisson crowd's fluctuating
        occupancy (docs: theory, The fluctuating crowd); by default the method's, as in
        :func:`crowdvib.estimate_hsi` (fluctuating with the likelihood, smeared with least
        squares).
    """

    def __setattr__(self, name, value):
        if self.__dict__.get("_frozen"):
            raise AttributeError(
                f"PSDObjective is immutable: {name} cannot be set after construction; use "
                "with_step_frequencies() or with_target() for a changed objective")
        object.__setattr__(self, name, value)

    def _evolve(self, **changes):
        """A copy with some members replaced (the constructor of the ``with_*`` objectives)."""
        other = copy.copy(self)
        for name, value in changes.items():
            object.__setattr__(other, name, _read_only(value))
        return other

    def __init__(self, measured, structure, crowd, *, band, force=None, outputs=None,
                 output_weights=None, frequency_weights=None, match_welch=True,
                 method=DEFAULT_METHOD, crowd_model=None):
        crowd_model = estimator_defaults(method, crowd_model)[0]
        self.method = method
        if not isinstance(measured, ResponsePSD):
            raise ParameterError(f"measured must be a ResponsePSD, got {type(measured).__name__}")
        measured.check_measured()
        check_type("structure", structure, ModalModel)
        check_type("crowd", crowd, Crowd)
        self._profile = None
        if crowd.profile is not None:
            # The record's windows: its Welch estimate's, placed from t = 0 (record_model).
            self._profile = (crowd.profile, None, (measured.window_length, measured.n_windows))
            crowd = crowd.with_density(crowd.profile.peak)      # checked > 0 just below
        if crowd.density <= 0:
            raise ParameterError(
                f"crowd.density must be > 0 to estimate HSI (no crowd, no interaction), "
                f"got {crowd.density:g}")
        outputs = measured.output_names if outputs is None else check_names("outputs", outputs)
        structure.output_index(outputs)
        self.band, keep = _check_band(band, measured.frequency)
        self.frequency = measured.frequency[keep]
        selected = measured.select(outputs)
        self.target = selected.psd[:, keep]
        self.wishart = None
        cross = (selected.cross[..., keep] if method == "likelihood" and len(outputs) >= 2
                 and selected.cross is not None else None)
        if cross is not None and output_weights is not None:
            raise ParameterError(
                "output_weights must be None for the Wishart likelihood of a record with "
                "cross-spectra (it weighs the outputs by their own statistics), got "
                f"{output_weights!r}; drop the cross-spectra for a weighted per-output sum")
        # Measured scatter of the ordinates over their χ² value (1: a stationary Gaussian record).
        self.dispersion = (np.ones_like(self.target) if selected.dispersion is None
                           else selected.dispersion[:, keep])
        # Work on PSDs divided by each output's peak in the band: J is unchanged, and no square
        # over- or underflows whatever the level (a record in the wrong units reaches the
        # plausibility check below instead of a cost of 0 or inf).
        self.level = self.target.max(axis=1)
        for name, level in zip(outputs, self.level):
            if not level > 0:
                raise ParameterError(f"measured PSD of output {name!r} is zero over the band")
        self._target = self.target / self.level[:, np.newaxis]
        norms = np.linalg.norm(self._target, axis=1)
        self.output_names = outputs
        self.output_weights = _normalised_weights("output_weights", output_weights, len(outputs))
        if frequency_weights is None:
            w = np.ones(self.frequency.size)
        elif callable(frequency_weights):
            w = as_float_array("frequency_weights", frequency_weights(self.frequency), ndim=1)
            _check_length("frequency_weights(f) on the band", w, self.frequency.size)
        else:
            w = as_float_array("frequency_weights", frequency_weights, ndim=1)
            _check_length("frequency_weights (one per measured frequency)", w, keep.size)
            w = w[keep]
        check_positive("frequency_weights", w)
        # ν and the bin correlation of the Welch estimate (a periodogram if unknown): the
        # statistics of the measured ordinates, used by the likelihood and the uncertainty.
        self.n_windows = measured.n_windows or 1
        self.degrees_of_freedom = welch_degrees_of_freedom(self.n_windows)
        if method == "least_squares":
            self._scale = (np.sqrt(self.output_weights)[:, np.newaxis] * np.sqrt(w)
                           / norms[:, np.newaxis])
        else:
            # Weights γ_l sum to 1: L γ_l is 1 per output when they are equal, as in a plain
            # sum of log-likelihoods. ν scales D, not its minimum.
            self._scale = (len(outputs) * self.output_weights[:, np.newaxis] * w
                           * self.degrees_of_freedom)
        match_welch = check_flag("match_welch", match_welch)
        window = measured.window_length if match_welch else None
        lowpass = measured.lowpass if match_welch else None
        self._model_inputs = dict(structure=structure, force=force, outputs=outputs,
                                  welch_window_length=window, lowpass=lowpass,
                                  crowd_model=crowd_model)
        self.crowd_model = crowd_model
        self.model = self.spectral_model(crowd)
        if self._profile is not None:
            # From here on a crowd's density scales the profile to that record mean.
            self._profile = (self._profile[0], self.model.crowd.density, self._profile[2])
        if method == "likelihood":
            use = self._likelihood_bins(outputs)
            if cross is not None:
                self._wishart_terms(cross[..., use])
        self._steps_model = (None, None)     # (μ_fs, σ_fs) → model, the last one (model_for)
        for name, value in list(vars(self).items()):
            setattr(self, name, _read_only(value))
        self._frozen = True

    def _wishart_terms(self, cross):
        """Set up the Wishart deviance of the measured cross-spectral matrix (its bins)."""
        # The normalisation D Ŝ D, D = diag(level^-1/2), leaves the deviance unchanged.
        norm = np.sqrt(np.outer(self.level, self.level))[..., np.newaxis]
        reference = self.model.cross_psd_array(None) / norm
        self.wishart = WishartTerms(cross / norm, reference, self._scale[0],
                                    LIKELIHOOD_DYNAMIC_RANGE)

    def _likelihood_bins(self, outputs):
        """Keep the bins the likelihood can use: within ``LIKELIHOOD_DYNAMIC_RANGE`` of the peak.

        The likelihood weighs relative errors, so a bin where the crowd's response is negligible
        (below the subharmonics, far above the harmonics) would be ruled by whatever else the
        record holds there — sensor noise, far leakage of the Hann window — which the model does
        not describe. The selection uses the model without HSI, hence neither θ nor the noise of
        the data; the 0 Hz bin (not a χ²_ν ordinate) is always left out.
        """
        reference = self.model.psd_array(None)
        use = (reference >= LIKELIHOOD_DYNAMIC_RANGE * reference.max(axis=1, keepdims=True))
        use = use.all(axis=0) & (self.frequency > 0)
        if use.sum() < 3:
            raise ParameterError(
                f"band {self.band} holds {int(use.sum())} frequencies where the crowd's response "
                "is within the likelihood's dynamic range; widen the band")
        self.frequency = self.frequency[use]
        self.target, self._target = self.target[:, use], self._target[:, use]
        self.dispersion = self.dispersion[:, use]
        self._scale = self._scale[:, use]
        self.model = self.spectral_model(self.model.crowd)
        positive = self._target > 0
        if not positive.all():
            row, column = np.argwhere(~positive)[0]
            raise ParameterError(
                f"measured PSD of output {outputs[row]!r} must be > 0 where the likelihood "
                f"uses it, got 0 at {self.frequency[column]:g} Hz")
        return use

    def spectral_model(self, crowd):
        """The forward model on the band grid for another crowd (same structure, filter, window).

        Parameters
        ----------
        crowd : Crowd
            The other crowd.
        """
        inputs = dict(self._model_inputs)
        if self._profile is not None:
            return self._varying_model(crowd, self.frequency, inputs)
        model = spectral_model(inputs.pop("structure"), crowd, self.frequency, **inputs)
        if self.crowd_model == "fluctuating":
            # The node count chosen for the objective's own crowd serves every other crowd
            # (nearby densities, other bins): choosing it again costs a dozen models.
            self._model_inputs.setdefault("n_nodes", model.nodes.size)
        return model

    def _varying_model(self, crowd, frequency, inputs):
        """The Welch average over the profile (its densities scaled to ``crowd.density`` as the
        record's mean once that is known: the crowd-size term moves the whole profile)."""
        profile, mean, windows = self._profile
        if mean is not None and crowd.density != mean:
            profile = profile.scaled(crowd.density / mean)
        return record_model(inputs.pop("structure"), crowd.with_density(profile), frequency,
                            record_windows=windows, **inputs)

    def model_for(self, steps):
        """The forward model with the crowd's step frequencies N(μ_fs, σ_fs), ``steps`` = (μ_fs, σ_fs) [Hz].

        For an estimate that fits the step-frequency distribution with the MSD: the last model
        is kept, so the evaluations of one optimiser step (which share μ_fs, σ_fs when only the
        MSD moves) build it once.

        Parameters
        ----------
        steps : (float, float)
            (μ_fs, σ_fs) [Hz].
        """
        key = (float(steps[0]), float(steps[1]))
        if self._steps_model[0] != key:
            # the crowd's own rule for the two (finite, > 0), its other fields already checked
            check_positive("steps (μ_fs, σ_fs)", key, unit="Hz")
            crowd = self.model.crowd._with_checked(step_frequency_mean=key[0],
                                                   step_frequency_std=key[1])
            # The fluctuating mixture keeps its occupancy law (it depends on the density only).
            # A cache, not state: what the objective computes does not depend on it.
            object.__setattr__(self, "_steps_model", (
                key, self.model.with_step_frequencies(crowd)
                if self.crowd_model == "fluctuating" or self._profile is not None
                else self.spectral_model(crowd)))
        return self._steps_model[1]

    def with_step_frequencies(self, steps) -> "PSDObjective":
        """The same misfit whose own model has the step frequencies ``steps`` = (μ_fs, σ_fs) [Hz].

        For what follows a fit of the step frequencies: the levels, the crowd-size term and
        the bootstrap's replicates then use the fitted crowd (a new objective; this one is kept).

        Parameters
        ----------
        steps : (float, float)
            (μ_fs, σ_fs) [Hz].
        """
        return self._evolve(model=self.model_for(steps))

    def exact_model(self, frequency: np.ndarray):
        """The forward model without the Welch kernel on another grid (same crowd, filter).

        Parameters
        ----------
        frequency : ndarray
            The grid [Hz].
        """
        inputs = dict(self._model_inputs, welch_window_length=None)
        if self._profile is not None:
            # The record's times weighed as its Welch windows weigh them (not uniformly).
            inputs["weights_window_length"] = self._profile[2][0]
            return self._varying_model(self.model.crowd, frequency, inputs)
        return spectral_model(inputs.pop("structure"), self.model.crowd, frequency, **inputs)

    def with_target(self, psd: np.ndarray) -> "PSDObjective":
        """The same misfit for another measured PSD on the objective's bins (a bootstrap draw).

        ``psd`` has the shape of :attr:`target`; the normalisation follows it as it follows
        the measured PSD (each output over its peak; least squares over its norm). For the
        Wishart likelihood ``psd`` is a cross-spectral matrix (p, p, K), normalised by the
        objective's own levels (the deviance does not depend on them).

        Parameters
        ----------
        psd : ndarray
            The other measured PSD on the objective's bins.
        """
        if self.wishart is not None:
            cross = np.asarray(psd, dtype=complex)
            target = np.einsum("aak->ak", cross).real
            wishart = copy.copy(self.wishart)
            wishart.set_target(cross / np.sqrt(np.outer(self.level, self.level))[
                ..., np.newaxis])
            return self._evolve(target=target, _target=target / self.level[:, np.newaxis],
                                wishart=wishart)
        target = np.asarray(psd, dtype=float)
        level = target.max(axis=1)
        normalised = target / level[:, np.newaxis]
        scale = self._scale
        if self.method == "least_squares":
            scale = self._scale * (np.linalg.norm(self._target, axis=1)
                                   / np.linalg.norm(normalised, axis=1))[:, np.newaxis]
        return self._evolve(target=target, level=level, _target=normalised, _scale=scale)

    def with_level(self, factor) -> "PSDObjective":
        """The same misfit with the measured PSD read ``factor`` times larger (a unit mix-up undone).

        Parameters
        ----------
        factor : float
            The factor the measured PSD is multiplied by, > 0.
        """
        return self._evolve(level=self.level * factor)

    def residuals(self, msd, *, model=None, steps=None):
        """Residual vector r (Σ r² = J) for an MSD model, or for no HSI with ``msd=None``.

        ``model`` replaces the objective's own forward model (e.g. one for another crowd);
        ``steps`` = (μ_fs, σ_fs) uses :meth:`model_for` those step frequencies.

        Parameters
        ----------
        msd : MSDModel or None
            The pedestrians' MSD θ; None for the structure without HSI.
        model : SpectralModel or FluctuatingSpectralModel, optional
            A forward model in place of the objective's own.
        steps : (float, float), optional
            (μ_fs, σ_fs) [Hz]: the model for these step frequencies (:meth:`model_for`).
        """
        modelled = self.modelled(msd, model=model, steps=steps)
        if self.wishart is not None:
            return self.wishart.residuals(modelled)
        if self.method == "least_squares":
            return ((self._target - modelled) * self._scale).ravel()
        # x − 1 − ln x ≥ 0 (clipped: round-off near x = 1 can make it −1e−16); a model ordinate
        # that underflows is held at a tiny level so that the deviance stays finite but large.
        x = self._target / np.maximum(modelled, 1e-300)
        deviance = np.maximum(x - 1.0 - np.log(x), 0.0)
        return (np.sign(x - 1.0) * np.sqrt(deviance * self._scale)).ravel()

    def modelled(self, msd, *, model=None, steps=None):
        """The model PSD in the objective's normalised units (each output over its level), or
        for the Wishart likelihood the cross-spectral matrix (p, p, K), S_ab over
        sqrt(level_a level_b).

        Parameters
        ----------
        msd : MSDModel or None
            The pedestrians' MSD θ; None for the structure without HSI.
        model : SpectralModel or FluctuatingSpectralModel, optional
            A forward model in place of the objective's own.
        steps : (float, float), optional
            (μ_fs, σ_fs) [Hz]: the model for these step frequencies (:meth:`model_for`).
        """
        if steps is not None:
            model = self.model_for(steps)
        model = self.model if model is None else model
        if self.wishart is not None:
            return model.cross_psd_array(msd) / np.sqrt(np.outer(self.level, self.level))[
                ..., np.newaxis]
        return model.psd_array(msd) / self.level[:, np.newaxis]

    def information(self, modelled, gradient, occupancy=None):
        """Score variance Var(g) and expected Hessian H of S = Σ r² about the fitted model:
        the two parts of the sandwich H⁻¹ Var(g) H⁻¹ (docs: theory, Sandwich covariance).

        Parameters
        ----------
        modelled : ndarray
            :meth:`modelled` at θ̂.
        gradient : ndarray
            Its derivatives, the parameters on a last axis.
        occupancy : (ndarray, float), optional
            ∂(modelled)/∂ln n and the relative variance of the record's crowd size.

        Returns
        -------
        variance, hessian : ndarray, shape (n_parameters, n_parameters)
        shift : ndarray, shape (n_parameters,), or None
            The score's move per unit of ln n (None without ``occupancy``): a density stated
            wrongly moves the score along it too (docs: theory, The crowd density's
            uncertainty).
        """
        correlation = welch_bin_correlation(self.n_windows)
        if self.wishart is not None:
            return self.wishart.information(modelled, gradient, self.degrees_of_freedom,
                                            correlation, self.dispersion.mean(axis=0),
                                            occupancy)
        q, hessian = self.score_terms(modelled, gradient)
        variance = score_variance(q, modelled * np.sqrt(self.dispersion),
                                  self.degrees_of_freedom, correlation, occupancy=occupancy)
        shift = None if occupancy is None else occupancy_shift(q, occupancy[0])
        return variance, hessian, shift

    def score_terms(self, modelled, gradient):
        """Linearised score and curvature of S = Σ r² about a model PSD.

        docs: theory, Statistical uncertainty of an estimate.

        The score is ∂S/∂θ = Σ_{l,k} q_{l,k} (Ĝ_{l,k} − G_{l,k}) and the expected Hessian H
        (E[Ĝ] = G), both in the normalised units of :meth:`modelled`.

        Parameters
        ----------
        modelled : ndarray, shape (n_outputs, n_bins)
            G(θ̂) from :meth:`modelled`.
        gradient : ndarray, shape (n_outputs, n_bins, n_parameters)
            ∂G/∂θ at θ̂, same units.

        Returns
        -------
        q : ndarray, shape (n_outputs, n_bins, n_parameters)
        hessian : ndarray, shape (n_parameters, n_parameters)
        """
        if self.method == "least_squares":
            weight = 2.0 * self._scale**2                     # S = Σ s² (Ĝ − G)²
        else:
            weight = self._scale / modelled**2                # S = Σ s (x − 1 − ln x)
        q = -weight[..., np.newaxis] * gradient
        hessian = np.einsum("lk,lkp,lkq->pq", weight, gradient, gradient)
        return q, hessian

    def level_ratio(self, msd):
        """Measured over modelled variance in the band, per output [-] (1 for a consistent level).

        ∫ G̃_l df / ∫ G_l(θ) df over the band: far from 1 at the optimum means the data and the
        model disagree on the level itself (units, gain, channel), which no MSD can fix.

        Parameters
        ----------
        msd : MSDModel or None
            The pedestrians' MSD θ; None for the structure without HSI.
        """
        with np.errstate(divide="ignore"):
            return self._target.sum(axis=1) / (self.model.psd_array(msd).sum(axis=1)
                                               / self.level)

    def cost(self, msd):
        """J(θ) of paper Equation (6), or the deviance D(θ) for the likelihood [-].

        Parameters
        ----------
        msd : MSDModel or None
            The pedestrians' MSD θ; None for the structure without HSI.
        """
        r = self.residuals(msd)
        return float(r @ r)
