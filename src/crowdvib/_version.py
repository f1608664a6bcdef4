"""crowdvib's version, apart from the package's ``__init__`` so that every layer can name it
without importing the package root (which re-exports every layer)."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("crowdvib")
except PackageNotFoundError:  # running from a source tree that was not installed
    __version__ = "0+unknown"
