"""Checks at the public boundary, each raising :class:`ParameterError` with parameter, rule and value,
and the type aliases of the public API's hints (:data:`ForceModel`, :data:`Seed`: for type
checkers only, nothing of them runs).

Validation happens once, where data enter the library; the numerics behind it trust their inputs.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Union

import numpy as np

from .errors import DataError, ParameterError

if TYPE_CHECKING:
    from .models.loading import ForceModel as _ForceProtocol
    from .models.measured import MeasuredForce

    #: A walking-force model: any models.loading.ForceModel (the harmonic models, a user's) or
    #: measured forces replayed.
    ForceModel = Union[_ForceProtocol, MeasuredForce]
    #: A seed or a generator: every random draw of crowdvib flows from one.
    Seed = Union[int, np.random.Generator, None]


def check_type(name, value, kind):
    """Require ``value`` to be an instance of ``kind``; return it."""
    if not isinstance(value, kind):
        raise ParameterError(f"{name} must be a {kind.__name__}, got {type(value).__name__}")
    return value


def check_flag(name, value):
    """Require a boolean (True or False, numpy's too): "no" or 0 for a switch is refused, not
    read by its truth value; return it as bool."""
    if not isinstance(value, (bool, np.bool_)):
        raise ParameterError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def check_count(name, value, minimum=0):
    """Require an integer count >= ``minimum`` (an integral float such as 3.0 too, not 2.5 nor
    True); return it as int."""
    integral = isinstance(value, (int, np.integer)) or (
        isinstance(value, (float, np.floating)) and float(value).is_integer())
    if isinstance(value, (bool, np.bool_)) or not integral or value < minimum:
        rule = "a positive integer" if minimum == 1 else f"an integer >= {minimum}"
        raise ParameterError(f"{name} must be {rule}, got {value!r}")
    return int(value)


def _refuse_non_real(name, value):
    """Strings, complex numbers and None are not read as numbers: numpy would turn "3" into
    3.0, None into NaN, and drop an imaginary part with only a ComplexWarning."""
    raw = value if isinstance(value, np.ndarray) else np.asarray(value)
    flat = raw.ravel()
    if raw.dtype.kind == "c":
        offending = flat[flat.imag != 0] if np.any(flat.imag != 0) else flat
    elif raw.dtype.kind in "US":
        offending = flat
    elif raw.dtype.kind == "O":
        offending = [x for x in flat.tolist() if x is None or isinstance(x, (str, bytes, complex))]
    else:
        return
    if len(offending):
        first = offending[0]
        first = first.item() if isinstance(first, np.generic) else first
        what = ("" if first is None else
                f": {'complex' if isinstance(first, complex) else 'a string'} is not read as a "
                "real number")
        raise ParameterError(f"{name} must be numeric, got {first!r}{what}")


def as_float_array(name, value, *, ndim=None):
    """Return ``value`` as a finite float64 array, checking its number of dimensions.

    Strings and complex values are refused (:func:`_refuse_non_real`), not converted.
    """
    try:
        _refuse_non_real(name, value)
        array = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        if isinstance(exc, ParameterError):
            raise
        raise ParameterError(f"{name} must be numeric, got {value!r}") from exc
    if ndim is not None and array.ndim != ndim:
        raise ParameterError(f"{name} must have {ndim} dimension(s), got shape {array.shape}")
    if not np.isfinite(array).all():
        bad = np.flatnonzero(~np.isfinite(array.ravel()))[0]
        raise ParameterError(f"{name} must be finite, got {array.ravel()[bad]} at flat index {bad}")
    return array


def _first_bad(array, ok):
    ok = np.asarray(ok)
    if ok.all():            # the common case, at a fraction of flatnonzero's cost
        return None
    index = np.flatnonzero(~ok.ravel())
    return None if index.size == 0 else array.ravel()[index[0]]


def check_positive(name, value, *, unit=""):
    """Require every entry of ``value`` to be finite and > 0; return it as float (array)."""
    array = as_float_array(name, value)
    bad = _first_bad(array, array > 0)
    if bad is not None:
        raise ParameterError(f"{name} must be > 0{unit and ' ' + unit}, got {bad:g}")
    return float(array) if array.ndim == 0 else array


def check_non_negative(name, value, *, unit=""):
    """Require every entry of ``value`` to be finite and >= 0."""
    array = as_float_array(name, value)
    bad = _first_bad(array, array >= 0)
    if bad is not None:
        raise ParameterError(f"{name} must be >= 0{unit and ' ' + unit}, got {bad:g}")
    return float(array) if array.ndim == 0 else array


def check_damping_ratio(name, value, *, upper=1.0, allow_zero=False):
    """Require a damping ratio given as a fraction: 0 < value < ``upper`` (0 <= value if allowed).

    The message of a value above ``upper`` says "fractions, not percent": 30 for 30 % is the
    mistake this check exists for.
    """
    array = as_float_array(name, value)
    low_ok = array >= 0 if allow_zero else array > 0
    bad = _first_bad(array, low_ok & (array < upper))
    if bad is not None:
        rule = f"{'>= 0' if allow_zero else '> 0'} and < {upper:g}"
        raise ParameterError(f"{name} must be {rule} (fractions, not percent), got {bad:g}")
    return float(array) if array.ndim == 0 else array


def check_open_unit(name, value):
    """Require 0 < value < 1."""
    x = float(as_float_array(name, value, ndim=0))
    if not 0.0 < x < 1.0:
        raise ParameterError(f"{name} must lie in the open interval (0, 1), got {x:g}")
    return x


def check_frequency_grid(frequency, name="frequency"):
    """A 1-D, finite, non-negative, strictly increasing frequency grid [Hz]."""
    frequency = as_float_array(name, frequency, ndim=1)
    check_non_negative(name, frequency, unit="Hz")
    if frequency.size == 0 or np.any(np.diff(frequency) <= 0):
        raise ParameterError(f"{name} must be a non-empty, strictly increasing grid [Hz], "
                             f"got {frequency.size} value(s)")
    return frequency


def frozen_array(array, dtype=float):
    """A read-only copy of ``array``: frozen dataclasses hold arrays nobody can change in place."""
    array = np.array(array, dtype=dtype)
    array.flags.writeable = False
    return array


def fields_from_dict(cls, data, **given):
    """An instance of the dataclass ``cls`` back from the dict its ``to_dict`` wrote.

    Each field is read from the key of its name: a list becomes a tuple, or an array where the
    field's annotation names ``ndarray`` (null as NaN, as JSON stores it); keys that
    ``to_dict`` derives from the fields (properties) are not read; ``given`` fields are taken
    as they are (objects the dict holds in another shape). A dict that is not one, or lacks a
    required key, is a DataError naming the class and the key; the values then meet the
    class's own checks, as any constructor's arguments do.
    """
    import dataclasses

    if not isinstance(data, Mapping):
        raise DataError(f"{cls.__name__}.from_dict needs a dict, got {type(data).__name__}")
    values = {}
    for item in dataclasses.fields(cls):
        if not item.init:
            continue
        if item.name in given:
            values[item.name] = given[item.name]
        elif item.name in data:
            values[item.name] = _field_value(data[item.name], str(item.type))
        elif item.default is dataclasses.MISSING and item.default_factory is dataclasses.MISSING:
            raise DataError(f"{cls.__name__}.from_dict: the dict lacks {item.name!r}")
    return cls(**values)


class FieldsFromDict:
    """Mixin of the dataclasses whose ``to_dict`` writes each field under its name:
    ``from_dict`` rebuilds one (:func:`fields_from_dict`)."""

    @classmethod
    def from_dict(cls, data):
        """The instance of :meth:`to_dict`'s dict (keys it derives, such as properties, are
        not read).

        Parameters
        ----------
        data : dict
            What :meth:`to_dict` wrote (as read back from JSON).

        Raises
        ------
        DataError
            ``data`` is not a dict or lacks a field; the class's own checks raise as its
            constructor does.
        """
        return fields_from_dict(cls, data)


def _field_value(value, annotation):
    """A JSON value as the field annotated ``annotation`` holds it (see fields_from_dict)."""
    if value is None or not isinstance(value, list):
        return value
    if "ndarray" in annotation:
        array = np.asarray(value)
        # JSON's null in a list of numbers is a NaN the writer stored (json_default)
        return np.asarray(value, dtype=float) if array.dtype == object else array
    return tuple(value) if "tuple" in annotation else value


def name_indices(names, known, what="output name"):
    """Positions of ``names`` (one name or several) in ``known``; an unknown name is an error
    that lists the known ones."""
    if not isinstance(names, (str, Iterable)):
        raise ParameterError(f"{what}s must be a name or a sequence of names, got "
                             f"{type(names).__name__} {names!r}")
    names = [names] if isinstance(names, str) else list(names)
    known = list(known)
    for name in names:
        if name not in known:
            raise ParameterError(f"{what} must be one of {known}, got {name!r}")
    return np.array([known.index(name) for name in names], dtype=int)


def check_scalar(name, value):
    """Require one number (not a sequence or array of them); return it as float. Finite and real
    as :func:`as_float_array` demands."""
    array = as_float_array(name, value)
    if array.ndim != 0:
        raise ParameterError(f"{name} must be one number, got {type(value).__name__} of shape "
                             f"{array.shape}")
    return float(array)


def check_fraction(name, value, *, upper_open=True):
    """Require a number in [0, 1) (``upper_open``) or [0, 1]; a string, None or a list is refused
    by its type, not compared."""
    x = check_scalar(name, value)
    if not (0.0 <= x < 1.0 if upper_open else 0.0 <= x <= 1.0):
        raise ParameterError(f"{name} must lie in [0, 1{')' if upper_open else ']'}, got {value!r}")
    return x


def check_names(name, value, *, allow_one=True):
    """Require a sequence of strings (or one string, if ``allow_one``); return it as a tuple."""
    if isinstance(value, str) and allow_one:
        return (value,)
    if isinstance(value, (str, bytes, Mapping)) or not isinstance(value, Iterable):
        raise ParameterError(f"{name} must be a sequence of str, got {type(value).__name__} "
                             f"{value!r}"[:200])
    value = tuple(value)
    bad = next((v for v in value if not isinstance(v, str)), None)
    if bad is not None:
        raise ParameterError(f"{name} must hold names (str), got {type(bad).__name__} {bad!r}")
    return value


def check_optional(name, value, kind, what=None):
    """Require None or an instance of ``kind`` (one type); return it."""
    if value is not None and not isinstance(value, kind):
        raise ParameterError(f"{name} must be {what or 'a ' + kind.__name__} or None, got "
                             f"{type(value).__name__}")
    return value


def check_mapping(name, value, what="a dict"):
    """Require None or a mapping (dict); return it."""
    if value is not None and not isinstance(value, Mapping):
        raise ParameterError(f"{name} must be {what} or None, got {type(value).__name__} "
                             f"{value!r}"[:200])
    return value
