"""From the bridge model to a design decision: tuned mass dampers and design-code checks.

``codes`` tables the design guides' constants (Sétra/AFGC 2006, HiVoSS 2008, EN 1990 A2, the UK
National Annex to BS EN 1991-2) with their provenance; ``check`` runs the comfort check without
HSI, with added mass and with HSI side by side (:func:`design_check` → :class:`DesignCheck`;
``ukna`` holds the UK NA's time-domain walkers and steady-state crowd; ``registry`` makes the
codes peers: a new code is a :class:`DesignCode` in one module, passed to
:func:`register_code`); ``stochastic`` predicts the RMS and expected peak of a crowd stream from
the spectral model (:func:`predict_response`); ``interval`` checks across the box of f_h1 and
ξ_h1 an estimate allows (:class:`MSDBox`, :func:`check_over_box`). ``tuning`` places and tunes a
:class:`TunedMassDamper` (Den Hartog, Asami et al.) on the empty or on the occupied structure.
The damper itself is a model (``crowdvib.models.damper``) that the response functions take as
``dampers=``.
"""

from ..models.damper import TunedMassDamper
from .check import DesignCheck, design_check
from .interval import MSDBox, check_over_box
from .registry import DesignCode, code_label, code_names, register_code, unregister_code
from .stochastic import ResponsePrediction, predict_response
from .tuning import optimal_tuning, tune_damper
from .ukna import UKNACode                    # registers the UK NA beside check's guides

__all__ = ["TunedMassDamper", "tune_damper", "optimal_tuning", "design_check", "DesignCheck",
           "predict_response", "ResponsePrediction", "DesignCode", "register_code",
           "unregister_code", "code_names", "code_label", "UKNACode", "MSDBox", "check_over_box"]
