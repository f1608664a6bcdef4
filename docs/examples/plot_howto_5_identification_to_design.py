"""
How-to 5: from an identified crowd to a design decision
=======================================================

**You have** a record of your bridge under a crowd (how-to 1) and a design case for it: the
codes and traffic classes the client asks for (how-to 2).

**You get** the design check with the pedestrians' MSD *identified* on the bridge rather than
assumed, and how far the utilisation moves across the estimate's 95 % interval: a verdict at
the interval's conservative end, which is the one to sign.

In a terminal::

    crowdvib estimate paper_example.toml --out estimate
    crowdvib check check_paper.toml --msd-from estimate --out check

and, for the interval, a few lines of Python (below). The cases are ``examples/paper_example.toml``
(the paper's bridge with a one-hour record under 0.5 persons/m²) and
``examples/check_paper.toml`` (the same bridge against four codes) of the repository.
"""

# %%
# Step 1: the estimate with its interval
# --------------------------------------
# As in how-to 1, with crowdvib's default estimator: f_h1 and ξ_h1 with their 95 % profile
# likelihood intervals. The record was simulated with f_h1 = 3 Hz and ξ_h1 = 0.30 (the
# ``expected`` lines).
import contextlib
import shlex
import shutil
import sys
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from crowdvib import MSDModel, load_case
from crowdvib.cases import check_case, load_results
from crowdvib.cli import main

try:
    examples = Path(__file__).resolve().parents[2] / "examples"    # the repository's
except NameError:                # sphinx-gallery runs the cells in docs/examples, no __file__
    examples = Path.cwd().resolve().parents[1] / "examples"
workdir = tempfile.TemporaryDirectory(prefix="crowdvib-howto-")   # removed at exit
folder = Path(workdir.name)
for name in ("paper_example.toml", "paper_example_record.npz", "check_paper.toml"):
    shutil.copy(examples / name, folder)


def run(command_line):
    """Run a crowdvib command line as typed in a terminal; print what it prints there."""
    print(f"$ {command_line}")
    # In the guide's folder (sphinx-gallery runs each cell in docs/examples); a terminal shows
    # both streams.
    with contextlib.chdir(folder), contextlib.redirect_stderr(sys.stdout):
        return main(shlex.split(command_line)[1:])


run("crowdvib estimate paper_example.toml --out estimate")
estimate = load_results(folder / "estimate").estimate
(f_low, f_high), (xi_low, xi_high) = (estimate["interval"][name]
                                      for name in ("frequency", "damping_ratio"))

# %%
# Step 2: the design check with the identified MSD
# ------------------------------------------------
# ``--msd-from`` replaces the case's ``[hsi]`` MSD by the estimate's for the "HSI" rows (the
# "no HSI" and "added mass" rows do not depend on it).
run("crowdvib check check_paper.toml --msd-from estimate --out check")

# %%
# Step 3: the utilisation across the interval
# -------------------------------------------
# :func:`crowdvib.cases.check_case` runs the same checks from Python, without writing anything,
# with any MSD. We check a 5 × 5 grid over the box of the two 95 % intervals (wider than their
# joint region, so on the safe side) and keep, per code, the largest utilisation over the
# outputs of the HSI model.
design_case = load_case(folder / "check_paper.toml")
codes = list(design_case.design.codes)


def hsi_utilisation(frequency, damping_ratio):
    """{code: largest utilisation over the outputs} with this MSD."""
    rows = check_case(design_case, msd=MSDModel(frequency, damping_ratio,
                                                estimate["mass_ratio"])).rows
    return {code: max(r["utilisation"] for r in rows if r["code"] == code and r["model"] == "HSI")
            for code in codes}


frequencies = np.linspace(f_low, f_high, 5)
damping_ratios = np.linspace(xi_low, xi_high, 5)
grid = [[hsi_utilisation(f, xi) for f in frequencies] for xi in damping_ratios]
at_estimate = hsi_utilisation(estimate["frequency"], estimate["damping_ratio"])

print(f"f_h1 = {estimate['frequency']:.2f} Hz ({f_low:.2f}–{f_high:.2f}), "
      f"ξ_h1 = {estimate['damping_ratio']:.3f} ({xi_low:.3f}–{xi_high:.3f})\n")
print(f"{'code':8s}{'at the estimate':>16s}{'across the interval':>22s}   verdict at the "
      "conservative end")
for code in codes:
    values = [cell[code] for row in grid for cell in row]
    verdict = ("passes" if max(values) <= 1.0 else
               "FAILS" if min(values) > 1.0 else "FAILS (the interval decides)")
    print(f"{code:8s}{at_estimate[code]:16.2f}{min(values):14.2f} – {max(values):4.2f}   "
          f"{verdict}")

# %%
# Lower ξ_h1 (less damping from the crowd) and higher f_h1 raise the response. A code that
# fails over the whole interval needs a damper (how-to 2) whatever the exact MSD; one that
# passes over all of it is settled too. Here HiVoSS, Sétra and EN 1990 fail throughout, and the
# UK NA is the code the interval decides: below its limit at the point estimate, about at it in
# the interval's unfavourable corner, so the verdict to sign is the one at that corner. The map
# of its utilisation over the interval, with the limit (1.0) and the estimate:
ukna = np.array([[cell["ukna"] for cell in row] for row in grid])
figure, axes = plt.subplots(figsize=(7, 4.5))
filled = axes.contourf(frequencies, damping_ratios, ukna, levels=12, cmap="viridis")
limit = axes.contour(frequencies, damping_ratios, ukna, levels=[1.0], colors="red")
axes.clabel(limit, fmt="limit %.1f")
axes.plot(estimate["frequency"], estimate["damping_ratio"], "w*", markersize=14,
          label="estimate")
figure.colorbar(filled, label="UK NA utilisation, HSI [-]")
axes.set(xlabel="f_h1 [Hz]", ylabel="ξ_h1 [-]",
         title="UK NA utilisation across the 95 % intervals of f_h1 and ξ_h1")
axes.legend(loc="upper right")

# %%
# And the modelling errors?
# -------------------------
# The interval is the record's statistical uncertainty only. The bridge's own frequency, damping
# and modal mass, known to a few percent, move the estimate too: ``crowdvib sensitivity``
# (how-to 4) prints the interval widened by that modelling bound ("together …"). Checking that
# wider box the same way gives the verdict that accounts for both.
