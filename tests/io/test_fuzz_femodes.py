"""Fuzzing the FE-export readers (UFF 15 + 55, CSV node table): only crowdvib errors may come out."""

import numpy as np
import pytest
from fuzzing import FUZZ, FUZZ_RANDOM, mutations, outcome, random_bytes
from hypothesis import given
from hypothesis import strategies as st

from crowdvib import ModalModel
from crowdvib.io import read_modal_model

pyuff = pytest.importorskip("pyuff")
# A damaged file may hold doubtful but legal values (a modal mass of 4 kg): a crowdvib warning
# is a fair outcome, only a foreign exception or a broken model is not.
pytestmark = [pytest.mark.fuzz, pytest.mark.filterwarnings("ignore::crowdvib.errors.CrowdvibWarning")]


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """A two-mode beam as a UFF file (pyuff) and as a CSV node table + modal table (the seeds)."""
    folder = tmp_path_factory.mktemp("fe")
    x = np.linspace(0.0, 40.0, 9)
    nodes = np.arange(1, 10)
    shapes = np.column_stack([np.sin(np.pi * x / 40), np.sin(2 * np.pi * x / 40)])
    sets = [{"type": 15, "node_nums": nodes, "def_cs": np.zeros(9, int),
             "disp_cs": np.zeros(9, int), "color": np.ones(9, int), "x": x, "y": np.zeros(9),
             "z": np.zeros(9)}]
    for j, f in enumerate((1.8, 7.2)):
        sets.append(pyuff.prepare_55(model_type=1, analysis_type=2, data_ch=2, spec_data_type=8,
                                     data_type=2, n_data_per_node=3, load_case=1, mode_n=j + 1,
                                     freq=f, modal_m=1.0, modal_damp_vis=0.01, modal_damp_his=0.0,
                                     r1=np.zeros(9), r2=np.zeros(9), r3=shapes[:, j] / 100,
                                     node_nums=nodes))
    pyuff.UFF(str(folder / "beam.uff")).write_sets(sets, "overwrite")
    lines = ["node,x,y,z,m1,m2"] + [f"{n},{x[i]},0,0,{shapes[i, 0]},{shapes[i, 1]}"
                                     for i, n in enumerate(nodes)]
    (folder / "nodes.csv").write_text("\n".join(lines) + "\n")
    (folder / "table.csv").write_text("frequency,damping_ratio,modal_mass\n1.8,0.01,2e4\n"
                                      "7.2,0.01,2e4\n")
    return folder


def check(model):
    if model is not None:
        assert isinstance(model, ModalModel)
        assert np.all(np.isfinite(model.mode_shapes)) and np.all(model.modal_masses > 0)
        assert np.max(np.abs(model.mode_shapes)) == pytest.approx(1.0)   # unity at antinode


def read_uff(folder, content):
    damaged = folder / "damaged.uff"
    damaged.write_bytes(content)
    check(outcome(read_modal_model, damaged, width=3.0, outputs={"mid": 20.0},
                  min_vertical=0.0))


def read_csv(folder, which, content):
    paths = {"nodes.csv": folder / "nodes.csv", "table.csv": folder / "table.csv"}
    damaged = folder / f"damaged_{which}"
    damaged.write_bytes(content)
    paths[which] = damaged
    check(outcome(read_modal_model, paths["table.csv"], paths["nodes.csv"], width=3.0,
                  outputs={"mid": 20.0}, min_vertical=0.0))


def test_the_seeds_read_back(folder):
    # Reference: the fixture's beam, mass-normalised (m = 1) → m = 1/max|φ|² = 100² (closed form)
    model = read_modal_model(folder / "beam.uff", width=3.0, outputs={"mid": 20.0})
    np.testing.assert_allclose(model.modal_masses, [1e4, 1e4], rtol=1e-5)
    model = read_modal_model(folder / "table.csv", folder / "nodes.csv", width=3.0,
                             outputs={"mid": 20.0})
    np.testing.assert_allclose(model.modal_masses, [2e4, 2e4])


@FUZZ_RANDOM
@given(content=random_bytes)
def test_random_bytes_uff(folder, content):
    read_uff(folder, content)


@FUZZ
@given(data=st.data())
def test_damaged_uff(folder, data):
    read_uff(folder, data.draw(mutations((folder / "beam.uff").read_bytes())))


@FUZZ
@given(which=st.sampled_from(("nodes.csv", "table.csv")), data=st.data())
def test_damaged_csv(folder, which, data):
    read_csv(folder, which, data.draw(mutations((folder / which).read_bytes())))


@FUZZ_RANDOM
@given(slope=st.floats(-2.0, 2.0), jitter=st.sampled_from([0.0, 1e-12, 1e-9, 1e-6, 1e-3]),
       seed=st.integers(0, 2**16))
def test_deck_geometry(folder, slope, jitter, seed):
    # Issue 24: deck nodes (nearly) on a line oblique to x let scipy's QhullError out. Any
    # line, slightly scattered, is now a model or a crowdvib error naming the file.
    x = np.linspace(0.0, 40.0, 9)
    y = slope * x + jitter * np.random.default_rng(seed).normal(size=9)
    shapes = np.column_stack([np.sin(np.pi * x / 40), np.sin(2 * np.pi * x / 40)])
    rows = ["node,x,y,z,m1,m2"] + [f"{i + 1},{x[i]:.17g},{y[i]:.17g},0,{shapes[i, 0]:.17g},"
                                   f"{shapes[i, 1]:.17g}" for i in range(9)]
    (folder / "deck.csv").write_text("\n".join(rows) + "\n")
    check(outcome(read_modal_model, folder / "table.csv", folder / "deck.csv", width=3.0,
                  outputs={"mid": 20.0}, min_vertical=0.0))
