"""The moving pictures a command adds to its results (issue 38): the modal model's shapes, the
replay of a simulated crossing, and the replay as a video file (``crowdvib simulate --animate``).
"""

from __future__ import annotations

from pathlib import Path

from ..errors import ParameterError
from ..response.time_domain.replay import DEFAULT_REPLAY_LENGTH, crossing_replay
from ..cases.demo import DEMO_SAMPLE_RATE, DEMO_WARM_UP
from ..errors import terminal_safe

__all__ = ["simulation_replay", "demo_replay", "check_video_path", "in_results",
           "VIDEO_SUFFIXES"]

#: What ``--animate`` writes, by the file's suffix.
VIDEO_SUFFIXES = (".gif", ".mp4")


def simulation_replay(found, *, start=None, length=None):
    """The crossing replay of a :class:`~crowdvib.cases.CaseSimulation`: its record's busiest
    stretch (or ``start``) of ``length`` s (default 30 s), made again from its seed.

    Returns
    -------
    Replay
    """

    case = found.case
    return crossing_replay(case.structure, case.crowd, found.duration, msd=found.msd,
                           force=case.force, sample_rate=found.sample_rate,
                           rng=found.simulation.seed, warm_up=case.simulation.warm_up,
                           start=start,
                           length=DEFAULT_REPLAY_LENGTH if length is None else length,
                           n_on_deck=found.simulation.n_on_deck)


def demo_replay(found):
    """The crossing replay of ``crowdvib demo``'s simulated record (None for ``--spectral``,
    which simulates nothing)."""

    if found.record is None:
        return None
    case = found.case
    return crossing_replay(case.structure, case.crowd, found.duration, msd=case.msd,
                           sample_rate=DEMO_SAMPLE_RATE, rng=found.seed, warm_up=DEMO_WARM_UP,
                           n_on_deck=found.record.n_on_deck)


def check_video_path(path, out):
    """``path`` as the video file to write, refused before any work: a suffix of
    :data:`VIDEO_SUFFIXES`, a folder that exists, and no file there yet (crowdvib does not
    overwrite a file it did not write). A video in the results folder ``out`` is one of its
    results (listed in its manifest, replaced with ``--force`` as they are)."""

    path = Path(path)
    if path.suffix.lower() not in VIDEO_SUFFIXES:
        raise ParameterError(f"--animate {terminal_safe(path)}: the video must be a "
                             f"{' or '.join(VIDEO_SUFFIXES)} file")
    if in_results(path, out):
        return path
    if path.exists() or path.is_symlink():
        raise ParameterError(f"--animate {terminal_safe(path)}: the file exists; crowdvib does "
                             "not overwrite a file it may not have written: move it away or "
                             "name another")
    if not path.parent.is_dir():
        raise ParameterError(f"--animate {terminal_safe(path)}: its folder "
                             f"{terminal_safe(path.parent)} does not exist")
    return path


def in_results(path, out):
    """Whether the video ``path`` lies in the results folder ``out`` itself."""
    return Path(path).resolve().parent == Path(out).resolve()
