"""The command line answers --help, --version and a wrong case path without importing scipy,
numba, matplotlib (issue 10: those imports are what made it take 2.6–3 s), numpy, psutil (the
default of --workers, counted only when a study runs), tqdm or the report's sections (issue 26
must-show: --help within 0.3 s; they were some 150 ms more). The time itself is measured by
benchmarks/bench_cli.py, not asserted here.

A command's module is imported only when that command is parsed or run (issue 34 §4):
``crowdvib --help`` lists the commands from the dispatcher's table and imports no
``crowdvib.cli.<command>`` module; ``crowdvib COMMAND --help`` imports that command's module
alone, and nothing of the library's work (cases, runs, io, …) comes with it."""

import subprocess
import sys

import pytest

from crowdvib.cli.main import _COMMANDS

_PROBE = """
import sys
from crowdvib.cli import main
try:
    code = main({argv!r})
except SystemExit as exit_:
    code = exit_.code
heavy = sorted({{name.split(".")[0] for name in sys.modules}}
               & {{"scipy", "numba", "matplotlib", "numpy", "psutil", "tqdm"}})
heavy += sorted({{"crowdvib.reporting.report", "crowdvib.reporting.sections"}} & set(sys.modules))
ours = sorted(name for name in sys.modules if name.startswith("crowdvib"))
print("HEAVY", ",".join(heavy), "EXIT", code)
print("CROWDVIB", ",".join(ours))
"""
#: What the dispatcher itself needs: the package root, the version, errors and file checks (for
#: a wrong case path), the command line's main and common modules.
DISPATCHER = {"crowdvib", "crowdvib._version", "crowdvib.errors", "crowdvib._files",
              "crowdvib.cli", "crowdvib.cli.main", "crowdvib.cli.common"}


def _probe(argv, tmp_path):
    done = subprocess.run([sys.executable, "-c", _PROBE.format(argv=argv)], cwd=tmp_path,
                          capture_output=True, text=True, check=True)
    heavy, ours = done.stdout.strip().splitlines()[-2:]
    return heavy, set(ours.removeprefix("CROWDVIB ").split(",")), done.stderr


@pytest.mark.parametrize("argv, code, command", [
    (["--help"], 0, None),
    (["--version"], 0, None),
    (["estimate", "--help"], 0, "estimate"),
    (["estimate", "no-such-case.toml", "--out", "out"], 1, "estimate"),
    (["sensitivity", "no-such-case.toml", "--out", "out"], 1, "sensitivity"),
])
def test_quick_answers_import_no_heavy_package(argv, code, command, tmp_path):
    heavy, ours, stderr = _probe(argv, tmp_path)
    assert heavy == f"HEAVY  EXIT {code}", (heavy, stderr[-500:])
    # the dispatcher and, when a command is named, that command's module: nothing else of ours
    expected = DISPATCHER | ({f"crowdvib.cli.{_COMMANDS[command][1]}"} if command else set())
    assert ours == expected
    if code == 1:
        assert "no-such-case.toml: case file not found" in stderr


@pytest.mark.parametrize("command", sorted(_COMMANDS))
def test_a_commands_help_builds_that_command_alone(command, tmp_path):
    # every command's arguments stay light: its --help brings its own module and no other
    heavy, ours, stderr = _probe([command, "--help"], tmp_path)
    assert heavy == "HEAVY  EXIT 0", (heavy, stderr[-500:])
    assert ours == DISPATCHER | {f"crowdvib.cli.{_COMMANDS[command][1]}"}
