"""What a case file describes, run from Python (issue 26 §1): ``crowdvib.cases`` gives the objects
the commands compute, and the same numbers the commands write.

Reference: the command line itself. ``crowdvib estimate`` and ``crowdvib map`` are run on the same
case files and their results.json must equal the library's ``to_dict()`` (every number to 1e-12
relative: the same pipeline, so the same floating-point operations; only the provenance stamp,
the figures and the warnings are the command's own).
"""

import json
import math
from pathlib import Path

import pytest

from crowdvib._files import json_default
from crowdvib.cases import CaseEstimate, case_estimator, estimate_case, map_case
from crowdvib.cli import main
from crowdvib.errors import ParameterError
from crowdvib.io.casefile import load_case
from crowdvib.reporting.paths import without_machine_paths

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
#: Keys of results.json that are the command's and not the computation's (the provenance stamp
#: of reporting.report.provenance, the figures drawn, the warnings caught, the data of the
#: report's moving pictures: issue 38).
COMMAND_KEYS = {"created", "case_sha256", "figures", "warnings", "mode_shapes", "replay"}


def _as_json(value, tmp_path=None):
    """The library's dict as JSON; with ``tmp_path``, its paths as results.json in
    ``tmp_path / "out"`` holds them (relative to the results folder, issue 36 §3)."""
    value = json.loads(json.dumps(value, default=json_default))
    return value if tmp_path is None else without_machine_paths(value,
                                                                (tmp_path / "out").resolve())


def _assert_same(library, written, where="results"):
    """Equal structure, equal strings, numbers equal to 1e-12 relative."""
    if isinstance(library, dict):
        assert set(library) == set(written), where
        for key in library:
            _assert_same(library[key], written[key], f"{where}.{key}")
    elif isinstance(library, list):
        assert len(library) == len(written), where
        for i, (a, b) in enumerate(zip(library, written)):
            _assert_same(a, b, f"{where}[{i}]")
    elif isinstance(library, float) and isinstance(written, float) and math.isfinite(library):
        assert written == pytest.approx(library, rel=1e-12, abs=0.0), where
    else:
        assert library == written, where


def _written(tmp_path, argv, status=0):
    out = tmp_path / "out"
    assert main([argv[0], *argv[1:], "--out", str(out)]) == status
    results = json.loads((out / "results.json").read_text())
    assert {"created", "case_sha256", "figures"} <= set(results)     # simulate catches no warnings
    return {k: v for k, v in results.items() if k not in COMMAND_KEYS}


@pytest.mark.parametrize("name", ["paper_example",
                                  pytest.param("eeklo_like", marks=pytest.mark.slow)])
def test_estimate_case_gives_what_crowdvib_estimate_writes(tmp_path, name):
    case = load_case(EXAMPLES / f"{name}.toml")
    fit = estimate_case(case)
    assert isinstance(fit, CaseEstimate) and not fit.joint
    written = _written(tmp_path, ["estimate", str(case.path)])
    library = _as_json(fit.to_dict(), tmp_path)
    _assert_same(library, written)
    # The numbers the issue names, spelled out: f_h1, ξ_h1 and their intervals.
    for key in ("frequency", "damping_ratio"):
        assert written["estimate"][key] == pytest.approx(getattr(fit.estimate.msd, key),
                                                         rel=1e-12)
    for key in ("frequency", "damping_ratio"):
        interval = written["estimate"]["interval"][key]
        assert interval == pytest.approx(list(fit.estimate.intervals[key]), rel=1e-12)
    # The objects behind them: the record of the fitted outputs and its Welch PSD.
    part = fit.records[0]
    assert part.measurement.psd.window_length == case.measurement.window_length
    assert written["record"]["channel_names"] == list(part.measurement.record.channel_names)


def test_map_case_gives_what_crowdvib_map_writes(tmp_path):
    # A 5 × 3 grid around the paper example's MSD (docs: theory, The paper's numerical example).
    import numpy as np

    case = load_case(EXAMPLES / "paper_example.toml")
    found = map_case(case, frequencies=np.linspace(2.0, 4.0, 5),
                     damping_ratios=np.linspace(0.2, 0.4, 3))
    assert found.landscape.cost.size == 15 and found.seconds > 0
    written = _written(tmp_path, ["map", str(case.path), "--frequencies", "2:4:5",
                                  "--damping-ratios", "0.2:0.4:3"])
    _assert_same(_as_json(found.to_dict(), tmp_path), written)


def test_a_study_task_holds_the_point_estimates_choices_only():
    # The sensitivity study compares point estimates (cli sensitivity): its tasks hold no
    # interval choice (the density's uncertainty is one), and no pre-fit check of the level,
    # which the study's nominal estimate makes once.
    case = load_case(EXAMPLES / "paper_example.toml")
    estimator = case_estimator(case)
    full, point = estimator.options(), estimator.options(point_only=True)
    assert set(full) - set(point) == {"interval", "level", "n_boot", "density_uncertainty",
                                      "check_level"}
    assert point["band"] == case.estimation.band and point["mass_ratio"] == case.msd.mass_ratio


def test_check_case_gives_what_crowdvib_check_writes(tmp_path):
    # The design checks of examples/check_paper.toml (docs: theory, Design checks).
    from crowdvib.cases import CaseCheck, check_case

    case = load_case(EXAMPLES / "check_paper.toml")
    found = check_case(case)
    assert isinstance(found, CaseCheck) and list(found.checks) == list(case.design.codes)
    # The bridge fails design codes: the checks' answer, exit status 4 (docs: Command line).
    written = _written(tmp_path, ["check", str(case.path)], status=4)
    library = _as_json(found.to_dict(), tmp_path)
    # Wall-clock time is the run's own; everything else is the computation's.
    written.pop("elapsed_s"), library.pop("elapsed_s")
    _assert_same(library, written)
    assert [row["passes"] for row in written["design"]["verdict"]] == [
        row["passes"] for row in found.rows]


def test_simulate_case_gives_what_crowdvib_simulate_writes(tmp_path):
    # The paper example (docs: theory, The paper's numerical example), 300 s: the same seed gives
    # the same record, sample for sample, and the same results.json.
    from crowdvib.cases import CaseSimulation, simulate_case
    from crowdvib.io.records import read_record

    case = load_case(EXAMPLES / "paper_example.toml")
    found = simulate_case(case, duration=300.0)
    assert isinstance(found, CaseSimulation) and found.msd is not None
    written = _written(tmp_path, ["simulate", str(case.path), "--duration-s", "300",
                                  "--format", "npz"])
    assert written.pop("record").pop("files") == ["record.npz"]
    library = _as_json(found.to_dict(), tmp_path)
    library.pop("record"), written.pop("elapsed_s")
    _assert_same(library, written)
    # The file holds the samples in the case's simulation.dtype (float32 by default).
    record = read_record(tmp_path / "out" / "record.npz")
    stored = found.record.data.astype(case.simulation.dtype)
    assert record.data == pytest.approx(stored.astype(float), rel=1e-12, abs=0.0)


def test_the_case_files_force_model_reaches_the_estimate(tmp_path):
    # Case.force (the file's force = "young", docs: theory, Your own model) is the model the
    # pipeline fits with: the estimate differs from the default Živanović one, and the command
    # agrees with the library.
    from crowdvib.models import YoungForce

    text = (EXAMPLES / "paper_example.toml").read_text().replace(
        "paper_example_record.npz", str(EXAMPLES / "paper_example_record.npz"))
    path = tmp_path / "young.toml"
    path.write_text('force = "young"\n' + text)
    case = load_case(path)
    assert isinstance(case.force, YoungForce)
    young = estimate_case(case).estimate.msd
    default = estimate_case(load_case(EXAMPLES / "paper_example.toml")).estimate.msd
    assert abs(young.frequency / default.frequency - 1) > 1e-6
    written = _written(tmp_path, ["estimate", str(path)])
    assert written["estimate"]["frequency"] == pytest.approx(young.frequency, rel=1e-12)
    assert written["estimate"]["damping_ratio"] == pytest.approx(young.damping_ratio, rel=1e-12)


def test_a_measured_force_is_refused_by_the_estimate(tmp_path):
    # force = "measured" replays walking histories (time domain only, io.casefile.FORCE_MODELS):
    # the estimate's spectral model has no load PSD for it, so it is refused by name rather than
    # estimated silently with the default Živanović model, as before Case.force reached the
    # pipeline.
    text = (EXAMPLES / "paper_example.toml").read_text().replace(
        "paper_example_record.npz", str(EXAMPLES / "paper_example_record.npz"))
    path = tmp_path / "measured.toml"
    path.write_text('force = "measured"\n' + text)
    with pytest.raises(ParameterError, match="MeasuredForce replays measured histories"):
        estimate_case(load_case(path))
