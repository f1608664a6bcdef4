"""Reading a ``results.json`` for the report: every key looked up defensively.

A results file may come from any crowdvib command, an older version or a hand edit, so each
accessor returns None (never raises) when a key is missing or has the wrong type.
"""

import json
from pathlib import Path

from ..errors import DataError

__all__ = ["read_results", "get", "hsi", "sensitivity", "summary", "estimate", "case_name"]


def read_results(path):
    """The JSON object of a ``results.json`` → dict (DataError naming the file otherwise)."""
    if not path.is_file():
        raise DataError(f"{path} does not exist: run a crowdvib command with --out "
                        f"{path.parent} first")
    try:
        results = json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as error:
        raise DataError(f"{path} is not valid JSON: {error}") from None
    if not isinstance(results, dict):
        raise DataError(f"{path} must hold a JSON object, got {type(results).__name__}")
    return results


def get(results, *paths):
    """The first value found along one of the key paths (tuples), else None."""
    for path in paths:
        value = results
        for key in path:
            if not isinstance(value, dict) or key not in value:
                value = None
                break
            value = value[key]
        if value is not None:
            return value
    return None


def hsi(results, key):
    """An estimator key: top level (demo) or under ``diagnostics`` (estimate)."""
    return get(results, (key,), ("diagnostics", key))


def sensitivity(results):
    """A SensitivityResult dict (under ``sensitivity`` or top level), or None."""
    value = get(results, ("sensitivity",))
    if value is None and isinstance(results.get("cases"), list):
        value = results
    return value if isinstance(value, dict) and isinstance(value.get("cases"), list) else None


def summary(results):
    """The sensitivity summary {parameter: {nominal, bound, bound_percent}}, if any."""
    found = get(results, ("sensitivity", "summary"), ("summary",))
    if not isinstance(found, dict):
        return None
    return {k: v for k, v in found.items() if isinstance(v, dict)}


def estimate(results):
    """The MSD estimate {frequency, damping_ratio, mass_ratio} of any command, or None."""
    found = results.get("estimate")
    if not isinstance(found, dict):
        found = get(results, ("sensitivity", "nominal"), ("nominal",))
    if not isinstance(found, dict):
        found = get(results, ("objective_map", "estimate"), ("objective_map", "grid_optimum"))
    return found if isinstance(found, dict) else None


def case_name(results):
    """The case's name (plain text)."""
    inputs = results.get("inputs")
    if isinstance(inputs, dict) and inputs.get("name"):
        return str(inputs["name"])
    case = results.get("case")
    return Path(str(case)).stem if case else "unnamed case"
