"""The units of accelerations crowdvib reads, and their conversion to m/s² (docs: theory,
Conventions: g = 9.81 m/s²).

:data:`UNITS` are the units a record may be in, with their scale to m/s²; :func:`unit_key`
reads how files and people write them (``m/s^2``, ``g0``); :func:`convert_units` turns samples
into m/s². A unit declared for a record is checked against its samples
(:func:`_check_declared_units`): the gravity offset of another unit is refused, an RMS above
1 g in g or mg doubted.
"""

import warnings

import numpy as np

from ..errors import DataError, ParameterError, PlausibilityWarning
from ..models.loading import STANDARD_GRAVITY
from ._common import quote, where

__all__ = ["UNITS", "unit_key", "unit_scale", "convert_units"]

#: Record units crowdvib reads → their scale to m/s².
UNITS = {"m/s2": 1.0, "g": STANDARD_GRAVITY, "mg": 1e-3 * STANDARD_GRAVITY, "mm/s2": 1e-3}
#: How files and people write them (compared lower case, blanks dropped).
_ALIASES = {"m/s2": "m/s2", "m/s^2": "m/s2", "m/s²": "m/s2", "ms-2": "m/s2", "ms^-2": "m/s2",
            "mps2": "m/s2", "m/s/s": "m/s2", "g": "g", "g0": "g", "mg": "mg",
            "mm/s2": "mm/s2", "mm/s^2": "mm/s2", "mm/s²": "mm/s2", "mms-2": "mm/s2"}


def unit_key(units):
    """The key of :data:`UNITS` that ``units`` names ("m/s^2" → "m/s2"), or None."""
    return _ALIASES.get(str(units).strip().lower().replace(" ", ""))


def unit_scale(units):
    """The factor that turns samples in ``units`` (a key of :data:`UNITS`) into m/s²."""
    return UNITS[units]


def _check_declared_units(source, names, data, units):
    """A record declared in ``units`` whose mean is the gravity offset in other units (DataError:
    an accelerometer at rest shows 1 g, so a mean of 9.81 declared as g, or of 1000 declared as
    g, is another unit's offset), or, declared in g or mg, whose RMS is above 1 g
    (PlausibilityWarning: footbridge accelerations stay below 0.2 g)."""
    scale = UNITS[units]
    for name, row in zip(names, data):
        mean = float(np.mean(row))
        rms = float(np.std(row))
        offset = next((other for other, other_scale in UNITS.items()
                       if other != units and other != "mm/s2"
                       and abs(abs(mean) * other_scale - STANDARD_GRAVITY)
                       <= 0.15 * STANDARD_GRAVITY and rms * other_scale < 0.5 * STANDARD_GRAVITY
                       and abs(abs(mean) * scale - STANDARD_GRAVITY) > 0.15 * STANDARD_GRAVITY),
                      None)
        if offset is not None:
            raise DataError(f"{where(source, name)}units {units!r} must not hold a mean of "
                            f"{mean:.3g} {units} (an accelerometer at rest shows 1 g): {mean:.3g} "
                            f"is the gravity offset in {'m/s²' if offset == 'm/s2' else offset}; "
                            f"declare units {offset!r}")
        if units in ("g", "mg") and rms * scale > STANDARD_GRAVITY:
            warnings.warn(f"{where(source, name)}RMS {rms:.3g} {units} is above 1 g, unusual for a "
                          f"footbridge (below 0.2 g): m/s² declared as {units}? ({rms:.3g} m/s² "
                          f"is {rms / STANDARD_GRAVITY:.3g} g)", PlausibilityWarning, stacklevel=4)


def _unit_key(units, prefix):
    key = unit_key(units)
    if key is None:
        raise ParameterError(f"{prefix}units must be 'm/s2', 'g', 'mg' or 'mm/s2', got "
                             f"{quote(units)}")
    return key


def convert_units(data, units):
    """Accelerations in ``units`` ("g", "mg", "m/s2" or "mm/s2") → m/s² (g = 9.81 m/s², docs:
    theory, Conventions).

    Parameters
    ----------
    data : array_like
        Accelerations in ``units``.
    units : str
        ``"g"`` (g = 9.81 m/s²), ``"mg"``, ``"m/s2"`` or ``"mm/s2"``.

    Returns
    -------
    ndarray
        The accelerations [m/s²], as floats.

    Examples
    --------
    >>> from crowdvib.io import convert_units
    >>> convert_units([0.0, 0.01], "g")
    array([0.    , 0.0981])
    """
    return np.asarray(data, dtype=float) * UNITS[_unit_key(units, "")]
