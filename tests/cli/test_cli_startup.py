"""The command line answers --help, --version and a wrong case path without importing scipy,
numba, matplotlib (issue 10: those imports are what made it take 2.6–3 s), numpy, psutil (the
default of --workers, counted only when a study runs) or the report's sections (issue 26
must-show: --help within 0.3 s; they were some 150 ms more). The time itself is measured by
benchmarks/bench_cli.py, not asserted here."""

import subprocess
import sys

import pytest

_PROBE = """
import sys
from crowdvib.cli import main
try:
    code = main({argv!r})
except SystemExit as exit_:
    code = exit_.code
heavy = sorted({{name.split(".")[0] for name in sys.modules}}
               & {{"scipy", "numba", "matplotlib", "numpy", "psutil"}})
heavy += sorted({{"crowdvib.reporting.report", "crowdvib.reporting.sections"}} & set(sys.modules))
print("HEAVY", ",".join(heavy), "EXIT", code)
"""


@pytest.mark.parametrize("argv, code", [
    (["--help"], 0),
    (["--version"], 0),
    (["estimate", "--help"], 0),
    (["estimate", "no-such-case.toml", "--out", "out"], 1),
    (["sensitivity", "no-such-case.toml", "--out", "out"], 1),
])
def test_quick_answers_import_no_heavy_package(argv, code, tmp_path):
    done = subprocess.run([sys.executable, "-c", _PROBE.format(argv=argv)], cwd=tmp_path,
                          capture_output=True, text=True, check=True)
    line = done.stdout.strip().splitlines()[-1]
    assert line == f"HEAVY  EXIT {code}", (line, done.stderr[-500:])
    if code == 1:
        assert "no-such-case.toml: case file not found" in done.stderr
