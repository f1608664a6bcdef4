"""Reading a ``results.json`` for the report: every key looked up defensively.

A results file may come from any crowdvib command, an older version or a hand edit, so each
accessor returns None (never raises) when a key is missing or has the wrong type. The accessors
live in the core (:mod:`crowdvib.cases.schema`), where the verdict reads them too.
"""

import json

from ..cases.schema import case_name, estimate, get, hsi, sensitivity, summary, upgrade
from ..errors import DataError

__all__ = ["read_results", "get", "hsi", "sensitivity", "summary", "estimate", "case_name"]


def read_results(path):
    """The JSON object of a ``results.json`` → dict in the current schema
    (:func:`~crowdvib.cases.schema.upgrade`; DataError naming the file otherwise)."""
    if not path.is_file():
        raise DataError(f"{path} does not exist: run a crowdvib command with --out "
                        f"{path.parent} first")
    try:
        results = json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as error:
        raise DataError(f"{path} is not valid JSON: {error}") from None
    if not isinstance(results, dict):
        raise DataError(f"{path} must hold a JSON object, got {type(results).__name__}")
    return upgrade(results)
