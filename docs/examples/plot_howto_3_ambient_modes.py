"""
How-to 3: the bridge's modes from an ambient test
=================================================

**You have** a record of the empty bridge's ambient vibrations (wind, traffic nearby, a few
passers-by) from a handful of accelerometers along the deck, e.g. half an hour per setup.

**You get** its vertical modes: the natural frequencies, damping ratios with their standard
deviations, the mode shapes at the sensors, and (with the modal masses you state or an FE
model) the modal-model CSV files a case file's ``[structure]`` reads, so that the other
how-to guides can use *measured* modes.

In a terminal::

    (write ambient.toml: the record, the method, the band; docs: :ref:`ambient-files`)
    crowdvib modes ambient.toml --out modes

Theory: :ref:`theory-oma` (covariance-driven stochastic subspace identification, SSI-cov, by
default; EFDD with ``method = "efdd"`` or as a cross-check).
"""

# %%
# The record
# ----------
# Your loggers' CSV stands here as a synthetic one: the paper example's 50 m beam with its modes
# at 2.0 Hz (ξ = 0.5 %) and 7.5 Hz (0.8 %), shaken by white-noise modal loads and seen by three
# accelerometers at the quarter points; 20 minutes at 20 Hz, in m/s², with a ``Time [s]``
# column. With your own file, skip this step.
import contextlib
import shlex
import sys
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from crowdvib import ModalModel
from crowdvib.cases import load_results
from crowdvib.cli import main
from crowdvib.oma.identify import ambient_response

workdir = tempfile.TemporaryDirectory(prefix="crowdvib-howto-")   # removed at exit
folder = Path(workdir.name)

rate, duration = 20.0, 1200.0                                # [Hz], [s]
sensors = {"quarter": 12.5, "mid": 25.0, "three_quarter": 37.5}   # [m] along the span
beam = ModalModel.simply_supported_beam(50.0, 3.0, (2.0, 7.5), (0.005, 0.008), 50e3, n_modes=2,
                                        outputs=sensors)
data = ambient_response(beam, duration, rate, 200.0**2, rng=27)
np.savetxt(folder / "ambient.csv", np.c_[np.arange(data.shape[1]) / rate, data.T], delimiter=",",
           fmt="%.6g", header="Time [s]," + ",".join(sensors), comments="")
with open(folder / "ambient.csv") as file:
    print("".join(file.readlines()[:3]) + "...")


def run(command_line):
    """Run a crowdvib command line as typed in a terminal; print what it prints there."""
    print(f"$ {command_line}")
    # In the guide's folder (sphinx-gallery runs each cell in docs/examples); a terminal shows
    # both streams.
    with contextlib.chdir(folder), contextlib.redirect_stderr(sys.stdout):
        return main(shlex.split(command_line)[1:])


# %%
# The ambient-test file
# ---------------------
# A small TOML file (docs: :ref:`ambient-files`): ``[record]`` names the file and the sensors'
# channels (the ``Time [s]`` column gives the sample rate); ``[identification]`` the method, the
# number of modes, the frequency band to look in and the highest model order of the
# stabilisation diagram (each mode takes two orders; the default, 40, takes several times
# longer); ``[modal_model]`` (optional) what OMA cannot
# measure, the modal masses, with the sensors' positions, so that ``crowdvib modes`` also writes
# a modal model. A test in several setups has one ``[[record]]`` block per setup and names the
# reference sensors that stayed in place.
with open(folder / "ambient.toml", "w", encoding="utf-8") as file:
    file.write('''name = "my footbridge, ambient test"

[record]
file = "ambient.csv"
channels = ["quarter", "mid", "three_quarter"]   # the sensors, in order

[identification]
method = "ssi-cov"
n_modes = 2
frequency_band = [1.0, 9.5]        # [Hz], below the Nyquist frequency 10 Hz
max_order = 20                     # SSI model orders 2…20: ample for two modes (default 40)

[modal_model]
modal_masses = [50e3, 50e3]        # [kg], of shapes scaled to 1 at their peak (e.g. from FE)
sensor_positions = [12.5, 25.0, 37.5]   # [m], one per sensor, in channel order
walkway = [0.0, 50.0]              # [m], its ends
width = 3.0                        # [m]
''')

# %%
# Identification
# --------------
# Look at each mode's f and ξ with their standard deviations (from the scatter over the
# stabilised model orders), and at the verdict.
status = run("crowdvib modes ambient.toml --out modes")
print("exit status", status)

# %%
# What it found
# -------------
# ``modes/modes.csv`` and ``modes/mode_shapes.csv`` hold the modes; ``results.json`` all of it.
# The record was made with 2.0 Hz, 0.5 % and 7.5 Hz, 0.8 %.
modes = load_results(folder / "modes").data["modes"]
for j, mode in enumerate(modes, start=1):
    print(f"mode {j}: f = {mode['frequency']:.3f} ± {mode['frequency_std']:.3f} Hz, "
          f"ξ = {100 * mode['damping_ratio']:.2f} ± {100 * mode['damping_std']:.2f} %, "
          f"shape at the sensors {np.round(mode['mode_shape'], 2).tolist()}")

# %%
# The mode shapes at the sensors, with the supports at 0 and 50 m: a half sine and a full sine.
positions = [0.0, *sensors.values(), 50.0]
figure, axes = plt.subplots(figsize=(7, 3))
for j, mode in enumerate(modes, start=1):
    axes.plot(positions, [0.0, *mode["mode_shape"], 0.0], "o-",
              label=f"mode {j}, {mode['frequency']:.2f} Hz")
axes.axhline(0.0, color="0.6", linewidth=0.8)
axes.set(xlabel="Position along the span [m]", ylabel="Mode shape [-]",
          title="Identified mode shapes")
axes.legend()

# %%
# The stabilisation diagram, ``modes/stabilisation.png``: a mode is a column of poles that stay
# put as the model order grows. A stable column in your band that is not among the identified
# modes deserves a look (raise ``n_modes``).
figure, axes = plt.subplots(figsize=(8, 4.5))
axes.imshow(plt.imread(folder / "modes/stabilisation.png"))
axes.set_axis_off()

# %%
# The modal model for a case file
# -------------------------------
# With ``[modal_model]``, ``crowdvib modes`` wrote the identified frequencies and damping ratios,
# the stated modal masses and coarse shapes (the sensors' values, zero at the walkway's ends) as
# the three CSV files a case file's ``[structure]`` reads (docs: :ref:`casefiles`)::
#
#     [structure]
#     modal_table = "modes/modal_table.csv"       # mode, frequency, damping_ratio, modal_mass
#     mode_shapes = "modes/modal_shapes.csv"      # position, one column per mode
#     output_points = "modes/output_points.csv"   # sensor name, one column per mode
#     width = 3.0
for name in ("modal_table.csv", "output_points.csv", "modal_shapes.csv"):
    with open(folder / "modes" / name) as file:
        print(f"modes/{name}:\n{file.read()}")
