"""What every run shares besides its folder: the lines it says, and the warnings it records."""

from collections.abc import Callable

__all__ = ["Say", "silent", "warning_texts"]

#: A run's ``say``: called with each line the command prints (the command line passes its
#: printer, which ``--quiet`` silences; a Python caller may pass ``print``).
Say = Callable[[str], None]


def silent(line: str = "") -> None:
    """The default ``say``: a run from Python prints nothing."""


def warning_texts(caught) -> list[str]:
    """``Category: message`` of each caught warning, as results.json records them."""
    return [f"{w.category.__name__}: {w.message}" for w in caught]
