"""Shared fixtures: the paper's numerical example (docs: theory, The paper's numerical example) and a seeded generator."""

import numpy as np
import pytest

from crowdvib import Crowd, ModalModel, MSDModel


@pytest.fixture
def paper_bridge():
    """50 m × 3 m simply supported beam, 2 Hz, 0.5 %, modal mass 50 t, unity-scaled (docs: theory, The paper's numerical example)."""
    return ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)


@pytest.fixture
def paper_crowd():
    """0.5 persons/m², 1.30 m/s, N(1.89, 0.175) Hz, 70 kg (docs: theory, The paper's numerical example)."""
    return Crowd(density=0.5, walking_speed=1.30, step_frequency_mean=1.89,
                 step_frequency_std=0.175, body_mass=70.0)


@pytest.fixture
def paper_msd():
    """f_h1 = 3.0 Hz, ξ_h1 = 0.30, μ_h1 = 0.95 (docs: theory, The paper's numerical example)."""
    return MSDModel(3.0, 0.30, 0.95)


@pytest.fixture
def welch_grid():
    """The Welch grid of T = 60 s from 0 to 10 Hz (docs: theory, Inverse problem)."""
    return np.arange(0, 601) / 60.0


@pytest.fixture
def rng():
    return np.random.default_rng(20221109)
