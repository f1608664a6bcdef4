"""Several OMA setups merged on a shared reference sensor (docs: theory, Operational modal
analysis, several setups; issue 13)."""

import json
import warnings

import numpy as np
import pytest

from crowdvib import (
    IdentifiabilityWarning,
    ModalModel,
    ParameterError,
    Record,
    identify_modes,
    write_record,
)
from crowdvib.cli import main
from crowdvib.oma.modeid import ModeIdentification
from crowdvib.oma.multisetup import merge_setups
from crowdvib.oma.identify import ambient_response

pytest.importorskip("pyoma2")

# The truth: the 3-mode bridge of test_oma (50 m simply supported, sine modes: closed form).
FREQUENCIES = np.array([2.0, 3.1, 6.5])
DAMPING = np.array([0.005, 0.012, 0.02])
MASSES = np.array([50e3, 40e3, 60e3])
SAMPLE_RATE, DURATION = 20.0, 1800.0
# Two setups; the first sensor of each (20 m, on no node of the three modes) is the reference.
SETUP_POSITIONS = (np.array([20.0, 10.0, 30.0]), np.array([20.0, 35.0, 42.5]))
#: Ambient load levels of the two setups [N²/Hz]: the wind changed between them.
LOADS = (200.0**2, 120.0**2)


def sine_rows(positions):
    """Mode shapes of the simply supported 50 m beam at ``positions`` (closed form)."""
    return np.sin(np.pi * np.outer(positions, np.arange(1, 4)) / 50.0)


def setup_records(seed):
    """30 min of ambient response per setup (independent white-noise modal loads)."""
    x = np.linspace(0.0, 50.0, 101)
    records = []
    for k, (positions, load) in enumerate(zip(SETUP_POSITIONS, LOADS)):
        names = tuple(f"p{v:g}" for v in positions)
        structure = ModalModel(FREQUENCIES, DAMPING, MASSES, x, sine_rows(x), 3.0, names,
                               sine_rows(positions))
        records.append(ambient_response(structure, DURATION, SAMPLE_RATE, load,
                                        rng=100 * seed + k))
    return records


def _mac(a, b):
    return (a * b).sum(0) ** 2 / ((a * a).sum(0) * (b * b).sum(0))


@pytest.fixture(scope="module")
def merged():
    return identify_modes(setup_records(1), SAMPLE_RATE, n_modes=3, frequency_band=(1.0, 9.0),
                          max_order=24, reference_sensors=[[0], [0]],
                          sensor_names=[["ref", "a", "b"], ["ref", "c", "d"]])


def test_two_setups_merge_to_the_sine_modes(merged):
    assert merged.sensor_names == ("ref", "a", "b", "c", "d")
    truth = sine_rows(np.concatenate([SETUP_POSITIONS[0], SETUP_POSITIONS[1][1:]]))
    assert np.all(_mac(merged.mode_shapes, truth) > 0.99)          # issue 13's criterion
    np.testing.assert_allclose(merged.frequencies, FREQUENCIES, rtol=0.005)
    # f is the inverse-variance weighted mean of the setups' (docs: several setups)
    f = np.array([s.frequencies for s in merged.setups])
    w = 1 / np.array([s.frequency_std for s in merged.setups]) ** 2
    np.testing.assert_allclose(merged.frequencies, (w * f).sum(0) / w.sum(0), rtol=1e-12)
    assert np.all(merged.frequency_std >= 1 / np.sqrt(w.sum(0)) * (1 - 1e-12))
    assert [s.sensor_names for s in merged.setups] == [("ref", "a", "b"), ("ref", "c", "d")]


def _identification(shapes, frequencies, frequency_std, names):
    n = shapes.shape[1]
    return ModeIdentification(np.asarray(frequencies, float), np.full(n, 0.01),
                              np.asarray(frequency_std, float), np.full(n, 0.001), shapes,
                              tuple(names), 20.0, {})


def test_poser_rescaling_and_weighted_mean_closed_form():
    # Exact sine shapes, each setup scaled by its own (negative, arbitrary) factor: the merge
    # must give back the sine shapes at all five sensors, +1 at the largest.
    first, second = sine_rows(SETUP_POSITIONS[0]), sine_rows(SETUP_POSITIONS[1])
    setups = [_identification(first * [-2.5, 0.3, 1.0], [2.0, 3.1, 6.5], [0.01, 0.01, 0.02],
                              "rab"),
              _identification(second * [0.7, -4.0, 0.2], [2.02, 3.1, 6.6], [0.01, 0.02, 0.01],
                              "rcd")]
    merged = merge_setups(setups, [np.array([0]), np.array([0])])
    truth = sine_rows(np.concatenate([SETUP_POSITIONS[0], SETUP_POSITIONS[1][1:]]))
    truth = truth / truth[np.argmax(np.abs(truth), axis=0), np.arange(3)]
    np.testing.assert_allclose(merged.mode_shapes, truth, atol=1e-12)
    # Mode 1: equal σ → mean 2.01; χ² = 2 (0.01/0.01)² = 2 > n − 1: σ widened by the Birge
    # ratio √2 → 0.01/√2 · √2 = 0.01 (hand computation).
    assert merged.frequencies[0] == pytest.approx(2.01, abs=1e-12)
    assert merged.frequency_std[0] == pytest.approx(0.01, abs=1e-12)
    # Mode 2: equal values → weighted mean 3.1, σ = 1/√(1/0.01² + 1/0.02²), Birge ratio 0
    assert merged.frequency_std[1] == pytest.approx(1 / np.sqrt(1e4 + 2.5e3), abs=1e-12)


def test_reference_on_a_node_is_warned():
    # 25 m is a node of mode 2: its rescaling in a setup referenced there is ill-conditioned.
    first, second = sine_rows(np.array([25.0, 10.0])), sine_rows(np.array([25.0, 40.0]))
    setups = [_identification(first, FREQUENCIES, [0.01] * 3, ["r", "a"]),
              _identification(second, FREQUENCIES, [0.01] * 3, ["r", "b"])]
    with pytest.warns(IdentifiabilityWarning, match=r"mode 2: its reference components"):
        merge_setups(setups, [np.array([0]), np.array([0])])


@pytest.mark.parametrize("kwargs, pattern", [
    ({"reference_sensors": [[0]]}, r"reference_sensors must give per setup \(2\)"),
    ({"reference_sensors": [[0], [5]]}, r"reference_sensors\[1\] must hold 1 distinct row "
                                        r"indices in \[0, 2\]"),
    ({"reference_sensors": [[0], [0]], "sensor_names": [["r", "a", "b"], ["s", "c", "d"]]},
     r"reference sensors must have the same names in every setup"),
])
def test_bad_setups(kwargs, pattern):
    records = [np.zeros((3, 200)), np.zeros((3, 300))]
    with pytest.raises(ParameterError, match=pattern):
        identify_modes(records, 20.0, **kwargs)


def test_one_array_is_not_several_setups():
    with pytest.raises(ParameterError, match=r"signals must be a sequence of at least 2 setups"):
        identify_modes(np.zeros((3, 200)), 20.0, reference_sensors=[[0], [0]])


def test_modes_cli_merges_setups(tmp_path):
    """``crowdvib modes`` with two [[record]] blocks sharing the channel "ref"."""
    for k, data in enumerate(setup_records(1)):
        write_record(Record(data, SAMPLE_RATE, ["ref", "a", "b"]), tmp_path / f"setup{k}.csv")
    (tmp_path / "ambient.toml").write_text(
        '[[record]]\nfile = "setup0.csv"\n[[record]]\nfile = "setup1.csv"\n'
        '[identification]\nn_modes = 3\nfrequency_band = [1.0, 9.0]\nmax_order = 24\n'
        'reference_channels = ["ref"]\n')
    out = tmp_path / "out"
    with warnings.catch_warnings():
        warnings.simplefilter("error", IdentifiabilityWarning)
        assert main(["modes", str(tmp_path / "ambient.toml"), "--out", str(out)]) == 0
    shapes = np.genfromtxt(out / "mode_shapes.csv", delimiter=",", names=True, dtype=None,
                           encoding="utf-8")
    # the roving channels share names across records: qualified by their setup
    assert shapes["sensor"].tolist() == ["ref", "a (setup 1)", "b (setup 1)", "a (setup 2)",
                                         "b (setup 2)"]
    truth = sine_rows(np.concatenate([SETUP_POSITIONS[0], SETUP_POSITIONS[1][1:]]))
    merged = np.column_stack([shapes[f"mode_{j}"] for j in (1, 2, 3)])
    assert np.all(_mac(merged, truth) > 0.99)
    results = json.loads((out / "results.json").read_text())
    assert len(results["setups"]) == 2
    assert "stabilisation_setup2.png" in results["figures"]
    assert "<h3>Setups</h3>" in (out / "report.html").read_text(encoding="utf-8")


def test_modes_cli_several_records_need_their_references(tmp_path, capsys):
    data = np.zeros((2, 200))
    for k in range(2):
        write_record(Record(data, SAMPLE_RATE, ["ref", "a"]), tmp_path / f"s{k}.csv")
    (tmp_path / "ambient.toml").write_text(
        '[[record]]\nfile = "s0.csv"\n[[record]]\nfile = "s1.csv"\n')
    assert main(["modes", str(tmp_path / "ambient.toml"), "--out", str(tmp_path / "o")]) == 1
    assert ("identification.reference_channels is required with several [[record]] blocks"
            in capsys.readouterr().err)
    (tmp_path / "ambient.toml").write_text(
        '[[record]]\nfile = "s0.csv"\n[[record]]\nfile = "s1.csv"\n'
        '[identification]\nreference_channels = ["r"]\n')
    assert main(["modes", str(tmp_path / "ambient.toml"), "--out", str(tmp_path / "o")]) == 1
    assert "record 1 lacks ['r']" in capsys.readouterr().err
