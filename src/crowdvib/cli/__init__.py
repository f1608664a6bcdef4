"""The command line: ``crowdvib demo`` and the case-file commands (``main`` parses and dispatches)."""

from .main import build_parser, main

__all__ = ["main", "build_parser"]
