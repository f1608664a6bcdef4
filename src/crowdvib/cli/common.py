"""What every command shares: printing, progress, versions, warnings and safe output directories."""

import argparse
import contextlib
import sys
import weakref
from pathlib import Path

from tqdm import tqdm

from .._files import folder_lock, output_error
from ..cases.results import (DESIGN_TABLES, ESTIMATION_TABLES, SIMULATION_TABLES,
                             software_versions as versions)

__all__ = ["add_output_arguments", "ESTIMATION_TABLES", "SIMULATION_TABLES", "DESIGN_TABLES", "say",
           "say_verdict", "case_inputs", "check_clash", "check_output", "prepare_output",
           "finish_output", "staged_output", "versions", "warning_texts", "progress_printer",
           "write_results"]


#: Exit status of a command that finished and wrote its results, but whose verdict doubts them
#: (docs: Command line, Exit status).
IN_DOUBT = 3
#: ``--quiet``: only the verdict, warnings and errors reach the terminal.
_QUIET = [False]


def set_quiet(quiet):
    """``--quiet``: silence :func:`say` and the progress bars (the verdict still prints)."""
    _QUIET[0] = bool(quiet)


def say(message="", *, always=False):
    if always or not _QUIET[0]:
        print(message, flush=True)


# ------------------------------------------------------------------------------ output directories
# One rule for every command (issue 9): crowdvib deletes or replaces only files its manifest
# lists, and --out may never be, or contain, the working directory or a file the run reads.
# A file a user added to (or edited in) crowdvib's results is foreign: --force and --resume
# then refuse and name it rather than delete it or list it as crowdvib's in the next manifest.



def case_inputs(case):
    """(label, path) of every file a case reads: the case file, its records and modal files.

    The modal files are not kept on the Case, so they are read back from its [structure] table
    (paths relative to the case file, as load_case resolves them).
    """
    import tomllib

    if case is None or case.path is None:
        return []
    inputs = [("the case file", case.path)]
    inputs += [("the record", path) for block in case.blocks()
               for path in block.measurement.files]
    try:
        with open(case.path, "rb") as handle:
            structure = tomllib.load(handle).get("structure", {})
    except (OSError, tomllib.TOMLDecodeError):   # load_case has read it: cannot happen
        structure = {}
    for key in ("modal_table", "mode_shapes", "output_points"):
        if isinstance(structure, dict) and isinstance(structure.get(key), str):
            inputs.append(("the modal file", (case.path.parent / structure[key]).resolve()))
    return inputs


def check_clash(out, inputs=()):
    """Refuse an ``--out`` that is, or contains, the working directory or an input file.

    Parameters
    ----------
    out : str or pathlib.Path
        The output directory (relative paths and symbolic links are resolved).
    inputs : sequence of (str, path)
        Labelled files the run reads, e.g. :func:`case_inputs`.
    """
    from ..errors import ParameterError

    target = Path(out).resolve()
    for label, path in [("the working directory", Path.cwd()), *inputs]:
        path = Path(path).resolve()
        if path == target or target in path.parents:
            verb = "is" if path == target else "contains"
            raise ParameterError(f"--out {out} {verb} {label} {path}: crowdvib never writes "
                                 "results over its inputs; choose another --out")


def check_output(out, *, force, resume=None, inputs=(), command="", stores=()):
    """Refuse an ``--out`` this run may not write; return its manifest (None if new or empty).

    Parameters
    ----------
    out : pathlib.Path
        The output directory.
    force : bool
        --force: replace a directory holding crowdvib results (only crowdvib's own files).
    resume : bool or None
        --resume of a resumable command (None: the command has no --resume).
    inputs : sequence of (str, path)
        Files the run reads (see :func:`check_clash`).
    command : str
        The command; ``--resume`` continues only in results of the same command.
    stores : sequence of str
        Task-store subdirectories of a resumable command.

    Raises
    ------
    ParameterError
        A clash with the inputs, ``out`` not a directory, a non-empty directory crowdvib did not
        write, existing results without --force/--resume, or files crowdvib did not write
        inside crowdvib's results.
    """
    from .._manifest import MANIFEST_NAME, foreign_files, only_stores, read_manifest
    from ..errors import ParameterError

    out = Path(out)
    check_clash(out, inputs)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"--out {out} exists and is not a directory")
    if not out.is_dir() or not any(out.iterdir()):
        return None
    manifest = read_manifest(out)
    if manifest is None and resume and only_stores(out, stores):
        # A study killed before crowdvib wrote manifests: only its task stores are there.
        manifest = {"command": command, "stores": list(stores), "files": []}
    if manifest is None:
        raise ParameterError(
            f"--out {out} is not empty and was not written by crowdvib (it holds no "
            f"{MANIFEST_NAME}): crowdvib replaces only its own results; choose another --out")
    if not (force or resume):
        hint = "--resume to continue it or --force" if resume is not None else "--force"
        raise ParameterError(f"--out {out} already holds results; use {hint} to replace them "
                             f"(crowdvib {manifest.get('command')} results)")
    if resume and not force and manifest.get("command") != command:
        raise ParameterError(f"--out {out} holds results of crowdvib {manifest.get('command')}, "
                             f"not of {command}: --resume continues only a {command} run")
    foreign = foreign_files(out, manifest, resume=bool(resume and not force))
    if foreign:
        shown = ", ".join(foreign[:5]) + (f" and {len(foreign) - 5} more" if len(foreign) > 5
                                          else "")
        raise ParameterError(f"--out {out} holds files crowdvib did not write (or that changed "
                             f"since): {shown}; move them away first, crowdvib replaces only "
                             "its own results")
    return manifest


def prepare_output(out, *, force, resume=False, inputs=(), command, stores=()):
    """Make ``out`` ready for a run that writes into it in place (a resumable study).

    Call it holding the folder's lock (:func:`crowdvib._files.folder_lock`). Checks it
    (:func:`check_output`); with --force removes the files of the previous crowdvib run; creates it and marks it with an incomplete manifest naming the task ``stores``, so an
    interrupted run can be resumed or replaced. Call :func:`finish_output` when done.

    Returns
    -------
    pathlib.Path
    """
    from .._manifest import read_manifest, remove_owned, write_manifest

    out = Path(out)
    manifest = check_output(out, force=force, resume=resume, inputs=inputs, command=command,
                            stores=stores)
    if force and manifest is not None:
        remove_owned(out)
        manifest = None
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise output_error(error, out) from error
    if manifest is None or read_manifest(out) is None:
        write_manifest(out, command, stores=stores, complete=False)
    return out


def finish_output(out, *, command, stores=()):
    """List every file of a finished in-place run in its manifest."""
    from .._manifest import write_manifest

    write_manifest(out, command, stores=stores, complete=True)


@contextlib.contextmanager
def staged_output(out, force, *, command, inputs=()):
    """Yield a staging directory that replaces ``out`` only if the block finishes.

    ``out`` is locked against a second run (:func:`crowdvib._files.folder_lock`) and checked
    (:func:`check_output`). The block writes into a fresh directory
    beside ``out``; when it finishes, a manifest listing its files is added and it is swapped in
    for ``out`` (the previous crowdvib results are then deleted, file by listed file). A failed
    run removes the staging directory and leaves ``out`` as it was, so no half-written results
    ever appear.
    """
    import os
    import shutil
    import tempfile

    from .._manifest import write_manifest

    out = Path(out)
    check_clash(out, inputs)
    with folder_lock(out, command):
        check_output(out, force=force, inputs=inputs, command=command)
        staging = None
        try:
            staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".part",
                                            dir=out.parent))
            # mkdtemp makes 0700 directories; results are shared like any directory mkdir makes.
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(staging, 0o777 & ~umask)
        except OSError as error:
            raise output_error(error, staging or out.parent) from error
        try:
            yield staging
            write_manifest(staging, command)
            _publish(staging, out, force=force, inputs=inputs, command=command)
        finally:
            if staging.exists():   # a directory this run created and filled
                shutil.rmtree(staging, ignore_errors=True)


def _publish(staging, out, *, force, inputs, command):
    """Swap the finished staging directory in for ``out``, deleting only crowdvib's old files."""
    import os

    from .._manifest import remove_owned

    # Checked again: files may have appeared in --out while the run was working.
    check_output(out, force=force, inputs=inputs, command=command)
    old = None
    try:
        if out.is_dir() and not any(out.iterdir()):
            out.rmdir()
        elif out.exists():
            old = out.with_name(f".{out.name}.old-{os.getpid()}")
            os.replace(out, old)
        os.replace(staging, out)
    except OSError as error:
        if old is not None and not out.exists():
            os.replace(old, out)              # the previous results back where they were
        raise output_error(error, out) from error
    if old is not None:
        left = remove_owned(old)
        if left:
            print(f"crowdvib: kept {old}: it holds files crowdvib did not write: "
                  f"{', '.join(left[:5])}", file=sys.stderr)


def warning_texts(caught):
    return [f"{w.category.__name__}: {w.message}" for w in caught]


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


def say_if_compiling(structure, hsi):
    """Tell the user when the simulation kernel is about to be compiled (first run only).

    numba caches the compiled kernel beside its source (``cache=True``), one per kind of run
    (with or without HSI, one or several modes, station grid); with no cache index there for the
    kind ``structure`` and ``hsi`` need and nothing compiled in this process, the first call
    compiles for a while, which must not look like a hang.
    """
    from ..response.simulation import kernel_needs_compiling

    if kernel_needs_compiling(structure, hsi):
        say("  compiling the simulation kernel (first run of this kind only, some 10–30 s) …")


def write_results(directory, results):
    """Write a command's results.json and report.html into ``directory``, both from the one
    result object (:class:`crowdvib.cases.Results`, schema of docs: Results and their files).

    Returns
    -------
    Results
    """
    from .._files import write_json
    from ..cases.results import Results
    from ..reporting.report import write_report

    found = Results.from_dict(results)
    write_json(directory / "results.json", found.to_dict())
    write_report(directory, results=found)
    return found


def say_verdict(directory):
    """Print the verdict on the results in ``directory`` (its doubts and failures, or that there
    are none): the findings ``load_results(directory).verdict()`` gives and report.html shows.

    Returns
    -------
    int
        The command's exit status: 0, or :data:`IN_DOUBT` when a finding doubts the result (a
        design code the bridge fails is an answer, not a doubt).
    """
    from ..cases.results import load_results

    warnings = [f for f in load_results(directory).verdict() if f.severity != "ok"]
    if not warnings:
        say("  verdict: no warnings (details in report.html)", always=True)
        return 0
    say(f"  verdict: check before use ({len(warnings)} warning(s); details in report.html):",
        always=True)
    for finding in warnings:
        say(f"    - {finding.text}", always=True)
    return IN_DOUBT if any(f.severity == "doubt" for f in warnings) else 0


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
    """``--workers N``: local worker processes, by default the machine's physical cores."""
    from .._threads import default_workers

    # The help names no number: it is published in the docs, built on another machine.
    parser.add_argument(
        "--workers", type=positive_int, default=default_workers(),
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
