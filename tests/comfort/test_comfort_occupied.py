"""The window's law over the crowd's occupancy states, and the thin crowd's bound (docs: theory,
A year of comfort, Where the Gaussian model holds)."""

import numpy as np
import pytest

from crowdvib.comfort.measure import (WindowLaw, peak_quantile, running_rms_quantile,
                                      thin_crowd_density, window_law)
from crowdvib.comfort.occupied import (OccupiedLaw, occupied_law, occupied_peak_cdf,
                                       occupied_peak_quantile, occupied_running_rms_quantile)
from crowdvib.design.stochastic import frequency_grid
from crowdvib.models.examples import paper_example
from crowdvib.response import FluctuatingSpectralModel, SpectralModel

Q = np.array([0.5, 0.9, 0.99])


def _states(law, *others):
    """An OccupiedLaw of the given (probability, WindowLaw) states."""
    pairs = [(1.0, law)] if not others else others
    fields = zip(*[(s.rms, s.crossing_rate, s.spread, s.ms_std, s.ms_rate) for _, s in pairs])
    return OccupiedLaw(np.array([p for p, _ in pairs]), np.ones(len(pairs)),
                       WindowLaw(*map(np.array, fields)))


def test_one_occupancy_state_is_the_window_law():
    # λ ≡ 1: E_λ ν_λ = ν, the same P = exp(−T ν) as measure.peak_cdf (and its running RMS)
    law = WindowLaw(0.3, 2.0, 0.05, 0.02, 0.4)
    one = _states(law)
    for model in ("vanmarcke", "davenport"):
        assert occupied_peak_quantile(Q, one, 600.0, model) == \
            pytest.approx(peak_quantile(Q, law, 600.0, model), rel=1e-12)
    assert occupied_running_rms_quantile(Q, one) == \
        pytest.approx(running_rms_quantile(Q, law), rel=1e-12)


def test_two_states_cross_at_their_mean_rate():
    # Davenport's crossings of two states in the window in shares 0.7 / 0.3, closed form:
    # P(max|a| ≤ x) = exp(−2 ν0 T (0.7 e^{−x²/2σ1²} + 0.3 e^{−x²/2σ2²}))
    quiet, loud = WindowLaw(0.2, 2.0, 0.0, 0.0, 0.0), WindowLaw(0.4, 2.0, 0.0, 0.0, 0.0)
    both = _states(None, (0.7, quiet), (0.3, loud))
    x = np.array([0.6, 1.0, 1.4])
    closed = np.exp(-2 * 2.0 * 600 * (0.7 * np.exp(-x**2 / 0.08) + 0.3 * np.exp(-x**2 / 0.32)))
    assert occupied_peak_cdf(x, both, 600.0, "davenport") == pytest.approx(closed, rel=1e-12)


@pytest.fixture(scope="module")
def paper():
    return paper_example()


def _both(paper, density):
    here = paper.crowd.with_density(density)
    grid = frequency_grid(paper.structure, here, paper.msd, [])
    states = occupied_law(paper.structure, here, grid, msd=paper.msd)
    # the mean crowd with the same load (the crossing kernel of the occupied mode): λ ≡ 1
    spread = FluctuatingSpectralModel(paper.structure, here, grid, n_nodes=1).crossing_spread
    smeared = SpectralModel(paper.structure, here, grid, crossing_spread=spread)
    return states, window_law(smeared.frequency, smeared.psd_array(paper.msd)[0])


def test_a_dense_crowd_has_the_average_psds_law(paper):
    # 1 person/m² on the paper's 150 m²: 150 walkers, σ_λ = sqrt(1.5/150) = 0.1, where the
    # simulator and the one-state law agree within 2.4 % (docs: theory, The check against the
    # simulator): the states' law stays within 0.5 % of it (0.01 % here; at 3 persons/m², where
    # the walkers' damping makes σ fall as λ grows, the states read 1–2 % higher)
    states, law = _both(paper, 1.0)
    assert occupied_peak_quantile(Q, states) == pytest.approx(peak_quantile(Q, law), rel=0.005)


def test_a_thin_crowd_reads_a_heavier_tail_than_its_average_psd(paper):
    # 0.1 persons/m²: 15 walkers, σ_λ = 0.32. The states keep the mean square E_λ σ_λ² of the
    # average PSD (within the interpolation, 1 %) but the loud states cross high levels more
    # often: the 99 % quantile rises (by 7 % here; the simulator's lies 8 % above even that,
    # docs: theory, The check against the simulator).
    states, law = _both(paper, 0.1)
    assert states.rms == pytest.approx(law.rms, rel=0.01)
    gain = occupied_peak_quantile(Q, states) / peak_quantile(Q, law) - 1
    assert 0.05 < gain[2] < 0.10 and gain[0] < gain[1] < gain[2]


def test_the_thin_crowd_is_a_hundred_walkers(paper):
    # the paper's walkway: 50 m × 3 m
    assert thin_crowd_density(paper.structure) == pytest.approx(100.0 / 150.0)


def test_a_torsion_mode_needs_more_walkers_to_be_dense():
    # κ = A ∫φ⁴ dA / (∫φ² dA)² (docs: theory, Where the Gaussian model holds): for
    # φ = sin(πx/L)(2y/W − 1) it is 1.5 × W ∫(2y/W − 1)⁴ dy / (∫(2y/W − 1)² dy)² = 1.5 × 9/5 = 2.7
    # (closed form), so the thin crowd's bound is 100 × 2.7/1.5 walkers over L W; the bending
    # mode beside it (κ = 1.5) does not lower it: the largest κ of the model counts.
    from crowdvib.comfort.measure import occupancy_shape_factor
    from crowdvib.models.structure import ModalModel

    length, width = 30.0, 4.0
    x, y = np.linspace(0, length, 601), np.linspace(0, width, 81)
    bending = np.broadcast_to(np.sin(np.pi * x / length), (y.size, x.size))
    torsion = np.sin(np.pi * x / length)[None, :] * (2 * y / width - 1)[:, None]
    bridge = ModalModel([2.0, 3.0], [0.005, 0.005], [3e4, 1e4], x,
                        np.stack([bending, torsion], axis=-1), width, ["edge"],
                        [[1.0, 1.0]], lanes=y)
    assert occupancy_shape_factor(bridge) == pytest.approx(2.7, rel=2e-3)
    assert thin_crowd_density(bridge) == pytest.approx(180.0 / (length * width), rel=2e-3)
