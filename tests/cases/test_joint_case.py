"""Joint fits from case files: several [[measurement]] blocks, one MSD (docs: theory, Joint estimation).

Two Gaussian records of the paper example (docs: theory, The paper's numerical example) at 0.25
and 0.5 P/m², half an hour each, with one true MSD (3.0 Hz, 0.30): `crowdvib estimate` must give
what :func:`crowdvib.estimate_hsi_joint` gives on the same Welch PSDs (the reference), cover the
truth, and draw the fit and its residuals per record.
"""

import json
from pathlib import Path

import numpy as np
import pytest

from crowdvib import (Crowd, LowPassFilter, ModalModel, MSDModel, ParameterError,
                      estimate_hsi_joint, response_psd, welch_psd)
from crowdvib.cli import main
from crowdvib.io.casefile import load_case
from crowdvib.io.records import Record, write_record
from crowdvib.signals.synthesis import gaussian_record, record_frequencies

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
BRIDGE = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3,
                                          outputs={"midspan": 25.0})
TRUTH = MSDModel(3.0, 0.30, 0.95)
RATE, DURATION = 25.0, 1800.0
BLOCKS = {"quarter": 0.25, "half": 0.5}


def _crowd(density):
    return Crowd(density=density, walking_speed=1.30, step_frequency_mean=1.89,
                 step_frequency_std=0.175, body_mass=70.0)


def _case_text(blocks):
    head = (EXAMPLES / "paper_example.toml").read_text().split("[measurement]")[0]
    tail = "[estimation]" + (EXAMPLES / "paper_example.toml").read_text().split(
        "[estimation]")[1]
    return head + blocks + tail


def _block(name, density):
    return (f'[[measurement]]\nname = "{name}"\nfiles = ["{name}.npz"]\nwindow_length = 60.0\n'
            f'filter = {{ cutoff = 10.0, order = 4 }}\n\n[measurement.crowd]\n'
            f'density = {density}\nwalking_speed = 1.30\nstep_frequency_mean = 1.89\n'
            f'step_frequency_std = 0.175\nbody_mass = 70.0\n\n')


@pytest.fixture(scope="module")
def joint_case(tmp_path_factory):
    folder = tmp_path_factory.mktemp("joint")
    frequency = record_frequencies(DURATION, RATE)
    for seed, (name, density) in enumerate(BLOCKS.items()):
        psd = response_psd(BRIDGE, _crowd(density), frequency, msd=TRUTH, crowd_model="smeared").psd
        data = gaussian_record(psd, RATE, rng=seed + 1)
        write_record(Record(data=data, sample_rate=RATE, channel_names=("midspan",)),
                     folder / f"{name}.npz")
    case = folder / "joint.toml"
    case.write_text(_case_text("".join(_block(n, d) for n, d in BLOCKS.items())),
                    encoding="utf-8")
    return case


def test_blocks_are_read_with_their_own_crowds(joint_case):
    case = load_case(joint_case)
    assert [b.name for b in case.records] == ["quarter", "half"]
    assert [b.crowd.density for b in case.records] == [0.25, 0.5]
    assert [c.crowd.density for c in case.blocks()] == [0.25, 0.5]
    assert case.blocks()[1].measurement.files[0].name == "half.npz"


def test_blocks_need_distinct_names(tmp_path):
    path = tmp_path / "twice.toml"
    path.write_text(_case_text(_block("same", 0.25) + _block("same", 0.5)), encoding="utf-8")
    with pytest.raises(ParameterError, match=r"measurement blocks must have distinct names"):
        load_case(path)


@pytest.mark.slow
def test_estimate_fits_one_msd_to_both_records(joint_case, tmp_path):
    out = tmp_path / "out"
    assert main(["estimate", str(joint_case), "--out", str(out)]) == 0
    results = json.loads((out / "results.json").read_text())
    found = results["estimate"]
    measurements, crowds = [], []
    for name, density in BLOCKS.items():
        from crowdvib.io.records import read_record

        record = read_record(joint_case.parent / f"{name}.npz")
        measurements.append(welch_psd(record.data, RATE, window_length=60.0,
                                      output_names=["midspan"],
                                      lowpass=LowPassFilter(10.0, 4, RATE)))
        crowds.append(_crowd(density))
    reference = estimate_hsi_joint(measurements, BRIDGE, crowds, band=(0.0, 10.0))
    assert found["frequency"] == pytest.approx(reference.msd.frequency, rel=1e-6)
    assert found["damping_ratio"] == pytest.approx(reference.msd.damping_ratio, rel=1e-6)
    for key in ("frequency", "damping_ratio"):
        low, high = found["interval"][key]
        assert low <= getattr(TRUTH, key) <= high
    assert results["diagnostics"]["output_names"] == ["record 1: midspan", "record 2: midspan"]
    assert [r["name"] for r in results["records"]] == ["quarter", "half"]
    figures = sorted(results["figures"])
    assert [f for f in figures if f.startswith("residuals_")] == [
        "residuals_half_midspan.png", "residuals_quarter_midspan.png"]
    assert all((out / f).exists() for f in figures)
    assert "residuals of the joint fit" in (out / "report.html").read_text() or \
        "Relative residuals" in (out / "report.html").read_text()
    assert np.isfinite(results["diagnostics"]["relative_cost"])
