"""Results that round-trip (issue 26 §2, "Must show"): a notebook-style session loads a case,
runs every command's work from Python and gets the results the command line writes;
``load_results`` reads each results.json back as its typed result, whose ``to_dict()`` is the
file and ``from_dict(to_dict(r)) == r``; the verdict is the same in Python, on the console and in
report.html.

Reference: the command line itself, run on the same example files (docs: :doc:`/results` for
the schema). Equality is exact: the same pipeline makes the same floating-point operations and
JSON keeps every digit of a float; only the keys the command adds itself (provenance stamp,
figures, caught warnings, wall-clock times, the record's files) are left out of the comparison.
"""

import json
from pathlib import Path

import pytest

from crowdvib import load_results
from crowdvib.cases import (SCHEMA, CheckResults, DemoResults, EstimateResults, MapResults,
                            ModesResults, Results, SensitivityResults, SimulateResults,
                            check_case, estimate_case, identify_ambient, map_case, simulate_case)
from crowdvib.cases.notebook import MAX_ROWS
from crowdvib.cases.verdict import is_doubt
from crowdvib.cli import main
from crowdvib.reporting.paths import without_machine_paths
from crowdvib.errors import DataError
from crowdvib.io.casefile import load_case

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
#: What a command adds to the computation's results: its provenance stamp, the figures it drew,
#: the warnings it caught, its wall-clock time, and the data of its report's moving pictures
#: (issue 38: the mode shapes, the crossing replay; figures of a kind, drawn by the report).
COMMAND_KEYS = {"created", "case_sha256", "figures", "warnings", "elapsed_s", "files",
                "mode_shapes", "replay"}


def _cli(out, argv, capsys):
    """Run a command into ``out``; its results.json as a dict, its result and its console text."""
    capsys.readouterr()
    status = main([*argv, "--out", str(out)])
    return _written(status, out, capsys.readouterr().out)


def _written(status, out, printed):
    """A command's run (its exit status, results folder ``out`` and console text), checked and
    read: its results.json as a dict, its result and its console text."""
    written = json.loads((out / "results.json").read_text(encoding="utf-8"))
    found = load_results(out / "results.json")
    # Exit status 3 exactly when the verdict doubts the result, else 4 when the bridge fails a
    # design code (docs: Command line, Exit status).
    doubts = found.in_doubt
    assert status == (3 if doubts else 4 if found.fails_design else 0), (status, found.verdict())
    # The file and the object hold the same thing, and the object survives its own dict.
    assert written["schema"] == SCHEMA and written["kind"] == found.kind
    assert found.to_dict() == written
    assert Results.from_dict(found.to_dict()) == found
    assert type(found).from_dict(found.to_dict()) == found
    _typed_parts(found)
    return written, found, printed


def _typed_parts(found):
    """Issue 34 §1: the results' parts are objects of the library, each back from its dict."""
    parts = found.parts()
    assert parts or found.kind == "simulate", found.kind      # a simulation without HSI: none
    for name, part in parts.items():
        items = (part.values() if isinstance(part, dict) else part if isinstance(part, tuple)
                 else (part,))
        for item in items:
            written = _json(item.to_dict())
            assert _json(type(item).from_dict(written).to_dict()) == written, (found.kind, name)


def _json(data):
    """What a results.json keeps of ``data`` (crowdvib's writer: NaN as null)."""
    from crowdvib._files import json_default

    return json.loads(json.dumps(data, default=json_default), parse_constant=lambda _: None)


def _here(computed, out):
    """A computation's results as its results folder ``out`` holds them: every path relative to
    the folder, or its name when far from it (issue 36 §3: no folder of the writer's machine)."""
    return without_machine_paths(computed, out.resolve())


def _computed(written):
    """The keys of a results.json the computation makes (not the command's own)."""
    kept = {k: v for k, v in written.items() if k not in COMMAND_KEYS}
    if isinstance(kept.get("record"), dict):      # simulate: the files written, per format
        kept["record"] = {k: v for k, v in kept["record"].items() if k != "files"}
    return kept


def _same_verdict(found, printed, out):
    """The console's verdict lines and report.html's summary box hold the result's findings."""
    doubts = [f.text for f in found.verdict() if is_doubt(f)]
    fails = [f.text for f in found.verdict() if f.severity == "fail" and not is_doubt(f)]
    if doubts:
        assert (f"check before use: the result itself is in doubt ({len(doubts)} warning(s)"
                in printed)
        # A run warning printed as raised is counted, not repeated (issue 36 §3).
        assert all(f"    - {text}" in printed or text in found.warnings for text in doubts)
    else:
        assert "verdict: no warnings" in printed or "not in doubt: no warnings" in printed
    assert all(f"    - {text}" in printed for text in fails)
    summary = (out / "report.html").read_text(encoding="utf-8").split(
        '<section id="summary">')[1].split("</section>")[0]
    assert summary.count("<li>") >= len(found.verdict())
    assert ("Check before use" in summary) == bool(doubts)
    assert ("The bridge fails" in summary) == bool(fails)


def test_a_notebook_session_gets_what_every_command_writes(tmp_path, capsys):
    import numpy as np

    case = load_case(EXAMPLES / "paper_example.toml")

    # crowdvib estimate
    fit = estimate_case(case)
    written, found, printed = _cli(tmp_path / "estimate", ["estimate", str(case.path)], capsys)
    assert isinstance(found, EstimateResults)
    # The file holds the computation, its paths relative to the results folder (issue 36 §3).
    assert _computed(written) == _here(fit.results().to_dict(), tmp_path / "estimate")
    assert written["case"] == "paper_example.toml"      # examples/ is not near tmp_path
    again = found.hsi_estimate()         # HSIEstimate.from_dict: the estimate back from the file
    assert again.msd == fit.estimate.msd and again.intervals == {
        name: tuple(fit.estimate.interval(name, fit.estimate.interval_level))
        for name in fit.estimate.free_parameters}
    assert again.to_dict()["estimate"]["standard_error"] == pytest.approx(
        written["estimate"]["standard_error"], rel=1e-12)     # through the covariance
    assert found.verdict() == fit.results(warnings=written["warnings"]).verdict()
    # The PSD's convergence as rows: one per window count; the full record against itself is 0.
    rows = found.convergence_table()
    assert [row["n_windows"] for row in rows] == list(fit.convergence.n_windows)
    assert rows[-1]["error"] == 0.0 and rows[-1]["output"] == "midspan"
    _same_verdict(found, printed, tmp_path / "estimate")

    # crowdvib map, a 5 × 3 grid around the paper's MSD (f_h1 = 3 Hz, ξ_h1 = 0.3)
    grid = map_case(case, frequencies=np.linspace(2.0, 4.0, 5),
                    damping_ratios=np.linspace(0.2, 0.4, 3))
    written, found, printed = _cli(tmp_path / "map", [
        "map", str(case.path), "--frequencies", "2:4:5", "--damping-ratios", "0.2:0.4:3"], capsys)
    assert isinstance(found, MapResults) and len(found.table()) == 15
    # One row per grid point; the second is (f_h1 = 2.5 Hz, ξ_h1 = 0.2), cost[ξ index, f index].
    assert found.table()[1] == {"frequency": 2.5, "damping_ratio": 0.2,
                                "cost": grid.landscape.cost[0, 1]}
    assert _computed(written) == _here(grid.results().to_dict(), tmp_path / "map")
    _same_verdict(found, printed, tmp_path / "map")

    # crowdvib simulate, 300 s of the same case (same seed, same record)
    simulation = simulate_case(case, duration=300.0)
    written, found, printed = _cli(tmp_path / "simulate", [
        "simulate", str(case.path), "--duration-s", "300", "--format", "npz"], capsys)
    assert isinstance(found, SimulateResults)
    assert _computed(written) == _computed(_here(simulation.results().to_dict(),
                                                 tmp_path / "simulate"))
    assert [row["output"] for row in found.table()] == list(case.structure.output_names)
    # Its notebook view holds its table, not an empty one (issue 36 §1): the RMS per output.
    assert all(f"<td>{row['output']}</td><td>{row['rms']:.4g}</td>" in found._repr_html_()
               for row in found.table())

    # crowdvib check (examples/check_paper.toml: the paper's bridge fails with HSI)
    design = load_case(EXAMPLES / "check_paper.toml")
    checks = check_case(design)
    written, found, printed = _cli(tmp_path / "check", ["check", str(design.path)], capsys)
    assert isinstance(found, CheckResults)
    assert _computed(written) == _computed(_here(checks.results().to_dict(), tmp_path / "check"))
    assert [f.severity for f in found.verdict()] == [f.severity for f in checks.verdict()]
    assert "fail" in {f.severity for f in found.verdict()} and not found.passes
    # Its notebook view holds the verdict rows (issue 36 §1), each utilisation as the table's.
    view, shown = found._repr_html_(), found.table()[:MAX_ROWS]      # 24 rows: the first 20
    assert view.count("<tr>") == len(shown) + 2 and "… and 4 more row(s)" in view
    assert all(f"<td>{row['utilisation']:.4g}</td>" in view for row in shown)
    assert "f_h1 = 3 Hz, ξ_h1 = 0.3, μ_h1 = 0.95 ([hsi])" in view         # the MSD it used
    # A given MSD ([hsi]) has no interval: asking says so, rather than returning None.
    with pytest.raises(DataError, match=r"no interval of frequency: the MSD was given "
                                        r"\(\[hsi\]\), not estimated"):
        found.interval("frequency")
    _same_verdict(found, printed, tmp_path / "check")

    # crowdvib modes on the ambient-test example (2.0 and 7.5 Hz)
    ambient = EXAMPLES / "ambient" / "paper_beam_ambient.toml"
    modes = identify_ambient(ambient)
    written, found, printed = _cli(tmp_path / "modes", ["modes", str(ambient)], capsys)
    assert isinstance(found, ModesResults)
    assert _computed(written) == _computed(_here(modes.results().to_dict(), tmp_path / "modes"))
    assert [round(row["frequency"], 1) for row in found.table()] == [2.0, 7.5]
    _same_verdict(found, printed, tmp_path / "modes")


@pytest.mark.slow
def test_the_study_and_the_demo_round_trip(tmp_path, capsys, demo_run):
    # crowdvib sensitivity and crowdvib demo have no crowdvib.cases call: their results.json
    # round-trips through load_results, and the verdict of the study names its cases on a bound.
    _, found, printed = _cli(tmp_path / "study", [
        "sensitivity", str(EXAMPLES / "paper_example.toml"), "--no-joint", "--no-record-length",
        "--workers", "1"], capsys)
    assert isinstance(found, SensitivityResults)
    assert [row["name"] for row in found.table()][0] == "nominal"
    _same_verdict(found, printed, tmp_path / "study")
    _, demo, _ = demo_run                 # `crowdvib demo --out DEMO` (tests/conftest.py)
    written, found, printed = _written(*demo_run)
    assert isinstance(found, DemoResults)
    # The demo's truth is the paper's MSD; its estimate is rebuilt as an HSIEstimate.
    assert found.hsi_estimate().msd.frequency == written["estimate"]["frequency"]
    _same_verdict(found, printed, demo)


def test_a_result_stores_what_write_json_writes():
    # numpy numbers and arrays as JSON numbers and lists, NaN and inf as null (as write_json
    # writes them), the key order kept (schema and kind first).
    import numpy as np

    found = Results.from_dict({"schema": SCHEMA, "kind": "simulate", "command": "simulate",
                               "response": {"output_names": ("mid",), "rms": np.array([0.5]),
                                            "peak": [np.float64(np.nan)],
                                            "max_running_rms": [np.inf]}})
    assert found.to_dict()["response"] == {"output_names": ["mid"], "rms": [0.5],
                                           "peak": [None], "max_running_rms": [None]}
    assert list(found.to_dict())[:2] == ["schema", "kind"]
    assert found.table() == [{"output": "mid", "rms": 0.5, "peak": None,
                              "max_running_rms": None}]


def test_the_notebook_view_and_the_table(tmp_path):
    # A results.json as the estimate writes it (values of the paper example's estimate).
    data = {"schema": SCHEMA, "kind": "estimate", "command": "estimate",
            "inputs": {"name": "bridge <A>"}, "expected": {"frequency": 3.0},
            "estimate": {"frequency": 3.1, "damping_ratio": 0.25, "mass_ratio": 0.95,
                         "interval": {"frequency": [2.99, 3.23],
                                      "damping_ratio": [0.19, 0.31], "level": 0.95,
                                      "method": "profile"},
                         "standard_error": {"frequency": 0.06, "damping_ratio": 0.03}},
            "diagnostics": {"relative_cost": 0.25}}
    found = Results.from_dict(data)
    view = found._repr_html_()
    # Escaped name, the estimate with its interval, and the verdict (J/J_noHSI above 10 %).
    assert "bridge &lt;A&gt;" in view and "3.1 (95 %: 2.99 – 3.23)" in view
    assert "check before use" in view and "J/J_noHSI = 0.25 is above 10%" in view
    frame = found.to_dataframe()
    assert list(frame["parameter"]) == ["frequency", "damping_ratio", "mass_ratio"]
    assert frame.loc[0, "low"] == 2.99 and frame.loc[0, "reference"] == 3.0
    assert frame.loc[1, "standard_error"] == 0.03


@pytest.mark.parametrize("text, message", [
    ("{not json", "is not valid JSON"),
    ("[1, 2]", "must hold a JSON object, got list"),
    ('{"command": "estimate"}', "holds no schema .*; crowdvib .* reads 'crowdvib.results/1'"),
    ('{"schema": "crowdvib.results/9", "kind": "estimate"}', "holds schema 'crowdvib.results/9'"),
    ('{"schema": "crowdvib.results/1", "kind": "fit"}', "kind must be one of .*got 'fit'"),
])
def test_a_results_file_crowdvib_cannot_read_is_a_data_error_naming_it(tmp_path, text, message):
    # docs: results, the schema: the file is named, and the rule it breaks.
    path = tmp_path / "results.json"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(DataError, match=f"{tmp_path}.*{message}"):
        load_results(path)


def test_a_missing_file_and_a_kind_of_another_class(tmp_path):
    with pytest.raises(DataError, match="does not exist: run a crowdvib command"):
        load_results(tmp_path)                              # a directory without results.json
    data = {"schema": SCHEMA, "kind": "check", "command": "check"}
    assert isinstance(Results.from_dict(data), CheckResults)
    with pytest.raises(DataError, match="holds 'check' results, not 'estimate'"):
        EstimateResults.from_dict(data)


def test_a_schema_1_folder_still_loads_reports_and_gives_its_parts(tmp_path):
    # Issue 34 §1: folders written before schema 2 still load. The file is what crowdvib
    # 6a9ea3b (schema 1) wrote for `crowdvib demo --spectral` (tests/cases/data/schema1_demo):
    # its estimator's keys at the top level, which schema 2 keeps under `diagnostics`.
    source = Path(__file__).parent / "data" / "schema1_demo" / "results.json"
    old = json.loads(source.read_text(encoding="utf-8"))
    assert old["schema"] == "crowdvib.results/1" and "relative_cost" in old
    found = load_results(source)
    assert isinstance(found, DemoResults) and found.data["schema"] == SCHEMA
    assert found.data["diagnostics"]["relative_cost"] == old["relative_cost"]
    assert "relative_cost" not in found.data and found.estimate == old["estimate"]
    parts = found.parts()
    assert parts["estimate"].msd.damping_ratio == old["estimate"]["damping_ratio"]
    assert parts["estimate"].relative_cost == old["relative_cost"]
    assert parts["truth"].frequency == 3.0
    assert parts["box"].damping_ratio == tuple(old["estimate"]["interval"]["damping_ratio"])
    assert not found.in_doubt
    # and the report of the old folder reads its estimate where schema 2 puts it
    folder = tmp_path / "old"
    folder.mkdir()
    (folder / "results.json").write_text(source.read_text(encoding="utf-8"), encoding="utf-8")
    assert main(["report", str(folder)]) == 0
    page = (folder / "report.html").read_text(encoding="utf-8")
    assert f"{old['relative_cost']:.3g}" in page
