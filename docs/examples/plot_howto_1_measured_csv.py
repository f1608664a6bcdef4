"""
How-to 1: from a measured CSV to an estimate and a report
=========================================================

**You have** a CSV of vertical accelerations from your footbridge while a crowd walked on it, as a
data logger writes it: a header row, a ``Time [s]`` column, values in g with the accelerometer's
1 g offset, and no stated sample rate. You know the bridge's first vertical mode (from a design
model or an ambient test, see :ref:`sphx_glr_auto_examples_plot_howto_3_ambient_modes.py`) and
roughly how many people were on it.

**You get** the pedestrians' mass-spring-damper (MSD) parameters f_h1 and ξ_h1 with their 95 %
interval, the fit of the measured PSD, and ``report.html`` to send on.

The steps are four commands in a terminal::

    crowdvib init bridge.csv                  # what the record holds → bridge.toml, a draft
    (edit bridge.toml: replace each "REPLACE: …" value)
    crowdvib estimate bridge.toml --out results
    crowdvib report results                   # (estimate already wrote it; again after edits)

This page runs them, in a fresh folder, each time the documentation is built.
"""

# %%
# The record
# ----------
# Your logger's file stands here as a synthetic one: 15 minutes at 25 Hz of the midspan response
# of the paper's example bridge (50 m, 2 Hz, 0.5 persons/m², pedestrians with f_h1 = 3 Hz and
# ξ_h1 = 0.30; theory: :ref:`theory-spectral`), a Gaussian record of its model PSD, written in g
# with the 1 g offset. With your own file, skip this step.
import contextlib
import re
import shlex
import sys
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from crowdvib import ModalModel, response_psd
from crowdvib.cases import load_results
from crowdvib.cli import main
from crowdvib.models.examples import paper_example
from crowdvib.models.loading import STANDARD_GRAVITY
from crowdvib.signals.synthesis import gaussian_record, record_frequencies

workdir = tempfile.TemporaryDirectory(prefix="crowdvib-howto-")   # removed at exit
folder = Path(workdir.name)

rate, duration = 25.0, 900.0                     # [Hz], [s]
paper = paper_example()
bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3, outputs={"midspan": 25.0})
psd = response_psd(bridge, paper.crowd, record_frequencies(duration, rate), msd=paper.msd,
                   crowd_model="smeared").psd
in_g = gaussian_record(psd, rate, rng=7)[0] / STANDARD_GRAVITY + 1.0
np.savetxt(folder / "bridge.csv", np.c_[np.arange(in_g.size) / rate, in_g], delimiter=",",
           fmt="%.6f", header="Time [s],midspan", comments="")
with open(folder / "bridge.csv") as file:
    print("".join(file.readlines()[:4]) + "...")


def run(command_line):
    """Run a crowdvib command line as typed in a terminal; print what it prints there."""
    print(f"$ {command_line}")
    # In the guide's folder (sphinx-gallery runs each cell in docs/examples); a terminal shows
    # both streams.
    with contextlib.chdir(folder), contextlib.redirect_stderr(sys.stdout):
        return main(shlex.split(command_line)[1:])


# %%
# Step 1: a case-file draft from the record
# ------------------------------------------
# ``crowdvib init`` reads the record and says what it found: the channels, the time column, the
# sample rate from the time stamps, the length, and a units guess (a mean of 1 is the gravity
# offset of an accelerometer reading g). It writes ``bridge.toml`` beside the record, never over
# an existing file.
run("crowdvib init bridge.csv")

# %%
# The draft holds what ``init`` found (``time_column``, ``units = "g"``, the channel) and a
# ``"REPLACE: …"`` value for each thing only you know: the bridge, the crowd and the frequency
# band of the fit. ``crowdvib estimate`` refuses the file, naming the key, while one is left.
with open(folder / "bridge.toml") as file:
    draft = file.read()
print("\n".join(line for line in draft.splitlines() if "REPLACE:" in line))

# %%
# Step 2: replace the placeholders
# --------------------------------
# In your editor, replace each ``"REPLACE: …"`` string by the number (here: the paper example's
# bridge, crowd and band; a mode's modal mass is that of the sine shape scaled to 1 at its peak).
# Nothing else needs editing; every other key keeps its default (docs: :ref:`casefiles`).
values = {"span": "50.0", "width": "3.0", "frequency": "2.0", "damping_ratio": "0.005",
          "modal_mass": "50e3", '"midspan"': "25.0", "density": "0.5", "band": "[0.0, 10.0]"}
case = draft
for key, value in values.items():
    case = re.sub(rf'(?m)^({re.escape(key)} = )"REPLACE:[^"\n]*"', rf"\g<1>{value}", case)
with open(folder / "bridge.toml", "w") as file:
    file.write(case)
print(case)

# %%
# Step 3: estimate
# ----------------
# ``crowdvib estimate`` reads the record (g → m/s², the offset removed with the mean), makes the
# Welch PSD and fits the model with the MSD pedestrians to it (the default estimator: the
# likelihood of the Welch PSD with the fluctuating crowd, its step frequencies fitted too;
# theory: :ref:`theory-default-estimator`). Look at three lines: ``estimate`` (f_h1 and ξ_h1 with
# their 95 % interval), ``J/J_noHSI`` (well below 1: the MSD explains what moving forces alone
# cannot) and ``verdict`` (any warning about the record or the fit, also in the report).
status = run("crowdvib estimate bridge.toml --out results")
print("exit status", status)

# %%
# Step 4: the numbers and the figure
# ----------------------------------
# ``results/results.json`` holds everything; :func:`crowdvib.cases.load_results` reads it back.
results = load_results(folder / "results")
estimate = results.estimate
for name, label, unit in (("frequency", "f_h1", " Hz"), ("damping_ratio", "ξ_h1", "")):
    low, high = estimate["interval"][name]
    print(f"{label} = {estimate[name]:.3g}{unit}, {estimate['interval']['level']:.0%} interval "
          f"{low:.3g}–{high:.3g}{unit} ({estimate['interval']['method']})")

# %%
# The fit, ``results/psd_midspan.png``: the measured PSD, the model with the estimated MSD, and
# the model without HSI, whose peak at 2 Hz is several times too high. The record was made with
# f_h1 = 3 Hz and ξ_h1 = 0.30: both lie within their intervals.
figure, axes = plt.subplots(figsize=(8, 4.5))
axes.imshow(plt.imread(folder / "results/psd_midspan.png"))
axes.set_axis_off()

# %%
# Step 5: the report
# ------------------
# ``crowdvib estimate`` wrote ``results/report.html``, a self-contained page (inputs, record, PSD
# fit, estimate with interval, warnings) to open in a browser or send. ``crowdvib report`` writes
# it again from ``results.json``, e.g. after a crowdvib update.
run("crowdvib report results")
print(sorted(path.name for path in (folder / "results").iterdir()))
