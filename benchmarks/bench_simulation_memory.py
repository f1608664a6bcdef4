"""Peak memory of long simulations (issue 28 §3). Prints a table; asserts nothing.

    python benchmarks/bench_simulation_memory.py [hours ...] [--psd days ...]

Each run is a fresh process (the paper example, HSI, 100 Hz); its peak RSS, wall and CPU time
come from ``os.wait4`` (the child's own rusage), so no run inherits another's high-water mark.
``import`` is the bare ``import crowdvib``; ``1 s`` also loads the compiled kernel: the baseline
the long runs are measured against. ``record`` is ``simulate`` returning the whole record;
``psd`` is ``simulate_psd`` (Welch PSD and summaries only, T = 60 s).
"""

import os
import subprocess
import sys
import time

SCRIPT = """
import sys
from crowdvib.models.examples import paper_example
mode, seconds = sys.argv[1], float(sys.argv[2])
if mode != "import":
    import crowdvib
    case = paper_example()
    if mode == "psd":
        result = crowdvib.simulate_psd(case.structure, case.crowd, seconds, msd=case.msd, rng=0,
                                       window_length=60.0)
        print(result.n_pedestrians)
    else:
        record = crowdvib.simulate(case.structure, case.crowd, seconds, msd=case.msd, rng=0)
        print(record.n_pedestrians, record.acceleration.nbytes + record.n_on_deck.nbytes)
"""


def run(mode, seconds):
    """Peak RSS [MB], wall [s], CPU [s] and the child's output of one run in a fresh process."""
    started = time.perf_counter()
    child = subprocess.Popen([sys.executable, "-c", SCRIPT, mode, str(seconds)],
                             stdout=subprocess.PIPE, text=True)
    out = child.stdout.read()
    _, status, usage = os.wait4(child.pid, 0)
    child.returncode = os.waitstatus_to_exitcode(status)
    if child.returncode:
        raise RuntimeError(f"{mode} {seconds} s failed ({child.returncode})")
    wall = time.perf_counter() - started
    return usage.ru_maxrss / 1024, wall, usage.ru_utime + usage.ru_stime, out.split()


def main(argv):
    hours = [float(a) for a in argv if not a.startswith("--")] or [1.0, 6.0, 24.0]
    days = []
    if "--psd" in argv:
        after = argv[argv.index("--psd") + 1:]
        hours = [float(a) for a in argv[:argv.index("--psd")]] or hours
        days = [float(a) for a in after] or [1.0]
    rows = [("import", 0.0), ("record", 1.0)] + [("record", 3600.0 * h) for h in hours]
    rows += [("psd", 86400.0 * d) for d in days]
    print(f"{'run':<8} {'duration':>10} {'peak RSS [MB]':>14} {'wall [s]':>9} {'CPU [s]':>8}  "
          "pedestrians, record [MB]")
    for mode, seconds in rows:
        rss, wall, cpu, out = run(mode, seconds)
        extra = ""
        if out:
            extra = out[0] + (f", {int(out[1]) / 2**20:.0f}" if len(out) > 1 else "")
        label = ("-" if mode == "import" else f"{seconds:g} s" if seconds < 3600
                 else f"{seconds / 3600:g} h" if seconds < 86400 else f"{seconds / 86400:g} d")
        print(f"{mode:<8} {label:>10} {rss:>14.0f} {wall:>9.1f} {cpu:>8.1f}  {extra}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
