"""``crowdvib sensitivity``: modelling errors and record length → nominal ± bound (paper Figs. 11, 19).

The work is :func:`crowdvib.runs.run_sensitivity`; this command parses its arguments, prints,
and on Ctrl-C says how to resume.
"""

import sys
from pathlib import Path

from .common import (add_workers_argument, close_progress, dask_address, progress_printer, say,
                     say_verdict, warnings_as_lines)


def add_arguments(parser):
    parser.add_argument("case", type=Path, help="case file (TOML) with [measurement] records")
    parser.add_argument("--out", type=Path, required=True, help="output directory")
    add_workers_argument(parser)
    parser.add_argument("--scheduler", type=dask_address, metavar="ADDRESS", default=None,
                        help="run on a dask.distributed scheduler, e.g. tcp://127.0.0.1:8786 "
                             "(needs crowdvib[dask])")
    parser.add_argument("--resume", action="store_true",
                        help="continue an interrupted study in --out without recomputing "
                             "finished tasks; tasks whose inputs (case values, record, options) "
                             "changed since are recomputed, and the command says how many")
    parser.add_argument("--force", action="store_true",
                        help="start afresh, replacing an existing output directory")
    parser.add_argument("--no-joint", action="store_true",
                        help="only individual errors (skip the 2⁵ joint sign combinations)")
    parser.add_argument("--no-record-length", action="store_true",
                        help="skip re-estimating on shorter parts of the record")
    parser.add_argument("--modes-from", type=Path, metavar="DIR", default=None,
                        help="results directory of `crowdvib modes`: the frequency and damping "
                             "error levels become 1 and 2 relative standard deviations of the "
                             "least certain identified mode (instead of 1/5 %% and 10/30 %%)")


def _resume_command(args):
    """The command line that resumes this study, as the user would type it."""
    import shlex

    words = ["crowdvib", "sensitivity", str(args.case), "--out", str(args.out)]
    if args.scheduler is not None:
        words += ["--scheduler", args.scheduler]
    elif args.workers != 1:     # the results do not depend on it; said as given
        words += ["--workers", str(args.workers)]
    words += [flag for flag, given in (("--no-joint", args.no_joint),
                                       ("--no-record-length", args.no_record_length)) if given]
    if args.modes_from is not None:
        words += ["--modes-from", str(args.modes_from)]
    return shlex.join(words + ["--resume"])


def run(args):
    from ..runs import run_sensitivity
    from ..runs.sensitivity import finished_tasks

    try:
        with warnings_as_lines("sensitivity"):
            run_sensitivity(args.case, args.out, workers=args.workers, scheduler=args.scheduler,
                            hung_after=args.hung_after, joint=not args.no_joint,
                            record_length=not args.no_record_length, modes_from=args.modes_from,
                            resume=args.resume, force=args.force, say=say,
                            progress=progress_printer)
    except KeyboardInterrupt:
        if not (args.out / "tasks").is_dir():
            raise           # before the study began: nothing kept, nothing to resume
        # Every finished task is already on disk; the cluster is closed by now.
        close_progress()
        print(f"crowdvib sensitivity: interrupted, {finished_tasks(args.out)} finished task(s) "
              f"kept in {args.out}; resume with: {_resume_command(args)}", file=sys.stderr,
              flush=True)
        return 130
    return say_verdict(args.out)
