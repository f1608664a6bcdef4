"""A year of comfort's library core (issue 37): the traffic, the window's law by the spectral
route, and the year's hours per class (docs: theory, A year of comfort)."""

import numpy as np
import pytest

from crowdvib.comfort import (CLASS_NAMES, ComfortYear, Traffic, comfort_year, peak_cdf,
                              peak_quantile, running_rms_cdf, running_rms_quantile, window_law)
from crowdvib.design import tune_damper
from crowdvib.errors import ParameterError
from crowdvib.models.examples import paper_example

#: A daily profile of the paper's bridge: night empty, two peaks (persons/m² by hour 0–23).
PROFILE = [0.0] * 6 + [0.1, 0.3, 0.6, 0.3, 0.2, 0.2, 0.4, 0.3, 0.2, 0.2, 0.3, 0.7, 0.5, 0.3,
                       0.2, 0.1, 0.05, 0.0]


# ------------------------------------------------------------------------------ traffic
def test_a_design_table_is_its_hours_and_the_rest_of_the_year_is_empty():
    traffic = Traffic.from_table([0.1, 0.5], [3000.0, 760.0], year_hours=8760.0)
    # 8760 − 3760 h of no crowd added as a state of density 0 (Traffic.from_table)
    assert traffic.density.tolist() == [0.1, 0.5, 0.0]
    assert traffic.hours.tolist() == [3000.0, 760.0, 5000.0]
    with pytest.raises(ParameterError, match="year_hours must be at least the table's 3760 h"):
        Traffic.from_table([0.1, 0.5], [3000.0, 760.0], year_hours=1000.0)


def test_a_daily_profile_stands_for_every_hour_of_every_day():
    traffic = Traffic.from_profile(PROFILE, days=365.0)
    # 168 hours of the week, each 365/7 days a year: 24 × 365 = 8760 h
    assert traffic.total_hours == pytest.approx(8760.0)
    assert traffic.density[24 + 8] == 0.6          # Tuesday 08:00 is hour 8 of the profile
    assert traffic.week_hours() == pytest.approx(np.full(168, 365 / 7))


def test_a_seasons_windows_fill_the_week_by_the_hour_rule():
    # Monday 08:00 measured twice (600 s and 1200 s), Monday 18:00 once; nothing else.
    traffic = Traffic.from_windows([0.2, 0.5, 0.8], ["2026-06-01T08:00", "2026-06-01T08:30",
                                                     "2026-06-01T18:10"], [600.0, 1200.0, 600.0])
    share = 8760.0 / 168
    assert traffic.total_hours == pytest.approx(8760.0)
    monday_8 = traffic.cell == 8
    # Monday 08:00 stands for its share, split by the windows' lengths (1 : 2)
    assert traffic.hours[monday_8] == pytest.approx([share / 3, 2 * share / 3])
    # Tuesday 08:00 (a weekday, not measured) takes Monday 08:00's windows; Saturday 08:00 (no
    # weekend measured) too, from any day; Tuesday 13:00 the nearest measured hour (08 or 18:
    # 5 h either side, both)
    for cell in (24 + 8, 5 * 24 + 8):
        assert sorted(traffic.density[traffic.cell == cell].tolist()) == [0.2, 0.5]
    assert sorted(traffic.density[traffic.cell == 24 + 13].tolist()) == [0.2, 0.5, 0.8]
    assert len(traffic.filled) == 168 - 2
    zero = Traffic.from_windows([0.2], ["2026-06-01T08:00"], unmeasured="zero")
    assert zero.density[zero.cell != 8].max() == 0.0 and zero.total_hours == pytest.approx(8760)


def test_a_seasons_rows_give_their_lengths_by_window_or_duration():
    # Traffic.from_season: a window's length is end − start, a whole record's its duration;
    # both rows measured Monday 08:00 share its 52.1 h in the ratio of their lengths (1 : 3)
    rows = [{"name": "a[0-300s]", "start": 0.0, "end": 300.0, "density": 0.2,
             "time": "2026-06-01T08:00"},
            {"name": "b", "duration": 900.0, "density": 0.6, "time": "2026-06-01T08:20"}]
    traffic = Traffic.from_season({"records": rows})
    assert traffic.hours[traffic.cell == 8] == pytest.approx([8760 / 168 / 4,
                                                              3 * 8760 / 168 / 4])


def test_resampling_a_season_draws_its_windows_again_from_the_seed():
    traffic = Traffic.from_windows([0.1, 0.4, 0.9], ["2026-06-01T08:00", "2026-06-02T08:00",
                                                     "2026-06-06T12:00"])
    first = traffic.resample(np.random.default_rng(3))
    again = traffic.resample(np.random.default_rng(3))
    assert first == again and first.total_hours == pytest.approx(8760.0)
    assert set(first.density.tolist()) <= {0.1, 0.4, 0.9}


# ------------------------------------------------------------------------------ the window
def _white_band(low=1.5, high=2.5, level=0.02):
    frequency = np.arange(0, 4001) * 0.001
    return frequency, np.where((frequency >= low) & (frequency <= high), level, 0.0)


def test_window_law_of_a_band_limited_white_spectrum_matches_its_closed_forms():
    frequency, psd = _white_band()
    law = window_law(frequency, psd, rms_window=1.0)
    # m_k = c (f2^{k+1} − f1^{k+1}) / (k + 1) for G = c on [f1, f2]; the trapezoid rule on the
    # sampled step adds half a bin at each edge: Δf / B = 1e-3 of m0
    m0, m1, m2 = (0.02 * (2.5 ** (k + 1) - 1.5 ** (k + 1)) / (k + 1) for k in range(3))
    assert law.rms == pytest.approx(np.sqrt(m0), rel=1e-3)
    assert law.crossing_rate == pytest.approx(np.sqrt(m2 / m0), rel=1e-3)
    assert law.spread == pytest.approx(np.sqrt(1 - m1**2 / (m0 * m2)), rel=1e-3)
    # |Z(u)| = c |sin(π B u) / (π u)| (B = 1 Hz): Var r = (2/τ) ∫_0^τ (1 − u/τ) |Z|² du by an
    # independent quadrature of the closed form
    u = np.linspace(1e-9, 1.0, 20001)
    z2 = (0.02 * np.sin(np.pi * u) / (np.pi * u)) ** 2
    assert law.ms_std == pytest.approx(np.sqrt(2 * np.trapezoid((1 - u) * z2, u)), rel=2e-3)
    # rate: 2 (|Z(0)|² − |Z(τ)|²)/τ², Z(1 s) = 0 here
    assert law.ms_rate == pytest.approx(np.sqrt(2 * 0.02**2) / (2 * np.pi * law.ms_std),
                                        rel=2e-3)


def test_davenports_peak_quantile_is_the_closed_form():
    law = window_law(*_white_band())
    q = np.array([0.5, 0.9, 0.99])
    # P(max|a| ≤ x) = exp(−2 ν0 T e^{−x²/2σ²}) → x_q = σ sqrt(2 ln(2 ν0 T / −ln q))
    closed = law.rms * np.sqrt(2 * np.log(2 * law.crossing_rate * 600 / -np.log(q)))
    assert peak_quantile(q, law, 600.0, "davenport") == pytest.approx(closed, rel=1e-9)
    # the clumped crossings (Vanmarcke) are fewer: a lower peak for the same q
    assert np.all(peak_quantile(q, law, 600.0) < closed)
    assert peak_cdf(peak_quantile(q, law), law.rms, law.crossing_rate, law.spread) == \
        pytest.approx(q, rel=1e-9)
    assert running_rms_cdf(running_rms_quantile(q, law), law) == pytest.approx(q, rel=1e-9)


# ------------------------------------------------------------------------------ the year
@pytest.fixture(scope="module")
def year():
    paper = paper_example()
    damper = tune_damper(paper.structure, 0, 0.02)
    return comfort_year(paper.structure, paper.crowd, Traffic.from_profile(PROFILE),
                        msd=paper.msd, msd_box={"frequency": [2.8, 3.2],
                                                "damping_ratio": [0.22, 0.38]},
                        dampers=[damper], n_densities=6)


def test_hours_per_class_sum_to_the_years_hours_for_every_model(year):
    # The classes partition the peak's range (docs: theory, A year of comfort): their hours add
    # up to the traffic's 8760 h for every model, with and without the damper.
    assert [(row["model"], row["damper"]) for row in year.rows] == [
        (m, d) for d in (False, True) for m in ("empty", "added_mass", "hsi")]
    for row in year.rows:
        assert sum(row["hours_per_class"].values()) == pytest.approx(8760.0, rel=1e-9)
        assert set(row["hours_per_class"]) == set(CLASS_NAMES)
        band = row["hours_band_hsi"]
        if row["model"] == "hsi":
            for name, value in row["hours_per_class"].items():
                assert band[name][0] <= value + 1e-9 and value <= band[name][1] + 1e-9


def test_the_damper_and_hsi_lower_the_hours_above_cl1(year):
    # The paper's bridge is lightly damped (0.5 %): a 2 % damper and the crowd's damping (HSI)
    # both cut the response (docs: theory, Dampers; the fluctuating crowd), so fewer hours exceed
    # CL1's 0.5 m/s²; the exceedance probability is the hours above over the year's.
    above = {(r["model"], r["damper"]): r["hours_above"]["0.5"] for r in year.rows}
    assert above[("empty", True)] < above[("empty", False)]
    assert above[("hsi", False)] < above[("empty", False)]
    for row in year.rows:
        assert row["exceedance"]["0.5"] == pytest.approx(row["hours_above"]["0.5"] / 8760)


def test_the_year_round_trips(year):
    assert ComfortYear.from_dict(year.to_dict()) == year
    assert len(year.row("hsi")["week_class"]) == 168


# ------------------------------------------------------------------------------ simulated
def test_simulated_windows_are_seeded_and_their_running_rms_stays_below_the_peak():
    from crowdvib.comfort.simulated import simulated_windows

    paper = paper_example()
    options = dict(msd=paper.msd, n_windows=3, duration=60.0, windows_per_task=2,
                   warm_up=20.0, seed=5)
    first = simulated_windows(paper.structure, paper.crowd, [0.5], **options)
    again = simulated_windows(paper.structure, paper.crowd, [0.5], **options)
    assert first.peak[0].shape == (3,)
    np.testing.assert_array_equal(first.peak[0], again.peak[0])
    # an RMS over any 1 s is at most the largest |a| in it: max running RMS ≤ peak, and a
    # sine's RMS is its peak / √2, a narrow-band response's about that
    assert np.all(first.running_rms[0] <= first.peak[0])
    assert np.all(first.running_rms[0] > 0.5 * first.peak[0])


def test_the_quantile_interval_covers_the_true_quantiles_of_a_normal_sample():
    from scipy import stats

    from crowdvib.comfort.simulated import _quantile_interval

    # order-statistic intervals (distribution-free); the normal quantiles are the reference
    q = np.array([0.5, 0.9, 0.99])
    low, high = _quantile_interval(np.random.default_rng(2).standard_normal(2000), q)
    truth = stats.norm.ppf(q)
    assert np.all(low <= truth) and np.all(truth <= high)
    assert np.all(high - low < 0.5)
