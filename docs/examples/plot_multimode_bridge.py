"""
A multi-mode bridge from modal CSV files
========================================

A real bridge comes as a finite-element or operational modal model: a table of modes, mode shapes
sampled along the walkway and the mode-shape rows of the sensors. This tutorial reads the
Eeklo-like three-span bridge shipped in ``examples/`` (a look-alike of the paper's Eeklo
footbridge: 14 modes, spans 27–42–27 m), compares its FRFs empty and occupied, and lists the
effective modal properties with a crowd of 0.5 persons/m² (theory: :ref:`theory-structure`,
:ref:`theory-occupied-frf`, :ref:`theory-effective-modal-properties`).
"""

# %%
# Reading the modal model
# -----------------------
# Three CSV files: ``frequency``, ``damping_ratio`` and ``modal_mass`` per mode; the shapes at
# positions along the walkway; the shape rows at the two sensors. The modal masses belong to the
# unity scaling of these shapes (:ref:`theory-mode-scaling`).
from pathlib import Path

import numpy as np

from crowdvib import Crowd, MSDModel, effective_modal_properties, frf, read_modal_model


def repository_examples():
    """The repository's examples/ folder, found upwards from where this script runs."""
    for folder in (Path.cwd(), *Path.cwd().parents):
        if (folder / "examples" / "eeklo_like_modes.csv").is_file():
            return folder / "examples"
    raise FileNotFoundError("examples/eeklo_like_modes.csv not found above " + str(Path.cwd()))


examples = repository_examples()
bridge = read_modal_model(examples / "eeklo_like_modes.csv", examples / "eeklo_like_shapes.csv",
                          width=3.5, output_points=examples / "eeklo_like_outputs.csv",
                          name="Eeklo-like footbridge")
print(bridge.n_modes, "modes;", "outputs:", bridge.output_names)
print("frequencies [Hz]:", np.round(bridge.frequencies, 2))

# %%
# The crowd and the MSD
# ---------------------
# The crowd the paper observed on the Eeklo bridge at 0.5 persons/m² (N(1.66, 0.19) Hz, 73.2 kg)
# and the MSD the paper estimated there.
crowd = Crowd(density=0.5, walking_speed=1.30, step_frequency_mean=1.66, step_frequency_std=0.19,
              body_mass=73.2)
msd = MSDModel(frequency=3.08, damping_ratio=0.34)
ratios = bridge.modal_mass_ratios(crowd.density, crowd.body_mass)
print("crowd-to-structure modal mass ratios [%]:", np.round(100 * ratios, 1))

# %%
# Effective modal properties
# --------------------------
# The modes with a large mass ratio and a frequency just above f_h1 gain the most damping
# (:ref:`theory-tmd-analogy`).
occupied = effective_modal_properties(bridge, crowd, msd)
print(" mode   empty f [Hz]  ξ [%]   occupied f [Hz]  ξ [%]")
for j in range(bridge.n_modes):
    print(f"{j + 1:5d}   {bridge.frequencies[j]:11.2f}  {100 * bridge.damping_ratios[j]:5.2f}"
          f"   {occupied.frequencies[j]:15.2f}  {100 * occupied.damping_ratios[j]:5.2f}")

# %%
# FRFs, empty and occupied
# ------------------------
# Accelerance at the centre of the main span for a vertical unit force at the same point.
frequency = np.linspace(0.5, 10.0, 4000)
empty = frf(bridge, frequency)
with_crowd = frf(bridge, frequency, crowd=crowd, msd=msd)
ax = empty.plot(with_crowd, output="main_span", input="main_span",
                title="Main-span accelerance, empty and with 0.5 persons/m²")
