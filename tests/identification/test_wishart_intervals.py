"""Intervals of the likelihood of two outputs: per-output sum against the complex Wishart
(docs: theory, The likelihood of several outputs).

Records are Gaussian with the model's cross-spectral matrix (gaussian_cross_record), so their
Welch cross-spectral matrices carry exactly the complex-Wishart scatter and the bin correlation
of a measurement of a stationary crowd; the truth is the MSD that made them (3.0 Hz, 0.30, 0.95).
``accuracy/wishart.py`` runs the same comparison over 200 records per case.
"""

import dataclasses
import warnings
from pathlib import Path

import numpy as np
import pytest

from crowdvib import (BoundWarning, Crowd, ModalModel, MSDModel, SpectralModel, estimate_hsi,
                      welch_psd)
from crowdvib.io.casefile import load_case
from crowdvib.signals.synthesis import gaussian_cross_record, record_frequencies
from tests.conftest import OWN_RECORDS

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
TRUTH = {"frequency": 3.0, "damping_ratio": 0.30}
MSD = MSDModel(3.0, 0.30, 0.95)


def _records(structure, crowd, outputs, window, seeds, duration=3600.0, rate=20.0):
    cross = SpectralModel(structure, crowd, record_frequencies(duration, rate),
                          outputs=outputs).cross_psd_array(MSD)
    for seed in seeds:
        yield welch_psd(gaussian_cross_record(cross, rate, rng=seed), rate, window_length=window,
                        output_names=outputs, cross=True).band(0.0, 10.0)


def _estimate(measured, structure, crowd, band, **options):
    # The records hold the smeared model's cross-spectra at the true crowd: the likelihood
    # fits that model with the crowd held.
    options = dict(dict(crowd_model="smeared", free_step_frequencies=False), **options)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BoundWarning)
        return estimate_hsi(measured, structure, crowd, band=band, method="likelihood", **options)


def _paper_pair():
    """The paper's example bridge (one mode) with outputs at midspan and quarter span."""
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3,
                                              outputs={"midspan": 25.0, "quarter": 12.5})
    crowd = Crowd(density=0.5, walking_speed=1.30, step_frequency_mean=1.89,
                  step_frequency_std=0.175, body_mass=70.0)
    return bridge, crowd


def test_a_fully_coherent_pair_has_the_interval_of_one_output():
    # Closed form: one mode makes the quarter-span record the midspan record over √2, so the
    # Wishart likelihood (reduced to the one direction the model spans) is the one-output
    # likelihood. The per-output sum doubles the deviance, D_sum = 2 D_1: alone its curvature
    # would give intervals √2 too narrow (H_sum = 2 H_1). Its sandwich takes the outputs as
    # fully coherent (Var(g_sum) = 4 Var(g_1)) and the profile statistic is scaled by
    # c = 2 H⁻¹/Cov, which halves with H doubled: c_sum ΔD_sum = c_1 ΔD_1, the same interval.
    bridge, crowd = _paper_pair()
    measured = next(_records(bridge, crowd, ("midspan", "quarter"), 60.0, [21]))
    found = {name: _estimate(data, bridge, crowd, (0.0, 10.0)) for name, data in
             (("wishart", measured), ("sum", dataclasses.replace(measured, cross=None)),
              ("one", measured.select(["midspan"])))}
    for parameter in TRUTH:
        one = np.array(found["one"].interval(parameter))
        for name in ("wishart", "sum"):
            np.testing.assert_allclose(found[name].interval(parameter), one, rtol=1e-5)
        assert found["wishart"].standard_errors[parameter] == pytest.approx(
            found["one"].standard_errors[parameter], rel=1e-4)


@pytest.mark.slow
def test_wishart_intervals_cover_a_partly_coherent_pair_and_are_narrower():
    # The Eeklo-like bridge (14 modes, band 2.5–8 Hz, T = 25 s) with outputs at the centre and
    # the quarter of the main span (48 and 37.5 m): its 5.7 Hz mode rules both, the pair is
    # partly coherent (energy-weighted coherence 0.83). Over 40 seeded records the Wishart 95 %
    # intervals must cover the truth in at least 85 % of them (34 of 40; at a true 95 % the
    # binomial chance of fewer is 1 %). The per-output sum's sandwich takes the pair as fully
    # coherent, too cautious here: its intervals are wider than the Wishart's, and, as it
    # ignores the cross-spectra, it scatters more from record to record.
    structure, crowd, outputs = _eeklo_quarter()
    found = {"wishart": [], "sum": []}
    for measured in _records(structure, crowd, outputs, 25.0, range(40)):
        for name, data in (("wishart", measured),
                           ("sum", dataclasses.replace(measured, cross=None))):
            estimate = _estimate(data, structure, crowd, (2.5, 8.0), **OWN_RECORDS)
            found[name].append([(getattr(estimate.msd, p), *estimate.interval(p))
                                for p in TRUTH])
    found = {name: np.array(rows) for name, rows in found.items()}   # (40, parameter, 3)
    truth = np.array(list(TRUTH.values()))
    wishart, summed = found["wishart"], found["sum"]
    covered = ((wishart[..., 1] <= truth) & (truth <= wishart[..., 2])).mean(axis=0)
    assert np.all(covered >= 0.85), covered
    width = {name: (rows[..., 2] - rows[..., 1]).mean(axis=0) for name, rows in found.items()}
    assert np.all(width["wishart"] < width["sum"]), width
    assert np.all(wishart[..., 0].std(axis=0) < summed[..., 0].std(axis=0))


@pytest.mark.slow
def test_wishart_bootstrap_scatter_matches_its_sandwich():
    # The parametric bootstrap of the Wishart likelihood draws two-output records from the
    # fitted model's cross-spectral matrix; its scatter must agree with the sandwich standard
    # errors, an independent derivation (100 replicates: a standard deviation within ±25 %,
    # over 3σ of its sampling error √(1/198) = 7 %). Eeklo-like main and side span: both
    # principal directions are kept in most bins, so the replicates' cross-spectra count.
    case = load_case(EXAMPLES / "eeklo_like.toml")
    structure, crowd, outputs = case.structure, case.crowd, ("main_span", "side_span")
    measured = next(_records(structure, crowd, outputs, 25.0, [7]))
    estimate = _estimate(measured, structure, crowd, (2.5, 8.0), interval="bootstrap",
                         n_boot=100, rng=3)
    samples = estimate.bootstrap_samples
    # The sandwich standard errors: every estimate with an interval carries the sandwich
    # covariance, computed from the fit before and apart from the replicates (estimate_hsi):
    # those of interval="wald" on the same record (bit for bit, seen when this was written),
    # without fitting it again.
    sandwich = estimate.standard_errors
    assert set(sandwich) == set(estimate.free_parameters)
    for i, name in enumerate(estimate.free_parameters):
        assert samples[:, i].std(ddof=1) == pytest.approx(sandwich[name], rel=0.25)
    again = _estimate(measured, structure, crowd, (2.5, 8.0), interval="bootstrap", n_boot=20,
                      rng=3)
    np.testing.assert_array_equal(again.bootstrap_samples, samples[:20])


def _eeklo_quarter():
    """Eeklo-like bridge with outputs at the centre and the quarter of the main span."""
    case = load_case(EXAMPLES / "eeklo_like.toml")
    outputs = ("main_span", "main_quarter")
    structure = case.structure.replace(
        output_names=outputs, output_shapes=case.structure.shapes_at(np.array([48.0, 37.5])))
    return structure, case.crowd, outputs


@pytest.mark.slow
def test_wishart_score_variance_matches_its_scatter_over_records():
    # Reference: the empirical covariance of the score g = ∂D/∂θ at the truth over 120 Gaussian
    # records (central differences of the deviance), against the sandwich's Var(g) with the
    # bin correlation ρ(d) of overlapped Hann segments. Eeklo-like main and side span: both
    # principal directions are kept in most bins, so the off-diagonal coordinates count. A variance
    # from 120 draws is within ±26 % (2σ of √(2/119)); without the bin correlation the
    # prediction is about half as large (docs: theory, Sandwich covariance), which must fail.
    from crowdvib.identification import PSDObjective
    from crowdvib.signals.welch import welch_bin_correlation

    case = load_case(EXAMPLES / "eeklo_like.toml")
    structure, crowd, outputs = case.structure, case.crowd, ("main_span", "side_span")
    step = np.array([1e-4 * 3.0, 1e-4 * 0.3])
    scores, predicted = [], None
    for measured in _records(structure, crowd, outputs, 25.0, range(100, 220)):
        objective = PSDObjective(measured, structure, crowd, band=(2.5, 8.0), method="likelihood",
                                 crowd_model="smeared")
        points = [MSDModel(3.0 + s * step[0] * (i == 0), 0.3 + s * step[1] * (i == 1), 0.95)
                  for i in range(2) for s in (1, -1)]
        costs = [objective.cost(m) for m in points]
        scores.append([(costs[0] - costs[1]) / (2 * step[0]),
                       (costs[2] - costs[3]) / (2 * step[1])])
        if predicted is None:
            assert objective.wishart.keep.all(axis=1).mean() > 0.5
            modelled = objective.modelled(MSD)
            gradient = np.stack([(objective.modelled(points[2 * i])
                                  - objective.modelled(points[2 * i + 1])) / (2 * step[i])
                                 for i in range(2)], axis=-1)
            ones = np.ones(objective.frequency.size)
            rho = welch_bin_correlation(objective.n_windows)
            predicted = objective.wishart.information(modelled, gradient,
                                                      objective.degrees_of_freedom, rho, ones)[0]
            independent = objective.wishart.information(modelled, gradient,
                                                        objective.degrees_of_freedom, (1.0,),
                                                        ones)[0]
    empirical = np.cov(np.array(scores).T)
    np.testing.assert_allclose(np.diag(empirical), np.diag(predicted), rtol=0.26)
    assert np.all(np.diag(independent) < 0.75 * np.diag(empirical))
