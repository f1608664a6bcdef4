"""The complex-Wishart deviance of a Welch cross-spectral matrix (identification.wishart; docs:
theory, The likelihood of several outputs)."""

import dataclasses

import numpy as np
import pytest

from crowdvib import ParameterError, SpectralModel, welch_psd
from crowdvib.identification import PSDObjective
from crowdvib.identification.uncertainty import score_variance
from crowdvib.identification.wishart import WISHART_RANK_TOLERANCE, WishartTerms
from crowdvib.signals.synthesis import gaussian_cross_record, record_frequencies

NU = 200.0


def _whittle(x):
    """ν (x − 1 − ln x): the one-output deviance of an ordinate ratio x (docs: theory)."""
    return NU * (x - 1.0 - np.log(x))


def _random_hermitian(rng, size, bins, jitter=0.3):
    factor = rng.normal(size=(bins, size, size)) + 1j * rng.normal(size=(bins, size, size))
    matrices = factor @ np.conj(np.swapaxes(factor, 1, 2)) + jitter * np.eye(size)
    return np.moveaxis(matrices, 0, -1)                                # (p, p, K)


def test_two_uncorrelated_outputs_give_the_sum_of_their_whittle_deviances():
    # Closed form: for diagonal S and Ŝ, tr(S⁻¹Ŝ) − ln det(S⁻¹Ŝ) − 2 = Σ_a (x_a − 1 − ln x_a).
    rng = np.random.default_rng(1)
    model = np.zeros((2, 2, 30), complex)
    target = np.zeros((2, 2, 30), complex)
    model[[0, 1], [0, 1]] = rng.uniform(0.5, 2.0, (2, 30))
    target[[0, 1], [0, 1]] = rng.uniform(0.5, 2.0, (2, 30))
    reference = np.broadcast_to(np.eye(2)[..., np.newaxis], (2, 2, 30)).astype(complex)
    terms = WishartTerms(target, reference, np.full(30, NU), 1e-4)
    r = terms.residuals(model)
    x = target[[0, 1], [0, 1]].real / model[[0, 1], [0, 1]].real
    assert r @ r == pytest.approx(_whittle(x).sum(), rel=1e-10)


def test_deviance_is_the_wishart_form_and_invariant_to_output_scaling():
    # Closed form ν Σ_k [tr(S⁻¹Ŝ) − ln det(S⁻¹Ŝ) − p], evaluated directly, and its invariance
    # under S → D S D, Ŝ → D Ŝ D (the objective's per-output normalisation) while every
    # direction stays kept (which directions are kept is judged in the normalised units).
    rng = np.random.default_rng(2)
    model, target = _random_hermitian(rng, 3, 25), _random_hermitian(rng, 3, 25)
    reference = _random_hermitian(rng, 3, 25, jitter=5.0)   # well conditioned: all kept
    terms = WishartTerms(target, reference, np.full(25, NU), 1e-4)
    assert terms.keep.all()
    ratio = np.linalg.solve(np.moveaxis(model, -1, 0), np.moveaxis(target, -1, 0))
    direct = NU * (np.trace(ratio, axis1=1, axis2=2).real
                   - np.log(np.linalg.det(ratio).real) - 3).sum()
    r = terms.residuals(model)
    assert r @ r == pytest.approx(direct, rel=1e-9)
    scale = np.diag([2.0, 0.7, 1.5])
    scaled = WishartTerms(np.einsum("ab,bcf,cd->adf", scale, target, scale),
                          np.einsum("ab,bcf,cd->adf", scale, reference, scale),
                          np.full(25, NU), 1e-4)
    assert scaled.keep.all()
    r_scaled = scaled.residuals(np.einsum("ab,bcf,cd->adf", scale, model, scale))
    assert r_scaled @ r_scaled == pytest.approx(direct, rel=1e-9)


def test_a_rank_one_model_reduces_to_the_whittle_deviance_of_its_principal_component():
    # Closed form: with the reference of rank 1 (direction u), only u carries data, and the
    # deviance is ν (x − 1 − ln x) with x = uᴴŜu / uᴴSu (projection of a complex Wishart matrix
    # on a fixed direction: a scaled χ²).
    rng = np.random.default_rng(3)
    u = np.array([0.8, 0.6j])
    reference = np.einsum("a,b,f->abf", u, u.conj(), np.linspace(1.0, 2.0, 20))
    reference = reference + 1e-6 * np.eye(2)[..., np.newaxis]      # second direction ≪ tolerance
    model, target = _random_hermitian(rng, 2, 20), _random_hermitian(rng, 2, 20)
    terms = WishartTerms(target, reference, np.full(20, NU), 1e-4)
    assert terms.keep[:, 0].all() and not terms.keep[:, 1].any()
    x = (np.einsum("a,abf,b->f", u.conj(), target, u).real
         / np.einsum("a,abf,b->f", u.conj(), model, u).real)
    r = terms.residuals(model)
    assert r @ r == pytest.approx(_whittle(x).sum(), rel=1e-9)


def test_directions_are_kept_by_the_rank_tolerance_and_the_dynamic_range():
    reference = np.zeros((2, 2, 3), complex)
    reference[0, 0] = [1.0, 1.0, 1e-3]
    reference[1, 1] = [2 * WISHART_RANK_TOLERANCE, 0.5 * WISHART_RANK_TOLERANCE, 1e-3]
    terms = WishartTerms(reference, reference, np.ones(3), 1e-2)
    # Bin 0: both kept; bin 1: the weak direction is below the rank tolerance; bin 2: both
    # directions are below 1 % of the band's largest eigenvalue (the dynamic range).
    np.testing.assert_array_equal(terms.keep, [[True, True], [True, False], [False, False]])


def test_score_variance_matches_a_monte_carlo_of_the_complex_wishart_law():
    # Reference: complex Wishart matrices drawn from their definition, Ŝ = (1/n) Σ_j z_j z_jᴴ with
    # z_j ~ CN(0, S), n = ν/2 (independent bins: ρ = (1,)); the score of the deviance,
    # g = Σ_k ∂D/∂θ at the truth, must have the variance information() predicts. With
    # independent bins D = −2 ln L is a full likelihood: Var(g) = 4 I and H = 2 I (I the Fisher
    # information), so Var(g) = 2 H and the sandwich is the inverse Fisher information.
    rng = np.random.default_rng(4)
    bins, n = 6, int(NU / 2)
    model = _random_hermitian(rng, 2, bins, jitter=1.0)
    gradient = np.stack([_random_hermitian(rng, 2, bins) - _random_hermitian(rng, 2, bins)
                         for _ in range(2)], axis=-1)
    terms = WishartTerms(model, model, np.full(bins, NU), 1e-6)
    variance, hessian, _ = terms.information(model, gradient, NU, (1.0,), np.ones(bins))
    inverse = np.linalg.inv(np.moveaxis(model, -1, 0))
    factor = np.linalg.cholesky(np.moveaxis(model, -1, 0))
    scores = []
    for _ in range(4000):
        z = factor @ ((rng.normal(size=(bins, 2, n)) + 1j * rng.normal(size=(bins, 2, n)))
                      / np.sqrt(2))
        sample = z @ np.conj(np.swapaxes(z, 1, 2)) / n
        # ∂D/∂θ = −ν Σ_k tr(S⁻¹ ∂S S⁻¹ (Ŝ − S))
        deviation = sample - np.moveaxis(model, -1, 0)
        scores.append([-NU * np.einsum("kab,kbc,kcd,kda->", inverse,
                                       np.moveaxis(gradient[..., i], -1, 0), inverse,
                                       deviation).real for i in range(2)])
    scores = np.array(scores)
    np.testing.assert_allclose(np.cov(scores.T), variance, rtol=0.08, atol=0.03 *
                               np.abs(variance).max())
    # Exact up to the 1e-10 ridge of the factor that whitens the variance.
    np.testing.assert_allclose(variance, 2 * hessian, rtol=1e-8)


def test_independent_score_rows_add_their_variances():
    # Closed form: rows that are independent add; one row is the coherent case itself.
    rng = np.random.default_rng(5)
    q = rng.normal(size=(3, 40, 2))
    spread = rng.uniform(0.5, 1.5, (3, 40))
    rho = (1.0, 0.46, 0.04)
    total = score_variance(q, spread, 50.0, rho, coherent=False)
    parts = sum(score_variance(q[i:i + 1], spread[i:i + 1], 50.0, rho) for i in range(3))
    np.testing.assert_allclose(total, parts, rtol=1e-12)


def _two_output_record(paper_crowd, paper_msd):
    from crowdvib import ModalModel
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3,
                                              outputs={"midspan": 25.0, "quarter": 12.5})
    frequency = record_frequencies(1800.0, 20.0)
    cross = SpectralModel(bridge, paper_crowd, frequency).cross_psd_array(paper_msd)
    records = gaussian_cross_record(cross, 20.0, rng=9)
    measured = welch_psd(records, 20.0, window_length=60.0, output_names=["midspan", "quarter"],
                         cross=True).band(0.0, 10.0)
    return bridge, measured


def test_objective_uses_the_wishart_likelihood_only_with_cross_spectra(paper_crowd, paper_msd):
    bridge, measured = _two_output_record(paper_crowd, paper_msd)
    options = dict(band=(0.0, 10.0), method="likelihood", crowd_model="smeared")
    assert PSDObjective(measured, bridge, paper_crowd, **options).wishart is not None
    plain = dataclasses.replace(measured, cross=None)
    assert PSDObjective(plain, bridge, paper_crowd, **options).wishart is None
    one = measured.select(["midspan"])
    assert PSDObjective(one, bridge, paper_crowd, **options).wishart is None
    squares = PSDObjective(measured, bridge, paper_crowd, band=(0.0, 10.0),
                           method="least_squares")
    assert squares.wishart is None
    with pytest.raises(ParameterError, match="output_weights must be None for the Wishart"):
        PSDObjective(measured, bridge, paper_crowd, output_weights=[0.7, 0.3], **options)


def test_fully_coherent_pair_counts_once(paper_crowd, paper_msd):
    # Closed form: one mode makes the two outputs scaled copies (quarter span = midspan/√2), so
    # every per-output deviance is the same function of θ. The summed likelihood therefore has
    # twice the curvature of one output (H_sum = 2 H_1: read alone it would give intervals √2
    # too narrow); the Wishart likelihood, reduced to the one direction the model spans, *is*
    # the one-output likelihood (H_W = H_1). The sandwich of the sum, which takes the outputs as
    # fully coherent, has Var(g) = 4 Var(g_1) and so restores the one-output covariance.
    bridge, measured = _two_output_record(paper_crowd, paper_msd)
    options = dict(band=(0.0, 10.0), method="likelihood", crowd_model="smeared")
    objectives = {"wishart": PSDObjective(measured, bridge, paper_crowd, **options),
                  "sum": PSDObjective(dataclasses.replace(measured, cross=None), bridge,
                                      paper_crowd, **options),
                  "one": PSDObjective(measured.select(["midspan"]), bridge, paper_crowd,
                                      **options)}
    parts = {}
    for name, objective in objectives.items():
        modelled = objective.modelled(paper_msd)
        step = 1e-5 * np.array([3.0, 0.3])
        gradient = np.stack([
            (objective.modelled(type(paper_msd)(3.0 + step[0], 0.3, 0.95))
             - objective.modelled(type(paper_msd)(3.0 - step[0], 0.3, 0.95))) / (2 * step[0]),
            (objective.modelled(type(paper_msd)(3.0, 0.3 + step[1], 0.95))
             - objective.modelled(type(paper_msd)(3.0, 0.3 - step[1], 0.95))) / (2 * step[1])],
            axis=-1)
        parts[name] = objective.information(modelled, gradient)
    np.testing.assert_allclose(parts["sum"][1], 2 * parts["one"][1], rtol=1e-8)
    np.testing.assert_allclose(parts["wishart"][1], parts["one"][1], rtol=1e-6)
    np.testing.assert_allclose(parts["wishart"][0], parts["one"][0], rtol=1e-6)
    np.testing.assert_allclose(parts["sum"][0], 4 * parts["one"][0], rtol=1e-8)
    costs = {name: objective.cost(paper_msd) for name, objective in objectives.items()}
    assert costs["wishart"] == pytest.approx(costs["one"], rel=1e-8)
    assert costs["sum"] == pytest.approx(2 * costs["one"], rel=1e-8)
