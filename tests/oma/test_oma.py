"""Operational modal analysis of the empty bridge (docs: theory, Operational modal analysis; issue 13)."""

import json
from dataclasses import replace

import numpy as np
import pytest

from crowdvib import (
    ModalModel,
    ParameterError,
    Pedestrian,
    Record,
    identify_modes,
    simulate,
    write_record,
)
from crowdvib.cli import main
from crowdvib.reporting.report import render_report
from crowdvib.oma.modeid import compare_identifications
from crowdvib.oma.identify import ambient_response
from crowdvib.studies.modelling_error import error_cases
from crowdvib.io import read_modal_model

pytest.importorskip("pyoma2")

# The truth: an empty 3-mode bridge, 50 m simply supported, sine modes (closed form).
FREQUENCIES = np.array([2.0, 3.1, 6.5])
DAMPING = np.array([0.005, 0.012, 0.02])
MASSES = np.array([50e3, 40e3, 60e3])
SENSORS = {"s1": 12.5, "s2": 25.0, "s3": 37.5}
SAMPLE_RATE, DURATION = 20.0, 1800.0


def bridge():
    x = np.linspace(0.0, 50.0, 101)
    order = np.arange(1, 4)
    return ModalModel(FREQUENCIES, DAMPING, MASSES, x, np.sin(np.pi * np.outer(x, order) / 50),
                      3.0, tuple(SENSORS),
                      np.sin(np.pi * np.outer(list(SENSORS.values()), order) / 50))


def ambient_record(structure, seed):
    """30 min: independent white-noise modal loads plus five walkers (simulate)."""
    ambient = ambient_response(structure, DURATION, SAMPLE_RATE, 200.0**2, rng=seed)
    walkers = [Pedestrian(t, 1.3, 1.70 + 0.04 * k, 70.0)
               for k, t in enumerate([10.0, 400.0, 800.0, 1200.0, 1500.0])]
    crowd = simulate(structure, pedestrians=walkers, duration=DURATION,
                     sample_rate=5 * SAMPLE_RATE, rng=seed)
    return ambient + crowd.acceleration[:, ::5]


@pytest.fixture(scope="module")
def ambient():
    return ambient_record(bridge(), 3)


@pytest.fixture(scope="module")
def identified(ambient):
    return bridge(), identify_modes(ambient, SAMPLE_RATE, n_modes=3, frequency_band=(1.0, 9.0),
                                    sensor_names=list(SENSORS), max_order=24, cross_check=True)


#: The seeds of benchmarks/bench_oma.py (its default run).
SEEDS = range(1, 9)


@pytest.fixture(scope="module")
def over_seeds():
    """Per method: relative errors of f and ξ and errors in σ, arrays (seed, mode)."""
    result = {}
    records = [ambient_record(bridge(), seed) for seed in SEEDS]
    for method in ("ssi-cov", "efdd"):
        rows = []
        for record in records:
            modes = identify_modes(record, SAMPLE_RATE, n_modes=3, frequency_band=(1.0, 9.0),
                                   max_order=24, method=method)
            rows.append((modes.frequencies / FREQUENCIES - 1, modes.damping_ratios / DAMPING - 1,
                         (modes.frequencies - FREQUENCIES) / modes.frequency_std,
                         (modes.damping_ratios - DAMPING) / modes.damping_std))
        result[method] = [np.array([r[i] for r in rows]) for i in range(4)]
    return result


# Issue 13: f within 0.5 % and ξ within 20 % on a 30-min record, ±1.96 σ covering the truth.
# What is true on the benchmark's 8 seeds (benchmarks/bench_oma.py; docs: theory, Operational
# modal analysis, accuracy): every f within 0.5 %; ξ of modes 2 and 3 within 20 % (SSI-cov:
# mode 3 of seed 8 at −22.6 %); ξ of the 0.5 % mode within 20 % on 6 of 8 seeds only (seeds 5
# and 6 beyond). That is the information bound, not a defect of the method: σ_ξ/ξ ≥ 1/√(2π f ξ T)
# = 9.4 % for it, so ±20 % is 2.1 σ, and an efficient estimator (maximum likelihood on the exact
# modal coordinates, `bench_oma.py bound`) is itself 29 % off on seed 6. The reported σ covers
# the truth on at least 7 of 8 seeds per mode and parameter.
@pytest.mark.parametrize("method, damping_within, covered", [
    ("ssi-cov", (6, 8, 7), 7), ("efdd", (6, 8, 8), 7)])
def test_accuracy_over_the_benchmark_seeds(over_seeds, method, damping_within, covered):
    f_error, xi_error, f_z, xi_z = over_seeds[method]
    assert np.all(np.abs(f_error) <= 0.005)
    assert np.all(np.sum(np.abs(xi_error) <= 0.20, axis=0) >= damping_within)
    assert np.all(np.sum(np.abs(f_z) <= 1.96, axis=0) >= covered)
    assert np.all(np.sum(np.abs(xi_z) <= 1.96, axis=0) >= covered)


def test_three_modes_recovered_with_covering_std(identified):
    _, modes = identified
    np.testing.assert_allclose(modes.frequencies, FREQUENCIES, rtol=0.005)
    np.testing.assert_allclose(modes.damping_ratios, DAMPING, rtol=0.20)
    # the 95 % interval ±1.96 σ covers the truth
    assert np.all(np.abs(modes.frequencies - FREQUENCIES) <= 1.96 * modes.frequency_std)
    assert np.all(np.abs(modes.damping_ratios - DAMPING) <= 1.96 * modes.damping_std)
    # never below the information bound σ_ξ = ξ/√(2π f ξ T) (docs: theory, information bound)
    bound = modes.damping_ratios / np.sqrt(2 * np.pi * modes.frequencies * modes.damping_ratios
                                           * DURATION)
    assert np.all(modes.damping_std >= bound * (1 - 1e-12))
    # shapes at the sensors: MAC with the sine rows (closed form) > 0.99
    truth = bridge().output_shapes
    mac = (modes.mode_shapes * truth).sum(0) ** 2 / ((modes.mode_shapes**2).sum(0)
                                                    * (truth**2).sum(0))
    assert np.all(mac > 0.99)


def test_cross_check_is_the_independent_efdd(ambient, identified):
    _, modes = identified
    check = modes.cross_check
    assert check.method == "efdd" and np.all(check.agree)
    # EFDD seeded at the SSI-cov frequencies finds the same peaks as EFDD alone (peak picking)
    alone = identify_modes(ambient, SAMPLE_RATE, n_modes=3, frequency_band=(1.0, 9.0),
                           sensor_names=list(SENSORS), method="efdd")
    np.testing.assert_array_equal(check.frequencies, alone.frequencies)
    np.testing.assert_array_equal(check.damping_std, alone.damping_std)
    np.testing.assert_allclose(check.damping_difference,
                               alone.damping_ratios - modes.damping_ratios, rtol=1e-12)
    np.testing.assert_allclose(check.damping_z, check.damping_difference / np.hypot(
        modes.damping_std, alone.damping_std), rtol=1e-12)
    # a mode whose damping the second method doubles is flagged; a missing one too
    doubled = replace(alone, damping_ratios=alone.damping_ratios * [1, 2, 1])
    assert compare_identifications(modes, doubled).agree.tolist() == [True, False, True]
    missing = replace(alone, frequencies=alone.frequencies * [1, 1, 1.2])
    flagged = compare_identifications(modes, missing)
    assert flagged.agree.tolist() == [True, True, False] and np.isnan(flagged.frequencies[2])


def test_modal_model_from_fe_pairing_and_from_stated_masses(identified):
    structure, modes = identified
    fe = structure.replace(frequencies=FREQUENCIES * 1.05, damping_ratios=[0.01, 0.01, 0.01])
    paired = modes.modal_model(fe)
    np.testing.assert_array_equal(paired.frequencies, modes.frequencies)
    np.testing.assert_array_equal(paired.modal_masses, MASSES)        # the FE model's
    coarse = modes.modal_model(modal_masses=MASSES, sensor_positions=list(SENSORS.values()),
                               walkway=(0.0, 50.0), width=3.0)
    # first mode: 1 at midspan, 0 at the supports, linear between (the documented coarse shape)
    np.testing.assert_allclose(coarse.mode_shapes[0, :, 0], [0.0, modes.mode_shapes[0, 0] /
                                                             modes.mode_shapes[1, 0], 1.0,
                                                             modes.mode_shapes[2, 0] /
                                                             modes.mode_shapes[1, 0], 0.0])
    levels = modes.error_levels()
    assert levels["frequencies"] == (max(modes.frequency_std / modes.frequencies),
                                     2 * max(modes.frequency_std / modes.frequencies))
    assert len(error_cases(levels)) == 1 + 2 * (2 * 5 + 2**5)    # accepted by the study
    figure = modes.plot_stabilisation()
    assert figure.axes[0].get_xlabel() == "frequency [Hz]"
    with pytest.raises(ParameterError, match="OMA gives no modal masses"):
        modes.modal_model()


def test_efdd_with_one_sensor(ambient):
    # One sensor: every MAC is 1, so the bells stop halfway (geometric mean) between the modes
    # (docs: theory, EFDD step 3); the sensor at 12.5 m sees all three modes.
    modes = identify_modes(ambient[:1], SAMPLE_RATE, n_modes=3, frequency_band=(1.0, 9.0),
                           method="efdd")
    np.testing.assert_allclose(modes.frequencies, FREQUENCIES, rtol=0.005)
    np.testing.assert_allclose(modes.damping_ratios, DAMPING, rtol=0.20)
    targets = modes.poles["targets"]                      # the peaks picked on s₁
    middles = np.sqrt(targets[1:] * targets[:-1])
    bells = np.array(modes.poles["bells"])
    assert np.all(bells[:-1, 1] <= middles) and np.all(bells[1:, 0] >= middles)


@pytest.mark.parametrize("call, pattern", [
    (lambda: identify_modes(np.zeros((2, 50)), 20.0), r"signals must have shape"),
    (lambda: identify_modes(np.zeros((2, 500)), 20.0, method="fdd"),
     r"method must be one of 'ssi-cov', 'efdd', got 'fdd'"),
    (lambda: identify_modes(np.zeros((2, 500)), 20.0, frequency_band=(5, 50)),
     r"frequency_band must satisfy 0 <= low < high <= Nyquist \(10 Hz\)"),
    (lambda: identify_modes(np.zeros((2, 500)), 20.0, sensor_names=["a"]),
     r"sensor_names must name 2 sensors"),
    (lambda: identify_modes(np.zeros((2, 500)), 20.0, mac_threshold=1.5),
     r"mac_threshold must lie in \(0, 1\), got 1.5"),
    (lambda: identify_modes(np.zeros((2, 500)), 20.0, segment_length=10),
     r"segment_length must be an integer >= 64, got 10"),
    (lambda: identify_modes(np.zeros((2, 500)), 20.0, n_modes=0),
     r"n_modes must be a positive integer, got 0"),
])
def test_bad_input(call, pattern):
    with pytest.raises(ParameterError, match=pattern):
        call()


def test_modes_cli_writes_the_identified_modes(ambient, tmp_path):
    """``crowdvib modes``: the same identification from a CSV record, files and report written."""
    write_record(Record(ambient, SAMPLE_RATE, list(SENSORS)), tmp_path / "ambient.csv")
    (tmp_path / "ambient.toml").write_text(
        'name = "three-mode bridge"\n[record]\nfile = "ambient.csv"\n'
        '[identification]\nn_modes = 3\nfrequency_band = [1.0, 9.0]\nmax_order = 24\n'
        '[modal_model]\nmodal_masses = [5e4, 4e4, 6e4]\nsensor_positions = [12.5, 25.0, 37.5]\n'
        'walkway = [0.0, 50.0]\nwidth = 3.0\n')
    out = tmp_path / "out"
    assert main(["modes", str(tmp_path / "ambient.toml"), "--out", str(out)]) == 0
    table = np.genfromtxt(out / "modes.csv", delimiter=",", names=True, dtype=None,
                          encoding="utf-8")
    np.testing.assert_allclose(table["frequency"], FREQUENCIES, rtol=0.005)
    model = read_modal_model(out / "modal_table.csv", out / "modal_shapes.csv", width=3.0,
                             output_points=out / "output_points.csv")
    np.testing.assert_allclose(model.modal_masses, MASSES)
    assert (out / "report.html").is_file() and (out / "stabilisation.png").is_file()


def test_modes_cli_cross_check(ambient, tmp_path, capsys):
    """``crowdvib modes --cross-check``: EFDD beside SSI-cov in a CSV, results.json and report."""
    write_record(Record(ambient, SAMPLE_RATE, list(SENSORS)), tmp_path / "ambient.csv")
    (tmp_path / "ambient.toml").write_text(
        '[record]\nfile = "ambient.csv"\n[identification]\nn_modes = 3\n'
        'frequency_band = [1.0, 9.0]\nmax_order = 24\n')
    out = tmp_path / "out"
    assert main(["modes", str(tmp_path / "ambient.toml"), "--out", str(out),
                 "--cross-check"]) == 0
    table = np.genfromtxt(out / "cross_check.csv", delimiter=",", names=True, dtype=None,
                          encoding="utf-8")
    modes = np.genfromtxt(out / "modes.csv", delimiter=",", names=True, dtype=None,
                          encoding="utf-8")
    np.testing.assert_allclose(table["frequency"] - modes["frequency"],
                               table["frequency_difference"], atol=1e-9)
    assert table["agree"].tolist() == [True] * 3                 # genfromtxt reads True
    results = json.loads((out / "results.json").read_text())
    assert results["cross_check"]["method"] == "efdd"
    assert results["figures"] == ["stabilisation.png", "singular_values.png", "mode_shapes.png"]
    report = (out / "report.html").read_text(encoding="utf-8")
    assert "Cross-check by EFDD" in report
    assert "EFDD confirms all 3 modes of SSI-cov within 1.96 combined σ" in report
    assert "verdict: no warnings" in capsys.readouterr().out


def test_report_warns_of_a_mode_the_methods_disagree_on():
    # A results.json as crowdvib modes writes it, mode 2's damping 5 combined σ apart.
    mode = {"frequency": 3.1, "frequency_std": 0.003, "damping_ratio": 0.012,
            "damping_std": 0.001}
    check = {"frequency": 3.101, "frequency_std": 0.003, "damping_ratio": 0.0191,
             "damping_std": 0.001, "frequency_difference": 0.001, "damping_difference": 0.0071,
             "frequency_z": 0.24, "damping_z": 5.0, "mac": 0.999, "agree": False}
    results = {"command": "modes", "method": "ssi-cov", "modes": [mode, mode],
               "cross_check": {"method": "efdd", "level": 1.96,
                               "modes": [{**check, "damping_z": 0.1, "agree": True}, check]}}
    text = render_report(results)
    assert "mode 2: SSI-cov and EFDD disagree beyond 1.96 combined σ" in text
    assert "mode 1: SSI-cov and EFDD disagree" not in text


def test_modes_cli_names_a_misspelt_key(tmp_path, capsys):
    (tmp_path / "bad.toml").write_text('[record]\nfile = "x.csv"\nchanels = ["a"]\n')
    (tmp_path / "x.csv").write_text("time,a\n0,0\n0.1,1\n0.2,0\n")
    assert main(["modes", str(tmp_path / "bad.toml"), "--out", str(tmp_path / "o")]) == 1
    assert "record.chanels" in capsys.readouterr().err
