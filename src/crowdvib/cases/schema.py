"""The versioned schema of ``results.json`` and the look-ups every reader of it shares.

Every command writes ``"schema": SCHEMA`` and ``"kind"`` (one of :data:`KINDS`) at the top of
its results.json (docs: :doc:`/results`); :func:`crowdvib.load_results` refuses a file without
them. The accessors below read a results dict defensively: a file from an older crowdvib or a
hand edit may lack any key, so each returns None (never raises) where a key is missing or has
the wrong type. The verdict (:mod:`crowdvib.cases.verdict`) and the report read through them.

Light on purpose (no numpy): the command line imports it at start-up.
"""

from pathlib import Path

__all__ = ["SCHEMA", "KINDS", "schema_header", "get", "hsi", "sensitivity", "summary",
           "estimate", "case_name", "real"]

#: The schema name and version every results.json carries; a change that removes or renames a
#: key, or changes its meaning, makes a new version.
SCHEMA = "crowdvib.results/1"
#: The kinds of results: one per command that writes a results.json.
KINDS = ("estimate", "sensitivity", "check", "modes", "simulate", "map", "demo", "season",
         "comfort")


def schema_header(kind: str) -> dict:
    """``{"schema": SCHEMA, "kind": kind}``: the first keys of a results.json."""
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {list(KINDS)}, got {kind!r}")
    return {"schema": SCHEMA, "kind": kind}


def real(x):
    """``x`` if it is a finite real number (not a bool), else None."""
    ok = (isinstance(x, (int, float)) and not isinstance(x, bool)
          and x == x and abs(x) != float("inf"))
    return x if ok else None


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
    """An estimator key: top level (demo) or under ``diagnostics`` (estimate, map, sensitivity)."""
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
