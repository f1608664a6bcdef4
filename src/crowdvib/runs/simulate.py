"""``crowdvib simulate`` as a call: a simulated record of a case, written in the chosen formats
beside its figures, results.json and report.html."""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING

from ..cases.results import provenance
from .animate import check_video_path, in_results
from .folders import case_inputs, staged_output, write_results
from .lines import Progress, Say, as_case, recorded_warnings, silent
from ..io.casefile import paper_example_case
from ..cases.simulation import simulate_case, simulation_msd
from ..io.records import RECORD_FORMATS, write_record
from ..reporting.plotting import plot_psd_comparison, save_figure
from ..response.time_domain.simulation import kernel_needs_compiling
from ..signals import welch_psd
from ..reporting.video import write_replay_video
from ..reporting.animation import mode_shape_table
from ..reporting.replay_view import replay_table
from .animate import simulation_replay
from .._files import unique_filenames
from ..reporting.plotting import plot_time_history

if TYPE_CHECKING:
    from collections.abc import Sequence

    from ..cases.results import Results
    from ..io.casefile import Case

__all__ = ["run_simulate"]


def run_simulate(case: Case | str | Path | None, out: str | Path, *,
                 duration: float | None = None, sample_rate: float | None = None,
                 seed: int | None = None, formats: Sequence[str] | None = None,
                 hsi: bool | None = None, force: bool = False, say: Say = silent,
                 progress: Progress | None = None, animate: str | Path | None = None,
                 replay_start: float | None = None, replay_length: float | None = None
                 ) -> Results:
    """What ``crowdvib simulate`` does: :func:`~crowdvib.cases.simulate_case`, the record in each
    of ``formats`` (default ``simulation.formats``), its PSD and time histories, results.json and
    report.html in ``out``.

    Parameters
    ----------
    case : Case, str, pathlib.Path or None
        With a ``[simulation]`` table, or its file (read here: the warnings of reading it are
        recorded with the run's); None: the paper's example
        (:func:`~crowdvib.io.paper_example_case`).
    out : str or pathlib.Path
        The results folder (:func:`~crowdvib.runs.staged_output`'s rules).
    duration, sample_rate, seed, hsi
        As :func:`~crowdvib.cases.simulate_case` (default the case's).
    formats : sequence of str, optional
        Record formats among :data:`~crowdvib.io.RECORD_FORMATS` (default
        ``simulation.formats``).
    force : bool
        Replace crowdvib's earlier results in ``out``.
    say : callable, optional
        Called with each line the command prints.
    progress : callable, optional
        ``progress(label, unit, offset)`` → the ``progress(done, total)`` callback of the
        simulation [s of simulated time, counted after the warm-up].
    animate : str or pathlib.Path, optional
        Also write the crossing replay (the report's) as this ``.gif`` (Pillow) or ``.mp4``
        (ffmpeg) video (:func:`~crowdvib.reporting.video.write_replay_video`); refused at
        once if the file exists.
    replay_start, replay_length : float, optional
        The stretch of the record the report (and the video) replays [s]: default the 30 s
        with the most walkers on the deck.

    Returns
    -------
    Results
        As written, with the run's warnings (:func:`~crowdvib.runs.lines.recorded_warnings`:
        each also shown when it happens).
    """

    animate = None if animate is None else check_video_path(animate, out)
    with recorded_warnings() as caught:
        case = paper_example_case() if case is None else as_case(case)
        return _simulate(case, out, duration, sample_rate, seed, formats, hsi, force, say,
                         progress, caught, animate, (replay_start, replay_length))


def _simulate(case, out, duration, sample_rate, seed, formats, hsi, force, say, progress,
              caught, animate=None, stretch=(None, None)):
    spec = case.simulation
    formats = spec.formats if formats is None else formats
    duration = spec.duration if duration is None else duration
    sample_rate = spec.sample_rate if sample_rate is None else sample_rate
    hsi = spec.hsi if hsi is None else hsi
    msd = simulation_msd(case) if hsi else None
    pedestrians = ("moving forces only (no HSI)" if msd is None else
                   f"MSD pedestrians f_h1 = {msd.frequency:g} Hz, ξ_h1 = {msd.damping_ratio:g}, "
                   f"μ_h1 = {msd.mass_ratio:g}")
    say(f"crowdvib simulate: {case.name}, {duration:g} s at {sample_rate:g} Hz, {pedestrians}")
    with staged_output(out, force, command="simulate", inputs=case_inputs(case)) as staging:
        started = time.perf_counter()
        if kernel_needs_compiling(case.structure, hsi):
            say(COMPILING)
        found = simulate_case(
            case, duration=duration, sample_rate=sample_rate, seed=seed, hsi=hsi,
            progress=None if progress is None else progress(
                f"simulated (after {spec.warm_up:g} s warm-up)", "s", spec.warm_up))
        simulation, record = found.simulation, found.record
        files = []
        for fmt in formats:
            suffix = "_v73.mat" if fmt == "mat73" else RECORD_FORMATS[fmt][0]
            files.append(write_record(record, staging / f"record{suffix}", format=fmt,
                                      dtype=spec.dtype).name)
        elapsed = time.perf_counter() - started
        window = min(case.measurement.window_length, record.duration)
        psd = welch_psd(record.data, record.sample_rate, window_length=window,
                        output_names=record.channel_names)
        # Every output on the PSD figure, named; one time history per output.
        figures = [save_figure(plot_psd_comparison(
            {name: psd.select(name) for name in psd.output_names},
            band=(0.0, min(record.sample_rate / 2, 12.0)),
            title=f"{case.name}: simulated record (Welch PSD)"), staging / "psd.png").name]
        figures += _time_histories(case, simulation, staging)
        results = found.to_dict()
        results["record"]["files"] = files
        replay = _replay(found, results, *stretch)
        results.update({"elapsed_s": elapsed, "figures": figures, **provenance(case.path),
                        "warnings": list(caught)})
        written = write_results(staging, results)
        if animate is not None and in_results(animate, out):     # one of the results
            _video(replay, case, staging / animate.name, animate, say)
    say(f"  wrote {', '.join(files)} and results.json to {out} ({elapsed:.1f} s)")
    if animate is not None and not in_results(animate, out):
        _video(replay, case, animate, animate, say)
    return written


def _video(replay, case, path, shown, say):
    """The replay as the video ``path`` (``shown`` in the line said)."""

    started = time.perf_counter()
    count = write_replay_video(replay, case.structure, path)
    say(f"  wrote the crossing replay to {shown} ({count} frames, "
        f"{time.perf_counter() - started:.1f} s)")


def _replay(found, results, start, length):
    """The modal model's shapes and the crossing replay of ``length`` s from ``start`` (default
    the busiest 30 s) into ``results`` (issue 38); the replay returned, for a video."""

    replay = simulation_replay(found, start=start, length=length)
    results["mode_shapes"] = mode_shape_table(found.case.structure,
                                              found.case.stationary_crowd(), found.msd)
    results["replay"] = replay_table(replay, found.case.structure, busiest=start is None)
    return replay


#: Said when the simulation kernel is about to be compiled: numba caches the compiled kernel
#: beside its source, one per kind of run (with or without HSI, one or several modes, station
#: grid); the first run of a kind compiles for a while, which must not look like a hang.
COMPILING = "  compiling the simulation kernel (first run of this kind only, some 10–30 s) …"


def _time_histories(case, simulation, staging):
    names = unique_filenames(simulation.output_names, prefix="time_history_", suffix=".png",
                             taken=("psd.png",))
    return [save_figure(plot_time_history(simulation, output=name,
                                          title=f"{case.name}: simulated time history at {name}"),
                        staging / names[name]).name for name in simulation.output_names]
