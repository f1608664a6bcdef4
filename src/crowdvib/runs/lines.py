"""What every run shares besides its folder: the case it reads, the lines it says, and the
warnings it records."""

import contextlib
import warnings
from collections.abc import Callable
from pathlib import Path
from ..errors import CrowdvibWarning, StudyWarning
from ..io.casefile import load_case

__all__ = ["Say", "Progress", "silent", "warning_texts", "caught_warnings", "as_case",
           "recorded_warnings"]

#: A run's ``say``: called with each line the command prints (the command line passes its
#: printer, which ``--quiet`` silences; a Python caller may pass ``print``).
Say = Callable[[str], None]
#: A run's ``progress``: ``progress(label, unit="s", offset=0.0)`` makes the ``progress(done,
#: total)`` callback of one stage of the run, counted in ``unit`` from ``offset`` (a
#: simulation's warm-up); the command line passes its progress bars.
Progress = Callable[..., Callable[[float, float], None]]


def silent(line: str = "") -> None:
    """The default ``say``: a run from Python prints nothing."""


def warning_texts(caught) -> list[str]:
    """``Category: message`` of each caught warning, as results.json records them."""
    return [f"{w.category.__name__}: {w.message}" for w in caught]


@contextlib.contextmanager
def caught_warnings():
    """Catch every warning a run raises, each time it is raised, for its results and report;
    but a ``ResourceWarning``, which the garbage collector raises for a file some earlier code
    left open whenever it happens to run, doubts nothing of this run and stays ignored as
    Python ignores it by default (CI once found one in a design check's results)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        warnings.simplefilter("ignore", ResourceWarning)
        yield caught


def as_case(case):
    """``case`` if it is a loaded :class:`~crowdvib.io.casefile.Case`, else the case file it
    names, read (a run reads it inside its record of warnings: a doubtful value of the case
    file is in its results and report, issue 27 §4)."""
    if isinstance(case, (str, Path)):

        return load_case(case)
    return case


@contextlib.contextmanager
def recorded_warnings():
    """Record a long run's crowdvib warnings (``Category: message``, each once, as results.json
    lists them) while every warning is still shown when it happens, by ``warnings.showwarning``
    (the command line: one line each). A :class:`~crowdvib.errors.StudyWarning` (stored tasks
    redone) is shown, not recorded: it doubts no result."""

    with warnings.catch_warnings():
        caught, show = [], warnings.showwarning

        def record(message, category, *rest):
            text = f"{category.__name__}: {message}"
            if (issubclass(category, CrowdvibWarning) and not issubclass(category, StudyWarning)
                    and text not in caught):
                caught.append(text)
            return show(message, category, *rest)

        warnings.simplefilter("always", CrowdvibWarning)
        warnings.showwarning = record
        yield caught
