"""Crowd on a footbridge with a tuned mass damper: time domain against the spectral model.

The paper's example with a 1 t damper at mid-span (1.96 Hz, 3 %), which splits the 2 Hz mode
into coupled modes near 1.85 and 2.12 Hz (crowdvib.effective_modal_properties, itself checked
against a direct eigen-solve in tests/design/test_dampers.py). One seeded 1500 s record per
case, as in the issue-3 Monte Carlo test: band variances within the same ±15 % of the spectral
model (response_psd with dampers=, the reference), and each coupled mode's PSD peak in the Welch
bin of the spectral model's and within one bin of the coupled natural frequency.
"""

import numpy as np
import pytest

from crowdvib import effective_modal_properties, response_psd, simulate
from crowdvib.design import TunedMassDamper

pytestmark = pytest.mark.slow

WINDOW = 60.0
GRID = np.arange(0, 601) / WINDOW
WARM_UP = 150.0
TMD = TunedMassDamper(1000.0, 1.96, 0.03, 25.0)
BANDS = [(1.5, 1.96), (1.96, 2.5), (2.5, 4.5)]


def _peak_in(psd, low, high):
    inside = (psd.frequency >= low) & (psd.frequency < high)
    return psd.frequency[inside][np.argmax(psd.psd[0, inside])]


@pytest.mark.parametrize("hsi", [False, True], ids=["no-HSI", "HSI"])
def test_crowd_with_damper_matches_spectral_model(paper_bridge, paper_crowd, paper_msd, hsi):
    msd = paper_msd if hsi else None
    record = simulate(paper_bridge, paper_crowd, 1500.0, msd=msd, rng=2023, warm_up=WARM_UP,
                      dampers=[TMD])
    measured = record.psd(WINDOW)
    model = response_psd(paper_bridge, paper_crowd, GRID, msd=msd, dampers=[TMD],
                         welch_window_length=WINDOW, crowd_model="smeared")
    ratios = [measured.variance(lo, hi)[0] / model.variance(lo, hi)[0] for lo, hi in BANDS]
    assert np.all(np.abs(np.array(ratios) - 1) <= 0.15), ratios
    if not hsi:
        # Without the crowd's damping the two coupled modes stand apart.
        props = effective_modal_properties(paper_bridge, dampers=[TMD])
        coupled = np.sort(np.concatenate([props.frequencies, props.interaction_frequencies]))
        for (low, high), natural in zip(BANDS[:2], coupled):
            peak = _peak_in(measured, low, high)
            assert peak == pytest.approx(_peak_in(model, low, high), abs=1e-9)
            assert abs(peak - natural) <= 1 / WINDOW
