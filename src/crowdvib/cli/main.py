"""Command line: ``crowdvib demo`` and the case-file commands.

The CLI only parses arguments, makes one call of the library (:mod:`crowdvib.runs`) and prints.
Exit status (docs: Command line, Exit status): 0 finished, 1 an error, 2 a usage error, 3
finished and written but the verdict doubts the result (1 with ``--strict``), 4 finished and
written, not in doubt, and the bridge fails a design code (an answer, issue 36 §3), 130 Ctrl-C.
Whatever ends a command, it ends in one line on stderr (the traceback only with ``--verbose``):
a crowdvib error's message, an ``OSError`` as its path and cause, Ctrl-C as "interrupted", and
any other exception as a bug in crowdvib, with how to report it. ``--quiet`` leaves the verdict,
warnings and errors; ``--verbose`` adds the log records of the estimator and the studies, and
tracebacks; ``--strict`` makes a result in doubt a failure (issue 27 §2).
"""

import argparse
import importlib
import logging
import sys
from pathlib import Path

from .._version import __version__
from .._files import os_error_text, require_file
from ..errors import CrowdvibError, terminal_safe
from .common import IN_DOUBT, close_progress, forget_printed, set_quiet

__all__ = ["main", "build_parser"]


#: command → (one-line help, the module of ``crowdvib.cli`` with its ``add_arguments(parser)``
#: and ``run(args) -> int``). A command's module is imported only when that command is parsed or
#: run: ``crowdvib --help`` lists the commands from this table alone (issue 34 §4).
_COMMANDS = {
    "init": ("a case-file draft from a measured record: what it holds, placeholders for the rest",
             "init"),
    "demo": ("estimate the MSD parameters back on the paper's numerical example", "demo"),
    "estimate": ("estimate the MSD parameters from a case file's measured records", "estimate"),
    "simulate": ("simulate a case (default: the paper example) and write its record",
                 "simulate"),
    "report": ("write report.html, a self-contained HTML report, into a results directory",
               "report"),
    "map": ("evaluate the objective J(f_h1, ξ_h1) of a case's estimator on a grid", "landscape"),
    "sensitivity": ("estimation error from modelling errors and record length: nominal ± bound",
                    "sensitivity"),
    "check": ("design checks of a case's [design] table (codes, with and without HSI)", "check"),
    "modes": ("the empty bridge's modes from an ambient record (operational modal analysis)",
              "modes"),
    "season": ("a season of records with a crowd table: each estimated, one MSD for all",
               "season"),
    "comfort": ("a year of comfort: hours per comfort class from a season or a traffic table",
                "comfort"),
}


def _command(name):
    """The module of command ``name`` (imported now, if it was not)."""
    return importlib.import_module(f".{_COMMANDS[name][1]}", __package__)


#: One or two examples per command, as its --help ends them (issue 36 §3); the files are the
#: repository's examples/ (run from a clone) or the user's own.
EXAMPLES = {
    "init": ["crowdvib init bridge.csv                     # drafts bridge.toml beside it",
             "crowdvib init logger.txt --sample-rate 100 -o bridge.toml"],
    "demo": ["crowdvib demo", "crowdvib demo --spectral --out demo"],
    "estimate": ["crowdvib estimate examples/paper_example.toml --out estimate",
                 "crowdvib estimate bridge.toml --out estimate --force"],
    "simulate": ["crowdvib simulate --out sim --duration-s 600",
                 "crowdvib simulate examples/eeklo_like.toml --out sim --format csv,npz"],
    "report": ["crowdvib report estimate",
               "crowdvib report estimate --template house.html"],
    "map": ["crowdvib map examples/paper_example.toml --out map",
            "crowdvib map bridge.toml --out map --frequencies 2:4:21 --damping-ratios 0.1:0.5:21"],
    "sensitivity": ["crowdvib sensitivity examples/paper_example.toml --out sens --workers 2",
                    "crowdvib sensitivity examples/paper_example.toml --out sens --resume"],
    "check": ["crowdvib check examples/check_paper.toml --out check",
              "crowdvib check bridge.toml --msd-from estimate --out check"],
    "modes": ["crowdvib modes examples/ambient/paper_beam_ambient.toml --out modes",
              "crowdvib modes ambient.toml --out modes --cross-check"],
    "season": ["crowdvib season bridge.toml crowd.csv --records records --out season",
               "crowdvib season bridge.toml crowd.csv --records records --out season --resume"],
    "comfort": ["crowdvib comfort bridge.toml --season season --msd-from season --out comfort",
                "crowdvib comfort bridge.toml --traffic traffic.csv --out comfort --workers 2"],
}


def _epilog(name):
    """A command's --help ending: its examples, then the exit statuses."""
    import textwrap

    examples = "\n".join(f"  {line}" for line in EXAMPLES.get(name, ()))
    return (f"examples:\n{examples}\n\n" if examples else "") + textwrap.fill(EXIT_STATUS, 79)


def build_parser(commands=None):
    """The argument parser with one sub-command per entry of ``_COMMANDS``.

    Parameters
    ----------
    commands : collection of str, optional
        The commands whose arguments are added (their modules imported); default all. The
        others are listed, with their help, and take no arguments: :func:`main` builds only the
        command it runs.
    """
    parser = argparse.ArgumentParser(
        prog="crowdvib",
        description="Crowd-induced footbridge vibrations with human-structure interaction.")
    parser.add_argument("--version", action="version", version=f"crowdvib {__version__}")
    _add_verbosity(parser, {})
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, (help_text, _) in _COMMANDS.items():
        sub = subparsers.add_parser(name, help=help_text, description=help_text,
                                    epilog=_epilog(name),
                                    formatter_class=argparse.RawDescriptionHelpFormatter)
        _add_verbosity(sub, {"default": argparse.SUPPRESS})
        if commands is None or name in commands:
            _command(name).add_arguments(sub)
    return parser


def _named(argv):
    """The command ``argv`` runs, as a one-element tuple (empty when it names none): its first
    word that is a command's name. The options before the command (-v, -q, --strict,
    --version, -h) take no value, so that word is the command whenever argparse accepts it."""
    words = sys.argv[1:] if argv is None else argv
    return tuple(word for word in words if word in _COMMANDS)[:1]


#: The exit statuses, as every command's help ends.
EXIT_STATUS = ("exit status: 0 finished; 1 error; 2 usage error; 3 finished and written, but the "
               "verdict doubts the result (check before use; 1 with --strict); 4 finished and "
               "written, not in doubt, and the bridge fails a design check (an answer, not a "
               "doubt); 130 interrupted")


def _add_verbosity(parser, suppress):
    """--verbose/-v, --quiet/-q and --strict, before or after the command name."""
    parser.add_argument("-v", "--verbose", action="store_true", **suppress,
                        help="show the estimator's and the studies' log records, and tracebacks "
                             "of errors")
    parser.add_argument("-q", "--quiet", action="store_true", **suppress,
                        help="print only the verdict, warnings and errors")
    parser.add_argument("--strict", action="store_true", **suppress,
                        help="a result in doubt is a failure: exit status 1 instead of 3 (the "
                             "results are written all the same), for scripts and CI")


def main(argv=None):
    """Run the command line; returns the exit code."""
    parser = build_parser(_named(argv))
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_:
        return int(exit_.code or 0)
    set_quiet(args.quiet)
    forget_printed()
    _log_records(args.verbose)
    try:
        case = getattr(args, "case", None)
        if isinstance(case, Path):
            # Before the command imports scipy and numba: a wrong path is answered at once.
            require_file(case, "case")
        if getattr(args, "workers", 0) is None:   # --workers' default, counted when it runs
            from .._resources import default_workers

            args.workers = default_workers()
        status = _command(args.command).run(args)
    except KeyboardInterrupt:
        # What a command keeps is its business (sensitivity keeps its finished tasks and says
        # so); a staged one has removed its unfinished results by now.
        close_progress()
        print(f"crowdvib {args.command}: interrupted", file=sys.stderr)
        return 130
    except Exception as error:
        close_progress()
        if args.verbose:
            raise
        print(f"crowdvib {args.command}: error: {terminal_safe(_one_line(error))}",
              file=sys.stderr)
        return 1
    if status == IN_DOUBT and args.strict:
        written = getattr(args, "out", None) or getattr(args, "output", None) or "--out"
        print(f"crowdvib {args.command}: error: --strict: the verdict doubts the result (see "
              f"above; written to {written})", file=sys.stderr)
        return 1
    return status


def _log_records(verbose):
    """--verbose: crowdvib's log records (INFO and up) on this run's stderr; else none."""
    logger = logging.getLogger("crowdvib")
    for handler in [h for h in logger.handlers if getattr(h, "crowdvib_cli", False)]:
        logger.removeHandler(handler)
    if verbose:
        handler = logging.StreamHandler(sys.stderr)
        handler.setFormatter(logging.Formatter("  %(name)s: %(message)s"))
        handler.crowdvib_cli = True
        logger.addHandler(handler)
    logger.setLevel(logging.INFO if verbose else logging.NOTSET)


def _one_line(error):
    """The line that tells a user what ended a command."""
    if isinstance(error, CrowdvibError):
        return str(error)
    if isinstance(error, OSError):
        return os_error_text(error)
    return (f"{type(error).__name__}: {error}. This is a bug in crowdvib: please report it with "
            "the output of the same command run with --verbose")


if __name__ == "__main__":
    sys.exit(main())
