"""Embedded example cases.

``paper_example`` is the numerical example of Van Nimmen & Van den Broeck (2023), docs: theory, The paper's numerical example:
a 50 m × 3 m simply supported footbridge (2 Hz, 0.5 %, modal mass 50 t), 0.5 persons/m² walking at
1.30 m/s with step frequencies N(1.89, 0.175) Hz, body mass 70 kg, MSD (3.0 Hz, 0.30, 0.95).
"""

from dataclasses import dataclass

from .crowd import Crowd
from .pedestrian import MSDModel
from .structure import ModalModel

__all__ = ["ExampleCase", "paper_example"]


@dataclass(frozen=True)
class ExampleCase:
    """A structure, a crowd and the MSD model that generates the "measured" response.

    Attributes
    ----------
    name : str
    structure : ModalModel
        The empty bridge.
    crowd : Crowd
        The crowd on it.
    msd : MSDModel
        The true MSD of the pedestrians.
    band : (float, float)
        Analysis band [Hz].
    window_length : float
        Welch segment length T [s].
    """

    name: str
    structure: ModalModel
    crowd: Crowd
    msd: MSDModel
    band: tuple
    window_length: float


def paper_example():
    """The paper's numerical example (docs: theory, The paper's numerical example); band 0–10 Hz, Welch T = 60 s.

    Returns
    -------
    ExampleCase
        The 50 m simply supported beam (2 Hz, 0.5 %, 50 t), the crowd of 0.5 persons/m² at
        1.30 m/s with N(1.89, 0.175) Hz steps and 70 kg, the MSD 3.0 Hz / 30 % / 95 %.

    Examples
    --------
    >>> from crowdvib.models import paper_example
    >>> paper_example().msd
    MSDModel(frequency=3.0, damping_ratio=0.3, mass_ratio=0.95)
    """
    structure = ModalModel.simply_supported_beam(
        span=50.0, width=3.0, frequency=2.0, damping_ratio=0.005, modal_mass=50e3,
        name="paper numerical example: 50 m simply supported footbridge")
    # Crowd.from_density(0.5) gives v = 1.298 m/s and μ_fs = 1.890 Hz; the paper rounds both.
    crowd = Crowd(density=0.5, walking_speed=1.30, step_frequency_mean=1.89,
                  step_frequency_std=0.175, body_mass=70.0)
    return ExampleCase(name="paper-example", structure=structure, crowd=crowd,
                       msd=MSDModel(frequency=3.0, damping_ratio=0.30, mass_ratio=0.95),
                       band=(0.0, 10.0), window_length=60.0)
