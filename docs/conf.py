"""Sphinx configuration of the crowdvib documentation.

Build: ``sphinx-build -W --keep-going -b html docs docs/_build/html`` from the repository root.
"""

import os
import re
import sys
from pathlib import Path

# Document the source tree next to this file, not whichever crowdvib happens to be installed.
ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(Path(__file__).resolve().parent / "_ext"))
# Gallery examples and autodoc import matplotlib: never open a window.
os.environ.setdefault("MPLBACKEND", "Agg")

import crowdvib  # noqa: E402
from sphinx.ext import autosummary  # noqa: E402

project = "crowdvib"
author = "the crowdvib developers"
copyright = "2026, the crowdvib developers"
release = crowdvib.__version__
version = ".".join(release.split(".")[:2])

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "sphinxarg.ext",
    "casefile_keys",
    "validation",
]

exclude_patterns = ["_build", "**.ipynb_checkpoints"]
templates_path = ["_templates"]

# -- equations ---------------------------------------------------------------------------------
math_number_all = False
math_eqref_format = "Eq. ({number})"
math_numfig = True
numfig = True
numfig_secnum_depth = 0

# -- API reference ------------------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": True, "inherited-members": False}
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
# The docstrings are checked for structure by numpydoc when it renders them; the validation of
# style rules (summary punctuation, every parameter typed, ...) is left to review, not the build.
numpydoc_validation_checks = set()
numpydoc_xref_param_type = False

# -- tutorials (sphinx-gallery) -------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": ["examples"],
    "gallery_dirs": ["auto_examples"],
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": True,
    "matplotlib_animations": False,
}

# -- HTML ------------------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"crowdvib {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_show_sourcelink = False


# -- docstrings ----------------------------------------------------------------------------------
def _escape_bars(app, what, name, obj, options, lines):
    """Escape the bars of |x| in crowdvib docstrings (written as plain text, not reST).

    The docstrings write magnitudes as |λ| or |H(f)|⁴, which reST would read as substitution
    references; crowdvib never uses substitutions, so every bare bar is a literal bar.
    """
    if not name.startswith("crowdvib"):
        return
    for i, line in enumerate(lines):
        lines[i] = line.replace("\\|", "|").replace("|", "\\|")


# autosummary ends a summary at the first ". ": "(paper Eq. 5 and 6)" came out as "(paper Eq.".
# A period after a reference abbreviation, or inside parentheses (no "(" before the next ")"),
# does not end the sentence.
_ABBREVIATIONS = ("Eq", "Eqs", "Fig", "Figs", "Sec", "Tab", "Ref", "cf", "approx", "No")
autosummary.periods_re = re.compile(
    "".join(rf"(?<!\b{word})" for word in _ABBREVIATIONS) + r"\.(?![^(]*\))(?:\s+)")


def setup(app):
    # Before numpydoc (priority 500) reads the sections.
    app.connect("autodoc-process-docstring", _escape_bars, priority=100)
