"""Simulation in bounded memory (issue 28 §3): the stream drawn a block at a time and windowed to
the kernel, compact records, and the PSD-only run ``simulate_psd``."""

import os
import subprocess
import sys

import numpy as np
import pytest

from crowdvib import ParameterError, Simulation, simulate, simulate_psd, welch_psd
from crowdvib.models.examples import paper_example
from crowdvib.response.time_domain import traffic


@pytest.fixture(scope="module")
def case():
    return paper_example()


def test_the_same_seed_gives_the_record_it_gave_before_streaming(case):
    # Reference: the same call on 8add6f1, before the stream was windowed (issue 28 §3 asks for
    # the same record from the same seed). The people on the deck are exact integers on any
    # computer; the accelerations agree to round-off across vector widths (simulate's docs).
    record = simulate(case.structure, case.crowd, 300.0, rng=4, chunk_duration=7.0)
    assert record.n_pedestrians == 677
    assert int(record.n_on_deck.astype(np.int64).sum()) == 2263767
    assert np.sqrt(np.mean(record.acceleration**2)) == pytest.approx(0.6320797974210813,
                                                                    rel=1e-9)
    assert record.acceleration[0, 1234] == pytest.approx(0.18376589947171454, rel=1e-9)
    hsi = simulate(case.structure, case.crowd, 600.0, msd=case.msd, rng=3, warm_up=20.0,
                   record_modal_load=True)
    assert hsi.n_pedestrians == 1277
    assert int(hsi.n_on_deck.astype(np.int64).sum()) == 4528173
    assert np.sqrt(np.mean(hsi.acceleration**2)) == pytest.approx(0.2923953191153193, rel=1e-9)


def test_a_stream_of_many_blocks_is_the_same_for_any_chunking(case, monkeypatch):
    # 100-walker blocks: the 300 s stream (~700 walkers) spans seven, each drawn from its own
    # generator and drawn again when a window needs it after eviction. The record depends on
    # the seed only (issue 28 §3), bit for bit whatever the chunk length.
    monkeypatch.setattr(traffic, "STREAM_BLOCK", 100)
    one = simulate(case.structure, case.crowd, 300.0, msd=case.msd, rng=2, chunk_duration=300.0)
    chunked = simulate(case.structure, case.crowd, 300.0, msd=case.msd, rng=2,
                       chunk_duration=1.7)
    assert one.n_pedestrians > 6 * 100
    np.testing.assert_array_equal(one.acceleration, chunked.acceleration)
    np.testing.assert_array_equal(one.n_on_deck, chunked.n_on_deck)
    # ...and it is a stream like any other: the deck holds d·B·L = 75 people on average
    # (docs: theory, Poisson arrivals), with the Poisson scatter of a 5-minute record.
    assert 60 < one.n_on_deck.mean() < 90


def test_windows_of_the_stream_are_its_slices(case, monkeypatch):
    # The kernel sees the stream a window at a time: any split gives the same walkers as the
    # stream taken whole (blocks evicted and drawn again in between).
    monkeypatch.setattr(traffic, "STREAM_BLOCK", 50)
    from crowdvib.models.loading import as_force_model

    force = as_force_model(None, time_domain=True)

    def stream():
        return traffic._Stream(case.structure, case.crowd, [], 0.0, 200.0, force,
                               np.random.default_rng(9))

    whole = stream().window(0, stream().size)[0]
    pieces = stream()
    cuts = [0, 17, 120, 121, 300, pieces.size]
    parts = [pieces.window(a, b)[0] for a, b in zip(cuts[:-1], cuts[1:])]
    for name in ("t_on", "t_off", "lateral", "step_frequency", "body_mass", "dlf", "phase"):
        np.testing.assert_array_equal(np.concatenate([getattr(p, name) for p in parts]),
                                      getattr(whole, name))
    assert np.all(np.diff(whole.t_on) >= 0)              # in order of arrival


def test_the_record_is_compact(case):
    record = simulate(case.structure, case.crowd, 60.0, rng=1)
    # n_on_deck: 2 bytes a sample (int16 holds any real deck), the time axis computed on read.
    assert record.n_on_deck.dtype == np.int16
    assert record.n_on_deck.nbytes == 2 * record.n_samples
    assert record.__dict__["_time"] is None
    np.testing.assert_array_equal(record.time, np.arange(6000) / 100.0)
    assert not record.time.flags.writeable
    # A given axis is kept as given (the dataclass's field, as before).
    given = Simulation(time=np.arange(4) * 0.5, acceleration=np.zeros((1, 4)),
                       output_names=("a",), n_on_deck=np.full(4, 40000), sample_rate=2.0,
                       seed=0, duration=2.0)
    np.testing.assert_array_equal(given.time, [0.0, 0.5, 1.0, 1.5])
    assert given.n_on_deck.dtype == np.int32             # 40 000 > the int16 range


def test_simulate_psd_is_welch_of_the_record(case):
    # The same seed and options: Welch of simulate's record (crowdvib.welch_psd, Hann, 50 %)
    # and the PSD summed chunk by chunk agree to round-off, whatever the chunks (7.3 s: shorter
    # than a window, so segments span chunks).
    options = dict(msd=case.msd, rng=5, warm_up=10.0)
    record = simulate(case.structure, case.crowd, 250.0, **options)
    expected = welch_psd(record.acceleration, 100.0, window_length=20.0,
                         output_names=record.output_names)
    result = simulate_psd(case.structure, case.crowd, 250.0, window_length=20.0,
                          chunk_duration=7.3, **options)
    assert result.psd.n_windows == expected.n_windows == 2 * 250 // 20 - 1
    np.testing.assert_array_equal(result.psd.frequency, expected.frequency)
    np.testing.assert_allclose(result.psd.psd, expected.psd, rtol=1e-12, atol=0.0)
    # The segments' scatter from running sums (centred products expanded about the mean).
    np.testing.assert_allclose(result.psd.dispersion, expected.dispersion, rtol=1e-9)
    summary = record.summary()
    np.testing.assert_allclose(result.rms, summary["rms"], rtol=1e-12)
    np.testing.assert_array_equal(result.peak, summary["peak"])
    assert result.mean_on_deck == pytest.approx(record.n_on_deck.mean(), rel=1e-12)
    assert result.max_on_deck == record.n_on_deck.max()
    assert (result.n_pedestrians, result.seed, result.duration) == (
        record.n_pedestrians, record.seed, 250.0)


def test_simulate_psd_refuses_a_window_longer_than_the_record(case):
    with pytest.raises(ParameterError, match=r"duration must hold one window: 10 s is shorter "
                                             r"than window_length = 20 s"):
        simulate_psd(case.structure, case.crowd, 10.0, window_length=20.0, rng=0)
    with pytest.raises(ParameterError, match=r"overlap must lie in \[0, 1\), got 1.0"):
        simulate_psd(case.structure, case.crowd, 100.0, window_length=20.0, overlap=1.0)


PEAK_RSS = """
import resource, sys
from crowdvib import simulate_psd
from crowdvib.models.examples import paper_example
case = paper_example()
simulate_psd(case.structure, case.crowd, float(sys.argv[1]), msd=case.msd, rng=0,
             window_length=60.0)
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
"""


def _peak_rss(seconds):
    """Peak RSS [MB] of a PSD-only run in a fresh process."""
    out = subprocess.run([sys.executable, "-c", PEAK_RSS, str(seconds)], check=True,
                         capture_output=True, text=True, env=dict(os.environ))
    return float(out.stdout.split()[-1])


@pytest.mark.slow
def test_psd_only_memory_does_not_grow_with_the_record(case):
    # Issue 28 §3: the whole record (and, before, every walker) grew with the duration: 1 h
    # 237 MB, 6 h 355 MB peak before the change. A PSD-only run keeps 32 bytes a walker and
    # at most three 65 536-walker blocks of draws: measured 1 h 217 MB, 6 h 229 MB
    # (benchmarks/bench_simulation_memory.py). 30 MB leaves room for the allocator's moods.
    hour, six_hours = _peak_rss(3600.0), _peak_rss(6 * 3600.0)
    assert six_hours - hour < 30.0, (hour, six_hours)


@pytest.mark.parametrize("forward_fraction", [0.0, 1.0])
def test_a_one_way_stream_walks_one_way(case, forward_fraction):
    # The stream lists the forward walkers first; with none (or only) of them, every walker
    # must still start at its own end and walk away from it (docs: theory, Poisson arrivals).
    from crowdvib import Crowd
    from crowdvib.response import generate_traffic

    crowd = Crowd(density=0.5, walking_speed=1.3, step_frequency_mean=1.87,
                  step_frequency_std=0.186, body_mass=75.0, forward_fraction=forward_fraction)
    walkers = generate_traffic(case.structure, crowd, 100.0, rng=1)
    direction = 1 if forward_fraction else -1
    assert len(walkers) > 200                       # λT + dBL = 195 + 75 on average
    assert {w.direction for w in walkers} == {direction}
    assert {w.position for w in walkers} == {case.structure.positions[0 if direction > 0 else -1]}
