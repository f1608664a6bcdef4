"""Speed of the spectral model and the estimator (issues 2 and 14). Prints a table; asserts nothing.

    python benchmarks/bench_spectral.py
"""

import time

import numpy as np
from threadpoolctl import threadpool_limits

from crowdvib import Crowd, ModalModel, MSDModel, estimate_hsi, response_psd
from crowdvib.models.examples import paper_example


def best_of(function, repeat=7, number=None):
    """Best mean time per call [s] over ``repeat`` batches."""
    if number is None:
        started = time.perf_counter()
        function()
        number = max(1, int(0.2 / max(time.perf_counter() - started, 1e-6)))
    timings = []
    for _ in range(repeat):
        started = time.perf_counter()
        for _ in range(number):
            function()
        timings.append((time.perf_counter() - started) / number)
    return min(timings)


def fourteen_mode_bridge():
    """A 96 m × 3 m deck with 14 modes and 2 outputs (Eeklo-sized; shapes assumed sines)."""
    x = np.linspace(0, 96.0, 481)
    order = np.arange(1, 15)
    shapes = np.sin(np.pi * np.outer(x, order) / 96.0)
    return ModalModel(frequencies=np.linspace(1.69, 12.0, 14), damping_ratios=np.full(14, 0.004),
                      modal_masses=np.full(14, 40e3), positions=x, mode_shapes=shapes, width=3.0,
                      output_names=["main", "side"],
                      output_shapes=np.sin(np.pi * np.outer([48.0, 13.5], order) / 96.0))


def main():
    case = paper_example()
    msd = MSDModel()
    grid = np.arange(0, 601) / 60.0
    rows = []
    rows.append(("response_psd, paper example, 601 f (0-10 Hz at 1/60 Hz)", "<= 1 ms",
                 best_of(lambda: response_psd(case.structure, case.crowd, grid, msd=msd,
                                              crowd_model="smeared"))))
    rows.append(("  same, Welch-smoothed model (T = 60 s)", "<= 2 ms",
                 best_of(lambda: response_psd(case.structure, case.crowd, grid, msd=msd,
                                              welch_window_length=60.0, crowd_model="smeared"))))
    big = fourteen_mode_bridge()
    crowd = Crowd.from_density(0.5)
    grid_6000 = np.linspace(0.0, 20.0, 6000)
    rows.append(("response_psd, 14 modes x 2 outputs x 6000 f", "<= 30 ms",
                 best_of(lambda: response_psd(big, crowd, grid_6000, msd=msd,
                                              crowd_model="smeared"))))
    with threadpool_limits(1):
        rows.append(("  same, Welch-smoothed (T = 60 s), one BLAS thread", "<= 20 ms",
                     best_of(lambda: response_psd(big, crowd, grid_6000, msd=msd,
                                                  welch_window_length=60.0,
                                                  crowd_model="smeared"), repeat=3)))
    measured = response_psd(case.structure, case.crowd, grid, msd=msd, welch_window_length=60.0,
                            crowd_model="smeared")
    rows.append(("estimate_hsi, paper example, 4 starts (Welch model)", "<= 0.5 s",
                 best_of(lambda: estimate_hsi(measured, case.structure, case.crowd,
                                              band=(0.0, 10.0)), repeat=3, number=1)))
    exact = response_psd(case.structure, case.crowd, grid, msd=msd, crowd_model="smeared")
    rows.append(("estimate_hsi, paper example, 4 starts (exact model)", "-",
                 best_of(lambda: estimate_hsi(exact, case.structure, case.crowd,
                                              band=(0.0, 10.0)), repeat=3, number=1)))
    print(f"{'benchmark':58s} {'target':>9s} {'measured':>12s}")
    for name, target, seconds in rows:
        shown = f"{seconds * 1e3:.3f} ms" if seconds < 1 else f"{seconds:.3f} s"
        print(f"{name:58s} {target:>9s} {shown:>12s}")


if __name__ == "__main__":
    main()
