"""What every command's results.json shares: the case tables it keeps, the software versions.

Light on purpose: the command line imports it at start-up (``crowdvib --help``).
"""

from .._version import __version__

__all__ = ["ESTIMATION_TABLES", "SIMULATION_TABLES", "DESIGN_TABLES", "software_versions"]

#: The case tables each kind of command reads; its results and report show no others.
ESTIMATION_TABLES = ("structure", "crowd", "hsi", "measurement", "estimation", "expected")
SIMULATION_TABLES = ("structure", "crowd", "hsi", "simulation", "expected")
DESIGN_TABLES = ("structure", "crowd", "hsi", "design")


def software_versions() -> dict:
    """The versions of crowdvib, numpy, scipy and Python, as every results.json records them."""
    import platform

    import numpy as np
    import scipy

    return {"crowdvib": __version__, "numpy": np.__version__, "scipy": scipy.__version__,
            "python": platform.python_version()}
