"""``crowdvib demo`` as a call: the paper's numerical example, truth against estimate, written
as a results folder."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ..cases.results import provenance
from ..reporting.text import interval_of
from .folders import check_output, staged_output, write_results
from .lines import Progress, Say, silent
from ..cases.demo import DEMO_ESTIMATORS, DEMO_SAMPLE_RATE, DEMO_WARM_UP, demo_case, require_demo_duration
from ..models.examples import paper_example
from ..response.time_domain.simulation import kernel_needs_compiling
from .simulate import COMPILING
from ..reporting.animation import mode_shape_table
from ..reporting.replay_view import replay_table
from .animate import demo_replay
from ..reporting.plotting import plot_psd_comparison, save_figure

if TYPE_CHECKING:
    from ..cases.results import Results

__all__ = ["run_demo"]


def run_demo(out: str | Path = "crowdvib-demo", *, duration: float = 3600.0,
             seed: int = 20230101, spectral: bool = False, force: bool = False,
             say: Say = silent, progress: Progress | None = None) -> Results:
    """What ``crowdvib demo`` does: :func:`~crowdvib.cases.demo_case`, its figure, results.json
    and report.html in ``out``.

    Parameters
    ----------
    out : str or pathlib.Path
        The results folder (:func:`~crowdvib.runs.staged_output`'s rules).
    duration, seed, spectral
        As :func:`~crowdvib.cases.demo_case`.
    force : bool
        Replace crowdvib's earlier results in ``out``.
    say : callable, optional
        Called with each line the command prints.
    progress : callable, optional
        ``progress(label, unit, offset)`` → the ``progress(done, total)`` callback of the
        simulation [s of simulated time, counted after the warm-up].

    Returns
    -------
    Results
    """

    case = paper_example()
    require_demo_duration(duration, case.window_length)
    check_output(out, force=force, command="demo")   # refuse before the work
    structure, crowd, truth, window = case.structure, case.crowd, case.msd, case.window_length
    say("crowdvib demo: the numerical example of Van Nimmen & Van den Broeck (2023)")
    say(f"  bridge  {structure.name}: f1 = {structure.frequencies[0]:g} Hz, "
        f"ξ1 = {structure.damping_ratios[0]:.1%}, m1 = {structure.modal_masses[0]:.3g} kg")
    say(f"  crowd   {crowd.density:g} persons/m² ({crowd.density * structure.area:.0f} on deck), "
        f"v = {crowd.walking_speed:.2f} m/s, f_s ~ N({crowd.step_frequency_mean:.2f}, "
        f"{crowd.step_frequency_std:.3f}) Hz, {crowd.body_mass:g} kg")
    say(f"  truth   MSD f_h1 = {truth.frequency:g} Hz, ξ_h1 = {truth.damping_ratio:g}, "
        f"μ_h1 = {truth.mass_ratio:g}")
    if not spectral and kernel_needs_compiling(structure, truth is not None):
        say(COMPILING)
    found = demo_case(duration=duration, seed=seed, spectral=spectral,
                      progress=None if progress is None else progress(
                          f"simulated (after {DEMO_WARM_UP:g} s warm-up)", "s", DEMO_WARM_UP))
    if spectral:
        say(f"  'measured' PSD: spectral model with HSI as a Welch estimate of a "
            f"{duration:g} s record (T = {window:g} s, {found.n_windows} windows, seeded "
            "scatter)")
    else:
        say(f"  'measured' record: time-domain simulation with moving MSD pedestrians, "
            f"{duration:g} s at {DEMO_SAMPLE_RATE:g} Hz ({found.record.n_pedestrians} "
            f"pedestrians, {found.seconds['record']:.1f} s wall); low-pass 10 Hz, Welch T = "
            f"{window:g} s, {found.n_windows} windows")
    for name, title, _ in DEMO_ESTIMATORS:
        estimate = found.estimates[name]
        say(f"\n  {title}: {len(estimate.starts)} fits, {estimate.n_evaluations} model "
            f"evaluations, {found.seconds[name]:.2f} s")
        _say_estimate(estimate, truth, say)
    occupied = found.occupied
    say(f"  occupied structure: {occupied.frequencies[0]:.3f} Hz, "
        f"{occupied.damping_ratios[0]:.2%} damping (empty: {structure.frequencies[0]:g} Hz, "
        f"{structure.damping_ratios[0]:.2%})")
    with staged_output(out, force, command="demo") as staging:
        written = write_results(staging, {**found.to_dict(),
                                          "figures": [_figure(found, spectral, staging)],
                                          **_moving(found), **provenance()})
    say(f"\n  wrote {Path(out) / 'results.json'} and {Path(out) / 'psd_fit.png'}")
    say(f"  report: {Path(out) / 'report.html'}")
    return written


def _say_estimate(estimate, truth, say):
    """Truth, estimate, error and interval of f_h1 and ξ_h1, and the misfit."""
    summary = estimate.to_dict()["estimate"]
    level = f"{100 * estimate.interval_level:g} % interval"
    say(f"  {'':14s}{'truth':>10s}{'estimate':>11s}{'error':>9s}   {level}")
    for label, key in (("f_h1 [Hz]", "frequency"), ("ξ_h1 [-]", "damping_ratio")):
        t, e, ends = getattr(truth, key), getattr(estimate.msd, key), interval_of(summary, key)
        inside = ("" if ends is None else
                  "   truth inside" if ends[0] <= t <= ends[1] else "   truth outside")
        say(f"  {label:14s}{t:10.3f}{e:11.3f}{(e - t) / t:+9.1%}   "
            + ("—" if ends is None else f"{ends[0]:.3f}–{ends[1]:.3f}") + inside)
    if estimate.density_share:
        say(f"  the interval carries a crowd density known to ±{estimate.density_uncertainty:.0%} "
            f"(the default density_uncertainty): {estimate.density_share['damping_ratio']:.0%} "
            "of ξ_h1's variance; this simulated density is exact, density_uncertainty=0 "
            "would give the record's scatter alone")
    misfit = "deviance D" if estimate.method == "likelihood" else "J (paper Eq. 6)"
    say(f"  misfit {misfit} = {estimate.cost:.3g}, relative to no HSI "
        f"{estimate.relative_cost:.3g}")


def _moving(found):
    """The modal model's shapes and, for a simulated record, the crossing replay (issue 38)."""

    structure = found.case.structure
    replay = demo_replay(found)
    return {"mode_shapes": mode_shape_table(structure),
            **({} if replay is None else {"replay": replay_table(replay, structure)})}


def _figure(found, spectral, out):
    """The measured PSD against each estimate's and the no-HSI model: psd_fit.png."""

    label = "measured (synthetic)" if spectral else "measured (simulated)"
    ax = plot_psd_comparison({label: found.measured, **found.model_psds()},
                             band=found.case.band, analysis_band=found.case.band,
                             title="Paper example: midspan acceleration PSD")
    return save_figure(ax, out / "psd_fit.png").name
