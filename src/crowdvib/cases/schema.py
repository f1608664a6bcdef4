"""The versioned schema of ``results.json`` and the look-ups every reader of it shares.

Every command writes ``"schema": SCHEMA`` and ``"kind"`` (one of :data:`KINDS`) at the top of
its results.json (docs: :doc:`/results`); :func:`crowdvib.load_results` refuses a file without
them. The accessors below read a results dict defensively: a file from an older crowdvib or a
hand edit may lack any key, so each returns None (never raises) where a key is missing or has
the wrong type. The verdict (:mod:`crowdvib.cases.verdict`) and the report read through them.

Light on purpose (no numpy): the command line imports it at start-up.
"""

from pathlib import Path

__all__ = ["SCHEMA", "READABLE", "KINDS", "schema_header", "upgrade", "get", "hsi",
           "sensitivity", "summary", "estimate", "case_name", "real"]

#: The schema name and version every results.json carries; a change that removes or renames a
#: key, or changes its meaning, makes a new version. Version 2 gives every key one place per
#: kind: the estimator's diagnostics under ``diagnostics`` for the demo too (version 1 kept the
#: demo's at the top level).
SCHEMA = "crowdvib.results/2"
#: The schemas this crowdvib reads: the current one, and those :func:`upgrade` brings to it.
READABLE = ("crowdvib.results/1", SCHEMA)
#: The kinds of results: one per command that writes a results.json.
KINDS = ("estimate", "sensitivity", "check", "modes", "simulate", "map", "demo", "season",
         "comfort")
#: Keys of a version-1 demo's top level that version 2 keeps under ``diagnostics``: those of
#: ``HSIEstimate.to_dict`` but its ``estimate``.
_DEMO_DIAGNOSTICS = ("method", "crowd_model", "crowd_model_details", "correlation", "covariance",
                     "interval_on_bound", "cost", "cost_no_hsi", "relative_cost",
                     "n_evaluations", "success", "active_bounds", "free_parameters", "bounds",
                     "band", "output_names", "output_weights", "starts", "message",
                     "level_ratio", "density", "crowd")


def upgrade(results):
    """A results.json object of a readable older schema (:data:`READABLE`) in the current one
    (a new dict; the current schema's, and anything else, as it is).

    Version 1 → 2: a demo's estimator diagnostics move from the top level to ``diagnostics``.
    """
    if not isinstance(results, dict) or results.get("schema") != READABLE[0]:
        return results
    found = {**results, "schema": SCHEMA}
    if found.get("kind") == "demo":
        moved = {key: found.pop(key) for key in _DEMO_DIAGNOSTICS if key in found}
        found["diagnostics"] = {**moved, **(found.get("diagnostics") or {})}
    return found


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
    """An estimator key (under ``diagnostics``: estimate, map, demo, season)."""
    return get(results, ("diagnostics", key))


def sensitivity(results):
    """The modelling-error study's dict (``sensitivity``), or None."""
    value = get(results, ("sensitivity",))
    return value if isinstance(value, dict) and isinstance(value.get("cases"), list) else None


def summary(results):
    """The sensitivity summary {parameter: {nominal, bound, bound_percent}}, if any."""
    found = get(results, ("sensitivity", "summary"))
    if not isinstance(found, dict):
        return None
    return {k: v for k, v in found.items() if isinstance(v, dict)}


def estimate(results):
    """The MSD estimate {frequency, damping_ratio, mass_ratio (, interval …)} of any command
    (``estimate``), or None."""
    found = results.get("estimate")
    return found if isinstance(found, dict) else None


def case_name(results):
    """The case's name (plain text)."""
    inputs = results.get("inputs")
    if isinstance(inputs, dict) and inputs.get("name"):
        return str(inputs["name"])
    case = results.get("case")
    return Path(str(case)).stem if case else "unnamed case"
