"""Results folders written safely: one rule for every command (issue 9), and the folder's
results.json and report.html from one result object.

crowdvib deletes or replaces only files its manifest lists, and an output folder may never be,
or contain, the working directory or a file the run reads. A file a user added to (or edited in)
crowdvib's results is foreign: ``force`` and ``resume`` then refuse and name it rather than
delete it or list it as crowdvib's in the next manifest. A run writes into a staging folder
swapped in when it finishes (:func:`staged_output`), or, a resumable study, in place under an
incomplete manifest (:func:`prepare_output`, :func:`finish_output`).

Light at import (the command line re-exports it at start-up): the rest loads on use.
"""

import contextlib
import sys
from pathlib import Path

from .._files import folder_lock, output_error
from ..errors import ParameterError
from .._manifest import MANIFEST_NAME, foreign_files, only_stores, read_manifest
from .._manifest import remove_owned, write_manifest
from .._files import write_json
from ..cases.results import Results
from ..reporting.paths import without_machine_paths
from ..reporting.report import case_template, write_report

__all__ = ["case_inputs", "check_clash", "check_output", "prepare_output", "finish_output",
           "staged_output", "write_results"]


def case_inputs(case):
    """(label, path) of every file a case reads: the case file, its records and modal files.

    The modal files are not kept on the Case, so they are read back from its [structure] table
    (paths relative to the case file, as load_case resolves them).

    Parameters
    ----------
    case : Case or None
        A loaded case (None, or an embedded example without a file: no inputs).

    Returns
    -------
    list of (str, pathlib.Path)
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

    Parameters
    ----------
    out : pathlib.Path
        The output folder.
    force, resume : bool
        Replace crowdvib's earlier results; continue them (see :func:`check_output`).
    inputs : sequence of (str, path)
        Files the run reads (see :func:`check_clash`).
    command : str
        The command (or run) writing it.
    stores : sequence of str
        Its task-store subfolders.

    Returns
    -------
    pathlib.Path
    """

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
    """List every file of a finished in-place run in its manifest.

    Parameters
    ----------
    out : pathlib.Path
        The folder :func:`prepare_output` made ready.
    command : str
        The command (or run) that wrote it.
    stores : sequence of str
        Its task-store subfolders.
    """

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

    Parameters
    ----------
    out : pathlib.Path
        The output folder.
    force : bool
        Replace crowdvib's earlier results in it.
    command : str
        The command (or run) writing it.
    inputs : sequence of (str, path)
        Files the run reads (see :func:`check_clash`).
    """
    import os
    import shutil
    import tempfile


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


def write_results(directory, results):
    """Write a command's results.json and report.html into ``directory``, both from the one
    result object (:class:`crowdvib.cases.Results`, schema of docs: Results and their files).

    Parameters
    ----------
    directory : pathlib.Path
        The folder (a staging folder of :func:`staged_output`).
    results : dict
        The results.json object.

    Returns
    -------
    Results
    """

    found = Results.from_dict(results)
    # The report is written from the paths as the run saw them (the case's template, its
    # records); results.json holds each relative to the results folder (a sibling of this
    # staging folder: the same relative path), as the report shows them, not a folder of the
    # machine that wrote it (issue 36 §3).
    written = Results.from_dict(without_machine_paths(found.to_dict(), directory.resolve()))
    write_json(directory / "results.json", written.to_dict())
    write_report(directory, results=found, template=case_template(results))
    return written
