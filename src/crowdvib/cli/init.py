"""``crowdvib init RECORD``: what a record holds, and a case-file draft for it (issue 27 §2).

The work is :mod:`crowdvib.io.draft`; this command prints its findings, writes the draft (never
over an existing file) and names the next command. What the draft is unsure of (units it cannot
tell, a header's unit the samples contradict) and the warnings of reading are printed on stderr,
``-q`` or not, and the command then exits with status 3 (1 with ``--strict``): a doubt in the
draft is a doubt (issue 36 §2).
"""

import sys
from pathlib import Path

from ..errors import terminal_safe
from .common import IN_DOUBT, positive_float, say


def add_arguments(parser):
    parser.add_argument("record", type=Path,
                        help="measured record (CSV, NPZ, MAT, UFF 58)")
    parser.add_argument("-o", "--output", type=Path, default=None,
                        help="case file to write (default the record's name with .toml, beside "
                             "it); an existing file is never replaced")
    parser.add_argument("--format", default=None,
                        help="record format: csv, npz, mat, mat73 or uff (default from the "
                             "suffix)")
    parser.add_argument("--sample-rate", type=positive_float, default=None,
                        help="sample rate [Hz] of a record without time stamps")
    parser.add_argument("--time-column", default="time",
                        help="name of the time column [s] (default: 'time' or the one usual "
                             "time header, e.g. 'Time [s]')")


def run(args):
    import shlex

    from ..io.draft import inspect_record, new_case_path, write_draft
    from ..runs.lines import caught_warnings, warning_texts

    output = new_case_path(args.record, args.output)   # refused before the record is read
    args.output = output      # named by --strict's line
    with caught_warnings() as caught:
        found = inspect_record(args.record, format=args.format, sample_rate=args.sample_rate,
                               time_column=args.time_column)
    time = (f"column {found.time_column!r}" if found.time_column else "none")
    source = {"time stamps": "from the time stamps", "given": "given (--sample-rate)",
              "file": "stated in the file"}[found.rate_source]
    say(f"crowdvib init: {found.path} ({found.format})")
    if found.skipped:
        say(f"  header       line {found.header_line}; skipped the {len(found.skipped)} line(s) "
            f"of metadata above it ({'; '.join(found.skipped[:3])}"
            f"{' …' if len(found.skipped) > 3 else ''})")
    say(f"  columns      {', '.join(map(repr, found.channel_names))}"
        + (f" and the time {time}" if found.time_column else ""))
    say(f"  time         {time}; sample rate {found.sample_rate:.6g} Hz {source}")
    say(f"  length       {found.n_samples} samples, {found.duration:g} s")
    if found.gaps:
        say(f"  dropouts     {found.gaps_text}: the draft sets gaps = \"{found.gap_mode}\" "
            "(\"cut\" keeps the longest stretch without one, \"bridge\" interpolates short ones)")
    for channel in found.channels:
        say(f"  {channel.name!r} → output {channel.output!r}: mean {channel.mean:.4g}, RMS "
            f"{channel.rms:.3g} → {channel.units or 'unsure'} ({channel.reason})")
    say(f"  units        {found.units or 'unsure'}: {found.units_reason}")
    doubts = [*warning_texts(caught), *found.doubts]
    for text in doubts:
        print(f"crowdvib init: warning: {terminal_safe(text)}", file=sys.stderr, flush=True)
    write_draft(found, output)
    say(f"  wrote {output}: replace its \"REPLACE: …\" values (the bridge, the crowd, the band"
        + ("" if found.units else ", the units") + "), then run")
    say(f"    crowdvib estimate {shlex.quote(str(output))} --out "
        f"{shlex.quote(output.stem + '-estimate')}")
    return IN_DOUBT if doubts else 0
