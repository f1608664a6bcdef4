"""From the bridge model to a design decision: tuned mass dampers and design-code checks.

``tuning`` places and tunes a :class:`TunedMassDamper` (Den Hartog, Asami et al.) on the empty
or on the occupied structure. The damper itself is a model (``crowdvib.models.damper``) that
the response functions take as ``dampers=``.
"""

from ..models.damper import TunedMassDamper
from .tuning import optimal_tuning, tune_damper

__all__ = ["TunedMassDamper", "tune_damper", "optimal_tuning"]
