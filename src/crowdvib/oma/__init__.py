"""Operational modal analysis: the empty bridge's modes from ambient records.

``identify`` (SSI-cov through pyOMA2, or ``efdd``; :func:`identify_modes`, and
:func:`ambient_response` to synthesise an ambient record), ``modeid`` (the result
:class:`ModeIdentification` and the cross-check of two methods) and ``multisetup`` (several
setups with reference sensors merged into one mode shape).
"""

from .identify import ModeIdentification, ambient_response, identify_modes
from .modeid import ModeCrossCheck

__all__ = ["identify_modes", "ModeIdentification", "ModeCrossCheck", "ambient_response"]
