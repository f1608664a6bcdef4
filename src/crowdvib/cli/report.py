"""``crowdvib report DIR``: rebuild report.html of a results directory.

The work is :func:`crowdvib.reporting.report.write_report`; this command parses its arguments
and prints.
"""

from pathlib import Path

from .._files import require_file
from .common import say


def add_arguments(parser):
    parser.add_argument("directory", type=Path,
                        help="results directory written by a crowdvib command (holds "
                             "results.json)")
    parser.add_argument("--template", type=Path, default=None, metavar="FILE",
                        help="Jinja2 page (.html or .j2) to lay out the report with; "
                             "default: the one results.json records, if it lies inside "
                             "DIRECTORY, else the built-in page")


def run(args):
    from ..reporting.report import write_report

    if args.template is not None:
        require_file(args.template, "report template")
    say(f"wrote {write_report(args.directory, template=args.template)}")
    return 0
