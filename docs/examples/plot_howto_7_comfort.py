"""
How-to 7: from a season to a year of comfort
============================================

**You have** a season of monitoring (how-to 6: ``crowdvib season`` on your records and crowd
table) and the case file of the bridge.

**You get** the hours a year the bridge spends in each comfort class (Sétra/HiVoSS CL1–CL4), the
probability that a ten-minute window exceeds a limit, and when in the week it does, without HSI,
with added mass and with the identified HSI, each without and with a tuned mass damper, with the
band of the identified MSD's interval and of the season's sampling (theory:
:ref:`theory-comfort`).

In a terminal::

    crowdvib season bridge.toml crowd.csv --records records --out season
    crowdvib comfort bridge.toml --season season --out comfort
    crowdvib comfort bridge.toml --traffic traffic.csv --msd-from season --out design-year

This page runs them on a synthetic season, each time the documentation is built.
"""

# %%
# A season
# --------
# Twelve ten-minute records over a week on the paper's example bridge (50 m, 2 Hz, 0.5 %),
# pedestrians of f_h1 = 3 Hz and ξ_h1 = 0.30, each a Gaussian record of its crowd's model PSD
# (``write_synthetic_season``), with the time each began. The case states the paper's least
# squares to keep this page fast (how-to 6 says why your season would keep the default).
import contextlib
import shlex
import sys
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

from crowdvib.cases import load_results
from crowdvib.cli import main
from crowdvib.models.examples import paper_example
from crowdvib.studies.season import write_synthetic_season

try:
    examples = Path(__file__).resolve().parents[2] / "examples"    # the repository's
except NameError:                # sphinx-gallery runs the cells in docs/examples, no __file__
    examples = Path.cwd().resolve().parents[1] / "examples"
workdir = tempfile.TemporaryDirectory(prefix="crowdvib-howto-")   # removed at exit
folder = Path(workdir.name)

paper = paper_example()
times = [f"2026-05-0{4 + day}T{hour:02d}:00" for day in (0, 2, 5) for hour in (8, 12, 17, 21)]
densities = [0.5, 0.25, 0.8, 0.1, 0.45, 0.3, 0.7, 0.05, 0.2, 0.35, 0.3, 0.1]
write_synthetic_season(folder / "records", paper.structure, paper.crowd, paper.msd,
                       densities=densities, duration=600.0, sample_rate=25.0, times=times,
                       rng=7)
text = (examples / "paper_example.toml").read_text(encoding="utf-8")
(folder / "bridge.toml").write_text(text.replace(
    "[estimation]\n", '[estimation]\nmethod = "least_squares"   # fast, for this page\n')
    + '\n[comfort]\ndamper_mass_ratio = 0.02   # the "+ damper" rows: a 2 % damper\n'
    'simulated_windows = 20      # thin crowds: 20 simulated windows a density (100 by default)\n',
    encoding="utf-8")


def run(command_line):
    """Run a crowdvib command line as typed in a terminal; print what it prints there."""
    print(f"$ {command_line}")
    with contextlib.chdir(folder), contextlib.redirect_stderr(sys.stdout):
        return main(shlex.split(command_line)[1:])


run("crowdvib season bridge.toml records/crowd.csv --records records --out season -q "
    "--workers 1")

# %%
# The year from the season
# ------------------------
# Each window stands for its hour of the week (52 hours a year); an hour of the week no window
# measured takes the windows of the same hour on days of the same kind (``[comfort] unmeasured``
# says otherwise). The MSD is the season's joint estimate, its interval the HSI band. Below a
# thin crowd, fewer than 100 effective walkers on the walkway (0.67 persons/m² here: a half-sine
# mode, where each walker counts as one), the no-HSI and HSI rows take windows made by the
# simulator, where the spectral law reads the upper tail low (``[comfort] simulate_below``; 0
# switches it off; docs: theory, A year of comfort).
status = run("crowdvib comfort bridge.toml --season season --out comfort --workers 1")
print("exit status", status)

# %%
# The figures
# -----------
# ``comfort/report.html`` holds them with the tables: hours a year per class (the bars' error
# marks are the HSI band), the probability that a window exceeds CL1's 0.5 m/s² against the
# density, the week's map of the expected class and the window's peak against the density.
results = load_results(folder / "comfort")
year = results.comfort_year()
year.plot("hours")
year.plot("week")
plt.show()

# %%
# In Python
# ---------
# The same numbers as a table (``results.to_dataframe()`` with pandas).
for row in results.table():
    print(f"{row['model']:16s} damper {str(row['damper']):5s} "
          f"CL1 {row['hours_CL1']:6.0f} h  CL2 {row['hours_CL2']:6.0f} h  "
          f"CL3 {row['hours_CL3']:6.0f} h  P(>0.5) {row['exceedance_0.5']:.2f}")

# %%
# A design traffic instead
# ------------------------
# Before a season exists, a daily profile (``hour, density``) or a design table
# (``density, hours_per_year``) stands for the year; ``--msd-from`` takes the MSD of an estimate,
# a sensitivity study or, as here, a season.
profile = [0.0] * 6 + [0.1, 0.3, 0.6, 0.3, 0.2, 0.2, 0.4, 0.3, 0.2, 0.2, 0.3, 0.7, 0.5, 0.3,
                       0.2, 0.1, 0.05, 0.0]
(folder / "traffic.csv").write_text(
    "hour,density\n" + "".join(f"{h},{d}\n" for h, d in enumerate(profile)), encoding="utf-8")
run("crowdvib comfort bridge.toml --traffic traffic.csv --msd-from season --out design-year -q "
    "--workers 1")
load_results(folder / "design-year").comfort_year().plot("exceedance")
plt.show()
