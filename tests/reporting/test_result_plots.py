"""Results draw themselves through crowdvib.reporting.plotting (architecture §3: ``.plot()`` delegates)."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from crowdvib import frf, response_psd, simulate  # noqa: E402
from crowdvib.identification import Estimator  # noqa: E402
from crowdvib.studies import objective_map  # noqa: E402


def test_result_plot_methods(paper_bridge, paper_crowd, paper_msd, welch_grid):
    psd = response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd, crowd_model="smeared")
    ax = psd.plot(label="model")
    assert ax.get_xlabel() == "Frequency [Hz]" and "(m/s²)²/Hz" in ax.get_ylabel()
    assert [line.get_label() for line in ax.get_lines()] == ["model"]
    empty = frf(paper_bridge, welch_grid[1:])
    occupied = frf(paper_bridge, welch_grid[1:], crowd=paper_crowd, msd=paper_msd)
    ax = empty.plot(occupied)
    assert len(ax.get_lines()) == 2 and "[Hz]" in ax.get_xlabel()
    landscape = objective_map(psd, paper_bridge, paper_crowd, frequencies=[2.5, 3.0, 3.5],
                              damping_ratios=[0.2, 0.3, 0.4],
                              estimator=Estimator(band=(0.0, 10.0)))
    ax = landscape.plot()
    assert "[Hz]" in ax.get_xlabel()
    record = simulate(paper_bridge, paper_crowd, 20.0, msd=paper_msd, rng=1)
    handles = record.plot()
    assert len(handles.axes) == 2 and "[m/s²]" in handles.axes[0].get_ylabel()
    assert np.isfinite(record.acceleration).all()
    plt.close("all")
