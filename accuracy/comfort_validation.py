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
[--seed S] [--rst FILE] [--cache FILE] [--case FILE [--output NAME]]``: default 500 windows at
0.1, 0.25, 0.5, 0.75 and 1.0 persons/m² on 2 workers; ``--rst`` writes the docs' table
(docs/theory/comfort_validation.inc); ``--cache`` keeps the simulated windows in a JSON file
(written if absent, read back when its windows, densities, seed, case and output are those asked
for: a change of the spectral route is checked again without simulating). ``--case`` checks
another bridge: a case file's structure and crowd with the MSD it simulates with
(:func:`crowdvib.cases.simulation.simulation_msd`, its ``[expected]`` truth), judged at
``--output`` (default its first output); the table then names the walkers expected on the
walkway at each density, against the thin-crowd rule's
(:func:`crowdvib.comfort.measure.thin_crowd_density`: 100 effective walkers).
"""

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

from crowdvib.comfort.measure import (THIN_CROWD_WALKERS, peak_quantile, thin_crowd_density,
                                      window_law)
from crowdvib.comfort.occupied import occupied_law, occupied_peak_quantile
from crowdvib.comfort.simulated import (GAUSSIAN_TOLERANCE, SimulatedWindows, simulated_check,
                                        simulated_windows)
from crowdvib.comfort.year import QUANTILES
from crowdvib.cases.simulation import simulation_msd
from crowdvib.design.stochastic import frequency_grid
from crowdvib.io.casefile import load_case
from crowdvib.models.examples import paper_example
from crowdvib.response.frequency_domain.fluctuation import spectral_model
from crowdvib.runner import study_executor

DENSITIES = (0.1, 0.25, 0.5, 0.75, 1.0)


def davenport(structure, crowd, msd, density, output=0):
    """Davenport's (Poisson crossings) quantiles of the peak at ``density``, for the table."""
    here = crowd.with_density(density)
    model = spectral_model(structure, here, frequency_grid(structure, here, msd, []))
    law = window_law(model.frequency, model.psd_array(msd)[output])
    return peak_quantile(np.array(QUANTILES), law, 600.0, "davenport")


def occupancy(structure, crowd, msd, density, output=0):
    """The quantiles of the peak over the crowd's occupancy states
    (:mod:`crowdvib.comfort.occupied`), for the table."""
    here = crowd.with_density(density)
    states = occupied_law(structure, here, frequency_grid(structure, here, msd, []), msd=msd,
                          output=output)
    return occupied_peak_quantile(np.array(QUANTILES), states)


def own_step_frequency(structure, crowd, msd, density, output=0, seed=37, n_draws=20000):
    """The quantiles of the peak over states of occupancy *and* of each walker's own step
    frequency (issue 37's candidate for the thin crowd; docs: theory, Where the Gaussian model
    holds), for the table: a Monte Carlo law of the states, seeded.

    A state is the walkers on the deck, each with its place x_k, step frequency f_k and DLFs
    α_kc (the simulator's draws: :meth:`ForceModel.sample`). Walker k adds φ²(x_k) g_k to the
    mean square, g_k = Σ_c α_kc²/2 c(r_c f_k) with c(f) the response per unit load at f:
    G(f)/s(f) of the average crowd smoothed by the crossing kernel (a Gaussian of σ_K,
    :mod:`crowdvib.response.frequency_domain._crossing`). With λ = Σ φ²/ψ̄ and u = Σ φ² g/(ψ̄ E[g]) a state's
    response is the occupancy state λ's (:func:`crowdvib.comfort.occupied.occupied_law`) with
    σ² = (σ_λ²/λ) u, and the window crosses a level at the states' mean rate.
    """
    from crowdvib.comfort.measure import WindowLaw
    from crowdvib.comfort.occupied import OccupiedLaw
    from crowdvib.models.loading import as_force_model
    from crowdvib.response.frequency_domain.fluctuation import FluctuatingSpectralModel
    from crowdvib.response.frequency_domain.spectral import SpectralModel

    here = crowd.with_density(density)
    grid = frequency_grid(structure, here, msd, [])
    states = occupied_law(structure, here, grid, msd=msd, output=output)
    force = as_force_model(None)
    spread = FluctuatingSpectralModel(structure, here, grid, n_nodes=1).crossing_spread
    load = force.load_spectrum(grid, here)
    gain = np.where(load > load.max() * 1e-12, SpectralModel(structure, here, grid)
                    .psd_array(msd)[output] / np.where(load > 0, load, 1.0), 0.0)
    step = grid[1] - grid[0]
    offset = np.arange(-int(5 * spread / step), int(5 * spread / step) + 1) * step
    kernel = np.exp(-offset**2 / (2 * spread**2))
    gain = np.convolve(gain, kernel / kernel.sum(), mode="same")

    rng = np.random.default_rng(seed)

    def walker(count):
        f = here.step_frequency_mean + here.step_frequency_std * rng.standard_normal(count)
        dlf, _ = force.sample(f, rng)
        return (dlf**2 / 2 * np.interp(force.ratios * f[:, None], grid, gain)).sum(axis=1)

    mean_g = walker(200000).mean()
    weights = structure._area_weights.ravel() / structure._area_weights.sum()
    phi2 = (structure.mode_shapes[..., FluctuatingSpectralModel(structure, here, grid,
                                                                n_nodes=1).mode] ** 2).ravel()
    psi = density * structure.area * (weights @ phi2)          # E[Σ φ²]
    counts = rng.poisson(density * structure.area, n_draws)
    occupancy, load_state = np.zeros(n_draws), np.zeros(n_draws)
    for i, count in enumerate(counts):
        shares = phi2[rng.choice(phi2.size, count, p=weights)]
        occupancy[i] = shares.sum() / psi
        load_state[i] = shares @ walker(count) / (psi * mean_g)
    at = np.clip(occupancy, states.occupancy[0], states.occupancy[-1])
    laws = states.laws

    def column(values):
        return np.interp(at, states.occupancy, values)

    rms = np.sqrt(column(laws.rms**2 / states.occupancy) * load_state)
    mixed = WindowLaw(rms, column(laws.crossing_rate), column(laws.spread),
                      column(laws.ms_std / laws.rms**2) * rms**2, column(laws.ms_rate))
    return occupied_peak_quantile(np.array(QUANTILES),
                                  OccupiedLaw(np.full(n_draws, 1 / n_draws), occupancy, mixed))


def _percent(values):
    return " / ".join(f"{100 * v:+.1f}" for v in values)


def _triple(values):
    return " / ".join(f"{v:.3f}" for v in values)


def table(rows, extra, states, own, n_windows, title, area):
    """The docs' list-table (RST); ``area`` the walkway's [m²] (the walkers expected on it)."""
    lines = [".. list-table:: Spectral against simulated 10-minute quantiles (50 / 90 / 99 %), "
             f"{title}, {n_windows} windows per density",
             "   :header-rows: 1", "",
             "   * - density [P/m²]", "     - walkers on the walkway",
             "     - peak, simulated [m/s²]",
             "     - peak, spectral − simulated [%]", "     - peak, Davenport − simulated [%]",
             "     - peak, occupancy states − simulated [%]",
             "     - peak, occupancy × own step frequency − simulated [%]",
             "     - running RMS, simulated [m/s²]", "     - running RMS, spectral − simulated [%]",
             "     - Gaussian (each within 5 % or inside the simulated 95 % interval)"]
    for row, dav, occupied, stepping in zip(rows, extra, states, own):
        lines += [f"   * - {row['density']:g}", f"     - {row['density'] * area:.0f}",
                  f"     - {_triple(row['simulated_peak'])}",
                  f"     - {_percent(row['peak_error'])}",
                  f"     - {_percent(np.array(dav) / np.array(row['simulated_peak']) - 1)}",
                  f"     - {_percent(np.array(occupied) / np.array(row['simulated_peak']) - 1)}",
                  f"     - {_percent(np.array(stepping) / np.array(row['simulated_peak']) - 1)}",
                  f"     - {_triple(row['simulated_running_rms'])}",
                  f"     - {_percent(row['running_rms_error'])}",
                  f"     - {'yes' if row['gaussian'] else 'no'}"]
    return "\n".join(lines) + "\n"


def cached(path, args, simulate):
    """The windows of ``args`` from the JSON file ``path`` if it holds them, else simulated and
    written there (``simulate()``; a file holding other windows is left alone)."""
    key = {"windows": args.windows, "densities": list(args.densities), "seed": args.seed}
    if args.case is not None:                    # the paper's files keep their key
        key.update(case=args.case.name, output=args.output)
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


def bridge(args):
    """(structure, crowd, MSD, output index, title) of the bridge checked."""
    if args.case is None:
        paper = paper_example()
        return paper.structure, paper.crowd, paper.msd, 0, "paper example with HSI"
    case = load_case(args.case)
    output = 0 if args.output is None else int(case.structure.output_index(args.output)[0])
    name = case.structure.output_names[output]
    return (case.structure, case.crowd, simulation_msd(case), output,
            f"{case.name} with HSI at {name}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--windows", type=int, default=500)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--densities", type=float, nargs="+", default=list(DENSITIES))
    parser.add_argument("--seed", type=int, default=37)
    parser.add_argument("--rst", type=Path, default=None)
    parser.add_argument("--cache", type=Path, default=None)
    parser.add_argument("--case", type=Path, default=None)
    parser.add_argument("--output", default=None)
    args = parser.parse_args()
    structure, crowd, msd, output, title = bridge(args)
    started, wall = time.process_time(), time.perf_counter()

    def simulate():
        with study_executor(args.workers, timeout_floor=600.0) as executor:
            return simulated_windows(structure, crowd, args.densities, msd=msd, output=output,
                                     n_windows=args.windows, seed=args.seed,
                                     executor=executor)

    windows = cached(args.cache, args, simulate)
    simulated_cpu = time.process_time() - started
    rows = simulated_check(structure, crowd, args.densities, msd=msd, output=output,
                           simulated=windows)
    extra = [davenport(structure, crowd, msd, d, output) for d in args.densities]
    states = [occupancy(structure, crowd, msd, d, output) for d in args.densities]
    own = [own_step_frequency(structure, crowd, msd, d, output, args.seed)
           for d in args.densities]
    text = table(rows, extra, states, own, args.windows, title, structure.area)
    print(text)
    parting = [row["density"] for row in rows if not row["gaussian"]]
    print(f"densities where the spectral route parts from the simulator (> "
          f"{100 * GAUSSIAN_TOLERANCE:g} %): {parting or 'none'}; thin-crowd rule: below "
          f"{THIN_CROWD_WALKERS:g} effective walkers = {thin_crowd_density(structure):.3g} "
          "persons/m² here")
    print(f"{args.windows} windows x {len(args.densities)} densities on {args.workers} "
          f"worker(s): wall {time.perf_counter() - wall:.0f} s, CPU of the simulation tasks "
          f"{windows.cpu:.0f} s (this process {simulated_cpu:.0f} s); load "
          f"{os.getloadavg()[0]:.1f}")
    if args.rst is not None:
        args.rst.write_text(text, encoding="utf-8")
        print(f"wrote {args.rst}")


if __name__ == "__main__":
    main()
