"""The inverse problem: the pedestrians' MSD from a measured response PSD.

``estimation`` (f_h1, ξ_h1 from a measured PSD: paper Eq. 5 and 6, and the joint fit of several
records; ``estimator``, its choices as one value) on the ``objective`` (the PSD misfit or the Whittle likelihood), with ``diagnostics``
(bounds, level, identifiability), ``uncertainty`` and ``wishart`` (the intervals), ``bootstrap``
and ``result`` (:class:`HSIEstimate`); ``step_frequencies`` fits the crowd's N(μ, σ) from the low
band. The studies that test the answer are in :mod:`crowdvib.studies`, the empty bridge's modes
in :mod:`crowdvib.oma`, and the task runner both use in :mod:`crowdvib.runner`.
"""

from .estimation import (DEFAULT_BOUNDS, DEFAULT_STARTS, HSIEstimate, estimate_hsi,
                         estimate_hsi_joint)
from .estimator import Estimator
from .objective import PSDObjective
from .step_frequencies import (DEFAULT_STEP_FREQUENCY_BOUNDS, StepFrequencyEstimate,
                               estimate_step_frequencies)

__all__ = ["estimate_hsi", "estimate_hsi_joint", "Estimator", "HSIEstimate", "PSDObjective", "DEFAULT_STARTS",
           "DEFAULT_BOUNDS", "estimate_step_frequencies", "StepFrequencyEstimate",
           "DEFAULT_STEP_FREQUENCY_BOUNDS"]
