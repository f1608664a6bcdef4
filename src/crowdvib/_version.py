"""crowdvib's version, apart from the package's ``__init__`` so that every layer can name it
without importing the package root (which re-exports every layer).

The one place it is written: pyproject.toml reads it from here (``[tool.setuptools.dynamic]``),
and reading it costs the command line no ``importlib.metadata`` (a tenth of ``--help``'s time).
"""

__version__ = "0.1.0"
