"""The MSD's leverage on the occupied frequency across the paper's parametric family (issue 33 §5).

    python accuracy/leverage.py [--step H]

Findings 5 and 6 of the paper's parametric study (docs: theory, Studies) are about where an
error ε_f in the bridge's natural frequency hurts the estimate. The fit can absorb a shift of
the occupied resonance f_occ only by moving f_h1, so what decides is the MSD's leverage on the
occupied frequency, ∂f_occ/∂f_h1: a 1 % error in f_1 moves f_occ by about ε_f f_1 ∂f_occ/∂f_1,
and the fit must move f_h1 by that over ∂f_occ/∂f_h1 to follow it.

For the family's structures (the 50 m × 3 m beam, first mode, f_1 = 1–6 Hz, modal mass from the
crowd-to-structure mass ratio μ_m, as ``crowdvib.studies.parametric_study`` builds them) at the
paper's crowd (0.5 P/m², 70 kg) and MSD (3.0 Hz, 30 %, 0.95), this prints, per f_1 and μ_m:

* ∂f_occ/∂f_h1 and ∂f_occ/∂f_1, central differences of
  :func:`crowdvib.effective_modal_properties` with relative step H (default 1e-4);
* f_h1 shift the fit needs to follow a 1 % error in f_1, ε_f f_1 (∂f_occ/∂f_1)/(∂f_occ/∂f_h1);
* the occupied and the empty half-power widths 2 ξ f [Hz], and their ratio.

ξ_1 = 0.5 % (the paper's lightest damping, where findings 5 and 6 are read). Asserts nothing;
under a second of CPU.
"""

import argparse

import numpy as np

from crowdvib import MSDModel, effective_modal_properties
from crowdvib.models.examples import paper_example
from crowdvib.studies.parametric import _paper_family_structure

FREQUENCIES = np.arange(1.0, 6.01, 0.5)
MASS_RATIOS = (0.025, 0.05, 0.10)
DAMPING = 0.005
EPSILON_F = 0.01


def occupied(f1, f_h1, mass_ratio, crowd, msd):
    """(f_occ, ξ_occ) of the family's structure f_1 with the MSD at f_h1."""
    structure = _paper_family_structure(f1, DAMPING, mass_ratio, crowd)
    props = effective_modal_properties(structure, crowd,
                                       MSDModel(f_h1, msd.damping_ratio, msd.mass_ratio))
    return float(props.frequencies[0]), float(props.damping_ratios[0])


def leverage(f1, mass_ratio, crowd, msd, step=1e-4):
    """Row of the table for one structure (module docstring)."""
    f_h1 = msd.frequency
    dh = step * f_h1
    d_h1 = (occupied(f1, f_h1 + dh, mass_ratio, crowd, msd)[0]
            - occupied(f1, f_h1 - dh, mass_ratio, crowd, msd)[0]) / (2 * dh)
    d1 = step * f1
    d_1 = (occupied(f1 + d1, f_h1, mass_ratio, crowd, msd)[0]
           - occupied(f1 - d1, f_h1, mass_ratio, crowd, msd)[0]) / (2 * d1)
    f_occ, xi_occ = occupied(f1, f_h1, mass_ratio, crowd, msd)
    return {"f1": f1, "mass_ratio": mass_ratio, "f_occ": f_occ, "dfocc_dfh1": d_h1,
            "dfocc_df1": d_1, "follow": EPSILON_F * f1 * d_1 / d_h1,
            "width_occupied": 2 * xi_occ * f_occ, "width_empty": 2 * DAMPING * f1}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--step", type=float, default=1e-4,
                        help="relative step of the central differences (default 1e-4)")
    args = parser.parse_args()
    example = paper_example()
    crowd, msd = example.crowd, example.msd
    print(f"crowd {crowd.density} P/m², MSD {msd.frequency} Hz / {msd.damping_ratio} / "
          f"{msd.mass_ratio}, ξ_1 = {DAMPING:.3f}, ε_f = {EPSILON_F:.0%}")
    print(f"{'f_1':>5} {'μ_m':>6} {'f_occ':>7} {'∂f_occ/∂f_h1':>13} {'∂f_occ/∂f_1':>12} "
          f"{'Δf_h1 for ε_f':>14} {'width occ.':>11} {'width empty':>12} {'ratio':>6}")
    for mass_ratio in MASS_RATIOS:
        for f1 in FREQUENCIES:
            row = leverage(float(f1), mass_ratio, crowd, msd, args.step)
            print(f"{row['f1']:5.1f} {row['mass_ratio']:6.3f} {row['f_occ']:7.3f} "
                  f"{row['dfocc_dfh1']:13.4f} {row['dfocc_df1']:12.4f} "
                  f"{row['follow']:+14.3f} {row['width_occupied']:11.4f} "
                  f"{row['width_empty']:12.4f} {row['width_occupied'] / row['width_empty']:6.2f}")


if __name__ == "__main__":
    main()
