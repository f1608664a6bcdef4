"""``crowdvib simulate``: a simulated record of a case, written in the chosen formats.

The work is :func:`crowdvib.runs.run_simulate`; this command parses its arguments and prints.
"""

from pathlib import Path

from .common import (add_output_arguments, progress_printer, record_formats, say, say_verdict,
                     warnings_as_lines)


def add_arguments(parser):
    parser.add_argument("case", type=Path, nargs="?", default=None,
                        help="case file (TOML); default the embedded paper example")
    add_output_arguments(parser)
    parser.add_argument("--duration-s", type=float, default=None,
                        help="record length [s] (default the case's simulation.duration)")
    parser.add_argument("--sample-rate", type=float, default=None,
                        help="simulation sample rate [Hz] (default the case's)")
    parser.add_argument("--seed", type=int, default=None,
                        help="seed of every random draw (default the case's seed)")
    parser.add_argument("--format", type=record_formats, default=None,
                        help="comma-separated record formats among csv, npz, mat, mat73, uff "
                             "(default the case's simulation.formats)")
    parser.add_argument("--no-hsi", action="store_true",
                        help="pedestrians as moving forces only (no MSD)")
    parser.add_argument("--animate", type=Path, default=None, metavar="FILE.gif|mp4",
                        help="also write the crossing replay (the report's) as a video: "
                             ".gif always, .mp4 where ffmpeg is installed")
    parser.add_argument("--replay-start", type=float, default=None, metavar="S",
                        help="the replay's first time [s] (default: the stretch with the most "
                             "walkers on the deck)")
    parser.add_argument("--replay-length", type=float, default=None, metavar="S",
                        help="the replay's length [s] (default 30)")


def run(args):
    from ..runs import run_simulate

    with warnings_as_lines("simulate"):
        run_simulate(args.case, args.out, duration=args.duration_s, sample_rate=args.sample_rate,
                     seed=args.seed, formats=args.format, hsi=False if args.no_hsi else None,
                     force=args.force, say=say, progress=progress_printer,
                     animate=args.animate, replay_start=args.replay_start,
                     replay_length=args.replay_length)
    return say_verdict(args.out)
