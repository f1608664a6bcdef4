"""Recovery of the MSD parameters from spectral "measurements" (paper verification; docs: theory, Inverse problem).

The "measurements" hold the paper's smeared model at the true crowd, so the paper's estimator
(``method="least_squares"``: smeared crowd, crowd as given) is the one that must give them back.
"""

import numpy as np
import pytest

from crowdvib import estimate_hsi, response_psd
from crowdvib.identification.estimation import DEFAULT_STARTS
from crowdvib.signals import synthetic_welch_psd

#: The paper's band and estimator.
PAPER = dict(band=(0.0, 10.0), method="least_squares")


def test_noise_free_recovery_from_every_start(paper_bridge, paper_crowd, paper_msd, welch_grid):
    # docs: theory, Inverse problem: the four starts all converge to (3.000, 0.300) on noise-free data.
    measured = response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd,
                            crowd_model="smeared")
    estimate = estimate_hsi(measured, paper_bridge, paper_crowd, **PAPER)
    assert len(estimate.starts) == len(DEFAULT_STARTS) == 4
    for run in estimate.starts:
        f, xi = run["estimate"]
        assert f == pytest.approx(3.0, rel=1e-3)
        assert xi == pytest.approx(0.30, rel=1e-3)
    assert estimate.success and estimate.active_bounds == ()
    assert estimate.cost < 1e-10 * estimate.cost_no_hsi


def test_noise_free_recovery_with_welch_model(paper_bridge, paper_crowd, paper_msd, welch_grid):
    measured = response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd,
                            welch_window_length=60.0, crowd_model="smeared")
    estimate = estimate_hsi(measured, paper_bridge, paper_crowd, **PAPER)
    assert estimate.msd.frequency == pytest.approx(3.0, rel=1e-3)
    assert estimate.msd.damping_ratio == pytest.approx(0.30, rel=1e-3)


def test_recovery_with_welch_scatter(paper_bridge, paper_crowd, paper_msd, welch_grid):
    # Issue 2: with the scatter of a 1-hour Welch estimate (119 windows of 60 s), f_h1 within
    # 3 % and ξ_h1 within 15 % of the truth. One record's estimate is a random variable (its
    # f_h1 scatters by about 1.5 %), so the claim is checked over the first 20 seeds: at least
    # 85 % of them meet both tolerances and the average is unbiased to 1 % / 5 %.
    expected = response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd,
                            welch_window_length=60.0, crowd_model="smeared")
    found = []
    for seed in range(1, 21):
        measured = synthetic_welch_psd(expected, n_windows=119, rng=seed)
        estimate = estimate_hsi(measured, paper_bridge, paper_crowd, **PAPER)
        # The fitted model explains the data far better than no HSI (paper: residual ≪ 1 %).
        assert estimate.relative_cost < 0.01
        found.append((estimate.msd.frequency, estimate.msd.damping_ratio))
    error = np.array(found) / [3.0, 0.30] - 1.0
    within = (np.abs(error[:, 0]) <= 0.03) & (np.abs(error[:, 1]) <= 0.15)
    assert within.mean() >= 0.85
    assert abs(error[:, 0].mean()) < 0.01
    assert abs(error[:, 1].mean()) < 0.05


def test_free_mass_ratio_is_estimated_too(paper_bridge, paper_crowd, welch_grid):
    from crowdvib import MSDModel
    truth = MSDModel(2.8, 0.35, 0.85)
    measured = response_psd(paper_bridge, paper_crowd, welch_grid, msd=truth, crowd_model="smeared")
    estimate = estimate_hsi(measured, paper_bridge, paper_crowd, **PAPER,
                            free_mass_ratio=True, starts=[(2.5, 0.3, 0.9), (3.5, 0.5, 0.7)])
    assert estimate.free_parameters == ("frequency", "damping_ratio", "mass_ratio")
    np.testing.assert_allclose([estimate.msd.frequency, estimate.msd.damping_ratio,
                                estimate.msd.mass_ratio], [2.8, 0.35, 0.85], rtol=1e-3)


def test_optimum_on_a_bound_warns(paper_bridge, paper_crowd, paper_msd, welch_grid):
    from crowdvib import BoundWarning
    measured = response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd,
                            crowd_model="smeared")
    with pytest.warns(BoundWarning, match="frequency:upper"):
        estimate = estimate_hsi(measured, paper_bridge, paper_crowd, **PAPER,
                                bounds={"frequency": (1.0, 2.5)}, starts=[(2.0, 0.3)])
    assert "frequency:upper" in estimate.active_bounds
    assert estimate.msd.frequency == pytest.approx(2.5)


def test_output_weights_are_normalised(paper_crowd, paper_msd, welch_grid):
    from crowdvib import ModalModel
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, [2.0, 4.6], 0.005, [50e3, 50e3],
                                              n_modes=2, outputs={"mid": 25.0, "quarter": 12.5})
    measured = response_psd(bridge, paper_crowd, welch_grid, msd=paper_msd, crowd_model="smeared")
    estimate = estimate_hsi(measured, bridge, paper_crowd, band=(1.0, 8.0),
                            output_weights=[3.0, 1.0], method="least_squares")
    np.testing.assert_allclose(estimate.output_weights, [0.75, 0.25])
    assert estimate.msd.frequency == pytest.approx(3.0, rel=1e-3)
