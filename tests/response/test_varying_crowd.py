"""A crowd that changes within a record: the simulator's non-homogeneous stream and the expected
Welch PSD Ḡ = Σ_i p_i G(f; d_i) (crowdvib.response.frequency_domain.varying; docs: theory, A crowd that changes;
issue 28 §1)."""

import numpy as np
import pytest
from scipy import stats

from crowdvib import (Crowd, CrowdProfile, ModalModel, MSDModel, ParameterError,
                      PlausibilityWarning, SpectralModel,
                      VaryingCrowdModel, simulate, simulate_many, simulate_psd, welch_psd)
from crowdvib.response.frequency_domain.varying import density_law
from crowdvib.signals.welch import welch_degrees_of_freedom

HOUR, WINDOW, RATE = 3600.0, 60.0, 50.0
PROFILES = {"ramp": CrowdProfile([0.0, HOUR], [0.2, 1.0]),
            "day": CrowdProfile([0.0, 900.0, 1800.0, 2700.0], [0.3, 0.9, 0.5, 0.15], "step")}


@pytest.fixture(scope="module")
def bridge():
    return ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)


@pytest.fixture(scope="module")
def walkers():
    return Crowd.from_density(0.6)


def test_constant_profile_gives_the_stationary_record(bridge, walkers):
    # A constant profile is the stationary crowd of its density: the same seed, the same record.
    stationary = simulate(bridge, walkers.with_density(0.5), 120.0, msd=MSDModel(), rng=3,
                          sample_rate=RATE)
    profiled = simulate(bridge, walkers.with_density(CrowdProfile.constant(0.5)), 120.0,
                        msd=MSDModel(), rng=3, sample_rate=RATE)
    assert np.array_equal(stationary.acceleration, profiled.acceleration)


def test_profiled_record_is_reproducible(bridge, walkers):
    # Same seed → same record; simulate_psd's Welch PSD of it equals welch_psd of the record.
    crowd = walkers.with_density(PROFILES["day"].scaled(1.0))
    first = simulate(bridge, crowd, 300.0, rng=8, sample_rate=RATE)
    again = simulate(bridge, crowd, 300.0, rng=8, sample_rate=RATE)
    assert np.array_equal(first.acceleration, again.acceleration)
    (batch,) = simulate_many(bridge, crowd, 300.0, seeds=[8], sample_rate=RATE)
    assert np.array_equal(first.acceleration, batch.acceleration)
    summary = simulate_psd(bridge, crowd, 300.0, rng=8, sample_rate=RATE, window_length=30.0)
    assert summary.psd.psd == pytest.approx(
        welch_psd(first.acceleration, RATE, window_length=30.0).psd, rel=1e-9, abs=1e-20)


def test_deck_follows_the_profile(bridge, walkers):
    # The people on the deck average the stream's density over the last crossing τ = L/v
    # (CrowdProfile.deck_density). Over a block B ≫ τ the time-average of a Poisson occupancy of
    # mean m has variance m τ/B (autocovariance m (1 − |s|/τ)): 4 standard deviations.
    profile = CrowdProfile([0.0, 600.0, 1200.0], [0.5, 0.0, 0.8], "step")
    record = simulate(bridge, walkers.with_density(profile), 1800.0, rng=2, sample_rate=10.0)
    tau = bridge.length / walkers.walking_speed
    t = np.arange(record.n_on_deck.size) / 10.0
    expected = profile.deck_density(t, tau) * bridge.area
    for start in range(0, 1800, 300):
        block = (t >= start) & (t < start + 300)
        m = expected[block].mean()
        assert abs(record.n_on_deck[block].mean() - m) <= 4 * np.sqrt(m * tau / 300) + 1e-12
    # Nobody enters while the density is 0: the deck is empty a crossing after 600 s.
    assert np.all(record.n_on_deck[(t > 600 + tau + 0.1) & (t < 1200)] == 0)


def test_constant_profile_model_is_the_spectral_model(bridge, walkers):
    # One level at the profile's density: Ḡ is the stationary model itself.
    frequency = np.arange(60, 181) / WINDOW
    model = VaryingCrowdModel(bridge, walkers.with_density(CrowdProfile.constant(0.4)),
                              frequency, duration=HOUR, welch_window_length=WINDOW, crowd_model="smeared")
    assert model.levels == pytest.approx([0.4]) and model.crowd.density == pytest.approx(0.4)
    assert model.psd_array(MSDModel()) == pytest.approx(SpectralModel(
        bridge, walkers.with_density(0.4), frequency,
        welch_window_length=WINDOW).psd_array(MSDModel()), rel=1e-12)


def test_levels_are_a_gauss_rule_of_the_density_law(bridge, walkers):
    # The n-point Gauss rule integrates polynomials of degree 2n − 1 exactly: the levels give
    # the density law's mean and variance (density_law: deck densities weighted by the Welch
    # windows' Hann²). A ramp's deck mean over [0, 3600] s is 0.6 less the half-crossing lag
    # 0.8/3600 · τ/2, the ends weighed less by Hann².
    ramp = PROFILES["ramp"]
    model = VaryingCrowdModel(bridge, walkers.with_density(ramp), np.arange(60, 181) / WINDOW,
                              duration=HOUR, welch_window_length=WINDOW, crowd_model="smeared")
    density, weight = density_law(bridge, walkers.with_density(ramp), HOUR,
                                  welch_window_length=WINDOW)
    assert model.levels.size >= 3 and model.probabilities.sum() == pytest.approx(1.0)
    for power in (1, 2, 3):
        assert model.probabilities @ model.levels**power == pytest.approx(
            weight @ density**power, rel=1e-9)
    assert np.all((model.levels > 0.2) & (model.levels < 1.0))
    tau = bridge.length / walkers.walking_speed
    assert model.crowd.density == pytest.approx(0.6 - 0.8 / HOUR * tau / 2, abs=2e-3)


@pytest.fixture(scope="module")
def records(bridge, walkers):
    """Three seeded hours of each profile at 50 Hz, as Welch PSDs of 60 s windows."""
    return {name: [welch_psd(simulate(bridge, walkers.with_density(profile), HOUR, msd=MSDModel(),
                                      rng=seed, sample_rate=RATE,
                                      warm_up=60.0).acceleration, RATE,
                             window_length=WINDOW) for seed in range(3)]
            for name, profile in PROFILES.items()}


@pytest.mark.parametrize("crowd_model", ["smeared", "fluctuating"])
@pytest.mark.parametrize("name", ["ramp", "day"])
def test_expected_psd_matches_the_simulator(bridge, walkers, records, name, crowd_model):
    # The mean of R Welch PSDs has ν = R ν_Welch(K) degrees of freedom; windows of different
    # expectations scatter more by Σ p G²/Ḡ² (variance_ratio). z² = (Ĝ/Ḡ − 1)² ν/(2 ratio) over
    # the bins within 10 % of the peak has mean ~1: below the 99.9 % point of χ²_m/m with m half
    # the bins (neighbouring Hann bins are correlated). The model of the mean density fails it.
    psds = records[name]
    frequency = psds[0].frequency
    band = (frequency >= 1.5) & (frequency <= 2.5)
    measured = np.mean([p.psd[0, band] for p in psds], axis=0)
    nu = len(psds) * welch_degrees_of_freedom(psds[0].n_windows)
    options = dict(duration=HOUR, welch_window_length=WINDOW, crowd_model=crowd_model,
                   **({"n_nodes": 3} if crowd_model == "fluctuating" else {}))
    crowd = walkers.with_density(PROFILES[name])
    model = VaryingCrowdModel(bridge, crowd, frequency[band], **options)
    expected, ratio = model.psd_array(MSDModel())[0], model.variance_ratio(MSDModel())[0]
    near = expected > 0.1 * expected.max()
    half = near.sum() / 2
    bound = stats.chi2.ppf(0.999, half) / half
    z2 = ((measured / expected - 1) ** 2 * nu / (2 * ratio))[near]
    assert z2.mean() < bound
    mean_density = VaryingCrowdModel(bridge, crowd, frequency[band],
                                     levels=1, **options).psd_array(MSDModel())[0]
    assert ((measured / mean_density - 1) ** 2 * nu / 2)[near].mean() > 10 * bound


def test_bad_varying_model(bridge, walkers):
    ramp = walkers.with_density(PROFILES["ramp"])
    with pytest.raises(ParameterError, match=r"levels must be an integer from 1 to 40, got 0"):
        VaryingCrowdModel(bridge, ramp, [1.0, 2.0], duration=HOUR, levels=0)
    with pytest.raises(ParameterError, match=r"duration must hold one Welch window: 30 s"):
        VaryingCrowdModel(bridge, ramp, [1.0, 2.0], duration=30.0,
                          welch_window_length=WINDOW)
    # The model of a crowd that changes needs a profile, and a density is a number or one.
    with pytest.raises(ParameterError, match=r"crowd.density must be a CrowdProfile .* got the "
                                             r"number 0.6"):
        VaryingCrowdModel(bridge, walkers, [1.0, 2.0], duration=HOUR)
    with pytest.raises(ParameterError, match=r"density must be a number \[persons/m²\] or a "
                                             r"CrowdProfile, got \[0.2, 0.4\]"):
        walkers.with_density([0.2, 0.4])


def test_profile_in_minutes_warns_at_the_call(bridge, walkers):
    with pytest.warns(PlausibilityWarning, match=r"in minutes\? \(they would span 300 s\)") as caught:
        simulate(bridge, walkers.with_density(CrowdProfile([0.0, 5.0], [0.2, 0.8])), 300.0, rng=1,
                 sample_rate=RATE)
    assert caught[0].filename == __file__
