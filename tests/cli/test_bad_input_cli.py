"""Bad input on the command line: every case fails before any long work with exit code 2 (a
usage error, from argparse) or 1 (a crowdvib error), and stderr names the parameter or file.

Exit codes are those documented in src/crowdvib/cli/main.py. The cases use the cheap example
case (examples/paper_example.toml, copied into tmp_path with its record) and failures that happen
before an estimation or simulation starts.
"""

import json
import shutil
from pathlib import Path

import pytest

from crowdvib.cases.schema import schema_header
from crowdvib.cli import main

pytestmark = pytest.mark.badinput

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _case(tmp_path, edit=None, name="case.toml"):
    """The paper example case and record in tmp_path/bridge; ``edit(text) -> text`` alters it."""
    folder = tmp_path / "bridge"
    folder.mkdir(exist_ok=True)
    shutil.copy(EXAMPLES / "paper_example_record.npz", folder / "paper_example_record.npz")
    text = (EXAMPLES / "paper_example.toml").read_text()
    (folder / name).write_text(edit(text) if edit else text)
    return folder / name


def _foreign_dir(tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("user data")
    return out


def _crowdvib_dir(tmp_path):
    """A real crowdvib results directory (`simulate`, 10 s of the embedded example)."""
    out = tmp_path / "sim"
    assert main(["simulate", "--duration-s", "10", "--format", "npz", "--out", str(out)]) == 0
    return out


def _results_dir(tmp_path, text):
    out = tmp_path / "results"
    out.mkdir()
    (out / "results.json").write_text(text)
    return out


# Each entry: id → (argv builder(tmp_path) → list, exit code, texts stderr must hold).
# ``{tmp}`` in a text is replaced by tmp_path.
CASES = {
    # ---- usage errors (argparse): exit 2
    "no command": (lambda t: [], 2, ["COMMAND"]),
    "unknown command": (lambda t: ["frobnicate"], 2, ["frobnicate"]),
    "unknown option": (lambda t: ["estimate", str(_case(t)), "--out", "o", "--bogus"], 2,
                       ["--bogus"]),
    "estimate without --out": (lambda t: ["estimate", str(_case(t))], 2, ["--out"]),
    "estimate without case": (lambda t: ["estimate", "--out", "o"], 2, ["case"]),
    "map grid of two numbers": (lambda t: ["map", str(_case(t)), "--out", "o",
                                           "--frequencies", "1:6"], 2, ["--frequencies", "1:6"]),
    "map grid not numbers": (lambda t: ["map", str(_case(t)), "--out", "o",
                                        "--frequencies", "a:b:c"], 2, ["--frequencies"]),
    "map damping grid count": (lambda t: ["map", str(_case(t)), "--out", "o",
                                          "--damping-ratios", "0.1:0.8:x"], 2,
                               ["--damping-ratios"]),
    "simulate duration text": (lambda t: ["simulate", "--out", "o", "--duration-s", "long"], 2,
                               ["--duration-s", "long"]),
    "simulate seed float": (lambda t: ["simulate", "--out", "o", "--seed", "1.5"], 2,
                            ["--seed", "1.5"]),
    "demo sample text": (lambda t: ["demo", "--duration-s", "1h"], 2, ["--duration-s"]),
    "sensitivity workers text": (lambda t: ["sensitivity", str(_case(t)), "--out", "o",
                                            "--workers", "two"], 2, ["--workers", "two"]),
    # Issue 10: --workers 0 and an unknown format are usage errors too.
    "sensitivity no workers": (lambda t: ["sensitivity", str(_case(t)), "--out", "o",
                                          "--workers", "0"], 2, ["--workers", ">= 1, got 0"]),
    "unknown --format": (lambda t: ["simulate", "--out", str(t / "o"), "--format", "xlsx"], 2,
                         ["--format", "'xlsx'"]),
    "--format in capitals": (lambda t: ["simulate", "--out", str(t / "o"), "--format", "CSV"], 2,
                             ["--format", "'CSV'"]),
    # ---- crowdvib errors: exit 1
    "case file missing": (lambda t: ["estimate", str(t / "nope.toml"), "--out", str(t / "o")], 1,
                          ["case file not found", "nope.toml"]),
    "case file binary": (lambda t: ["estimate", str(_case(t, lambda s: "\x00\xff\x01binary")),
                                    "--out", str(t / "o")], 1, ["case.toml", "TOML"]),
    "case unknown key": (lambda t: ["estimate", str(_case(t, lambda s: s.replace(
        "[crowd]\n", "[crowd]\ndensityy = 1.0\n"))), "--out", str(t / "o")], 1,
                         ["case.toml", "densityy"]),
    "case negative seed": (lambda t: ["map", str(_case(t, lambda s: s.replace(
        "seed = 20230101", "seed = -1"))), "--out", str(t / "o")], 1, ["case.toml", "seed"]),
    "case density text": (lambda t: ["estimate", str(_case(t, lambda s: s.replace(
        "density = 0.5 ", 'density = "high" '))), "--out", str(t / "o")], 1,
                          ["case.toml", "density"]),
    "record missing": (lambda t: ["estimate", str(_case(t, lambda s: s.replace(
        "paper_example_record.npz", "gone.npz"))), "--out", str(t / "o")], 1, ["gone.npz"]),
    "--out is a file": (lambda t: ["estimate", str(_case(t)), "--out",
                                   str(_case(t) .parent / "paper_example_record.npz")], 1,
                        ["--out", "is the record"]),
    "--out is an existing plain file": (lambda t: ["demo", "--out", str(_case(t))], 1,
                                        ["--out", "case.toml", "not a directory"]),
    "--out is the case file": (lambda t: ["simulate", str(_case(t)), "--out", str(_case(t))], 1,
                               ["--out", "is the case file"]),
    "--out is the case folder": (lambda t: ["estimate", str(_case(t)), "--out",
                                            str(t / "bridge"), "--force"], 1,
                                 ["contains the case file", "case.toml"]),
    "--out is the working directory": (lambda t: ["demo", "--out", ".", "--force"], 1,
                                       ["--out . is the working directory"]),
    "--out contains the working directory": (lambda t: ["map", str(_case(t)), "--out", "/"], 1,
                                             ["--out / contains the working directory"]),
    "--out foreign directory": (lambda t: ["estimate", str(_case(t)), "--out",
                                           str(_foreign_dir(t)), "--force"], 1,
                                ["mine", "not written by crowdvib"]),
    "demo into foreign directory": (lambda t: ["demo", "--out", str(_foreign_dir(t))], 1,
                                    ["mine", "not written by crowdvib"]),
    "--resume in foreign directory": (lambda t: ["sensitivity", str(_case(t)), "--out",
                                                 str(_foreign_dir(t)), "--resume"], 1,
                                      ["mine", "not written by crowdvib"]),
    "--resume in another command's results": (lambda t: [
        "sensitivity", str(_case(t)), "--out", str(_crowdvib_dir(t)), "--resume"], 1,
        ["sim", "holds results of crowdvib simulate, not of sensitivity"]),
    "existing results without --force": (lambda t: [
        "simulate", "--out", str(_crowdvib_dir(t)), "--duration-s", "10"], 1,
        ["sim", "already holds results; use --force"]),
    "--force over a user's file in results": (lambda t: [
        "simulate", "--out", str(_add(_crowdvib_dir(t), "mine.csv")), "--force"], 1,
        ["sim", "mine.csv", "did not write"]),
    "broken manifest": (lambda t: [
        "simulate", "--out", str(_add(_crowdvib_dir(t), "crowdvib-manifest.json")), "--force"],
        1, ["sim", "not written by crowdvib"]),
    "report of a missing directory": (lambda t: ["report", str(t / "nowhere")], 1,
                                      ["nowhere", "does not exist"]),
    "report of a directory without results": (lambda t: ["report", str(_foreign_dir(t))], 1,
                                              ["results.json", "does not exist"]),
    "report of broken results.json": (lambda t: ["report", str(_results_dir(t, "{oops"))], 1,
                                      ["results.json", "not valid JSON"]),
    "report of a results.json list": (lambda t: ["report", str(_results_dir(t, "[1, 2]"))], 1,
                                      ["results.json", "JSON object"]),
    "report over a user's report.html": (lambda t: [
        "report", str(_add(_results_dir(t, json.dumps({"command": "x"})), "report.html"))], 1,
        ["report.html", "was not written by crowdvib"]),
}


def _add(directory, name):
    """Write a user's file ``name`` into ``directory`` (returns the directory)."""
    (directory / name).write_text("a user's file")
    return directory


def test_the_catalogue_has_at_least_25_cases():
    assert len(CASES) >= 25


@pytest.mark.parametrize("name", list(CASES))
def test_bad_command_line(name, tmp_path, monkeypatch, capsys):
    build, code, texts = CASES[name]
    monkeypatch.chdir(tmp_path)
    argv = build(tmp_path)
    capsys.readouterr()                       # drop the output of building the case
    before = _snapshot(tmp_path)
    assert main(argv) == code
    err = capsys.readouterr().err
    assert "Traceback" not in err
    for text in texts:
        assert text.replace("{tmp}", str(tmp_path)) in err, (text, err)
    if code == 1:
        assert err.startswith(f"crowdvib {argv[0]}: error: ")
    # A refused command changes no file that was there before it ran.
    after = _snapshot(tmp_path)
    assert {k: v for k, v in after.items() if k in before} == before


def _snapshot(root):
    return {p.relative_to(root).as_posix(): p.read_bytes()
            for p in sorted(Path(root).rglob("*")) if p.is_file()}


@pytest.mark.parametrize("argv, package, extra", [
    (["simulate", "--out", "{out}", "--format", "npz,mat73"], "h5py", "mat73"),
    (["simulate", "--out", "{out}", "--format", "uff"], "pyuff", "uff"),
    (["sensitivity", "case.toml", "--out", "{out}", "--scheduler", "tcp://127.0.0.1:1"],
     "distributed", "dask"),
])
def test_missing_optional_package_is_a_usage_error_before_any_work(tmp_path, capsys, monkeypatch,
                                                                    argv, package, extra):
    # Issue 10: a missing optional dependency is reported before any work starts, with the
    # command that installs it (exit 2: the options ask for what this installation cannot do).
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == package else real(name, *a))
    out = tmp_path / "out"
    assert main([word.replace("{out}", str(out)) for word in argv]) == 2
    error = capsys.readouterr().err
    assert f"needs the package {package}" in error
    assert f"pip install 'crowdvib[{extra}]'" in error
    assert not out.exists()


# --- crowdvib check ([design], issue 11) ------------------------------------------------------

def _design_case(tmp_path, edit=lambda text: text):
    text = (EXAMPLES / "check_paper.toml").read_text()
    path = tmp_path / "design.toml"
    path.write_text(edit(text))
    return path


@pytest.mark.parametrize("edit, message", [
    (lambda t: t.replace('codes = ["hivoss", "setra", "en1990", "ukna"]', 'codes = ["bs5400"]'),
     "design.codes must list codes among"),
    (lambda t: t.replace('k1 = "urban"', 'k1 = "city"'), "site factor k1 must be a number or one of"),
    (lambda t: t.replace('ukna = "C"', 'ukna = "E"'), "traffic_class must be one of"),
    (lambda t: t.replace('weighting = "Wb"', 'weighting = "Wk"'), "design.weighting must be one of"),
    (lambda t: t.replace("[design]", "[design]\ntypo = 1"), "design.typo"),
    (lambda t: t.replace('codes = ["hivoss", "setra", "en1990", "ukna"]', 'codes = ["hivoss"]'),
     "classes.setra is given but 'setra' is not in design.codes"),
])
def test_check_bad_design_table(tmp_path, capsys, edit, message):
    assert main(["check", str(_design_case(tmp_path, edit)), "--out", str(tmp_path / "o")]) == 1
    assert message in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_check_needs_a_design_table(tmp_path, capsys):
    assert main(["check", str(_case(tmp_path)), "--out", str(tmp_path / "o")]) == 1
    assert "crowdvib check needs a [design] table" in capsys.readouterr().err


def test_check_msd_from_without_estimate(tmp_path, capsys):
    source = _results_dir(tmp_path, json.dumps(schema_header("simulate")))
    assert main(["check", str(_design_case(tmp_path)), "--out", str(tmp_path / "o"),
                 "--msd-from", str(source)]) == 1
    assert "holds no MSD estimate" in capsys.readouterr().err


def test_check_msd_from_a_results_json_without_its_schema_names_the_file(tmp_path, capsys):
    # --msd-from reads the folder as load_results does (issue 34 §1): a results.json without
    # the schema every crowdvib command writes is refused, naming the file and what to do.
    source = _results_dir(tmp_path, json.dumps({"command": "estimate", "estimate": {
        "frequency": 2.8, "damping_ratio": 0.35, "mass_ratio": 0.9}}))
    assert main(["check", str(_design_case(tmp_path)), "--out", str(tmp_path / "o"),
                 "--msd-from", str(source)]) == 1
    err = capsys.readouterr().err
    assert f"{source / 'results.json'} holds no schema" in err
    assert "run the command again to write it" in err and not (tmp_path / "o").exists()
