"""Measured walking forces replayed by the simulator (docs: theory, Measured walking forces; issue 13)."""

import numpy as np
import pytest
from scipy import signal

from crowdvib import Crowd, ParameterError, Pedestrian, SpectralModel, simulate
from crowdvib.models import MeasuredForce, ZivanovicForce
from crowdvib.models.measured import builtin_walking_forces, replay_value
from crowdvib.response import generate_traffic

# Per walk: step frequency [Hz] and first-harmonic DLF [-], copied from summary_derived.csv, the
# derived table that accompanies the PhysioNet gaitpdb records (see
# crowdvib/data/WALKING_FORCES_PROVENANCE.txt): Welch PSD, 30 s windows, 10 s cut at each end,
# DLF_k = sqrt(2 ∫ G df over ±0.2 Hz around k f_step) / mean force.
SUMMARY = {
    "GaCo01_01": (1.633, 0.109), "GaCo02_01": (1.800, 0.128), "GaCo02_02": (1.933, 0.151),
    "GaCo03_01": (1.667, 0.107), "GaCo03_02": (1.800, 0.144), "GaCo04_01": (1.633, 0.292),
    "GaCo04_02": (1.667, 0.298), "GaCo05_01": (1.933, 0.179),
}
MASS = 70.0
G = 9.81


def welch_step_and_dlf1(force, weight, sample_rate=100.0):
    """The summary table's recipe on a dynamic force history normalised by ``weight``."""
    frequency, psd = signal.welch(force, sample_rate, nperseg=int(30 * sample_rate))
    band = (frequency > 1.2) & (frequency < 2.6)
    step = frequency[band][np.argmax(psd[band])]
    power = psd[np.abs(frequency - step) <= 0.2].sum() * (frequency[1] - frequency[0])
    return step, np.sqrt(2 * power) / weight


def replayed(bridge, force, duration, step_frequency=1.8, seed=3, **options):
    """Modal load of one walker on the spot at midspan (φ = 1 there): the replayed force itself."""
    walker = Pedestrian(0.0, 0.0, step_frequency, MASS, position=bridge.length / 2)
    return simulate(bridge, pedestrians=[walker], duration=duration, force=force, rng=seed,
                    record_modal_load=True, **options)


def test_packaged_records_are_the_eight_walks():
    names, forces, rate = builtin_walking_forces()
    assert names == tuple(SUMMARY)
    assert rate == 100.0 and forces.shape == (8, 12119)
    # Insoles read 1.20–1.33 × body weight (README of the source): the mean force must be
    # ~1.2–1.33 × m g for the subjects' body masses (demographics: 83, 70, 70, 101, 101, 65, 65, 88 kg).
    masses = np.array([83, 70, 70, 101, 101, 65, 65, 88.0])
    ratio = forces.mean(axis=1) / (masses * G)
    assert np.all((ratio > 1.19) & (ratio < 1.34))


@pytest.mark.parametrize("name", list(SUMMARY))
def test_replay_reproduces_step_frequency_and_dlf1(paper_bridge, name, reference):
    force = MeasuredForce(records=[name], time_scale=False, random_start=False)
    duration = force.table.shape[1] / 100.0          # the whole trimmed walk, as measured
    record = replayed(paper_bridge, force, duration)
    step, dlf1 = welch_step_and_dlf1(record.modal_load[0], MASS * G)
    expected_step, expected_dlf1 = SUMMARY[name]
    source = "summary_derived.csv of the PhysioNet gaitpdb records (issue 13: within 5 %)"
    reference(f"replayed walk {name}: step frequency", step, expected_step, rel=0.05, unit="Hz",
              source=source)
    reference(f"replayed walk {name}: first-harmonic DLF", dlf1, expected_dlf1, rel=0.05,
              source=source)


def test_time_scaling_sets_the_walkers_step_frequency(paper_bridge):
    """Replayed at f_s = 2.1 Hz: the mean step frequency (centroid of the peak) moves there."""
    from crowdvib.models.measured import _mean_step_frequency

    force = MeasuredForce(records=["GaCo04_01"], random_start=False)
    native = _mean_step_frequency(force.table[0], 100.0)
    once = force.table.shape[1] / 100.0 * native / 2.1      # the walk once, compressed in time
    record = replayed(paper_bridge, force, once, step_frequency=2.1)
    assert native < 1.7
    assert _mean_step_frequency(record.modal_load[0], 100.0) == pytest.approx(2.1, rel=0.01)


def test_zivanovic_first_harmonic_option(paper_bridge):
    """first_harmonic="zivanovic": DLF1 = μ₁(f_s) of the Kerr polynomial (docs: theory, Živanović)."""
    force = MeasuredForce(records=["GaCo02_01"], first_harmonic="zivanovic")
    record = replayed(paper_bridge, force, force.table.shape[1] / 100.0 / 1.8 * force
                      .record_step_frequency[0], step_frequency=1.8)
    _, dlf1 = welch_step_and_dlf1(record.modal_load[0], MASS * G)
    assert dlf1 == pytest.approx(float(ZivanovicForce.first_harmonic_dlf(1.8)), rel=0.05)


def test_kernel_replay_equals_numpy_twin(paper_bridge):
    """The kernel's table look-up equals MeasuredForce.time_history (same seed, same draws)."""
    force = MeasuredForce()
    record = replayed(paper_bridge, force, 20.0, step_frequency=1.75, seed=8)
    expected = force.time_history(record.time, 1.75, MASS, rng=8)
    np.testing.assert_allclose(record.modal_load[0], expected, rtol=0, atol=1e-9 * MASS * G)
    assert np.std(expected) > 0.05 * MASS * G


def test_replay_value_interpolates_and_wraps():
    row = np.array([0.0, 1.0, 4.0, 9.0])
    # linear between samples; past the end the row continues periodically (9 → 0)
    np.testing.assert_allclose(replay_value(row, [0.5, 2.25, 3.5, 4.0, 5.5, -0.5]),
                               [0.5, 5.25, 4.5, 0.0, 2.5, 4.5])


def test_crowd_seeded_reproducible_and_chunk_invariant(paper_bridge, paper_crowd, paper_msd):
    force = MeasuredForce()
    one = simulate(paper_bridge, paper_crowd, 30.0, msd=paper_msd, force=force, rng=11,
                   record_modal_load=True)
    again = simulate(paper_bridge, paper_crowd, 30.0, msd=paper_msd, force=force, rng=11,
                     record_modal_load=True)
    chunked = simulate(paper_bridge, paper_crowd, 30.0, msd=paper_msd, force=force, rng=11,
                       record_modal_load=True, chunk_duration=7.3)
    other = simulate(paper_bridge, paper_crowd, 30.0, msd=paper_msd, force=force, rng=12)
    assert np.array_equal(one.acceleration, again.acceleration)
    assert np.array_equal(one.acceleration, chunked.acceleration)
    assert np.array_equal(one.modal_load, chunked.modal_load)
    assert not np.array_equal(one.acceleration, other.acceleration)
    assert np.std(one.acceleration) > 0


def test_mixed_crowd_keeps_explicit_harmonics(paper_bridge):
    """An explicit harmonic pedestrian keeps its sinusoid when the crowd replays records."""
    walker = Pedestrian(0.0, 0.0, 2.0, MASS, position=25.0, harmonics=[(1.0, 0.4, 0.0)])
    record = simulate(paper_bridge, pedestrians=[walker], duration=5.0, rng=1,
                      force=MeasuredForce(), record_modal_load=True)
    # closed form: W α sin(2π f t) at φ = 1
    np.testing.assert_allclose(record.modal_load[0],
                               MASS * G * 0.4 * np.sin(2 * np.pi * 2.0 * record.time),
                               atol=1e-6)


def test_spectral_side_refuses_measured_force(paper_bridge, paper_crowd):
    with pytest.raises(ParameterError, match="no load PSD"):
        SpectralModel(paper_bridge, paper_crowd, np.arange(1, 100) / 10, force=MeasuredForce())
    with pytest.raises(ParameterError, match="cannot be written as harmonics"):
        generate_traffic(paper_bridge, Crowd.from_density(0.2), 10.0, force=MeasuredForce())


@pytest.mark.parametrize("options, pattern", [
    ({"records": ["GaCo99_01"]}, r"records must name packaged walks"),
    ({"first_harmonic": "young"}, r"first_harmonic must be 'measured' or 'zivanovic', got 'young'"),
    ({"forces": np.ones(100), "sample_rate": 100.0}, r"forces must be \(n_records, n_samples\)"),
    ({"forces": np.ones((1, 1000)), "sample_rate": -1.0}, r"sample_rate must be > 0 Hz"),
    ({"time_scale": "yes"}, r"time_scale must be True or False"),
])
def test_bad_options(options, pattern):
    with pytest.raises(ParameterError, match=pattern):
        MeasuredForce(**options)
