"""The models the rest is built on: the empty bridge, the crowd, each walker's body and force.

``structure`` (ModalModel) → ``crowd`` (Crowd; ``profile``: CrowdProfile, its density against
time) → ``pedestrian`` (MSDModel) → ``loading`` (walking force models; ``measured``: replayed
measured forces); ``examples`` bundles them into the paper's numerical example.
"""

from .crowd import Crowd, bruno_venuti_step_frequency, weidmann_speed
from .examples import ExampleCase, paper_example
from .loading import STANDARD_GRAVITY, ForceModel, WalkingForce, YoungForce, ZivanovicForce
from .measured import MeasuredForce
from .pedestrian import MSDModel
from .profile import CrowdProfile
from .structure import ModalModel

__all__ = ["ModalModel", "Crowd", "CrowdProfile", "MSDModel", "ZivanovicForce", "YoungForce",
           "MeasuredForce", "ForceModel", "WalkingForce", "STANDARD_GRAVITY",
           "weidmann_speed", "bruno_venuti_step_frequency", "ExampleCase", "paper_example"]
