"""Speed and memory of the time-domain simulator (issue 3). Prints a table and JSON; asserts nothing.

    python benchmarks/bench_simulation.py

Targets (issue 3): paper example (~75 on deck, 1 mode, HSI) <= 2 ms wall per simulated second;
14-mode 96 m × 3 m deck at 0.5 persons/m² (~150 on deck), HSI, 2 outputs <= 15 ms per simulated
second; peak memory of a 1-hour simulation <= 300 MB. JIT compile time is reported apart.
"""

import json
import os
import resource
import subprocess
import sys
import tempfile
import time
import tracemalloc

from bench_spectral import fourteen_mode_bridge

import crowdvib.response.time_domain._integrator
from crowdvib import Crowd, MSDModel, simulate
from crowdvib.response.time_domain._integrator import kernel_for
from crowdvib.models.examples import paper_example


def wall_per_second(structure, crowd, msd, duration, repeat=3):
    """Best wall time per simulated second [ms] over ``repeat`` runs, and the record."""
    best, record = float("inf"), None
    for seed in range(repeat):
        started = time.perf_counter()
        record = simulate(structure, crowd, duration, msd=msd, rng=seed)
        best = min(best, time.perf_counter() - started)
    return 1e3 * best / duration, record


COLD_START = """
import time
from crowdvib import simulate
from crowdvib.models.examples import paper_example
case = paper_example()
started = time.perf_counter()
simulate(case.structure, case.crowd, 1.0, msd=case.msd, rng=0)
print(time.perf_counter() - started)
"""


def cold_compile_seconds():
    """First call in a fresh process with an empty numba cache: the JIT compile time [s]."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        out = subprocess.run([sys.executable, "-c", COLD_START], env=env, check=True,
                             capture_output=True, text=True)
    return float(out.stdout.split()[-1])


def main():
    case = paper_example()
    compile_time = cold_compile_seconds()
    started = time.perf_counter()
    simulate(case.structure, case.crowd, 1.0, msd=case.msd, rng=0)
    first_call = time.perf_counter() - started
    stats = kernel_for(case.structure, True).stats
    rows = [("JIT compile (fresh process, empty cache)", f"{compile_time:.2f} s", "1 s simulated"),
            ("first call (JIT compile or cache load)", f"{first_call:.2f} s",
             f"cache hits {sum(stats.cache_hits.values())}, "
             f"misses {sum(stats.cache_misses.values())}")]

    results = {"compile_s": compile_time, "first_call_s": first_call}
    for label, msd, key in (("paper example, no HSI", None, "paper_no_hsi_ms_per_s"),
                            ("paper example, HSI", case.msd, "paper_hsi_ms_per_s")):
        ms, record = wall_per_second(case.structure, case.crowd, msd, 300.0)
        results[key] = ms
        rows.append((label, f"{ms:.2f} ms/s",
                     f"{record.n_on_deck.mean():.0f} on deck, h = {1e3 * record.time_step:.2f} ms"
                     + (", target <= 2 ms/s" if msd is not None else "")))

    # For scale: the force components sampled at 10 steps per period too (a finer step).
    default = crowdvib.response.time_domain._integrator.FORCE_STEPS_PER_PERIOD
    crowdvib.response.time_domain._integrator.FORCE_STEPS_PER_PERIOD = 10
    ms, record = wall_per_second(case.structure, case.crowd, case.msd, 300.0)
    crowdvib.response.time_domain._integrator.FORCE_STEPS_PER_PERIOD = default
    results["paper_hsi_force_10_steps_per_period_ms_per_s"] = ms
    rows.append(("paper example, HSI, forces at 10 steps/period", f"{ms:.2f} ms/s",
                 f"h = {1e3 * record.time_step:.2f} ms (not the default)"))

    bridge = fourteen_mode_bridge()
    crowd = Crowd(density=0.5, walking_speed=1.30, step_frequency_mean=1.89,
                  step_frequency_std=0.175, body_mass=70.0)
    ms, record = wall_per_second(bridge, crowd, MSDModel(), 120.0)
    results["fourteen_modes_hsi_ms_per_s"] = ms
    rows.append(("14 modes, 96 m × 3 m, HSI, 2 outputs", f"{ms:.2f} ms/s",
                 f"{record.n_on_deck.mean():.0f} on deck, h = {1e3 * record.time_step:.2f} ms, "
                 "target <= 15 ms/s"))

    tracemalloc.start()
    started = time.perf_counter()
    record = simulate(case.structure, case.crowd, 3600.0, msd=case.msd, rng=0,
                      record_modal_load=True)
    hour = time.perf_counter() - started
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    max_rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024   # KiB on Linux
    results.update(hour_wall_s=hour, hour_traced_peak_mb=peak / 2**20, max_rss_mb=max_rss)
    rows.append(("1 hour, paper example, HSI (+ modal load)", f"{hour:.1f} s",
                 f"traced peak {peak / 2**20:.1f} MB, process max RSS {max_rss:.0f} MB, "
                 "target <= 300 MB"))

    width = max(len(r[0]) for r in rows)
    for name, value, note in rows:
        print(f"{name:<{width}}  {value:>12}  {note}")
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
