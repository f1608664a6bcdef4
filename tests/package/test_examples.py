"""The example cases: records made by crowdvib, and what the paper does with them (issue 4)."""

from pathlib import Path

import numpy as np
import pytest

from crowdvib import LowPassFilter, welch_psd
from crowdvib.io.casefile import load_case, load_measurement
from crowdvib.identification import estimate_step_frequencies
from crowdvib.signals import psd_convergence

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(scope="module")
def waalse_krook():
    case = load_case(EXAMPLES / "waalse_krook_like.toml")
    return case, load_measurement(case)


def test_example_records_match_their_cases():
    for name in ("paper_example", "eeklo_like", "waalse_krook_like"):
        case = load_case(EXAMPLES / f"{name}.toml")
        record = load_measurement(case)
        assert set(record.channel_names) == set(case.structure.output_names)
        assert record.duration == pytest.approx(case.simulation.duration)
        # Small files: float32 at 25 Hz (issue 4 asks for small example records).
        assert all(f.stat().st_size < 1_000_000 for f in case.measurement.files)


def test_waalse_krook_like_record_is_eight_minutes(waalse_krook):
    # docs: theory, The paper's case studies / §6: 8-minute record, T = 60 s, 50 % overlap → 15 Welch windows.
    case, record = waalse_krook
    assert record.duration == pytest.approx(480.0)
    psd = welch_psd(record.data, record.sample_rate, window_length=60.0)
    assert psd.n_windows == 15


def test_waalse_krook_like_step_frequency_fit_recovers_the_crowd(waalse_krook):
    # The record was simulated with N(1.68, 0.13) Hz ([expected]; the paper's WK crowd,
    # docs: theory, The paper's case studies). Issue 4: μ within 2 %, σ within 20 %, from the 2.3 Hz low-passed PSD
    # without HSI, started away from the truth.
    case, record = waalse_krook
    low = LowPassFilter(2.3, 4, record.sample_rate)
    measured = welch_psd(record.data, record.sample_rate, window_length=60.0,
                         output_names=record.channel_names, lowpass=low)
    result = estimate_step_frequencies(measured, case.structure, case.crowd, cutoff=2.3,
                                       band=(1.0, 2.3), starts=[(1.8, 0.2)])
    assert result.crowd.step_frequency_mean == pytest.approx(
        case.expected["step_frequency_mean"], rel=0.02)
    assert result.crowd.step_frequency_std == pytest.approx(
        case.expected["step_frequency_std"], rel=0.20)
    assert result.cost < result.cost_initial or result.starts[0]["start"] == [1.8, 0.2]
    assert result.crowd.density == case.crowd.density    # only (μ, σ) are fitted


def test_waalse_krook_like_convergence_falls_as_windows_are_added(waalse_krook):
    # Paper Fig. 15: ΔG_kT falls with k; the paper reports ≈ 10 % between k = 7 and n_T = 8.
    case, record = waalse_krook
    conv = psd_convergence(record.data, record.sample_rate, window_length=60.0, band=(2.0, 6.0),
                           lowpass=LowPassFilter(10.0, 4, record.sample_rate))
    assert conv.n_windows.tolist() == list(range(1, 9))
    error = conv.error[:, :-1]
    assert np.all(error[:, 0] > error[:, -1])
    assert np.all(np.diff(error, axis=1) < 0.05)      # never rises by more than 5 points
    assert np.all(error[:, -1] < 0.25)


def test_step_frequency_fit_needs_the_lowpassed_psd(waalse_krook):
    from crowdvib.errors import ParameterError
    case, record = waalse_krook
    measured = welch_psd(record.data, record.sample_rate, window_length=60.0,
                         output_names=record.channel_names)
    with pytest.raises(ParameterError, match=r"measured.lowpass must be the low-pass filter at "
                                             r"cutoff 2.3 Hz"):
        estimate_step_frequencies(measured, case.structure, case.crowd)


def test_ambient_example_runs_through_crowdvib_modes(tmp_path):
    # Issue 27 §1: the ambient-test example runs with `crowdvib modes` and finds the modes
    # examples/make_examples.py shook the beam with (AMBIENT_FREQUENCIES = 2.0, 7.5 Hz;
    # AMBIENT_DAMPING = 0.5 %, 0.8 %); the record stays small.
    import csv

    from crowdvib.cli.main import main

    pytest.importorskip("pyoma2")
    ambient = EXAMPLES / "ambient" / "paper_beam_ambient.toml"
    assert (EXAMPLES / "ambient" / "paper_beam_ambient_record.npz").stat().st_size < 1_000_000
    assert main(["modes", str(ambient), "--out", str(tmp_path / "out")]) == 0
    with open(tmp_path / "out" / "modes.csv", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    assert [float(r["frequency"]) for r in rows] == pytest.approx([2.0, 7.5], rel=0.005)
    assert [float(r["damping_ratio"]) for r in rows] == pytest.approx([0.005, 0.008], rel=0.25)
    # [modal_model] made the modal-model files a case file reads (structure.modal_table)
    assert (tmp_path / "out" / "modal_table.csv").exists()


def test_cli_reference_has_a_working_example_per_command():
    # Issue 27 §1: the CLI reference (docs/cli.rst) shows an example per command; each parses
    # with the real parser and names files that exist in examples/.
    import shlex

    from crowdvib.cli import build_parser

    text = (EXAMPLES.parent / "docs" / "cli.rst").read_text(encoding="utf-8")
    # the examples are the literal blocks of the commands' sections
    lines = [line.strip() for line in text.splitlines() if line.startswith(" " * 9 + "crowdvib ")]
    parser = build_parser()
    commands = set(parser._subparsers._group_actions[0].choices)
    seen = set()
    for line in lines:
        words = shlex.split(line)[1:]
        args = parser.parse_args(words)                 # a usage error exits: the test fails
        seen.add(words[0])
        for word in words:
            if word.startswith("examples/"):
                assert (EXAMPLES.parent / word).exists(), line
        assert args.command == words[0]
    assert seen == commands
