"""Speed and scaling (issue 14). Prints tables; asserts nothing.

    python benchmarks/bench_scaling.py [welch|kernel|simulate|hundred|all] [--records N]
        [--seconds S] [--figure PATH]

* Welch-window spectral model on one core (BLAS limited to one thread): crowdvib's evaluation
  (4 points per bin, narrow peaks in closed form) against the dense 16-points-per-bin rule it
  replaced and against a plain-numpy reference (benchmarks/_numpy_reference.py), with the
  largest difference relative to the peak.
* The simulation kernel on one core: µs per walker-step (walkers on the deck × RK4 steps) for the
  paper example, with and without HSI and at 0.1 P/m², against the plain-numpy RK4 of
  _numpy_reference.py (same walkers; the largest difference of the two records relative to the
  peak is printed); then the kernel alone (no drawing of walkers) per RK4 step on an empty deck
  and at 0.1, 0.5 and 1 P/m², and its fixed cost per step (issue 28 §4). Run it with
  NUMBA_NUM_THREADS=1.
* simulate_many: records of the paper example in 1 and 2 threads, records per second, and the
  extrapolated time of 100 one-hour records; ``hundred`` times the 100 one-hour records themselves
  (two threads).
* ``--figure PATH``: the scaling curves of the run (µs per walker-step against the number of modes,
  records per second against threads) drawn into one PNG.

Timings are medians of interleaved repeats (the machine may be shared); the load average
(``os.getloadavg``) is printed beside every figure.
"""

import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from _numpy_reference import exact_psd, simulate_rk4, welch_expectation
from bench_spectral import fourteen_mode_bridge
from threadpoolctl import threadpool_limits

from crowdvib import Crowd, ModalModel, MSDModel, SpectralModel, simulate, simulate_many
from crowdvib.io.casefile import load_case
from crowdvib.models.examples import paper_example
from crowdvib.models.loading import ZivanovicForce
from crowdvib.response.time_domain._integrator import prepare
from crowdvib.response.time_domain.simulation import checked_run
from crowdvib.signals import LowPassFilter

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def load():
    return "load {:.1f}/{:.1f}/{:.1f}".format(*os.getloadavg())


def interleaved(functions, repeat=9, budget=0.1):
    """Median seconds per call of each function, the calls interleaved round by round."""
    numbers = []
    for function in functions:
        started = time.perf_counter()
        function()
        numbers.append(max(1, int(budget / max(time.perf_counter() - started, 1e-6))))
    timings = [[] for _ in functions]
    for _ in range(repeat):
        for k, function in enumerate(functions):
            started = time.perf_counter()
            for _ in range(numbers[k]):
                function()
            timings[k].append((time.perf_counter() - started) / numbers[k])
    return [statistics.median(t) for t in timings]


def welch_cases():
    paper = paper_example()
    eeklo = load_case(EXAMPLES / "eeklo_like.toml")
    big = fourteen_mode_bridge()
    return [
        ("paper example, 601 f, T = 60 s", paper.structure, paper.crowd, paper.msd,
         np.arange(0, 601) / 60.0, 60.0, None, "<= 2 ms"),
        ("14 modes x 2 outputs x 6000 f, T = 60 s", big, Crowd.from_density(0.5), MSDModel(),
         np.linspace(0.0, 20.0, 6000), 60.0, None, "<= 20 ms"),
        ("eeklo-like, 2.5-8 Hz, T = 25 s, low-pass", eeklo.structure, eeklo.crowd, eeklo.msd,
         np.arange(63, 201) / 25.0, 25.0, LowPassFilter(10.0, 4, 25.0), "-"),
    ]


def welch_row(name, structure, crowd, msd, grid, window, lowpass, target, force):
    """One row of the Welch table: numpy reference, dense rule, crowdvib (median ms)."""
    model = SpectralModel(structure, crowd, grid, welch_window_length=window, lowpass=lowpass)
    attached = model._attached(msd)
    outputs = model.output_names

    def reference():
        return welch_expectation(structure, crowd, msd, grid, outputs, force, window)

    functions = [lambda: model._dense_welch_psd(attached), lambda: model.psd_array(msd)]
    if lowpass is None:                          # the numpy reference has no filter
        functions.insert(0, reference)
    times = interleaved(functions, repeat=5)
    numpy_time = times[0] if lowpass is None else float("nan")
    dense_time, new_time = times[-2:]
    truth = reference() if lowpass is None else model._dense_welch_psd(attached)
    error = (np.abs(model.psd_array(msd) - truth) / truth.max(axis=1, keepdims=True)).max()
    print(f"{name:42s}{target:>9s}{numpy_time * 1e3:9.2f}{dense_time * 1e3:9.2f}"
          f"{new_time * 1e3:8.2f}{numpy_time / new_time:8.1f}{dense_time / new_time:10.1f}"
          f"{error:13.1e}  {load()}")


def exact_row(name, structure, crowd, msd, grid, force):
    """One row of the exact-PSD table: numpy reference against crowdvib (median ms)."""
    model = SpectralModel(structure, crowd, grid)
    outputs = model.output_names
    numpy_time, new_time = interleaved(
        [lambda: exact_psd(structure, crowd, msd, grid, outputs, force),
         lambda: model.psd_array(msd)], repeat=5)
    print(f"{name:42s} numpy {numpy_time * 1e3:8.2f}  crowdvib {new_time * 1e3:7.2f}"
          f"  ratio {numpy_time / new_time:6.1f}  {load()}")


def bench_welch():
    print("Welch-window model, one BLAS thread: median ms per evaluation")
    print(f"{'case':42s}{'target':>9s}{'numpy':>9s}{'dense':>9s}{'new':>8s}"
          f"{'np/new':>8s}{'dense/new':>10s}{'max|Δ|/peak':>13s}  load")
    force = ZivanovicForce()
    with threadpool_limits(1):
        for case in welch_cases():
            welch_row(*case, force)
    print("(numpy: benchmarks/_numpy_reference.py, exact PSD at 16 points per bin by batched "
          "linalg.solve, then the kernel sum; dense: the rule crowdvib used before; the "
          "eeklo-like row is compared with dense, the numpy reference has no filter)")
    print()
    print("Exact PSD (no Welch smoothing), one BLAS thread: median ms per evaluation")
    paper = paper_example()
    with threadpool_limits(1):
        exact_row("paper example, 601 f", paper.structure, paper.crowd, paper.msd,
                  np.arange(0, 601) / 60.0, force)
        exact_row("14 modes x 2 outputs x 6000 f", fourteen_mode_bridge(),
                  Crowd.from_density(0.5), MSDModel(), np.linspace(0.0, 20.0, 6000), force)


def walker_steps(record):
    """Walkers on the deck summed over the internal steps of a record (sampled at the outputs)."""
    return float(record.n_on_deck.sum()) * round(1 / (record.time_step * record.sample_rate))


def kernel_row(name, case, msd, seconds, reference_seconds, crowd=None):
    """µs per walker-step of simulate and of the plain-numpy RK4 on the same walkers."""
    crowd = crowd or case.crowd

    def run(seed):
        return simulate(case.structure, crowd, seconds, msd=msd, rng=seed)

    run(0)                                                  # compile or load the cache
    timings, cpu, steps = [], [], []
    for seed in range(5):
        started, cpu_started = time.perf_counter(), time.process_time()
        record = run(seed)
        timings.append(time.perf_counter() - started)
        cpu.append(time.process_time() - cpu_started)
        steps.append(walker_steps(record))
    ours = statistics.median(t / s for t, s in zip(timings, steps)) * 1e6
    ours_cpu = statistics.median(t / s for t, s in zip(cpu, steps)) * 1e6
    spec = checked_run(case.structure, crowd, reference_seconds, msd=msd, rng=7)
    integrator, n_samples = prepare(spec), spec.n_samples
    started = time.perf_counter()
    expected = simulate_rk4(integrator, n_samples * integrator.substeps)
    numpy_time = time.perf_counter() - started
    record = simulate(case.structure, crowd, reference_seconds, msd=msd, rng=7)
    numpy_us = numpy_time / walker_steps(record) * 1e6
    error = np.abs(record.acceleration - expected).max() / np.abs(expected).max()
    on_deck = statistics.mean(s / (seconds * 100.0) for s in steps)
    print(f"{name:28s}{on_deck:9.0f}{ours:10.4f}{ours_cpu:10.4f}"
          f"{1e3 * statistics.median(timings) / seconds:8.3f}{numpy_us:10.3f}{numpy_us / ours:8.0f}"
          f"{error:12.1e}  {load()}")


def kernel_only(case, crowd, msd, seconds, repeat=7):
    """CPU µs per RK4 step of the kernel alone (no drawing of walkers: ``_Integrator.advance``
    over a prepared run) and the mean number on the deck; the fastest of ``repeat`` runs."""
    best, on_deck = np.inf, 0.0
    for seed in range(repeat):
        spec = checked_run(case.structure, crowd, seconds, msd=msd, rng=seed)
        run, n_samples = prepare(spec), spec.n_samples
        run.advance(run.substeps)                           # the first window, outside the timing
        steps = (n_samples - 1) * run.substeps
        started = time.process_time()
        run.advance(steps)
        best = min(best, (time.process_time() - started) / steps)
        on_deck += run.n_on_deck[:n_samples - 1].mean() / repeat
    return best * 1e6, on_deck


def fixed_cost(case, seconds=120.0):
    """The kernel's cost per step apart from the walkers, with HSI: on an empty deck, and as the
    intercept of a straight line through the costs at 0.1, 0.5 and 1 P/m²."""
    print(f"Kernel alone, one thread, paper example with HSI ({seconds:g} s, fastest of 7, "
          "CPU µs)")
    print(f"{'crowd':28s}{'on deck':>9s}{'µs/step':>10s}{'µs/walker-step':>16s}  load")
    empty, _ = kernel_only(case, case.crowd.with_density(1e-6), case.msd, seconds)
    print(f"{'empty deck':28s}{0:9.0f}{empty:10.3f}{'-':>16s}  {load()}")
    points = []
    for density in (0.1, 0.5, 1.0):
        per_step, on_deck = kernel_only(case, case.crowd.with_density(density), case.msd, seconds)
        points.append((on_deck, per_step))
        print(f"{f'{density:g} P/m²':28s}{on_deck:9.1f}{per_step:10.3f}"
              f"{per_step / on_deck:16.4f}  {load()}")
    slope, intercept = np.polyfit(*zip(*points), 1)
    print(f"fixed cost per step: {empty:.3f} µs on an empty deck, {intercept:.3f} µs by the "
          f"straight line ({slope:.4f} µs per walker on the deck)")


def bench_kernel(seconds=300.0):
    case = paper_example()
    print(f"Simulation kernel, one thread, paper example ({seconds:g} s records, median of 5; "
          "numpy: 20 s)")
    print(f"{'case':28s}{'on deck':>9s}{'µs wall':>10s}{'µs CPU':>10s}{'ms/s':>8s}"
          f"{'numpy µs':>10s}{'ratio':>8s}{'max|Δ|/peak':>12s}  load")
    kernel_row("HSI (target <= 0.012 µs)", case, case.msd, seconds, 20.0)
    kernel_row("HSI, 0.1 P/m²", case, case.msd, seconds, 20.0, case.crowd.with_density(0.1))
    kernel_row("no HSI", case, None, seconds, 20.0)
    print("(µs per walker-step: wall and CPU time of simulate() over the walkers on the deck "
          "summed over the RK4 steps; ms/s: wall per simulated second; numpy: wall µs of "
          "benchmarks/_numpy_reference.py simulate_rk4 on the same walkers, ratio numpy/ours)")
    print()
    fixed_cost(case)
    print()
    print("Modes: the paper's deck and crowd with HSI, n modes at 2–12 Hz (h = 5 ms), 120 s records")
    print(f"{'modes':>6s}{'µs/walker-step':>16s}{'ms/s':>8s}  load")
    curve = []
    for n_modes in (1, 4, 14, 50):
        bridge = ModalModel.simply_supported_beam(50.0, 3.0, np.linspace(2.0, 12.0, n_modes), 0.005,
                                                  50e3, n_modes=n_modes)
        simulate(bridge, case.crowd, 2.0, msd=case.msd, rng=0)
        timings, steps = [], []
        for seed in range(3):
            started = time.perf_counter()
            record = simulate(bridge, case.crowd, 120.0, msd=case.msd, rng=seed)
            timings.append(time.perf_counter() - started)
            steps.append(walker_steps(record))
        per_step = statistics.median(t / s for t, s in zip(timings, steps)) * 1e6
        print(f"{n_modes:6d}{per_step:16.4f}{1e3 * statistics.median(timings) / 120.0:8.3f}  {load()}")
        curve.append((n_modes, per_step))
    return curve


def bench_simulate(records=4, seconds=300.0):
    case = paper_example()
    seeds = list(range(records))

    def run(threads):
        started, cpu = time.perf_counter(), time.process_time()
        simulate_many(case.structure, case.crowd, seconds, seeds=seeds, msd=case.msd,
                      workers=threads)
        return time.perf_counter() - started, time.process_time() - cpu

    simulate_many(case.structure, case.crowd, 2.0, seeds=[0, 1], msd=case.msd)   # compile
    rounds = {1: [], 2: []}
    for _ in range(3):
        for threads in (1, 2):
            rounds[threads].append((*run(threads), load()))
    print(f"simulate_many, paper example with HSI: {records} records x {seconds:g} s "
          f"(median of 3 interleaved rounds)")
    print(f"{'threads':>8s}{'wall [s]':>10s}{'CPU [s]':>9s}{'CPU/wall':>9s}"
          f"{'wall ms/record-s':>18s}{'CPU ms/record-s':>17s}{'records/s':>10s}"
          f"{'speed-up':>10s}  loads of the rounds")
    base = None
    for threads, rows in rounds.items():
        wall = statistics.median(r[0] for r in rows)
        cpu = statistics.median(r[1] for r in rows)
        base = base or wall
        print(f"{threads:8d}{wall:10.2f}{cpu:9.2f}{cpu / wall:9.2f}"
              f"{1e3 * wall / (records * seconds):18.3f}{1e3 * cpu / (records * seconds):17.3f}"
              f"{records / wall:10.3f}{base / wall:10.2f}  {'; '.join(r[2] for r in rows)}")
    best = min(statistics.median(r[0] for r in rows) for rows in rounds.values())
    cpu = min(statistics.median(r[1] for r in rows) for rows in rounds.values())
    print(f"extrapolated (not measured): 100 one-hour records ≈ "
          f"{best / (records * seconds) * 360000:.0f} s wall at this load; "
          f"{cpu / (records * seconds) * 360000 / 2:.0f} s on 2 idle cores from the CPU time")
    return [(threads, records / statistics.median(r[0] for r in rows))
            for threads, rows in rounds.items()]


def bench_hundred():
    """100 one-hour records of the paper example on two threads, measured (issue 14: < 2 min)."""
    case = paper_example()
    simulate_many(case.structure, case.crowd, 2.0, seeds=[0, 1], msd=case.msd)   # compile
    before = load()
    started, cpu = time.perf_counter(), time.process_time()
    simulate_many(case.structure, case.crowd, 3600.0, seeds=list(range(100)), msd=case.msd,
                  workers=2)
    print(f"100 one-hour records of the paper example, 2 threads: "
          f"{time.perf_counter() - started:.1f} s wall, {time.process_time() - cpu:.1f} s CPU "
          f"(target < 120 s; {before} before, {load()} after)")


def draw(path, modes, threads):
    """The scaling curves of this run in one figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [curve for curve in (modes, threads) if curve]
    figure, axes = plt.subplots(1, len(panels), figsize=(4.5 * len(panels), 3.6), squeeze=False)
    left, right = (axes[0, 0], axes[0, -1])
    if modes:
        n, us = zip(*modes)
        left.loglog(n, us, "o-")
        left.set_xlabel("modes")
        left.set_ylabel("µs per walker-step (one thread)")
        left.set_title("simulation kernel, paper deck with HSI")
    if threads:
        k, rate = zip(*threads)
        right.plot(k, rate, "o-", label="measured")
        right.plot(k, [rate[0] * i for i in k], "--", color="0.6", label="linear")
        right.set_xlabel("threads")
        right.set_ylabel("records per second")
        right.set_xticks(k)
        right.legend()
        right.set_title("simulate_many, paper example")
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    print(f"figure: {path}")


def main(argv):
    what = argv[0] if argv and not argv[0].startswith("--") else "all"
    records = int(argv[argv.index("--records") + 1]) if "--records" in argv else 4
    seconds = float(argv[argv.index("--seconds") + 1]) if "--seconds" in argv else 300.0
    figure = argv[argv.index("--figure") + 1] if "--figure" in argv else None
    print(f"crowdvib benchmarks, issue 14 ({os.cpu_count()} CPUs, {load()})")
    modes = threads = None
    if what in ("welch", "all"):
        bench_welch()
        print()
    if what in ("kernel", "all"):
        modes = bench_kernel()
        print()
    if what in ("simulate", "all"):
        threads = bench_simulate(records, seconds)
    if what in ("hundred", "all"):
        bench_hundred()
    if figure and (modes or threads):
        draw(figure, modes, threads)


if __name__ == "__main__":
    main(sys.argv[1:])
