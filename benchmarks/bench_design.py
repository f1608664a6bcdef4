"""Speed of the design checks and damper tuning (issue 11). Prints a table; asserts nothing.

    python benchmarks/bench_design.py
"""

from pathlib import Path

import numpy as np

from crowdvib import Crowd, MSDModel, frf
from crowdvib.design import design_check, tune_damper
from crowdvib.design.codes import TRAFFIC_CLASSES

from crowdvib.io.casefile import load_case

from bench_spectral import best_of, fourteen_mode_bridge

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def main():
    bridge = fourteen_mode_bridge()
    msd = MSDModel()
    rows = []
    for code, classes in TRAFFIC_CLASSES.items():
        for traffic_class in classes:
            def run(code=code, traffic_class=traffic_class):
                return design_check(bridge, code, traffic_class=traffic_class, msd=msd)
            check = run()
            rows.append((f"design_check {code} {traffic_class} (empty, added mass, HSI)",
                         "< 1 s", best_of(run, repeat=3), check))
    eeklo = load_case(EXAMPLES / "eeklo_like.toml").structure
    for traffic_class in ("A", "B", "C", "D"):
        def run(traffic_class=traffic_class):
            return design_check(eeklo, "ukna", traffic_class=traffic_class, msd=msd)
        label = (f"ukna {traffic_class} eeklo_like {eeklo.n_modes} modes x "
                 f"{eeklo.n_outputs} outputs (time domain)")
        rows.append((label, "< 5 s",
                     best_of(run, repeat=3), run()))
    crowd = Crowd.from_density(0.5)
    damper = tune_damper(bridge, 0, 0.02)
    for code, traffic_class in (("hivoss", "TC3"), ("setra", "I")):
        def run(code=code, traffic_class=traffic_class):
            return design_check(bridge, code, traffic_class=traffic_class, msd=msd,
                                dampers=[damper])
        rows.append((f"design_check {code} {traffic_class}, 2 % damper on mode 1", "< 1 s",
                     best_of(run, repeat=3), run()))
    grid = np.linspace(0.0, 20.0, 6000)
    timed = [("tune_damper mode 1, empty", best_of(lambda: tune_damper(bridge, 0, 0.02), 3)),
             ("tune_damper mode 1, occupied (HSI)",
              best_of(lambda: tune_damper(bridge, 0, 0.02, crowd=crowd, msd=msd), 3)),
             ("frf 2 x 2 x 6000 f, crowd + damper",
              best_of(lambda: frf(bridge, grid, crowd=crowd, msd=msd, dampers=[damper]), 3))]
    print(f"{'benchmark':56s} {'target':>7s} {'time':>10s} {'governing [m/s²]':>18s} "
          f"{'HSI/empty':>10s} {'class':>6s}")
    for name, target, seconds, check in rows:
        governing = "/".join(f"{value:.3f}" for value in check.governing)
        ratio = "/".join(f"{value:.2f}" for value in check.ratios["hsi/empty"])
        print(f"{name:56s} {target:>7s} {seconds * 1e3:8.2f} ms {governing:>18s} {ratio:>10s} "
              f"{'/'.join(check.comfort_class):>6s}")
    for name, seconds in timed:
        print(f"{name:56s} {'-':>7s} {seconds * 1e3:8.2f} ms")


if __name__ == "__main__":
    main()
