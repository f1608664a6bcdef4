"""OMA accuracy (issue 13): identify_modes on simulated 30-minute ambient records of a 3-mode bridge.

The bridge, the ambient load (independent white-noise modal loads, exact Gaussian synthesis) and
the five walkers are those of tests/oma/test_oma.py (imported from it, so the two cannot drift).

Usage::

    python benchmarks/bench_oma.py [N seeds] [max_order]   # SSI-cov and EFDD, seeds 1..N
    python benchmarks/bench_oma.py bound [N]                # the information bound, checked
    python benchmarks/bench_oma.py pyoma2 [N]               # why crowdvib has its own EFDD
    python benchmarks/bench_oma.py setups [N]               # two setups, merged shapes
    python benchmarks/bench_oma.py speed                    # CPU of a 30-min record (issue 27)

The first prints per seed and method the relative errors of f_j and ξ_j and the error of ξ_j in
units of its reported σ, then per mode and method: mean and largest |Δf|/f, RMS and largest
|Δξ|/ξ, the seeds within 0.5 % (f) and 20 % (ξ), and the share whose ±1.96 σ covers the truth;
and the median time per identification. ``bound`` fits the exact SDOF spectrum by maximum
likelihood (Whittle) to the exact modal coordinates of ambient-only records: an efficient
estimator, whose scatter shows the information bound σ_ξ/ξ = 1/√(2π f ξ T) and which seeds no
estimator can bring within 20 %. ``pyoma2`` runs pyOMA2's EFDD at its defaults, again with its
SDOF bell squared, and crowdvib's. ``setups`` measures the bridge in two setups sharing one
reference sensor and compares the merged shapes with the sine modes (MAC). ``speed`` times
SSI-cov (CPU seconds of the process) on a 30-minute two-channel record at 50 Hz of a bridge with
modes at 1.69, 2.0 and 7.5 Hz, with and without a band, at the block rows and model order
identify_modes chooses, and prints the modes found against the truth (issue 27: under a minute
of CPU. At a load of 6 to 11 on 2 cores: before, 23 s with the band and 57–59 s without; after,
1.6–2.7 s and 5.5–5.7 s; docs: theory, Operational modal analysis, the cost of SSI-cov).
"""

import os
import sys
import time
from pathlib import Path

import numpy as np

from crowdvib import identify_modes

# The case of the tests: their bridge, ambient load and walkers, imported so they cannot drift.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "oma"))
from test_oma import (  # noqa: E402
    DAMPING,
    DURATION,
    FREQUENCIES,
    SAMPLE_RATE,
    ambient_record,
    bridge,
)
from test_oma_setups import SETUP_POSITIONS, setup_records, sine_rows  # noqa: E402

METHODS = ("ssi-cov", "efdd")


def _load():
    return f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores"


def accuracy(n=8, max_order=24):
    structure = bridge()
    errors = {m: [] for m in METHODS}
    times = {m: [] for m in METHODS}
    print(f"{'seed':>4s} {'method':>7s} {'s':>5s}  {'f error [%]':>24s}  {'ξ error [%]':>20s}  "
          f"{'ξ error / σ_ξ':>20s}", flush=True)
    for seed in range(1, n + 1):
        record = ambient_record(structure, seed)
        for method in METHODS:                           # interleaved: same load for both
            started = time.perf_counter()
            modes = identify_modes(record, SAMPLE_RATE, n_modes=3, frequency_band=(1.0, 9.0),
                                   max_order=max_order, method=method)
            times[method].append(time.perf_counter() - started)
            row = (modes.frequencies / FREQUENCIES - 1, modes.damping_ratios / DAMPING - 1,
                   (modes.frequencies - FREQUENCIES) / modes.frequency_std,
                   (modes.damping_ratios - DAMPING) / modes.damping_std)
            errors[method].append(row)
            print(f"{seed:4d} {method:>7s} {times[method][-1]:5.1f}  "
                  f"{' '.join(f'{v:+7.3f}' for v in 100 * row[0]):>24s}  "
                  f"{' '.join(f'{v:+6.1f}' for v in 100 * row[1]):>20s}  "
                  f"{' '.join(f'{v:+6.2f}' for v in row[3]):>20s}", flush=True)
    print(f"\n{n} seeds, {_load()}")
    print("method   mode  f [Hz]  ξ      mean|Δf| max|Δf|  f≤0.5%  rms Δξ  max|Δξ|  ξ≤20%  "
          "f cov  ξ cov")
    for method in METHODS:
        ef, ex, zf, zx = (np.array([r[i] for r in errors[method]]) for i in range(4))
        for j in range(3):
            print(f"{method:>7s}  {j + 1:4d}  {FREQUENCIES[j]:6.2f}  {DAMPING[j]:.3f}  "
                  f"{np.mean(np.abs(ef[:, j])):7.3%}  {np.max(np.abs(ef[:, j])):7.3%}  "
                  f"{np.sum(np.abs(ef[:, j]) <= 0.005):3d}/{n:<3d} "
                  f"{np.sqrt(np.mean(ex[:, j] ** 2)):6.1%}  {np.max(np.abs(ex[:, j])):6.1%}  "
                  f"{np.sum(np.abs(ex[:, j]) <= 0.2):3d}/{n:<3d}"
                  f"{np.mean(np.abs(zf[:, j]) <= 1.96):5.0%}  {np.mean(np.abs(zx[:, j]) <= 1.96):5.0%}")
    for method in METHODS:
        print(f"time per identification, {method}: median {np.median(times[method]):.2f} s "
              f"(min {np.min(times[method]):.2f} s)")


def bound(n=100):
    """Whittle maximum likelihood on the exact modal coordinates (ambient load only)."""
    from scipy.optimize import minimize

    from crowdvib.oma.modeid import information_bound
    from crowdvib.oma.identify import ambient_response

    structure = bridge()
    frequency = np.fft.rfftfreq(int(DURATION * SAMPLE_RATE), 1 / SAMPLE_RATE)
    band = (frequency > 0.2) & (frequency < 0.98 * SAMPLE_RATE / 2)
    omega = 2 * np.pi * frequency[band]
    errors = []
    for seed in range(1, n + 1):
        ambient = ambient_response(structure, DURATION, SAMPLE_RATE, 200.0**2, rng=seed)
        modal = np.linalg.solve(structure.output_shapes, ambient)
        row = []
        for j in range(3):
            periodogram = np.abs(np.fft.rfft(modal[j])[band]) ** 2

            def deviance(p):
                w0, xi = 2 * np.pi * p[0], np.exp(p[1])
                shape = omega**4 / ((w0**2 - omega**2) ** 2 + (2 * xi * w0 * omega) ** 2)
                return np.sum(np.log(np.mean(periodogram / shape) * shape))   # level profiled

            fit = minimize(deviance, [FREQUENCIES[j], np.log(DAMPING[j])], method="Nelder-Mead",
                           options={"xatol": 1e-8, "fatol": 1e-10})
            row.append((fit.x[0] / FREQUENCIES[j] - 1, np.exp(fit.x[1]) / DAMPING[j] - 1))
        errors.append(row)
    errors = np.array(errors)                                      # seed, mode, (f, ξ)
    sf, sx = information_bound(FREQUENCIES, DAMPING, DURATION)
    print(f"Whittle ML on the exact modal coordinates, seeds 1..{n} ({_load()})")
    print("mode  σ_f/f bound  rms Δf/f   σ_ξ/ξ bound  rms Δξ/ξ  seeds beyond 20 %")
    for j in range(3):
        print(f"{j + 1:4d}  {sf[j] / FREQUENCIES[j]:11.4%}  "
              f"{np.sqrt(np.mean(errors[:, j, 0] ** 2)):8.4%}  {sx[j] / DAMPING[j]:11.1%}  "
              f"{np.sqrt(np.mean(errors[:, j, 1] ** 2)):8.1%}  "
              f"{np.flatnonzero(np.abs(errors[:, j, 1]) > 0.2) + 1}")


def pyoma2(n=3):
    """pyOMA2's EFDD at its defaults and with its bell squared, against crowdvib's EFDD."""
    import contextlib
    import io
    import logging

    import pyoma2.functions.fdd as fdd
    from pyoma2.algorithms import EFDD
    from pyoma2.setup import SingleSetup

    logging.getLogger("pyoma2").setLevel(logging.WARNING)
    amplitude = fdd.SD_svalsvec

    def power(matrix):                       # pyOMA2 returns √(singular values): square them
        values, vectors = amplitude(matrix)
        return values**2, vectors

    def run(record, nxseg, squared, method="per"):
        fdd.SD_svalsvec = power if squared else amplitude
        try:
            setup = SingleSetup(record.T, fs=SAMPLE_RATE)
            algorithm = EFDD(name="efdd", nxseg=nxseg, method_SD=method)
            setup.add_algorithms(algorithm)
            with contextlib.redirect_stderr(io.StringIO()):
                setup.run_by_name("efdd")
                algorithm.mpe(list(FREQUENCIES))
            return algorithm.result.Xi
        finally:
            fdd.SD_svalsvec = amplitude

    print(f"ξ_j [%] (truth {', '.join(f'{100 * v:.1f}' for v in DAMPING)}), {_load()}")
    for seed in range(1, n + 1):
        record = ambient_record(bridge(), seed)
        rows = {"pyOMA2 EFDD, defaults (nxseg 1024)": run(record, 1024, False),
                "pyOMA2 EFDD, nxseg 4096": run(record, 4096, False),
                "pyOMA2 EFDD, method_SD='cor', nxseg 4096": run(record, 4096, False, "cor"),
                "pyOMA2 EFDD, bell squared, nxseg 1024": run(record, 1024, True),
                "pyOMA2 EFDD, bell squared, nxseg 4096": run(record, 4096, True),
                "crowdvib EFDD": identify_modes(record, SAMPLE_RATE, n_modes=3,
                                                frequency_band=(1.0, 9.0),
                                                method="efdd").damping_ratios}
        for name, xi in rows.items():
            print(f"seed {seed}  {name:40s} {' '.join(f'{100 * v:5.2f}' for v in xi)}")


def setups(n=8):
    """Two setups sharing one reference sensor: merged shapes against the sine modes."""
    truth = sine_rows(np.concatenate([SETUP_POSITIONS[0], SETUP_POSITIONS[1][1:]]))
    print(f"two setups at {SETUP_POSITIONS[0].tolist()} and {SETUP_POSITIONS[1].tolist()} m, "
          f"reference at {SETUP_POSITIONS[0][0]:g} m; {_load()}")
    print("seed  method   s     f error [%]               MAC merged vs sine")
    for seed in range(1, n + 1):
        records = setup_records(seed)
        for method in METHODS:
            started = time.perf_counter()
            modes = identify_modes(records, SAMPLE_RATE, n_modes=3, frequency_band=(1.0, 9.0),
                                   max_order=24, method=method, reference_sensors=[[0], [0]])
            elapsed = time.perf_counter() - started
            mac = ((modes.mode_shapes * truth).sum(0) ** 2
                   / ((modes.mode_shapes**2).sum(0) * (truth**2).sum(0)))
            print(f"{seed:4d}  {method:>7s} {elapsed:5.1f}  "
                  f"{' '.join(f'{v:+7.3f}' for v in 100 * (modes.frequencies / FREQUENCIES - 1))}"
                  f"   {' '.join(f'{v:.5f}' for v in mac)}", flush=True)


#: ``speed``: the issue-27 bridge, two sensors (12.5 m, 30 m of 50 m): its two close walking-range
#: modes (first bending and a torsion-like mode of the same row shape) and a second bending mode.
SPEED_FREQUENCIES = np.array([1.69, 2.0, 7.5])
SPEED_DAMPING = np.array([0.008, 0.005, 0.012])
SPEED_RATE, SPEED_DURATION = 50.0, 1800.0


def speed_record(seed=1):
    """30 min of ambient response at 50 Hz, two sensors (``crowdvib.oma.ambient_response``)."""
    from crowdvib import ModalModel
    from crowdvib.oma import ambient_response

    x = np.linspace(0.0, 50.0, 101)
    sensors = np.array([12.5, 30.0])

    def rows(at):
        return np.column_stack([np.sin(np.pi * at / 50), np.cos(np.pi * at / 50),
                                np.sin(2 * np.pi * at / 50)])

    structure = ModalModel(SPEED_FREQUENCIES, SPEED_DAMPING, [5e4, 5e4, 5e4], x, rows(x), 3.0,
                           ("s1", "s2"), rows(sensors))
    return ambient_response(structure, SPEED_DURATION, SPEED_RATE, 200.0**2, rng=seed)


def speed():
    """CPU time of identify_modes (SSI-cov) on a 30-min two-channel record at 50 Hz."""
    import warnings

    record = speed_record()
    print(f"{_load()}; truth f = {SPEED_FREQUENCIES.tolist()} Hz, ξ = {SPEED_DAMPING.tolist()}")
    print(f"{'record':>7s} {'ch':>3s} {'rate':>5s} {'band [Hz]':>10s} {'decim':>5s} {'br':>4s} "
          f"{'order':>5s} {'CPU s':>6s} {'wall s':>6s}  modes found: f [Hz] (ξ)")
    for band in ((1.0, 9.0), None):
        started, wall = time.process_time(), time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")               # noise columns: not the point here
            modes = identify_modes(record, SPEED_RATE, frequency_band=band)
        cpu, wall = time.process_time() - started, time.perf_counter() - wall
        settings = modes.settings
        found = ", ".join(f"{f:.3f} ({xi:.4f})" for f, xi in zip(modes.frequencies,
                                                                 modes.damping_ratios))
        print(f"{SPEED_DURATION / 60:5.0f} min {record.shape[0]:3d} {SPEED_RATE:5g} "
              f"{'none' if band is None else f'{band[0]:g}–{band[1]:g}':>10s} "
              f"{settings['decimation']:5d} {settings['block_rows']:4d} "
              f"{settings['max_order']:5d} {cpu:6.1f} {wall:6.1f}  {found}", flush=True)


if __name__ == "__main__":
    commands = {"bound": bound, "pyoma2": pyoma2, "setups": setups, "speed": speed}
    if len(sys.argv) > 1 and sys.argv[1] in commands:
        commands[sys.argv[1]](*(int(a) for a in sys.argv[2:]))
    else:
        accuracy(*(int(a) for a in sys.argv[1:]))
