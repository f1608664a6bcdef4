"""A case file's crowd that changes within its record: ``[crowd] counts = "counts.csv"`` or
``density_profile`` (crowdvib.io.casefile; docs: theory, A crowd that changes; issue 28 §1)."""

import warnings

import numpy as np
import pytest

from crowdvib import (Crowd, CrowdProfile, ModalModel, MSDModel, ParameterError, Record,
                      simulate, write_record)
from crowdvib.cases import estimate_case
from crowdvib.io.casefile import load_case

BEAM = ('[structure]\ntype = "simply_supported_beam"\nspan = 50.0\nwidth = 3.0\n'
        'frequency = 2.0\ndamping_ratio = 0.005\nmodal_mass = 5e4\n'
        'outputs = { midspan = 25.0 }\n')


def _case(tmp_path, crowd, measurement="", csv=("counts.csv", "time,count\n0,30\n600,90\n")):
    (tmp_path / csv[0]).write_text(csv[1])
    path = tmp_path / "case.toml"
    path.write_text(BEAM + "[crowd]\n" + crowd + measurement)
    return path


def test_counts_become_the_case_profile(tmp_path):
    # density = count/(L·B), L·B = 150 m², held over each interval; the walkers' reference
    # density (speed, step frequency) defaults to the profile's mean over its table.
    case = load_case(_case(tmp_path, 'counts = "counts.csv"\n'))
    assert case.crowd.profile.kind == "step"
    assert case.crowd.profile.density == pytest.approx([0.2, 0.6])
    assert case.reference_density == pytest.approx(0.2)      # the mean over [0, 600] s
    assert case.stationary_crowd().density == pytest.approx(0.2)
    # Every command's inputs (results.json, the report) show it with the crowd.
    assert case.inputs(["crowd"])["crowd"]["profile"] == {
        "kind": "step", "time": [0.0, 600.0], "density": pytest.approx([0.2, 0.6])}
    # A density profile is linear by default; a time frame moves the record's t = 0.
    path = _case(tmp_path, 'density_profile = "d.csv"\ndensity = 0.5\n',
                 '[measurement]\ntime_frame = [100.0, 700.0]\n',
                 ("d.csv", "time,density\n0,0.2\n3600,1.0\n"))
    case = load_case(path)
    assert case.crowd.profile.kind == "linear" and case.reference_density == 0.5
    assert case.inputs(["crowd"])["crowd"]["density"] == 0.5
    assert case.record_crowd().profile.density_at(0.0) == pytest.approx(0.2 + 0.8 * 100 / 3600)


@pytest.mark.parametrize("crowd, measurement, message", [
    ('counts = "counts.csv"\ndensity_profile = "counts.csv"\n', "",
     r"crowd.counts and crowd.density_profile must not both be given"),
    ('density_profile = "counts.csv"\n', "",
     r"missing column\(s\) \['density'\]"),
    ('counts = "counts.csv"\n', '[measurement]\ntime_frame = "stationary"\n',
     r'must come with one \[measurement\] .* got time_frame = "stationary"'),
    ('counts = "counts.csv"\n', '[measurement]\noverlap = 0.75\n',
     r"Welch windows at overlap 0.5 \(as the estimator places them\), got overlap = 0.75"),
    ('counts = "counts.csv"\nprofile_kind = "cubic"\n', "",
     r"crowd.profile_kind must be one of \['linear', 'step'\], got 'cubic'"),
])
def test_bad_case_profile(tmp_path, crowd, measurement, message):
    with pytest.raises(ParameterError, match=message):
        load_case(_case(tmp_path, crowd, measurement))


def test_bad_counts_name_the_file(tmp_path):
    path = _case(tmp_path, 'counts = "counts.csv"\n',
                 csv=("counts.csv", "time,count\n0,30\n600,9000\n"))
    with pytest.raises(ParameterError, match=r"case.toml: crowd.counts \(counts.csv\): count must "
                                             r"stay below the jam density"):
        load_case(path)


def test_simulate_case_follows_the_counts(tmp_path):
    # crowdvib simulate draws the case's stream: 30 then 90 people counted (a step at 600 s).
    # Means over 5-minute blocks away from the step, within 4 Poisson standard deviations of a
    # time-average (variance m τ/B, tests/response/test_varying_crowd.py).
    from crowdvib.cases import simulate_case

    case = load_case(_case(tmp_path, 'counts = "counts.csv"\n'))
    on_deck = simulate_case(case, duration=1200.0, sample_rate=10.0, seed=4,
                            hsi=False).simulation.n_on_deck
    tau = 50.0 / case.crowd.walking_speed
    for people, block in ((30, slice(2000, 5000)), (90, slice(8000, 11000))):
        assert abs(on_deck[block].mean() - people) < 4 * np.sqrt(people * tau / 300)


def _ramp_case(tmp_path):
    """An hour whose crowd ramps 0.2 → 1.0 P/m², counted per minute, fitted by least squares
    on 0.5–10 Hz (as tests/identification/test_varying_crowd_estimate.py) → the case's path."""
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    profile = CrowdProfile([0.0, 3600.0], [0.2, 1.0])
    record = simulate(bridge, Crowd.from_density(0.6).with_density(profile), 3600.0,
                      msd=MSDModel(), rng=1, sample_rate=50.0, warm_up=60.0)
    write_record(Record(record.acceleration, 50.0, record.output_names), tmp_path / "ramp.npz")
    minutes = np.arange(60) * 60.0
    counts = np.array([profile.mean(t, t + 60.0) for t in minutes]) * bridge.area
    table = "time,count\n" + "".join(f"{t:g},{c:.3f}\n" for t, c in zip(minutes, counts))
    path = _case(tmp_path, 'counts = "counts.csv"\ndensity = 0.6\n',
                 '[measurement]\nfiles = ["ramp.npz"]\n[measurement.filter]\ncutoff = false\n'
                 '[estimation]\nmethod = "least_squares"\nband = [0.5, 10.0]\n',
                 ("counts.csv", table))
    return path


def test_estimate_case_uses_the_counts(tmp_path):
    # The case's estimate with the counts holds the truth (docs: theory, A crowd that changes).
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = estimate_case(load_case(_ramp_case(tmp_path)))
    low, high = fit.estimate.intervals["frequency"]
    assert low < 3.0 < high
    low, high = fit.estimate.intervals["damping_ratio"]
    assert low < 0.30 < high
    # The estimator was given the counted crowd; the estimate's crowd for the stationary figures
    # (mode shapes, `crowdvib estimate`'s results) is its walkers at the file's density 0.6.
    assert fit.records[0].crowd.profile is not None
    assert fit.crowd.profile is None and fit.crowd.density == 0.6


def test_map_and_sensitivity_fit_the_crowd_that_was_counted(tmp_path):
    # Every command that estimates fits the counted crowd: `crowdvib map`'s estimate and its
    # landscape, and `crowdvib sensitivity`'s nominal estimate and its studies, are those of
    # `crowdvib estimate` (before, they silently fitted the stationary crowd at the mean).
    from crowdvib.cases import map_case, study_case
    from crowdvib.identification import PSDObjective

    case = load_case(_ramp_case(tmp_path))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = estimate_case(case)
        mapped = map_case(case, frequencies=[2.5, 3.0, 3.5], damping_ratios=[0.2, 0.3])
        study = study_case(case, levels={"frequencies": (0.01,)}, joint=False,
                           record_length=False)
    truth_fit = (fit.estimate.msd.frequency, fit.estimate.msd.damping_ratio)
    assert (mapped.estimate.msd.frequency, mapped.estimate.msd.damping_ratio) == truth_fit
    assert (study.study.nominal["frequency"], study.study.nominal["damping_ratio"]) == truth_fit
    # The map's costs are the counted crowd's objective (the reference: PSDObjective with the
    # case's profile, as the estimator builds it).
    objective = PSDObjective(fit.records[0].measurement.psd, case.structure,
                             fit.crowd.with_density(case.record_crowd().density),
                             band=(0.5, 10.0), method="least_squares")
    assert mapped.landscape.cost[1, 1] == pytest.approx(objective.cost(MSDModel(3.0, 0.3, 0.95)),
                                                        rel=1e-12)


def test_a_season_refuses_a_counted_case(tmp_path):
    from crowdvib.cases import season_case

    path = _case(tmp_path, 'counts = "counts.csv"\n')
    (tmp_path / "crowd.csv").write_text("record,density\nr.npz,0.5\n", encoding="utf-8")
    with pytest.raises(ParameterError, match=r"case.toml: crowd.counts or crowd.density_profile "
                                             r"must not be given for a season: the crowd table "
                                             r"gives each record's crowd"):
        season_case(load_case(path), tmp_path / "crowd.csv")
