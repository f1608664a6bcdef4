"""``crowdvib season``: a season of monitoring records with a crowd table, each record estimated
with its interval and all of them together (issue 28 §2).

The work is :func:`crowdvib.runs.run_season`; this command parses its arguments, prints, and on
Ctrl-C says how to resume.
"""

import sys
from pathlib import Path

from .common import (add_workers_argument, close_progress, dask_address, positive_int,
                     progress_printer, say, say_verdict, warnings_as_lines)


def add_arguments(parser):
    parser.add_argument("case", type=Path,
                        help="case file (TOML): the bridge, the crowd's other properties, how a "
                             "record is read and estimated; its measurement.files (folders "
                             "allowed) are the season's records")
    parser.add_argument("crowd_table", type=Path,
                        help="crowd table CSV: per record (or start/end window) its count or "
                             "density, optionally step frequencies, duration and time")
    parser.add_argument("--out", type=Path, required=True, help="output directory")
    parser.add_argument("--records", type=Path, metavar="DIR", default=None,
                        help="folder of the records (default: the case's measurement.files, "
                             "else the crowd table's folder)")
    add_workers_argument(parser)
    parser.add_argument("--scheduler", type=dask_address, metavar="ADDRESS", default=None,
                        help="run on a dask.distributed scheduler, e.g. tcp://127.0.0.1:8786 "
                             "(needs crowdvib[dask])")
    parser.add_argument("--batch-size", type=positive_int, metavar="N", default=None,
                        help="records per task sent to the workers (default: 1 on local "
                             "workers; on dask, batches of 1/16 of a worker's share)")
    parser.add_argument("--resume", action="store_true",
                        help="continue an interrupted season in --out without estimating "
                             "finished records again")
    parser.add_argument("--force", action="store_true",
                        help="start afresh, replacing an existing output directory")
    parser.add_argument("--no-joint", action="store_true",
                        help="only each record's estimate (skip the joint one)")
    parser.add_argument("--joint-min-density", type=float, metavar="D", default=0.0,
                        help="leave rows of fewer persons/m² out of the joint estimate (their "
                             "records hold little of the MSD; default 0: every row)")


def _resume_command(args):
    """The command line that resumes this season, as the user would type it."""
    import shlex

    words = ["crowdvib", "season", str(args.case), str(args.crowd_table), "--out", str(args.out)]
    if args.records is not None:
        words += ["--records", str(args.records)]
    if args.scheduler is not None:
        words += ["--scheduler", args.scheduler]
    elif args.workers != 1:     # the results do not depend on it; said as given
        words += ["--workers", str(args.workers)]
    if args.batch_size is not None:
        words += ["--batch-size", str(args.batch_size)]
    if args.joint_min_density:
        words += ["--joint-min-density", f"{args.joint_min_density:g}"]
    return shlex.join(words + ["--no-joint"] * args.no_joint + ["--resume"])


def run(args):
    from ..io.casefile import load_case
    from ..runner import TaskStore
    from ..runs import run_season

    case = load_case(args.case)
    try:
        with warnings_as_lines("season"):
            run_season(case, args.crowd_table, args.out, records=args.records,
                       workers=args.workers, scheduler=args.scheduler,
                       hung_after=args.hung_after, joint=not args.no_joint,
                       joint_min_density=args.joint_min_density, batch_size=args.batch_size,
                       resume=args.resume, force=args.force, say=say,
                       progress=progress_printer("records", unit=""))
    except KeyboardInterrupt:
        if not (args.out / "tasks").is_dir():
            raise           # before the season began: nothing kept, nothing to resume
        close_progress()
        print(f"crowdvib season: interrupted, {len(TaskStore(args.out / 'tasks').keys())} "
              f"finished record(s) kept in {args.out}; resume with: {_resume_command(args)}",
              file=sys.stderr, flush=True)
        return 130
    return say_verdict(args.out)
