"""Every name the API reference lists under ``crowdvib.cases`` is reachable as
``crowdvib.cases.<name>`` (the package imports its modules lazily from a table, which a new
function can miss: Sphinx's autosummary then fails to import it, docs/api/index.rst)."""

import re
from pathlib import Path

import crowdvib.cases as cases

API = Path(__file__).resolve().parents[2] / "docs" / "api" / "index.rst"


def _listed(module):
    """The autosummary entries of ``.. currentmodule:: module`` in the API reference."""
    text = API.read_text(encoding="utf-8")
    section = text.split(f".. currentmodule:: {module}\n", 1)[1].split(".. currentmodule::")[0]
    return re.findall(r"^   ([A-Za-z_][A-Za-z0-9_]*)$", section, flags=re.M)


def test_every_name_the_api_reference_lists_resolves():
    names = _listed("crowdvib.cases")
    assert {"check_case", "msd_box", "load_results"} <= set(names)
    assert [name for name in names if not hasattr(cases, name)] == []
