"""A joint fit of records whose crowds change, from a case file: each ``[[measurement]]`` block's
``[measurement.crowd]`` gives its own ``counts`` (issue 28 §1; docs: theory, A crowd that changes,
and Joint estimation).

Two records of walkers on the paper's bridge (docs: theory, The paper's numerical example), an
hour each at 25 Hz, one counted while the crowd grows from 0.2 to 1.0 P/m², one while it thins
from 1.0 to 0.2: the case's joint estimate must be :func:`crowdvib.estimate_hsi_joint` with the
two profiles, and cover the truth where the blocks' mean densities put f_h1 low (as on one
record, tests/identification/test_varying_crowd_estimate.py).
"""

import warnings

import numpy as np
import pytest

from crowdvib import (Crowd, CrowdProfile, ModalModel, MSDModel, ParameterError,
                      estimate_hsi_joint, simulate)
from crowdvib.cases import estimate_case
from crowdvib.io.casefile import load_case
from crowdvib.io.records import Record, write_record

BRIDGE = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3,
                                          outputs={"midspan": 25.0})
TRUTH = MSDModel(3.0, 0.30, 0.95)
RATE, HOUR = 25.0, 3600.0
MINUTES = np.arange(0.0, HOUR, 60.0)
#: People counted on the 150 m² deck each minute: a ramp up and a ramp down.
COUNTS = {"growing": np.round(150.0 * np.linspace(0.2, 1.0, MINUTES.size)),
          "thinning": np.round(150.0 * np.linspace(1.0, 0.2, MINUTES.size))}
WALKERS = 'walking_speed = 1.30\nstep_frequency_mean = 1.89\nstep_frequency_std = 0.175\n'
HEAD = ('[structure]\ntype = "simply_supported_beam"\nspan = 50.0\nwidth = 3.0\n'
        'frequency = 2.0\ndamping_ratio = 0.005\nmodal_mass = 5e4\n'
        'outputs = { midspan = 25.0 }\n\n[crowd]\ndensity = 0.6\n' + WALKERS + '\n')
TAIL = '[estimation]\nband = [0.5, 10.0]\n'


def _block(name, crowd):
    return (f'[[measurement]]\nname = "{name}"\nfiles = ["{name}.npz"]\nwindow_length = 60.0\n'
            f'time_frame = [0.0, {HOUR}]\n\n[measurement.crowd]\n{crowd}' + WALKERS + '\n')


@pytest.fixture(scope="module")
def season(tmp_path_factory):
    folder = tmp_path_factory.mktemp("joint_profiles")
    for seed, (name, counts) in enumerate(COUNTS.items(), start=1):
        profile = CrowdProfile.from_counts(MINUTES, counts, BRIDGE.area)
        record = simulate(BRIDGE, Crowd.from_density(0.6).with_density(profile), HOUR, msd=TRUTH,
                          rng=seed, sample_rate=RATE, warm_up=60.0)
        write_record(Record(record.acceleration, RATE, ("midspan",)), folder / f"{name}.npz")
        lines = ["time,count"] + [f"{t:g},{c:g}" for t, c in zip(MINUTES, counts)]
        (folder / f"{name}.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
    counted = folder / "counted.toml"
    counted.write_text(HEAD + "".join(_block(n, f'counts = "{n}.csv"\n') for n in COUNTS)
                       + TAIL, encoding="utf-8")
    mean = folder / "mean.toml"
    mean.write_text(HEAD + "".join(_block(n, "density = 0.6\n") for n in COUNTS) + TAIL,
                    encoding="utf-8")
    return counted, mean


@pytest.mark.slow
def test_joint_fit_with_each_records_counts_recovers_the_truth(season):
    counted, mean = season
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")      # the mean-density fit may warn of its misfit
        with_counts = estimate_case(load_case(counted))
        at_the_mean = estimate_case(load_case(mean))
    case = with_counts.case
    assert [b.crowd.profile.density_at(30.0) for b in case.records] == pytest.approx(
        [COUNTS["growing"][0] / 150.0, COUNTS["thinning"][0] / 150.0])
    # The case's joint fit is estimate_hsi_joint with the blocks' crowds, each carrying its
    # profile (the reference).
    parts = with_counts.records
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reference = estimate_hsi_joint([p.measurement.psd for p in parts], BRIDGE,
                                       [b.crowd for b in case.records], band=(0.5, 10.0))
    estimate = with_counts.estimate
    assert estimate.msd.frequency == pytest.approx(reference.msd.frequency, rel=1e-9)
    assert estimate.msd.damping_ratio == pytest.approx(reference.msd.damping_ratio, rel=1e-9)
    # With the counts the 95 % intervals hold the truth; at the mean density (0.6 P/m² in
    # both) the model misses the dense windows, which weigh most, and puts f_h1 low.
    for name in ("frequency", "damping_ratio"):
        low, high = estimate.interval(name, 0.95)
        assert low <= getattr(TRUTH, name) <= high
    assert at_the_mean.estimate.interval("frequency", 0.95)[1] < TRUTH.frequency
    assert estimate.relative_cost < 0.5 * at_the_mean.estimate.relative_cost


def test_a_crowd_for_every_record():
    # Each record's crowd carries its own density (a number or a profile): one crowd per record.
    with pytest.raises(ParameterError, match=r"measurements and crowds must pair up one record "
                                             r"with one crowd, got 2 measurement\(s\) and 1 "
                                             r"crowd\(s\)"):
        estimate_hsi_joint([None, None], BRIDGE, [Crowd.from_density(0.5)], band=(0.5, 10.0))


def test_a_block_profile_needs_the_records_time(tmp_path):
    (tmp_path / "c.csv").write_text("time,count\n0,30\n600,90\n", encoding="utf-8")
    path = tmp_path / "case.toml"
    path.write_text(HEAD + _block("one", 'counts = "c.csv"\n').replace(
        f"time_frame = [0.0, {HOUR}]", 'time_frame = "stationary"') + _block("two", "density = 0.5\n")
        + TAIL, encoding="utf-8")
    with pytest.raises(ParameterError, match=r'case.toml: measurement\[1\].crowd.counts or '
                                             r'measurement\[1\].crowd.density_profile must come '
                                             r'with its \[\[measurement\]\] block whose '
                                             r'time_frame .* got time_frame = "stationary"'):
        load_case(path)
