"""The spectral route of a year of comfort against the simulator (issue 37; docs: theory, A year
of comfort, The check against the simulator).

Per density, N ten-minute windows simulated in the time domain (moving walkers with the paper's
MSD on the paper's bridge, :func:`crowdvib.comfort.simulated.simulated_windows`, on the local
pool) give the 50, 90 and 99 % quantiles of the window's peak |a| and of its largest 1-s running
RMS; the spectral route gives them from the response's spectral moments
(:func:`crowdvib.comfort.measure.peak_quantile`, Vanmarcke's clumped crossings, and Davenport's
Poisson crossings beside it). A density whose six spectral quantiles each lie within 5 % of the
simulated one, or inside its distribution-free 95 % interval (the windows cannot tell them apart:
the 99 % quantile of 100 windows is nearly their largest), is "Gaussian"; the others are named,
and the year takes the simulator's windows there (``comfort_year(simulated=…,
simulate_below=…)``).

Usage: ``python accuracy/comfort_validation.py [--windows N] [--workers W] [--densities D ...]
[--seed S] [--rst FILE] [--cache FILE]``: default 500 windows at 0.1, 0.25, 0.5, 0.75 and 1.0 persons/m² on 2
workers; ``--rst`` writes the docs' table (docs/theory/comfort_validation.inc); ``--cache``
keeps the simulated windows in a JSON file (written if absent, read back when its windows, densities
and seed are those asked for: a change of the spectral route is checked again without simulating).
"""

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

from crowdvib.comfort.measure import peak_quantile, window_law
from crowdvib.comfort.occupied import occupied_law, occupied_peak_quantile
from crowdvib.comfort.simulated import (GAUSSIAN_TOLERANCE, SimulatedWindows, simulated_check,
                                        simulated_windows)
from crowdvib.comfort.year import QUANTILES
from crowdvib.design.stochastic import frequency_grid
from crowdvib.models.examples import paper_example
from crowdvib.response.fluctuation import spectral_model
from crowdvib.runner import study_executor

DENSITIES = (0.1, 0.25, 0.5, 0.75, 1.0)


def davenport(structure, crowd, msd, density):
    """Davenport's (Poisson crossings) quantiles of the peak at ``density``, for the table."""
    here = crowd.with_density(density)
    model = spectral_model(structure, here, frequency_grid(structure, here, msd, []))
    law = window_law(model.frequency, model.psd_array(msd)[0])
    return peak_quantile(np.array(QUANTILES), law, 600.0, "davenport")


def occupancy(structure, crowd, msd, density):
    """The quantiles of the peak over the crowd's occupancy states
    (:mod:`crowdvib.comfort.occupied`), for the table."""
    here = crowd.with_density(density)
    states = occupied_law(structure, here, frequency_grid(structure, here, msd, []), msd=msd)
    return occupied_peak_quantile(np.array(QUANTILES), states)


def _percent(values):
    return " / ".join(f"{100 * v:+.1f}" for v in values)


def _triple(values):
    return " / ".join(f"{v:.3f}" for v in values)


def table(rows, extra, states, n_windows):
    """The docs' list-table (RST)."""
    lines = [".. list-table:: Spectral against simulated 10-minute quantiles (50 / 90 / 99 %), "
             f"paper example with HSI, {n_windows} windows per density",
             "   :header-rows: 1", "",
             "   * - density [P/m²]", "     - peak, simulated [m/s²]",
             "     - peak, spectral − simulated [%]", "     - peak, Davenport − simulated [%]",
             "     - peak, occupancy states − simulated [%]",
             "     - running RMS, simulated [m/s²]", "     - running RMS, spectral − simulated [%]",
             "     - Gaussian (each within 5 % or inside the simulated 95 % interval)"]
    for row, dav, occupied in zip(rows, extra, states):
        lines += [f"   * - {row['density']:g}", f"     - {_triple(row['simulated_peak'])}",
                  f"     - {_percent(row['peak_error'])}",
                  f"     - {_percent(np.array(dav) / np.array(row['simulated_peak']) - 1)}",
                  f"     - {_percent(np.array(occupied) / np.array(row['simulated_peak']) - 1)}",
                  f"     - {_triple(row['simulated_running_rms'])}",
                  f"     - {_percent(row['running_rms_error'])}",
                  f"     - {'yes' if row['gaussian'] else 'no'}"]
    return "\n".join(lines) + "\n"


def cached(path, args, simulate):
    """The windows of ``args`` from the JSON file ``path`` if it holds them, else simulated and
    written there (``simulate()``; a file holding other windows is left alone)."""
    key = {"windows": args.windows, "densities": list(args.densities), "seed": args.seed}
    if path is not None and path.exists():
        found = json.loads(path.read_text(encoding="utf-8"))
        if found.get("key") != key:
            raise SystemExit(f"{path} holds other windows ({found.get('key')}); asked {key}")
        return SimulatedWindows(tuple(found["densities"]), tuple(map(np.array, found["peak"])),
                                tuple(map(np.array, found["running_rms"])), found["cpu"])
    windows = simulate()
    if path is not None:
        path.write_text(json.dumps(dict(windows.to_dict(), key=key, cpu=windows.cpu)),
                        encoding="utf-8")
    return windows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--windows", type=int, default=500)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--densities", type=float, nargs="+", default=list(DENSITIES))
    parser.add_argument("--seed", type=int, default=37)
    parser.add_argument("--rst", type=Path, default=None)
    parser.add_argument("--cache", type=Path, default=None)
    args = parser.parse_args()
    paper = paper_example()
    started, wall = time.process_time(), time.perf_counter()

    def simulate():
        with study_executor(args.workers, timeout_floor=600.0) as executor:
            return simulated_windows(paper.structure, paper.crowd, args.densities,
                                     msd=paper.msd, n_windows=args.windows, seed=args.seed,
                                     executor=executor)

    windows = cached(args.cache, args, simulate)
    simulated_cpu = time.process_time() - started
    rows = simulated_check(paper.structure, paper.crowd, args.densities, msd=paper.msd,
                           simulated=windows)
    extra = [davenport(paper.structure, paper.crowd, paper.msd, d) for d in args.densities]
    states = [occupancy(paper.structure, paper.crowd, paper.msd, d) for d in args.densities]
    text = table(rows, extra, states, args.windows)
    print(text)
    parting = [row["density"] for row in rows if not row["gaussian"]]
    print(f"densities where the spectral route parts from the simulator (> "
          f"{100 * GAUSSIAN_TOLERANCE:g} %): {parting or 'none'}")
    print(f"{args.windows} windows x {len(args.densities)} densities on {args.workers} "
          f"worker(s): wall {time.perf_counter() - wall:.0f} s, CPU of the simulation tasks "
          f"{windows.cpu:.0f} s (this process {simulated_cpu:.0f} s); load "
          f"{os.getloadavg()[0]:.1f}")
    if args.rst is not None:
        args.rst.write_text(text, encoding="utf-8")
        print(f"wrote {args.rst}")


if __name__ == "__main__":
    main()
