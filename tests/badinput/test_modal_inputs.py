"""Bad modal inputs (issue 24 §4/§5, modal items): modal files, FE exports and operational modal
analysis give a crowdvib error naming the file or parameter and the rule, or a warning naming the
doubtful value and its likely cause; never a silently wrong mode or a foreign traceback.

Every case failed on 49020a3 (silent, or a TypeError/IndexError/QhullError/LinAlgError).
"""

import re
import warnings

import numpy as np
import pytest

from crowdvib import ModalModel, Record, write_record
from crowdvib.cli import main
from crowdvib.errors import (DataError, EstimationError, IdentifiabilityWarning, ParameterError,
                             PlausibilityWarning)
from crowdvib.io import read_modal_model
from tests.unit.test_femodes import write_uff

pyuff = pytest.importorskip("pyuff")

X = np.linspace(0.0, 40.0, 9)                       # a 40 m beam, nodes every 5 m
SINES = np.column_stack([np.sin(np.pi * X / 40), np.sin(2 * np.pi * X / 40)])
TABLE = "frequency,damping_ratio,modal_mass\n1.8,0.01,2e4\n7.2,0.01,2e4\n"


def node_table(tmp_path, x=X, y=None, shapes=SINES, table=TABLE):
    """A CSV node table (node, x, y, z, one vertical column per mode) and its modal table."""
    y = np.zeros(x.size) if y is None else y
    rows = ["node,x,y,z,m1,m2"] + [",".join([str(i + 1)] + [repr(float(v)) for v in (
        x[i], y[i], 0.0, shapes[i, 0], shapes[i, 1])]) for i in range(x.size)]
    (tmp_path / "nodes.csv").write_text("\n".join(rows) + "\n")
    (tmp_path / "table.csv").write_text(table)
    return tmp_path / "table.csv", tmp_path / "nodes.csv"


# ------------------------------------------------------------------ modal files and FE exports
def test_node_coordinates_in_millimetres_are_warned(tmp_path):
    # Issue 24: a 40 m deck exported in mm (40 000 "m") was silent. The reader names the file,
    # the extent, the likely mix-up and the extent in metres (40 000 mm = 40 m).
    files = node_table(tmp_path, x=X * 1000)
    with pytest.warns(PlausibilityWarning) as caught:     # the model's own notes come too
        read_modal_model(*files, width=3.0, outputs={"mid": 20000.0})
    assert any(re.fullmatch(r"nodes\.csv: the nodes span 40000 m along x.*millimetres\? \(they "
                            r"would span 40 m\)", str(w.message)) for w in caught)


def test_an_all_zero_mode_column_is_refused(tmp_path):
    # Issue 24: an all-zero shape was accepted (a mode that no walker can excite, with an
    # infinite deck mass); the reader names the column.
    (tmp_path / "modes.csv").write_text(TABLE)
    (tmp_path / "shapes.csv").write_text("position,a,b\n0,0,0\n20,0,1\n40,0,0\n")
    with pytest.raises(DataError, match=r"shapes\.csv: mode column\(s\) \['a'\] are all zero"):
        read_modal_model(tmp_path / "modes.csv", tmp_path / "shapes.csv", width=3.0,
                         outputs={"mid": 20.0})


def test_a_missing_modal_mass_column_with_unity_scaled_shapes_is_refused(tmp_path):
    # Issue 24: without modal_mass the shapes count as mass-normalised, so unity-scaled sines
    # became modal masses 1/max|φ|² = 1 kg (closed form). Refused, naming the column and the
    # masses it would imply.
    files = node_table(tmp_path, table="frequency,damping_ratio\n1.8,0.01\n7.2,0.01\n")
    with pytest.raises(DataError, match=r"table\.csv: no modal_mass column.*mode\(s\) \[1, 2\] "
                                        r"peak at \|φ\| = \[1\.0, 1\.0\].*\[1\.0, 1\.0\] kg"):
        read_modal_model(*files, width=3.0, outputs={"mid": 20.0})


def test_a_missing_modal_mass_column_with_mass_normalised_shapes_reads(tmp_path):
    # The documented use stays: φ = sine/√(2e4) → engaged modal mass 2e4 kg (closed form).
    files = node_table(tmp_path, shapes=SINES / np.sqrt(2e4),
                       table="frequency,damping_ratio\n1.8,0.01\n7.2,0.01\n")
    model = read_modal_model(*files, width=3.0, outputs={"mid": 20.0})
    np.testing.assert_allclose(model.modal_masses, [2e4, 2e4], rtol=1e-12)


def test_a_misspelt_fe_option_is_named(tmp_path):
    # Issue 24: a misspelt keyword left read_modal_model as a TypeError of FEModes.modal_model.
    with pytest.raises(ParameterError, match=r"'min_vertcal' is not an option of "
                                             r"read_modal_model \(did you mean 'min_vertical'\?\)"):
        read_modal_model(*node_table(tmp_path), width=3.0, outputs={"mid": 20.0},
                         min_vertcal=0.2)


def test_uff_node_numbers_without_coordinates_are_refused(tmp_path):
    # Issue 24 (fuzzing): one flipped byte in node 109's line of data set 15 (the fuzzer's find)
    # makes pyuff read 10 node numbers for 9 coordinates; FEModes.modal_model raised IndexError.
    path = tmp_path / "beam.uff"
    write_uff(path, X, SINES, [2e4, 2e4])                  # nodes 101 … 109
    line = b"       109         0         0         1"
    path.write_bytes(path.read_bytes().replace(line, line[:-10] + b" 0       1"))
    with pytest.raises(DataError, match=r"beam\.uff: data set 15 must give x, y, z for each of "
                                        r"its 10 node\(s\), got 9"):
        read_modal_model(path, width=3.0, outputs={"mid": 20.0})


def test_deck_nodes_on_an_oblique_line_are_refused(tmp_path):
    # Issue 24 (fuzzing): deck nodes on a line oblique to the along axis (y = 0.1 x) left the
    # 2-D interpolation as scipy's QhullError.
    files = node_table(tmp_path, y=0.1 * X)
    with pytest.raises(DataError, match=r"nodes\.csv: the deck nodes must lie on a line along "
                                        r"the walkway or span an area.*across extent 4 m over "
                                        r"40 m"):
        read_modal_model(*files, width=3.0, outputs={"mid": 20.0})
