"""Start-up time of the command line (issue 10; target < 0.5 s for --help, --version, errors).

    python benchmarks/bench_cli.py [--repeat 7]

Each command runs in a fresh interpreter (``python -m crowdvib …``), as a user's shell would run
it; the table prints the median and the spread of the wall times. Asserts nothing.
"""

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

TARGET = 0.5


def _commands(scratch):
    missing = scratch / "no-such-case.toml"
    return [("crowdvib --help", ["--help"], 0),
            ("crowdvib --version", ["--version"], 0),
            ("crowdvib estimate --help", ["estimate", "--help"], 0),
            ("missing case file (error)", ["estimate", str(missing), "--out",
                                           str(scratch / "out")], 1),
            ("--workers 0 (usage error)", ["sensitivity", str(missing), "--out",
                                           str(scratch / "out"), "--workers", "0"], 2)]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        rows = []
        for label, arguments, expected in _commands(Path(scratch)):
            times = []
            for _ in range(args.repeat):
                started = time.perf_counter()
                done = subprocess.run([sys.executable, "-m", "crowdvib", *arguments],
                                      capture_output=True, text=True, check=False)
                times.append(time.perf_counter() - started)
                if done.returncode != expected:
                    raise SystemExit(f"{label}: exit {done.returncode}, expected {expected}: "
                                     f"{done.stderr[-500:]}")
            rows.append((label, statistics.median(times), min(times), max(times)))
    print(f"{'command':30s} {'median [s]':>10s} {'min [s]':>8s} {'max [s]':>8s}  target")
    for label, median, low, high in rows:
        verdict = "ok" if median < TARGET else "SLOW"
        print(f"{label:30s} {median:10.3f} {low:8.3f} {high:8.3f}  < {TARGET} s {verdict}")


if __name__ == "__main__":
    main()
