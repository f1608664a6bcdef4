"""Outputs that cannot harm inputs and reports that cannot be injected (issue 9, faults 1, 3, 6).

Each fault test reproduces a behaviour seen on crowdvib 4bf1026 (quoted from the issue) and
checks it is now refused with the input files byte-identical. The rule under test is
src/crowdvib/cli/common.py (check_output): --out may not be, or contain, the working directory or
an input; crowdvib replaces only files its manifest (src/crowdvib/_manifest.py) lists.
"""

import html
import json
import os
import shutil
from html.parser import HTMLParser
from pathlib import Path

import markupsafe
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from crowdvib import Record, write_record
from crowdvib._files import child_path, safe_filename, unique_filenames
from crowdvib._manifest import MANIFEST_NAME, foreign_files, read_manifest, remove_owned
from crowdvib._files import sha256_file
from crowdvib.cli import main
from crowdvib.cli.common import IN_DOUBT
from crowdvib.reporting.report import REPORT_NAME, render_report
from tests.conftest import copy_paper_case

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _tree(root):
    """{relative path: bytes} of every file below ``root`` (the snapshot 'intact' compares)."""
    root = Path(root)
    return {p.relative_to(root).as_posix(): p.read_bytes()
            for p in sorted(root.rglob("*")) if p.is_file()}


def _paper_case(folder):
    """The paper example with the paper's estimator, copied into ``folder`` → the case path."""
    return copy_paper_case(folder, "case.toml")


def _short_case(folder, outputs="{ midspan = 25.0 }", channels=""):
    """The paper example on a 120 s record (cheap to estimate): case path in ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(3)
    write_record(Record(rng.normal(size=(1, 120 * 25)).astype(np.float32), 25.0,
                        channel_names=("midspan",)), folder / "rec.npz")
    text = ((EXAMPLES / "paper_example.toml").read_text()
            .replace("paper_example_record.npz", "rec.npz")
            .replace("window_length = 60.0", "window_length = 20.0")
            .replace("outputs = { midspan = 25.0 }", f"outputs = {outputs}")
            .replace("[measurement]\n", "[measurement]\n" + channels))
    (folder / "case.toml").write_text(text)
    return folder / "case.toml"


# ------------------------------------------------------------------------------ fault 1
def test_fault1_sensitivity_out_dot_force_keeps_the_working_directory(tmp_path, monkeypatch,
                                                                      capsys):
    # Issue 9, fault 1: "`crowdvib sensitivity CASE --out . --force` removes the current
    # directory's files before reading the records".
    _paper_case(tmp_path)
    (tmp_path / "thesis.tex").write_text("four years of work")
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "raw.bin").write_bytes(b"\x00\x01" * 100)
    before = _tree(tmp_path)
    monkeypatch.chdir(tmp_path)
    assert main(["sensitivity", "case.toml", "--out", ".", "--force"]) == 1
    err = capsys.readouterr().err
    assert f"--out . is the working directory {tmp_path.resolve()}" in err
    assert _tree(tmp_path) == before


def test_fault1_out_above_the_working_directory_is_refused(tmp_path, monkeypatch, capsys):
    case = _paper_case(tmp_path / "cases")
    (tmp_path / "work").mkdir()
    before = _tree(tmp_path)
    monkeypatch.chdir(tmp_path / "work")
    assert main(["map", str(case), "--out", "..", "--force"]) == 1
    assert f"--out .. contains the working directory {(tmp_path / 'work').resolve()}" in \
        capsys.readouterr().err
    assert _tree(tmp_path) == before


@pytest.mark.parametrize("command", ["estimate", "simulate", "map", "sensitivity"])
def test_fault1_force_into_the_case_folder_keeps_case_and_record(tmp_path, command, capsys):
    # Issue 9, fault 1: "`estimate`/`simulate --force --out <the case's folder>` replace the case
    # file and its record with results".
    case = _paper_case(tmp_path / "bridge")
    before = _tree(tmp_path)
    assert main([command, str(case), "--out", str(case.parent), "--force"]) == 1
    err = capsys.readouterr().err
    assert f"--out {case.parent} contains the case file {case}" in err
    assert _tree(tmp_path) == before


def test_fault1_symlinked_and_relative_outs_are_resolved(tmp_path, monkeypatch, capsys):
    case = _paper_case(tmp_path / "bridge")
    (tmp_path / "link").symlink_to(tmp_path / "bridge", target_is_directory=True)
    before = _tree(tmp_path / "bridge")
    assert main(["estimate", str(case), "--out", str(tmp_path / "link"), "--force"]) == 1
    assert f"contains the case file {case}" in capsys.readouterr().err
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "bridge/case.toml", "--out", "bridge/../link", "--force"]) == 1
    assert f"--out bridge/../link contains the case file {case}" in capsys.readouterr().err
    assert _tree(tmp_path / "bridge") == before


def test_fault1_out_holding_a_record_or_modal_file_elsewhere_is_refused(tmp_path, capsys):
    # Records and modal files may live outside the case's folder: --out may not contain them.
    data = tmp_path / "data"
    data.mkdir()
    for name in ("eeklo_like_modes.csv", "eeklo_like_shapes.csv", "eeklo_like_outputs.csv",
                 "eeklo_like_record.npz"):
        shutil.copy(EXAMPLES / name, data / name)
    text = (EXAMPLES / "eeklo_like.toml").read_text()
    case = tmp_path / "cases" / "eeklo.toml"
    case.parent.mkdir()
    record_only = text.replace('"eeklo_like_record.npz"', '"../data/eeklo_like_record.npz"')
    for name in ("modes", "shapes", "outputs"):
        record_only = record_only.replace(f'"eeklo_like_{name}.csv"',
                                          f'"../data/eeklo_like_{name}.csv"')
    case.write_text(record_only)
    before = _tree(tmp_path)
    assert main(["estimate", str(case), "--out", str(data), "--force"]) == 1
    assert f"--out {data} contains the record {data / 'eeklo_like_record.npz'}" in \
        capsys.readouterr().err
    case.write_text(record_only.replace('"../data/eeklo_like_record.npz"',
                                        '"../cases/x.npz"'))
    before = _tree(tmp_path)
    assert main(["estimate", str(case), "--out", str(data), "--force"]) == 1
    assert f"--out {data} contains the modal file {data / 'eeklo_like_modes.csv'}" in \
        capsys.readouterr().err
    assert _tree(tmp_path) == before


def test_fault1_demo_into_a_foreign_directory_is_refused(tmp_path, capsys):
    # Issue 9, fault 1: "`demo` replaces an existing `--out` without `--force`" — with or
    # without --force, a directory crowdvib did not write is refused before any work.
    out = tmp_path / "photos"
    out.mkdir()
    (out / "holiday.jpg").write_bytes(b"\xff\xd8 jpeg")
    before = _tree(tmp_path)
    for extra in ([], ["--force"]):
        assert main(["demo", "--spectral", "--out", str(out), *extra]) == 1
        err = capsys.readouterr()
        assert (f"--out {out} is not empty and was not written by crowdvib (it holds no "
                f"{MANIFEST_NAME})") in err.err
        assert "estimate over" not in err.out                   # refused before the work
    assert _tree(tmp_path) == before


def test_demo_replaces_its_own_results_only_with_force(tmp_path, capsys):
    out = tmp_path / "demo"
    assert main(["demo", "--spectral", "--seed", "1", "--out", str(out)]) == 0
    first = _tree(out)
    assert main(["demo", "--spectral", "--seed", "2", "--out", str(out)]) == 1
    assert "already holds results; use --force" in capsys.readouterr().err
    assert _tree(out) == first
    assert main(["demo", "--spectral", "--seed", "2", "--out", str(out), "--force"]) == 0
    assert json.loads((out / "results.json").read_text())["seed"] == 2
    assert [p.name for p in tmp_path.iterdir()] == ["demo"]     # no staging or .old left


# ------------------------------------------------------------------------------ the manifest
@pytest.fixture
def simulated(tmp_path):
    """A `crowdvib simulate` results directory (30 s of the embedded paper example)."""
    out = tmp_path / "sim"
    assert main(["simulate", "--duration-s", "30", "--format", "npz", "--out", str(out)]) == 0
    return out


def test_manifest_lists_every_file_with_size_and_digest(simulated):
    manifest = json.loads((simulated / MANIFEST_NAME).read_text())
    listed = {f["path"]: f for f in manifest["files"]}
    files = sorted(p.name for p in simulated.iterdir() if p.name != MANIFEST_NAME)
    assert sorted(listed) == files == ["psd.png", "record.npz", "report.html", "results.json",
                                       "time_history_midspan.png"]
    for name, entry in listed.items():
        assert entry["size"] == (simulated / name).stat().st_size
        assert entry["sha256"] == sha256_file(simulated / name)
    assert manifest["command"] == "simulate" and manifest["complete"] is True
    from crowdvib import __version__
    assert manifest["crowdvib_version"] == __version__
    # Directories crowdvib creates get the permissions of a plain mkdir (0755 under umask 022),
    # not mkdtemp's 0700.
    umask = os.umask(0)
    os.umask(umask)
    assert simulated.stat().st_mode & 0o777 == 0o777 & ~umask


def test_force_replaces_a_crowdvib_directory_file_by_listed_file(simulated, capsys):
    assert main(["simulate", "--duration-s", "30", "--format", "csv", "--out", str(simulated),
                 "--force"]) == 0
    names = sorted(p.name for p in simulated.iterdir())
    assert "record.csv" in names and "record.npz" not in names    # the old run's files are gone
    assert foreign_files(simulated) == []
    assert sorted(p.name for p in simulated.parent.iterdir()) == ["sim"]


def test_force_refuses_a_crowdvib_directory_holding_user_files(simulated, capsys):
    # Decision (documented in cli/common.py check_output): a file a user added to, or edited
    # in, crowdvib's results makes --force refuse and name it; nothing is deleted.
    (simulated / "notes.txt").write_text("my notes")
    (simulated / "results.json").write_text('{"edited": true}')
    before = _tree(simulated)
    assert main(["simulate", "--duration-s", "30", "--out", str(simulated), "--force"]) == 1
    err = capsys.readouterr().err
    assert "holds files crowdvib did not write (or that changed since): notes.txt, " \
           "results.json" in err
    assert _tree(simulated) == before


def test_a_forged_or_broken_manifest_protects_nothing_it_does_not_list(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "mine.txt").write_text("user data")
    (out / MANIFEST_NAME).write_text("{not json")
    assert read_manifest(out) is None
    (out / MANIFEST_NAME).write_text(json.dumps({"crowdvib_manifest": 1, "files": []}))
    assert foreign_files(out) == ["mine.txt"]
    assert remove_owned(out) == ["mine.txt"]
    assert (out / "mine.txt").read_text() == "user data"


def test_resume_continues_only_a_crowdvib_study(tmp_path, simulated, capsys):
    case = _paper_case(tmp_path / "bridge")
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "x.txt").write_text("x")
    assert main(["sensitivity", str(case), "--out", str(foreign), "--resume"]) == 1
    assert "was not written by crowdvib" in capsys.readouterr().err
    assert main(["sensitivity", str(case), "--out", str(simulated), "--resume"]) == 1
    assert (f"--out {simulated} holds results of crowdvib simulate, not of sensitivity"
            in capsys.readouterr().err)
    assert (foreign / "x.txt").read_text() == "x"


def test_report_does_not_overwrite_a_report_crowdvib_did_not_write(tmp_path, capsys):
    (tmp_path / "results.json").write_text(json.dumps({"command": "estimate"}))
    (tmp_path / REPORT_NAME).write_text("<p>my own report</p>")
    assert main(["report", str(tmp_path)]) == 1
    assert f"{tmp_path / REPORT_NAME} was not written by crowdvib" in capsys.readouterr().err
    assert (tmp_path / REPORT_NAME).read_text() == "<p>my own report</p>"


# ------------------------------------------------------------------------------ fault 3: names
def test_fault3_an_output_name_cannot_write_outside_out(tmp_path):
    # Issue 9, fault 3: "an output name `x/../../../somewhere/pwn` becomes a figure path".
    name = "x/../../../somewhere/pwn"
    case = _short_case(tmp_path / "a" / "b" / "case", outputs=f'{{ "{name}" = 25.0 }}',
                       channels=f'channels = {{ "{name}" = "midspan" }}\n')
    out = tmp_path / "a" / "b" / "c" / "out"
    before = _tree(tmp_path)
    # Finished: a short record, whose unconverged PSD the verdict doubts (exit 3).
    assert main(["estimate", str(case), "--out", str(out)]) == IN_DOUBT
    after = _tree(tmp_path)
    outside = {k: v for k, v in after.items() if not k.startswith("a/b/c/out/")}
    assert outside == before                       # nothing written or changed outside --out
    figures = json.loads((out / "results.json").read_text())["figures"]
    assert figures == ["psd_x_.._.._.._somewhere_pwn.png", "psd_convergence.png"]
    assert (out / figures[0]).read_bytes().startswith(b"\x89PNG")
    assert not any("pwn" in p.name or "somewhere" in p.name for p in tmp_path.rglob("*")
                   if out not in p.parents)


@settings(max_examples=300, deadline=None)
@given(st.text(min_size=0, max_size=400))
def test_safe_filename_stays_a_direct_child(tmp_path_factory, text):
    directory = tmp_path_factory.getbasetemp()
    name = safe_filename(text)
    assert name and name == safe_filename(name)
    assert len(name.encode()) <= 120
    path = directory / f"psd_{name}.png"
    assert path.resolve().parent == directory.resolve() and path.name == f"psd_{name}.png"
    assert child_path(directory, f"psd_{name}.png") == path


@settings(max_examples=200, deadline=None)
@given(st.lists(st.text(max_size=300), min_size=1, max_size=8, unique=True))
def test_distinct_names_get_distinct_files(names):
    # "x/y" and "x_y", "A" and "a" (case-insensitive file systems), names equal after the hash cut,
    # and the fixed psd_convergence.png must all stay apart.
    files = unique_filenames(names, prefix="psd_", suffix=".png", taken=("psd_convergence.png",))
    assert list(files) == names
    lowered = [f.lower() for f in files.values()]
    assert len(set(lowered)) == len(names) and "psd_convergence.png" not in lowered
    assert all(f == "psd_" + safe_filename(f[4:-4]) + ".png" for f in files.values())


@pytest.mark.parametrize("text, expected", [
    ("../../etc/passwd", "_.._etc_passwd"), ("/", "_"), ("..", "unnamed"), ("", "unnamed"),
    ("a\x00b", "a_b"), ("CON", "CON_"), ("nul.txt", "nul.txt_"), ("Überbau Süd", "Uberbau_Sud"),
    (".hidden", "hidden"), ("main_span", "main_span")])
def test_safe_filename_examples(text, expected):
    assert safe_filename(text) == expected


def test_figures_named_outside_the_directory_are_not_embedded(tmp_path):
    # A results.json cannot pull another file into the report.
    secret = tmp_path / "secret.png"
    secret.write_bytes(b"\x89PNG\r\n\x1a\n secret")
    out = tmp_path / "out"
    out.mkdir()
    (out / "link.png").symlink_to(secret)
    text = render_report({"figures": ["../secret.png", str(secret), "link.png"]}, out)
    assert "data:image" not in text
    assert text.count("is not a PNG or SVG file of the results directory") == 3


# ------------------------------------------------------------------------------ fault 6: report
_PAYLOADS = ["<script>alert(1)</script>", '"><img src=x onerror=alert(1)>',
             "</title><script>alert(2)</script>", "' onmouseover='alert(3)"]


def _hostile_results(payload):
    """A results.json with ``payload`` in every string the report shows (keys included)."""
    return {
        "command": payload, "crowdvib_version": payload, "seed": payload, "case": payload,
        "case_sha256": payload, "created": payload, "versions": {payload: payload},
        "inputs": {"name": payload, "description": payload, payload: {payload: payload}},
        "estimate": {"frequency": payload, "damping_ratio": 0.3},
        "expected": {"frequency": payload}, "truth": {payload: payload},
        "diagnostics": {"success": False, "message": payload,
                        "active_bounds": [payload, f"frequency:{payload}"],
                        "output_names": [payload], "bounds": {"frequency": [payload, 1]},
                        "relative_cost": payload, "band": [payload, payload],
                        "starts": [{"start": {payload: payload}, "status": payload}]},
        "sensitivity": {"cases": [{"name": payload, "kind": "individual", "error": payload}],
                        "summary": {"frequency": {"nominal": payload, "bound": payload}}},
        "record_length": [{"duration": payload, "error": payload}],
        "warnings": [payload], "figures": [payload, payload + ".png"],
    }


@pytest.mark.parametrize("payload", _PAYLOADS)
def test_fault6_report_escapes_results_strings(tmp_path, payload, capsys):
    # Issue 9, fault 6: "`crowdvib report` writes strings from results.json into report.html
    # unescaped".
    (tmp_path / "results.json").write_text(json.dumps(_hostile_results(payload)))
    assert main(["report", str(tmp_path)]) == 0
    text = (tmp_path / REPORT_NAME).read_text(encoding="utf-8")
    assert "<script" not in text and "<img" not in text and "onmouseover='" not in text
    # Escaped as markupsafe does (&#34; and &#39; for quotes), the text a reader sees.
    assert str(markupsafe.escape(payload)) in text
    assert html.unescape(str(markupsafe.escape(payload))) == payload
    assert _tags(text) == _tags(render_report(_hostile_results("benign"), tmp_path))


class _TagCounter(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tags = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, tuple(sorted(k for k, _ in attrs))))


def _tags(text):
    parser = _TagCounter()
    parser.feed(text)
    return parser.tags


@settings(max_examples=60, deadline=None)
# "name" and "description" are excluded: as a payload they collide with the fixed keys of the
# "inputs" table in _hostile_results, whose dict literal then holds one entry fewer (another
# results file, not another rendering of the same one).
@given(st.text(min_size=1, max_size=40).filter(lambda t: t not in ("name", "description")))
def test_any_string_in_results_leaves_the_markup_unchanged(text):
    # The page's elements and attribute names are the same whatever text the file holds, but
    # for the bare <sub> of the symbols the report typesets in a warning's words (f_h1, ξ_h1,
    # μ_h1, J/J_noHSI: reporting.sections.finding_markup, after escaping): a text holding
    # "f_h1" is shown as f<sub>h1</sub>, an element with no attribute and no content of its own.
    def tags(results):
        return [tag for tag in _tags(render_report(results)) if tag != ("sub", ())]
    assert tags(_hostile_results(text)) == tags(_hostile_results("benign"))


# ------------------------------------------------------------------------------ in-place studies
def test_sensitivity_force_and_resume_follow_the_manifest(tmp_path, capsys):
    case = _paper_case(tmp_path / "bridge")
    out = tmp_path / "study"
    argv = ["sensitivity", str(case), "--out", str(out), "--no-joint", "--no-record-length"]
    assert main(argv) == 0
    manifest = read_manifest(out)
    assert manifest["complete"] is True and manifest["command"] == "sensitivity"
    assert {"results.json", "report.html", "estimation_errors.png"} <= \
        {f["path"] for f in manifest["files"]}
    assert any(f["path"].startswith("tasks/") for f in manifest["files"])
    assert foreign_files(out) == []
    assert main(argv) == 1
    assert "use --resume to continue it or --force to replace them" in capsys.readouterr().err
    (out / "tasks" / "notes.txt").write_text("mine")
    before = _tree(out)
    assert main(argv + ["--force"]) == 1
    assert "tasks/notes.txt" in capsys.readouterr().err
    assert _tree(out) == before
    (out / "tasks" / "notes.txt").unlink()
    assert main(argv + ["--force"]) == 0
    assert foreign_files(out) == [] and read_manifest(out)["complete"] is True


def test_an_interrupted_study_can_be_resumed_or_replaced(tmp_path):
    # A study killed after some tasks: an incomplete manifest naming its stores, task files and
    # the hidden temporary of an unfinished atomic write (src/crowdvib/_files.py atomic_path).
    # A task file is crowdvib's by its content (issue 24 §3: its digest), so it is written by
    # the TaskStore here, not faked as "{}" (which is now a user's file --force refuses).
    from crowdvib.runs import prepare_output
    from crowdvib.runner import TaskStore

    out = tmp_path / "study"
    prepare_output(out, force=False, resume=False, command="sensitivity", stores=("tasks",))
    assert read_manifest(out)["complete"] is False
    store = TaskStore(out / "tasks")
    store.put("nominal@0123", {"frequency": 3.0})
    task_file, = (out / "tasks").glob("*.json")
    (out / "tasks" / ".4567.json.abc.part").write_text("{")
    assert foreign_files(out) == []
    prepare_output(out, force=False, resume=True, command="sensitivity", stores=("tasks",))
    assert store.get("nominal@0123") == {"frequency": 3.0} and task_file.exists()
    prepare_output(out, force=True, resume=False, command="sensitivity", stores=("tasks",))
    assert sorted(p.name for p in out.rglob("*")) == [MANIFEST_NAME]


def test_a_study_from_before_manifests_resumes_but_is_not_replaced(tmp_path):
    from crowdvib.runs import prepare_output
    from crowdvib.errors import ParameterError

    out = tmp_path / "study"
    (out / "tasks").mkdir(parents=True)
    # Named as a task file (16 hex digits, issue 24 §3): --resume may recompute it, not --force.
    (out / "tasks" / "0123456789abcdef.json").write_text("{}")
    with pytest.raises(ParameterError, match="not written by crowdvib"):
        prepare_output(out, force=True, command="sensitivity", stores=("tasks",))
    prepare_output(out, force=False, resume=True, command="sensitivity", stores=("tasks",))
    assert (out / "tasks" / "0123456789abcdef.json").read_text() == "{}"
    assert read_manifest(out)["stores"] == ["tasks"]
