"""
How-to 6: a season of monitoring data
=====================================

**You have** a footbridge with an accelerometer that has recorded for weeks, one file per
stretch of time, and a camera or a counter that tells how many people were on the deck during
each. You have a case file of the bridge (how-to 1), which describes one record.

**You get** every record's f_h1 and ξ_h1 with its 95 % interval in one table (CSV, Parquet, a
pandas DataFrame), their trends against the crowd's density and against time, and one MSD fitted
to the whole season at once, every record with its own crowd (theory:
:ref:`theory-joint-estimation`).

In a terminal::

    crowdvib season bridge.toml crowd.csv --records records --out season
    crowdvib season bridge.toml crowd.csv --records records --out season --resume   # after ^C

The crowd table names each record (or a window of one, with ``start`` and ``end`` in seconds)
and its crowd, as a ``count`` of persons on the deck or a ``density``; optional columns give the
step frequencies, the length the count was taken over, and the time (the columns:
:func:`crowdvib.io.read_crowd_table`). This page runs it on a synthetic season, each time the
documentation is built.
"""

# %%
# The records and the crowd table
# -------------------------------
# Your season stands here as eight records of ten minutes at 25 Hz over one day, on the paper's
# example bridge (50 m, 2 Hz) with pedestrians of f_h1 = 3 Hz and ξ_h1 = 0.30, the crowd
# following a day's profile: few people at dawn, a morning and an evening peak. Each record is a
# Gaussian record of its crowd's model PSD (``write_synthetic_season``). The counter gives whole
# persons; one record is split in two windows with their own counts, and at night the counter
# saw nobody.
import contextlib
import shlex
import sys
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

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
hours = np.array([2.0, 7.0, 8.0, 9.5, 12.5, 16.0, 17.5, 18.5, 20.0])
densities = 0.05 + 0.55 * np.exp(-((hours - 8) / 1.2) ** 2) + 0.75 * np.exp(
    -((hours - 17.5) / 1.8) ** 2)
write_synthetic_season(folder / "records", paper.structure, paper.crowd, paper.msd,
                       densities=densities, duration=600.0, sample_rate=25.0, rng=6)
area = paper.structure.area                                    # 150 m² of deck
counts = np.round(densities * area).astype(int)
counts[0] = 0                                                  # 02:00: the counter saw nobody
times = [f"2026-05-04T{int(h):02d}:{int(60 * (h % 1)):02d}" for h in hours]
rows = [f"record_{i:03d}.npz,,,{n},{t}" for i, (n, t) in enumerate(zip(counts, times), start=1)
        if i != 6]
rows += [f"record_006.npz,0,300,{counts[5]},2026-05-04T16:00",      # one record, two windows
         f"record_006.npz,300,600,{counts[5]},2026-05-04T16:05"]
(folder / "crowd.csv").write_text("record,start,end,count,time\n" + "\n".join(rows) + "\n",
                                  encoding="utf-8")
print((folder / "crowd.csv").read_text())

# %%
# The case file
# -------------
# The bridge and how a record is read and estimated: the paper's example case. To keep this
# page fast it states the paper's least-squares estimator (a fraction of a second per record);
# your season would keep crowdvib's default estimator, some seconds a record. The case's crowd
# gives what the table does not: body mass, walking speed and step frequencies.
text = (examples / "paper_example.toml").read_text(encoding="utf-8")
(folder / "bridge.toml").write_text(text.replace(
    "[estimation]\n", '[estimation]\nmethod = "least_squares"   # fast, for this page\n'),
    encoding="utf-8")


def run(command_line):
    """Run a crowdvib command line as typed in a terminal; print what it prints there."""
    print(f"$ {command_line}")
    with contextlib.chdir(folder), contextlib.redirect_stderr(sys.stdout):
        return main(shlex.split(command_line)[1:])


# %%
# The season
# ----------
# Every row of the table is estimated on its own, with its interval, as a task of crowdvib's
# study runner: ``--workers N`` runs them on N local processes, ``--scheduler ADDRESS`` on a
# Dask cluster (in batches of records, so that dask's own cost per task stays small), and every
# finished record is kept in ``season/tasks``, so that ``--resume`` goes on after an
# interruption without estimating a record twice. Then all rows are estimated together: one MSD,
# each row with its crowd, by the rows' own estimator (theory: :ref:`theory-season-joint`).
# crowdvib's default likelihood weighs each record by what it holds of the MSD. The paper's least
# squares, as on this page, weigh every record alike, and a record of a thin crowd holds little
# of the MSD: with it, over a long season, ``--joint-min-density 0.3`` keeps the many quiet hours
# out of the joint estimate (``benchmarks/bench_season.py`` measures why).
status = run("crowdvib season bridge.toml crowd.csv --records records --out season --workers 1")
print("exit status", status)

# %%
# The table
# ---------
# ``season/season.csv`` (and ``season.parquet`` with ``pip install 'crowdvib[parquet]'``) holds
# one row per record or window; in Python, ``load_results("season").to_dataframe()`` gives it as
# a DataFrame. The night record is kept as ``skipped``: nobody, nothing to estimate. A record in
# ``doubt`` says why in ``warnings`` (here: few people, so ξ_h1's interval reaches its bound).
results = load_results(folder / "season")
table = results.to_dataframe()
print(table[["name", "count", "density", "frequency", "frequency_low", "frequency_high",
             "damping_ratio", "status"]].round(3).to_string(index=False))
print("joint estimate:", {key: round(results.estimate[key], 3)
                          for key in ("frequency", "damping_ratio")},
      "95 % interval of f_h1:", [round(v, 3) for v in results.interval("frequency")[:2]])

# %%
# The trends
# ----------
# ``season/season_trends.png``: f_h1 and ξ_h1 of every record with its interval, against the
# density and against time, and the joint estimate with its interval as a gray band. A trend
# against density would say the MSD model misses something that depends on the crowd (theory:
# :ref:`theory-joint-estimation`); here the records scatter within their intervals around the truth.
image = plt.imread(folder / "season" / "season_trends.png")
fig, ax = plt.subplots(figsize=(10, 6.5))
ax.imshow(image)
ax.set_axis_off()
plt.show()

# %%
# The report
# ----------
# ``season/report.html`` is the document to send: the season's span under the title (dates,
# rows, records, hours, densities), the joint estimate with the rows it rests on, a Records
# section with every row of the crowd table (its row number, time, crowd, f_h1 and ξ_h1 with
# their intervals, its status, and whether the joint estimate holds it or why not), the
# records' warnings counted, and this figure. A record in doubt makes the verdict doubt the
# season (exit status 3), as a warning does for one record.

# %%
# From Python
# -----------
# The same season without a results folder: :func:`crowdvib.cases.season_case` returns the
# table, the joint estimate and the figure; ``executor=`` and ``store=`` as for every study
# (:func:`crowdvib.runner.study_executor`, :class:`crowdvib.runner.TaskStore`).
#
# .. code-block:: python
#
#     from crowdvib import load_case
#     from crowdvib.cases import season_case
#     from crowdvib.runner import study_executor
#
#     with study_executor(workers=2) as executor:
#         found = season_case(load_case("bridge.toml"), "crowd.csv", records="records",
#                             executor=executor, store="season-tasks")
#     found.season.to_dataframe()          # the table
#     found.season.joint                   # the joint HSIEstimate
#     found.season.plot()                  # the trends
