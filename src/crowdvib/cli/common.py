"""What every command shares: printing, progress, versions, warnings and staged output directories."""

import contextlib
import sys
import time
from pathlib import Path

import numpy as np

from .. import __version__

__all__ = ["say", "staged_output", "versions", "warning_texts", "progress_printer"]



def say(message=""):
    print(message, flush=True)


# ------------------------------------------------------------------------------ estimate/simulate
def _prepare_out(out, force):
    """A fresh temporary directory beside ``out``; refuses an existing ``out`` without --force."""
    import tempfile

    from ..errors import ParameterError

    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"--out {out} exists and is not a directory")
    if out.is_dir() and any(out.iterdir()) and not force:
        raise ParameterError(f"--out {out} already holds results; use --force to replace them")
    out.parent.mkdir(parents=True, exist_ok=True)
    return Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".part", dir=out.parent))


@contextlib.contextmanager
def staged_output(out, force):
    """Yield a staging directory that replaces ``out`` only if the block finishes.

    A failed run removes the staging directory and leaves ``out`` as it was, so no half-written
    results ever appear; an existing ``out`` is refused without ``--force``.
    """
    import shutil

    staging = _prepare_out(out, force)
    try:
        yield staging
        _publish(staging, out)
    finally:
        if staging.exists():
            shutil.rmtree(staging, ignore_errors=True)


def _publish(staging, out):
    """Swap the finished staging directory in for ``out``."""
    import os
    import shutil

    out = Path(out)
    old = None
    if out.exists():
        old = out.with_name(f".{out.name}.old-{os.getpid()}")
        os.replace(out, old)
    os.replace(staging, out)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def versions():
    import platform

    import scipy

    return {"crowdvib": __version__, "numpy": np.__version__, "scipy": scipy.__version__,
            "python": platform.python_version()}


def warning_texts(caught):
    return [f"{w.category.__name__}: {w.message}" for w in caught]


def progress_printer(label, unit="s"):
    """A ``progress(done, total)`` callback drawing a progress bar on stderr.

    On a terminal the bar is redrawn in place with the elapsed and remaining time; in a log
    (not a terminal) a line is written every 10 %.
    """
    shown = [-1]
    started = time.perf_counter()
    terminal = sys.stderr.isatty()

    def progress(done, total):
        fraction = min(done / total, 1.0) if total > 0 else 1.0
        elapsed = time.perf_counter() - started
        left = f"~{elapsed * (1 - fraction) / fraction:.0f} s left" if fraction > 0 else ""
        text = (f"  {label} {done:.0f}/{total:.0f} {unit} "
                f"[{'#' * int(30 * fraction):30s}] {fraction:4.0%}  {elapsed:.0f} s elapsed {left}")
        if terminal:
            end = "\n" if fraction >= 1 else ""
            print("\r" + text, end=end, file=sys.stderr, flush=True)
        elif int(10 * fraction) > shown[0]:
            shown[0] = int(10 * fraction)
            print(text, file=sys.stderr, flush=True)

    return progress
