"""What every command shares: printing, progress bars, the verdict line and the argument types.

Light on purpose: ``crowdvib --help`` and every command's ``--help`` import this module and
nothing of the library's work (issue 34 §4); what a command runs with (tqdm's bars, the results
of :mod:`crowdvib.cases`) is imported when it runs. The results folder's rules and writing are
the library's (:mod:`crowdvib.runs.folders`).
"""

import argparse
import contextlib
import sys
import warnings
import weakref
from pathlib import Path

from ..errors import terminal_safe

__all__ = ["say", "say_verdict", "say_warnings", "warnings_as_lines", "progress_printer",
           "add_output_arguments"]


#: Exit status of a command that finished and wrote its results, but whose verdict doubts them
#: (docs: Command line, Exit status).
IN_DOUBT = 3
#: Exit status of a command that finished and wrote its results, not in doubt, by which the
#: bridge fails a design code: an answer, not a doubt (issue 36 §3).
FAILS_DESIGN = 4
#: ``--quiet``: only the verdict, warnings and errors reach the terminal.
_QUIET = [False]
#: The warnings this run printed as they were raised: the verdict counts them, not again.
_PRINTED: list = []
#: ANSI colours of the verdict's headings on a terminal: red fails, yellow doubts, green none.
_COLOURS = {"fail": "31", "doubt": "33", "ok": "32"}


def _paint(text, severity, stream=None):
    """``text`` in the colour of ``severity`` when ``stream`` (stdout) is a terminal and the
    user has not asked for none (the NO_COLOR convention, no-color.org)."""
    import os

    stream = sys.stdout if stream is None else stream
    if not getattr(stream, "isatty", lambda: False)() or os.environ.get("NO_COLOR"):
        return text
    return f"\x1b[{_COLOURS[severity]}m{text}\x1b[0m"


def forget_printed():
    """A new run: no warning printed yet (the command line runs one command per process, the
    tests many)."""
    _PRINTED.clear()


def set_quiet(quiet):
    """``--quiet``: silence :func:`say` and the progress bars (the verdict still prints)."""
    _QUIET[0] = bool(quiet)


def say(message="", *, always=False, severity=None):
    """Print a line of the command's output; text from files in it reaches the terminal escaped
    (:func:`crowdvib.errors.terminal_safe`: a case's name may hold ESC or U+202E), a verdict
    heading in its ``severity``'s colour on a terminal."""
    if always or not _QUIET[0]:
        text = terminal_safe(message)
        print(text if severity is None else _paint(text, severity), flush=True)


@contextlib.contextmanager
def warnings_as_lines(command):
    """Print each crowdvib warning as one line on stderr when it happens (a damaged task file,
    inputs changed since a study began), not as a Python warning with a source line."""
    from ..errors import CrowdvibWarning

    with warnings.catch_warnings():
        others = warnings.showwarning

        def show(message, category, *rest):
            if not issubclass(category, CrowdvibWarning):
                return others(message, category, *rest)
            print(f"crowdvib {command}: warning: {terminal_safe(message)}", file=sys.stderr,
                  flush=True)
            _PRINTED.append(str(message))

        warnings.simplefilter("always", CrowdvibWarning)
        warnings.showwarning = show
        yield


def say_warnings(command, results):
    """The warnings a run recorded in its results, one line each on stderr (once: the verdict
    then counts them)."""
    for text in results.warnings:
        if text not in _PRINTED:
            print(f"crowdvib {command}: warning: {terminal_safe(text)}", file=sys.stderr)
            _PRINTED.append(text)


#: Progress bars drawn and not yet closed: a command that ends early closes them
#: (:func:`close_progress`), so its last line starts a line of its own.
_BARS: weakref.WeakSet = weakref.WeakSet()


def close_progress():
    """Close every progress bar a failed or interrupted command left open."""
    for bar in list(_BARS):
        bar.close()


def progress_printer(label, unit="s", offset=0.0):
    """A ``progress(done, total)`` callback drawing a tqdm bar on stderr.

    The bar shows the rate so far and the time left at that rate. ``offset`` is a leading part
    of ``done`` and ``total`` that is not the user's work (a simulation's warm-up): the bar counts
    from it, and the label says what it was.
    """
    bar = None

    def progress(done, total):
        nonlocal bar
        if _QUIET[0]:
            return
        if bar is None:
            from tqdm import tqdm

            terminal = sys.stderr.isatty()
            bar = tqdm(total=max(total - offset, 0.0), desc=f"  {label}", unit=f" {unit}",
                       file=sys.stderr, leave=True, dynamic_ncols=True,
                       mininterval=0.5 if terminal else 15.0,
                       bar_format="{desc} {n:.0f}/{total:.0f}{unit} |{bar}| {percentage:3.0f}%"
                                  "  {elapsed} elapsed, {remaining} left")
            _BARS.add(bar)
        bar.update(max(min(done, total) - offset, 0.0) - bar.n)
        if done >= total:
            bar.close()

    return progress


def say_verdict(directory):
    """Print the verdict on the results in ``directory``: the findings
    ``load_results(directory).verdict()`` gives and report.html shows, in two parts, each in
    its words and colour (issue 36 §3): the design checks the bridge fails (an answer), and the
    doubts about the result itself (check before use). A warning already printed as raised is
    counted, not printed again.

    Returns
    -------
    int
        The command's exit status: :data:`IN_DOUBT` when the verdict doubts the result, else
        :data:`FAILS_DESIGN` when the bridge fails a design code, else 0.
    """
    from ..cases.results import load_results
    from ..cases.verdict import is_doubt

    found = load_results(directory)
    verdict = found.verdict()
    fails = [f for f in verdict if f.severity == "fail" and not is_doubt(f)]
    doubts = [f for f in verdict if is_doubt(f)]
    if fails:
        say(f"  verdict: the bridge fails {len(fails)} design check(s) (the checks' answer; "
            "details in report.html):", always=True, severity="fail")
        for finding in fails:
            say(f"    - {finding.text}", always=True)
    if not doubts:
        say("  verdict: " + ("the result itself is not in doubt: no warnings" if fails
                             else "no warnings") + " (details in report.html)",
            always=True, severity="ok")
        return FAILS_DESIGN if fails else 0
    say(f"  verdict: check before use: the result itself is in doubt ({len(doubts)} "
        "warning(s); details in report.html):", always=True, severity="doubt")
    shown = [f for f in doubts if not (f.key == "warnings" and f.text in _PRINTED)]
    for finding in shown:
        say(f"    - {finding.text}", always=True)
    if len(shown) < len(doubts):
        say(f"    - and the {len(doubts) - len(shown)} warning(s) printed above", always=True)
    return IN_DOUBT


def positive_float(text):
    """argparse type: a finite number > 0 (a bad value is a usage error, exit 2)."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 < value < float("inf"):
        raise argparse.ArgumentTypeError(f"expected a finite number > 0, got {text!r}")
    return value


def positive_int(text):
    """argparse type: an integer >= 1 (a bad value is a usage error, exit 2)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {value}")
    return value


def add_output_arguments(parser):
    """``--out DIR`` (required) and ``--force``, as every command that writes results takes them."""
    parser.add_argument("--out", type=Path, required=True, help="output directory")
    parser.add_argument("--force", action="store_true",
                        help="replace an existing output directory")


def add_workers_argument(parser):
    """``--workers N``: local worker processes, by default the machine's physical cores (counted
    by :func:`crowdvib.cli.main.main` once the command is known to run: psutil is slow to import
    for ``--help``)."""
    # The help names no number: it is published in the docs, built on another machine.
    parser.add_argument(
        "--workers", type=positive_int, default=None,
        help="local worker processes, each with its share of the cores for BLAS and numba "
             "(default: the physical cores of the machine it runs on; 1 runs in this process)")
    parser.add_argument(
        "--hung-after", type=positive_float, default=60.0, metavar="SECONDS",
        help="local workers: a task running longer than this and than 10 times the slowest "
             "finished task is taken as hung; its worker is replaced and the task run again, "
             "three tries in all (default: 60)")


def record_formats(text):
    """argparse type: comma-separated record formats, each known (else a usage error, exit 2)."""
    from ..io.records import RECORD_FORMATS

    formats = tuple(part.strip() for part in text.split(",") if part.strip())
    unknown = [f for f in formats if f not in RECORD_FORMATS]
    if unknown or not formats:
        raise argparse.ArgumentTypeError(
            f"must list formats among {list(RECORD_FORMATS)}, got {text!r}")
    for fmt in formats:
        _require(_OPTIONAL.get(fmt), f"--format {fmt}")
    return formats


def dask_address(text):
    """argparse type: a dask scheduler address, once dask.distributed is known to be installed."""
    _require(_OPTIONAL["dask"], "--scheduler")
    return text


#: What needs an optional package: name → (module, extra that installs it).
_OPTIONAL = {"mat73": ("h5py", "mat73"), "uff": ("pyuff", "uff"), "dask": ("distributed", "dask")}


def _require(need, option):
    """A usage error before any work starts when ``option`` needs a package that is missing."""
    import importlib.util

    if need is not None and importlib.util.find_spec(need[0]) is None:
        raise argparse.ArgumentTypeError(
            f"{option} needs the package {need[0]}, which is not installed: "
            f"pip install 'crowdvib[{need[1]}]'")
