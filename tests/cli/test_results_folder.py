"""Results folders that verify, lock and fail cleanly (issue 24 §2 last item, §3 and §5).

Each test reproduces what a tester saw on crowdvib 49020a3 (quoted from the issue) and checks the
rule that replaced it: task files carry the SHA-256 of their content and are reused only if it
matches (src/crowdvib/runner/tasks.py read_task_file); one run at a time writes an --out
(src/crowdvib/_files.py folder_lock); --force deletes only what provably is crowdvib's
(src/crowdvib/_manifest.py); a failed write is one error naming the path and the cause, and
every command ends in one line (src/crowdvib/cli/main.py). The numbers a run ends with are
compared with crowdvib's own clean run of the same inputs, bit for bit.
"""

import errno
import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from crowdvib._files import lock_path
from crowdvib.cli import main
from tests.conftest import default_sigint, paper_case_least_squares
from crowdvib.errors import StudyWarning
from crowdvib.runner import TaskStore, run_tasks
from crowdvib.runner.tasks import record_digest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
#: The paper example with the paper's estimator (the study's machinery is the subject).
CASE = paper_case_least_squares()
#: 21 estimations in this process, about a second.
STUDY = ["sensitivity", str(CASE), "--no-joint", "--no-record-length", "--workers", "1"]


def _results(out):
    return json.loads((Path(out) / "results.json").read_text())["sensitivity"]


def _leftovers(root):
    """Hidden temporaries and locks below ``root``: a failed or interrupted run leaves none."""
    return sorted(p.relative_to(root).as_posix() for p in Path(root).rglob(".*"))


@pytest.fixture(scope="module")
def clean(tmp_path_factory):
    """The cheap study run once, undisturbed: (its results, its folder)."""
    out = tmp_path_factory.mktemp("clean") / "study"
    assert main([*STUDY, "--out", str(out)]) == 0
    return _results(out), out


def _task_file(out, name):
    """The task file of task ``name`` in ``out``/tasks."""
    for path in (Path(out) / "tasks").glob("*.json"):
        if json.loads(path.read_text()).get("name") == name:
            return path
    raise AssertionError(f"no task file of {name}")


def _study(tmp_path):
    out = tmp_path / "study"
    assert main([*STUDY, "--out", str(out)]) == 0
    return out


# ------------------------------------------------------------------------------ task files (§2)
def test_an_edited_task_value_is_recomputed_with_a_warning_naming_its_file(tmp_path, clean,
                                                                          capsys):
    # Issue 24: a nominal f_h1 edited from 3.07 to 4.61 Hz in a (still valid JSON) task file
    # became the study's answer on --resume, without a warning.
    out = _study(tmp_path)
    path = _task_file(out, "nominal")
    record = json.loads(path.read_text())
    assert round(record["result"]["frequency"], 2) == 3.07
    record["result"]["frequency"] = 4.61
    path.write_text(json.dumps(record, indent=2))
    capsys.readouterr()
    assert main([*STUDY, "--out", str(out), "--resume"]) == 0
    err = capsys.readouterr().err
    assert f"task file {path} is damaged (its content does not match the SHA-256" in err
    assert _results(out) == clean[0]                      # the clean run's answer, not 4.61
    assert json.loads(path.read_text())["result"]["frequency"] == \
        clean[0]["nominal"]["frequency"]                  # rewritten with the computed value


@pytest.mark.parametrize("rehash", [False, True], ids=["digest-kept", "digest-forged"])
def test_a_task_result_missing_a_field_is_recomputed_not_a_keyerror(tmp_path, clean, capsys,
                                                                   rehash):
    # Issue 24: a task file with a field removed ended in a raw KeyError. The digest catches the
    # edit; a digest recomputed by hand still leaves a result the study cannot read, which the
    # field check (studies.py _ESTIMATE_FIELDS) catches.
    out = _study(tmp_path)
    path = _task_file(out, "nominal")
    record = json.loads(path.read_text())
    del record["result"]["frequency"]
    if rehash:
        record["sha256"] = record_digest(record)
    path.write_text(json.dumps(record))
    capsys.readouterr()
    assert main([*STUDY, "--out", str(out), "--resume"]) == 0
    err = capsys.readouterr().err
    reason = "its result lacks frequency" if rehash else "its content does not match"
    assert f"task file {path} is damaged ({reason}" in err
    assert "KeyError" not in err and "Traceback" not in err
    assert _results(out) == clean[0]


def _square(payload):
    return {"value": payload * payload}


def test_run_tasks_reuses_only_results_matching_their_digest(tmp_path):
    # The library rule under the CLI: an edited result is not returned, it is computed again.
    store = TaskStore(tmp_path)
    assert run_tasks(_square, [("a", 3.0), ("b", 4.0)], store=store) == \
        {"a": {"value": 9.0}, "b": {"value": 16.0}}
    path = next(p for p in tmp_path.glob("*.json") if json.loads(p.read_text())["name"] == "a")
    path.write_text(path.read_text().replace("9.0", "10.0"))
    with pytest.warns(StudyWarning, match=f"task file {path} is damaged"):
        assert run_tasks(_square, [("a", 3.0), ("b", 4.0)], store=store)["a"] == {"value": 9.0}


# ------------------------------------------------------------------------------ --force (§3)
def test_force_never_deletes_a_users_json_in_a_task_store(tmp_path, capsys):
    # Issue 24: --force deleted *.json files a user put inside tasks/, without naming them. Only
    # a file whose content proves crowdvib wrote it (its digest) may go; the rest is named.
    out = _study(tmp_path)
    notes = out / "tasks" / "notes.json"
    notes.write_text('{"my": "notes"}')
    copied = out / "tasks" / "0123456789abcdef.json"      # named like a task file, edited
    copied.write_text(_task_file(out, "nominal").read_text().replace('"nominal"', '"mine"'))
    capsys.readouterr()
    assert main([*STUDY, "--out", str(out), "--force"]) == 1
    err = capsys.readouterr().err
    assert "tasks/0123456789abcdef.json, tasks/notes.json" in err
    assert notes.read_text() == '{"my": "notes"}' and copied.exists()
    notes.unlink()
    copied.unlink()
    assert main([*STUDY, "--out", str(out), "--force"]) == 0


# ------------------------------------------------------------------------------ the lock (§3)
_HOLD = ("import sys, time\n"
         "from crowdvib._files import folder_lock\n"
         "with folder_lock(sys.argv[1], 'sensitivity'):\n"
         "    print('locked', flush=True)\n"
         "    time.sleep(600)\n")


@pytest.fixture
def holder():
    """Start a process holding the lock of a folder → its Popen (killed at the end)."""
    started = []

    def hold(out):
        process = subprocess.Popen([sys.executable, "-c", _HOLD, str(out)],
                                   stdout=subprocess.PIPE, text=True)
        started.append(process)
        assert process.stdout.readline().strip() == "locked"
        return process

    yield hold
    for process in started:
        process.kill()
        process.wait()
        process.stdout.close()      # else the garbage collector warns of it in a later test


@pytest.mark.parametrize("command", ["sensitivity", "simulate"])
def test_a_second_writer_is_refused_naming_the_holder(tmp_path, holder, capsys, command):
    # Issue 24: two runs writing one --out at once were not excluded. Both kinds of output are
    # locked: in place (a study) and staged (every other command).
    out = tmp_path / "out"
    process = holder(out)
    argv = ([*STUDY, "--out", str(out)] if command == "sensitivity"
            else ["simulate", "--duration-s", "30", "--out", str(out)])
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert (f"--out {out} is being written by another crowdvib run (crowdvib sensitivity, pid "
            f"{process.pid} on host {socket.gethostname()}, started 20") in err
    assert not out.exists()                                 # nothing written meanwhile


def test_a_stale_lock_of_a_killed_run_is_taken_over_with_a_note(tmp_path, holder, clean,
                                                                capsys):
    out = tmp_path / "study"
    process = holder(out)
    process.kill()
    process.wait()
    assert json.loads(lock_path(out).read_text())["pid"] == process.pid   # left behind
    assert main([*STUDY, "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert (f"took over the lock of {out} left by a run that ended without releasing it "
            f"(crowdvib sensitivity, pid {process.pid} on host {socket.gethostname()}") in err
    assert _results(out) == clean[0]
    assert not lock_path(out).exists()                       # released at the end


def test_a_killed_runs_forked_worker_does_not_keep_the_lock(tmp_path, capsys):
    # A study's local pool forks its workers while the lock is held (runner/_pool.py);
    # flock belongs to the open file, so a worker outliving its killed parent would keep --out
    # locked against the --resume. Forked children close their copy (_files.py _HELD).
    script = _HOLD.replace("    print('locked', flush=True)\n",
                           "    child = os.fork()\n"
                           "    if child == 0:\n"
                           "        time.sleep(600)\n"
                           "    print(child, flush=True)\n").replace("import sys", "import os, sys")
    out = tmp_path / "study"
    parent = subprocess.Popen([sys.executable, "-c", script, str(out)], stdout=subprocess.PIPE,
                              text=True)
    child = int(parent.stdout.readline())
    try:
        parent.kill()
        parent.wait()
        os.kill(child, 0)                                    # the worker lives on
        assert main([*STUDY, "--out", str(out)]) == 0
        assert f"pid {parent.pid} on host" in capsys.readouterr().err      # taken over
    finally:
        os.kill(child, signal.SIGKILL)
        parent.stdout.close()


def test_a_file_system_without_locks_is_written_with_a_note(tmp_path, capsys, monkeypatch):
    # NFS without its lock service answers flock with ENOLCK: the run goes on and says that it
    # could not exclude a second one.
    import fcntl

    def flock(descriptor, operation):
        raise OSError(errno.ENOLCK, os.strerror(errno.ENOLCK))

    monkeypatch.setattr(fcntl, "flock", flock)
    out = tmp_path / "sim"
    assert main(["simulate", "--duration-s", "30", "--out", str(out)]) == 0
    assert (f"crowdvib: note: {tmp_path} cannot be locked: make sure no other run writes "
            f"{out} meanwhile") in capsys.readouterr().err
    assert sorted(os.listdir(tmp_path)) == ["sim"]


# ------------------------------------------------------------------------------ write faults (§5)
def _fail_replace(monkeypatch, code, after):
    """os.replace raises OSError(``code``) from its ``after``-th call on (as a full disk would)."""
    real, calls = os.replace, []

    def replace(source, target, *args, **kwargs):
        calls.append(target)
        if len(calls) > after:
            raise OSError(code, os.strerror(code), str(source))
        return real(source, target, *args, **kwargs)

    monkeypatch.setattr(os, "replace", replace)
    return calls


def test_a_full_disk_mid_study_is_one_error_and_resume_finishes(tmp_path, clean, capsys,
                                                                monkeypatch):
    # Issue 24: ENOSPC ended in a raw OSError traceback. Now: one line naming the task file and
    # the cause; no half-written file; --resume after freeing space finishes with the clean run's
    # numbers and keeps the 5 tasks written before the fault.
    out = tmp_path / "study"
    calls = _fail_replace(monkeypatch, errno.ENOSPC, after=6)    # the manifest, then 5 tasks
    assert main([*STUDY, "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert [line for line in err.splitlines() if line.startswith("crowdvib")] == [
        f"crowdvib sensitivity: error: cannot write {calls[-1]}: No space left on device (the "
        "disk is full: free space and run again; a study continues with --resume)"]
    assert "Traceback" not in err
    assert _leftovers(tmp_path) == []
    kept = {p: p.stat().st_mtime_ns for p in (out / "tasks").glob("*.json")}
    assert len(kept) == 5
    monkeypatch.undo()                                       # space freed
    assert main([*STUDY, "--out", str(out), "--resume"]) == 0
    assert _results(out) == clean[0]
    assert {p: p.stat().st_mtime_ns for p in kept} == kept


@pytest.mark.parametrize("code, cause", [
    (errno.EROFS, "Read-only file system (the file system is mounted read-only)"),
    (errno.EPERM, "Operation not permitted (an immutable file or folder? see lsattr)"),
])
def test_a_read_only_out_is_one_error_and_leaves_nothing(tmp_path, tmp_path_factory, capsys,
                                                         monkeypatch, code, cause):
    # Issue 24: --out on a read-only file system or under an immutable folder (chattr +i).
    # Tests run as root, which ignores chmod 555, so the answer of the file system (EROFS) or
    # of the immutable flag (EPERM) is simulated at the first file crowdvib writes. The same
    # run first elsewhere, so that numba's cache (also written with os.replace) is written
    # before the fault whichever test ran first.
    assert main(["simulate", "--duration-s", "30", "--out",
                 str(tmp_path_factory.mktemp("warm") / "sim")]) == 0
    capsys.readouterr()
    calls = _fail_replace(monkeypatch, code, after=0)
    out = tmp_path / "sim"
    assert main(["simulate", "--duration-s", "30", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    line, = [line for line in err.splitlines() if line.startswith("crowdvib simulate:")]
    assert line == f"crowdvib simulate: error: cannot write {calls[0]}: {cause}"
    assert "Traceback" not in err
    assert sorted(os.listdir(tmp_path)) == []                # no out, staging, lock or temporary


def test_a_file_size_limit_is_one_error_and_resume_finishes(tmp_path, clean):
    # Issue 24: past a file-size limit (ulimit -f) the write failed with a traceback. In a
    # subprocess limited to 64 KiB per file, the study writes its task files (about 1 KiB) and
    # fails on its figure, naming it; run again without the limit, --resume finishes.
    import resource

    out = tmp_path / "study"
    limit = 64 * 1024

    def limited():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    command = [sys.executable, "-m", "crowdvib", *STUDY, "--out", str(out)]
    run = subprocess.run(command, preexec_fn=limited, capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 1, run.stderr
    last, = [line for line in run.stderr.splitlines() if line.startswith("crowdvib")]
    assert last.startswith(f"crowdvib sensitivity: error: cannot write {out}/")
    assert last.endswith("File too large (over the file-size limit of this process, ulimit -f, "
                         "or of the file system)")
    assert "Traceback" not in run.stderr
    assert _leftovers(tmp_path) == []
    assert len(list((out / "tasks").glob("*.json"))) == 21
    resumed = subprocess.run(command + ["--resume"], capture_output=True, text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    assert _results(out) == clean[0]


# ------------------------------------------------------------------------------ map (§5)
def test_map_ctrl_c_is_one_line_exit_130_and_leaves_nothing(tmp_path):
    # Issue 24: Ctrl-C of `crowdvib map` printed three chained KeyboardInterrupt tracebacks. Map
    # does not run as tasks: it keeps nothing, and leaves no staging directory or lock behind.
    out = tmp_path / "map"
    process = subprocess.Popen([sys.executable, "-m", "crowdvib", "map", str(CASE), "--out",
                                str(out), "--frequencies", "1:6:2000"], cwd=tmp_path,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               start_new_session=True, preexec_fn=default_sigint)
    deadline = time.monotonic() + 120
    while not any(tmp_path.glob(".map.*.part")):             # the run has begun writing
        assert process.poll() is None and time.monotonic() < deadline
        time.sleep(0.05)
    time.sleep(3.0)                                          # into the estimate or the grid
    os.killpg(process.pid, signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130
    assert "Traceback" not in stderr and "KeyboardInterrupt" not in stderr
    assert [line for line in stderr.splitlines() if "crowdvib map:" in line] == \
        ["crowdvib map: interrupted"]
    assert sorted(os.listdir(tmp_path)) == []


@pytest.mark.parametrize("option, value, message", [
    ("--frequencies", "1:6:0", "count must be 3 to 100000 points, got 0"),
    ("--frequencies", "1:6:1", "count must be 3 to 100000 points, got 1"),
    ("--damping-ratios", "0.1:0.8:10000000000",
     "count must be 3 to 100000 points, got 10000000000"),
    ("--max-minutes", "nan", "expected a finite number > 0, got 'nan'"),
    ("--max-minutes", "-5", "expected a finite number > 0, got '-5'"),
])
def test_map_refuses_a_grid_axis_it_cannot_use(tmp_path, capsys, option, value, message):
    # Issue 24: 1:6:0 and 1:6:1 ended in numpy tracebacks (the curvature at the minimum takes 3
    # points per axis), 10^10 points in a MemoryError; a usage error now, before any work.
    assert main(["map", str(CASE), "--out", str(tmp_path / "map"), option, value]) == 2
    assert f"argument {option}: {message}" in capsys.readouterr().err


@pytest.mark.parametrize("options, message", [
    (["--frequencies", "1:6:100000", "--max-minutes", "1"],
     r"frequencies × damping_ratios = 100000 × 36 = 3600000 grid points would take about "
     r"\d+ h \d+ min \(.* ms per point, timed on the first\), more than the limit of 1 min"),
    (["--frequencies", "1:6:100000", "--damping-ratios", "0.1:0.8:100000"],
     r"= 10000000000 grid points need 74.5 GiB for their costs alone, more than half the "
     r"16 GiB free: use fewer points"),
])
def test_map_refuses_a_grid_that_will_not_fit(tmp_path, capsys, monkeypatch, options, message):
    # Issue 24: `map --frequencies 1:6:100000` computed for minutes. 3.6 million points at even
    # 0.05 ms each (a fast machine) take 3 min, over the 1 min limit; 10^10 costs need 8 bytes
    # each, 74.5 GiB, on a machine made to report 16 GiB free.
    import re

    real = os.sysconf
    free = {"SC_AVPHYS_PAGES": 16 * 2**30 // 4096, "SC_PAGE_SIZE": 4096}
    monkeypatch.setattr(os, "sysconf", lambda name: free.get(name) or real(name))
    started = time.monotonic()
    assert main(["map", str(CASE), "--out", str(tmp_path / "map"), *options]) == 1
    err = capsys.readouterr().err
    assert re.search(message, err), err
    assert time.monotonic() - started < 60                  # refused before the work
    assert sorted(os.listdir(tmp_path)) == []


# ------------------------------------------------------------------------------ main.py (§5)
def test_any_exception_ends_a_command_in_one_line(tmp_path, capsys, monkeypatch):
    # Issue 24: "6 CLI commands end in raw tracebacks". An OSError names its path and cause; any
    # other exception is a bug, said so with how to report it; --verbose keeps the traceback.
    from crowdvib.cli import simulate

    def denied(args):
        raise PermissionError(errno.EACCES, "Permission denied", "/data/bridge.npz")

    monkeypatch.setattr(simulate, "run", denied)
    assert main(["simulate", "--out", str(tmp_path / "sim")]) == 1
    assert capsys.readouterr().err == ("crowdvib simulate: error: /data/bridge.npz: Permission "
                                       "denied (check the permissions of the file and its "
                                       "folder)\n")

    def bug(args):
        raise TypeError("unsupported operand")

    monkeypatch.setattr(simulate, "run", bug)
    assert main(["simulate", "--out", str(tmp_path / "sim")]) == 1
    assert capsys.readouterr().err == (
        "crowdvib simulate: error: TypeError: unsupported operand. This is a bug in crowdvib: "
        "please report it with the output of the same command run with --verbose\n")
    with pytest.raises(TypeError, match="unsupported operand"):
        main(["--verbose", "simulate", "--out", str(tmp_path / "sim")])

    def interrupted(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(simulate, "run", interrupted)
    assert main(["simulate", "--out", str(tmp_path / "sim")]) == 130
    assert capsys.readouterr().err == "crowdvib simulate: interrupted\n"
