"""Fuzzing the modal-model CSV readers: only crowdvib errors may come out (issue 9, fault 6)."""

import numpy as np
import pytest
from fuzzing import FUZZ, FUZZ_RANDOM, mutations, outcome, random_bytes
from hypothesis import given
from hypothesis import strategies as st

from crowdvib import ModalModel
from crowdvib.io import read_modal_model, write_modal_model

FILES = ("modes.csv", "shapes.csv", "outputs.csv")
# A damaged file may hold doubtful but legal values (a modal mass of 4 kg): a crowdvib warning
# is a fair outcome, only a foreign exception or a broken model is not.
pytestmark = [pytest.mark.fuzz, pytest.mark.filterwarnings("ignore::crowdvib.errors.CrowdvibWarning")]


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """A three-mode beam with two output points, written by crowdvib (the seeds)."""
    folder = tmp_path_factory.mktemp("modal")
    beam = ModalModel.simply_supported_beam(40.0, 3.0, [1.8, 7.2, 16.2], [0.005, 0.01, 0.01],
                                            [40e3, 40e3, 40e3], n_modes=3,
                                            outputs={"mid": 20.0, "quarter": 10.0})
    write_modal_model(beam, *(folder / name for name in FILES))
    return folder


def read_damaged(folder, which, content):
    paths = [folder / name for name in FILES]
    damaged = folder / f"damaged_{which}"
    damaged.write_bytes(content)
    paths[FILES.index(which)] = damaged
    model = outcome(read_modal_model, paths[0], paths[1], width=3.0, output_points=paths[2])
    if model is not None:
        assert isinstance(model, ModalModel)
        assert np.all(np.isfinite(model.frequencies)) and np.all(model.frequencies > 0)
        assert model.output_shapes.shape == (len(model.output_names), model.n_modes)
    return model


def test_the_seed_files_read_back(folder):
    # Reference: the beam written by the fixture (three modes, outputs mid and quarter).
    model = read_damaged(folder, "modes.csv", (folder / "modes.csv").read_bytes())
    assert model.n_modes == 3 and model.output_names == ("mid", "quarter")


@FUZZ_RANDOM
@given(which=st.sampled_from(FILES), content=random_bytes)
def test_random_bytes(folder, which, content):
    read_damaged(folder, which, content)


@FUZZ
@given(which=st.sampled_from(FILES), data=st.data())
def test_damaged_file(folder, which, data):
    read_damaged(folder, which, data.draw(mutations((folder / which).read_bytes())))
