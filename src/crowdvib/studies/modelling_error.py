"""Trust in the estimate: estimation errors from modelling errors and from record length.

* :func:`modelling_error_study` re-estimates the MSD parameters with the inputs the method assumes
  known perturbed (structural frequencies ε_f, damping ratios ε_ξ, modal masses ε_m, mean and
  standard deviation of the step frequencies ε_μfs, ε_σfs), individually and jointly, and turns the
  spread into the paper's "nominal ± bound" (paper Figs. 11 and 19).
* :func:`record_length_study` re-estimates on the first k·T seconds of the record.

Studies are lists of independent, deterministic tasks run by
:func:`crowdvib.runner.tasks.run_tasks`, in this process or on an executor (see
:mod:`crowdvib.runner.engine`), each finished task kept under a key made from its content
in a :class:`~crowdvib.runner.tasks.TaskStore`: same inputs, same result, on any executor.
"""

import itertools
import warnings
from dataclasses import dataclass, field, replace

import numpy as np

from .._estimators import PAPER_ERROR_LEVELS
from .._validation import FieldsFromDict, as_float_array, check_mapping, check_positive
from ..errors import BoundWarning, CrowdvibError, ParameterError
from ..identification.estimation import estimate_hsi
from ..identification.estimator import check_estimator
from ..identification.multistart import JOINED
from ..runner.tasks import run_tasks
from ..signals import welch_psd
from .plots import plot_estimation_errors

__all__ = ["ErrorCase", "SensitivityResult", "modelling_error_study", "record_length_study",
           "error_cases", "PAPER_ERROR_LEVELS"]


_STRUCTURE_PARAMETERS = ("frequencies", "damping_ratios", "modal_masses")
_CROWD_PARAMETERS = ("step_frequency_mean", "step_frequency_std")


# ------------------------------------------------------------------------------ error cases
#: The assumed-known inputs a study perturbs, in words (CLI tables, report, figures).
PARAMETER_WORDS = {"frequencies": "structural frequency", "damping_ratios": "structural damping",
                   "modal_masses": "modal mass", "step_frequency_mean": "mean step frequency",
                   "step_frequency_std": "step-frequency spread"}


@dataclass(frozen=True)
class ErrorCase:
    """One perturbation of the assumed-known inputs.

    Attributes
    ----------
    name : str
        Unique label, e.g. ``"frequencies+0.05"`` or ``"joint+-+-+@0.05"``.
    perturbations : tuple of (str, float)
        Parameter → relative error ε (fraction, signed), e.g. (("frequencies", 0.05),).
    level : int
        Index of the error level (0 = lower, 1 = higher).
    kind : str
        ``"individual"``, ``"joint"`` or ``"nominal"``.
    """

    name: str
    perturbations: tuple
    level: int = 0
    kind: str = "individual"

    @property
    def label(self):
        """The case in words, e.g. "structural frequency +5 %", "joint, level 2 (+ − + − +)"."""
        if self.kind == "nominal":
            return "nominal (no modelling error)"
        if self.kind == "joint":
            signs = " ".join("+" if value > 0 else "−" for _, value in self.perturbations)
            return f"joint, level {self.level + 1} ({signs})"
        (name, value), = self.perturbations
        return f"{PARAMETER_WORDS[name]} {'+' if value > 0 else '−'}{100 * abs(value):g} %"

    def apply(self, structure, crowd):
        """The structure and crowd with this case's relative errors applied.

        Parameters
        ----------
        structure : ModalModel
            The nominal structure.
        crowd : Crowd
            The nominal crowd.

        Returns
        -------
        (ModalModel, Crowd)
        """
        changes = dict(self.perturbations)
        structure_changes = {name: getattr(structure, name) * (1 + changes[name])
                             for name in _STRUCTURE_PARAMETERS if name in changes}
        crowd_changes = {name: getattr(crowd, name) * (1 + changes[name])
                         for name in _CROWD_PARAMETERS if name in changes}
        return (structure.replace(**structure_changes) if structure_changes else structure,
                replace(crowd, **crowd_changes) if crowd_changes else crowd)


def error_cases(levels=None, *, joint=True, signs=(+1, -1)):
    """The individual and joint error cases of a study (paper Figs. 5, 6, 11).

    Individual: each parameter at each level and sign. Joint: every parameter at the same level
    with every combination of signs (2⁵ per level), whose worst case is the joint bound.
    """
    check_mapping("levels", levels, "a dict of parameter → error fractions")
    levels = dict(PAPER_ERROR_LEVELS if levels is None else levels)
    for name, values in levels.items():
        if name not in _STRUCTURE_PARAMETERS + _CROWD_PARAMETERS:
            raise ParameterError(
                f"levels keys must be among {list(_STRUCTURE_PARAMETERS + _CROWD_PARAMETERS)}, "
                f"got {name!r}")
        check_positive(f"levels[{name!r}]", values)
    n_levels = {len(np.atleast_1d(v)) for v in levels.values()}
    if len(n_levels) != 1:
        raise ParameterError(f"levels must give the same number of levels per parameter, got {levels}")
    n_levels = n_levels.pop()
    cases = [ErrorCase("nominal", (), 0, "nominal")]
    for index in range(n_levels):
        for name, values in levels.items():
            epsilon = float(np.atleast_1d(values)[index])
            for sign in signs:
                cases.append(ErrorCase(f"{name}{sign * epsilon:+g}", ((name, sign * epsilon),),
                                       index, "individual"))
        if joint:
            names = list(levels)
            for combination in itertools.product((+1, -1), repeat=len(names)):
                label = "".join("+" if s > 0 else "-" for s in combination)
                perturbations = tuple((n, s * float(np.atleast_1d(levels[n])[index]))
                                      for n, s in zip(names, combination))
                cases.append(ErrorCase(f"joint{label}@level{index}", perturbations, index,
                                       "joint"))
    return cases


# ------------------------------------------------------------------------------ study
@dataclass(frozen=True)
class _EstimationTask:
    """Everything one re-estimation needs, in one picklable object.

    ``warm``: starting points θ (every free parameter) in place of the multistart: the optima
    of the nominal estimate's multistart (:func:`_warm_starts`), for a case that differs from
    the nominal by one small perturbation; empty for the estimator's own starts.
    ``warm_cost``: the misfit above which a warm-started fit is not trusted (twice the
    nominal's).
    """

    measured: object
    structure: object
    crowd: object
    case: ErrorCase
    options: tuple
    warm: tuple = ()
    warm_cost: float = float("inf")


def _estimate_task(task):
    structure, crowd = task.case.apply(task.structure, task.crowd)
    # A warm-started case skips the level check: its nominal has passed it on the same record
    # (warm starts exist only then), the case moves the inputs by a few per cent, not by the
    # check's factor 10, and the check's grid of model evaluations was a third of the task
    # (issue 39); a warm-started record length is a part of the record whose whole passed it.
    # Every other task (the nominal, a cold case, the whole record) checks.
    options = dict(task.options, check_level=not task.warm)
    with warnings.catch_warnings():
        # An active bound is reported in the result; a warning per task would only be noise.
        warnings.simplefilter("ignore", BoundWarning)
        # Each task's point estimate is what a study compares; its interval would only cost.
        estimate = None
        if task.warm:
            estimate = estimate_hsi(task.measured, structure, crowd, interval=None,
                                    **dict(options, starts=[list(p) for p in task.warm]))
        if estimate is None or _left_the_basin(estimate, task.warm_cost):
            # No warm start, or one whose fit left the nominal's basin: the estimator's full
            # multistart.
            estimate = estimate_hsi(task.measured, structure, crowd, interval=None, **options)
    return {"frequency": estimate.msd.frequency, "damping_ratio": estimate.msd.damping_ratio,
            "mass_ratio": estimate.msd.mass_ratio, "cost": estimate.cost,
            "relative_cost": estimate.relative_cost, "success": estimate.success,
            "active_bounds": list(estimate.active_bounds), "optima": _optima(estimate)}


#: The one search bound a warm fit may end on at a high misfit without the full multistart:
#: ξ_h1 at its upper bound, f_h1 inside its own (_left_the_basin).
_DAMPED_END = ("damping_ratio:upper",)


def _left_the_basin(estimate, limit):
    """Whether a warm-started fit is not to be trusted (docs: theory, Modelling-error study,
    Warm starts): it did not converge, or it ends at more than ``limit`` (twice the nominal's
    misfit) on a search bound other than the damping ratio's upper bound alone.

    An end on ξ_h1's upper bound alone, f_h1 inside its bounds, is a record whose resonance is
    wider than any MSD within the bounds makes it: there the full multistart's four starts end
    on that bound too (the Eeklo-like case's 17 such cases and the paper example's 8: the same
    f_h1 to 2.5e-4 but one, whose warm fit ends on a second optimum along the bound 0.3 % lower
    in f_h1 at 0.7 % more misfit; issue 39). A warm fit that has left the resonance ends on
    f_h1's bound too (the paper example's structural frequency −5 % case: the corner f_h1 = 10
    Hz, ξ_h1 = 1 at 35 times the misfit the multistart finds inside).
    """
    if not estimate.success:
        return True
    return bool(estimate.active_bounds) and not estimate.cost <= limit and (
        tuple(estimate.active_bounds) != _DAMPED_END)


def _optima(estimate):
    """The distinct ends of an estimate's starts (θ, every free parameter), best first: the
    local optima its multistart found. Two ends within 1e-3 (relative) are one optimum; a
    refit started at another start's end (the likelihood's fit on the fitted crowd's bins) is
    that end's continuation, not an optimum of its own (its start is that end, moved at most
    1e-3 of the bounds inside them); a start stopped in an earlier start's basin (status
    JOINED) ended on its way to that optimum, not at one."""
    rows = [row for row in estimate.starts if row["status"] != JOINED]
    ends = [row["estimate"] for row in rows]
    ends = sorted(((row["cost"], tuple(row["estimate"])) for row in rows
                   if not any(np.allclose(row["start"], end, rtol=2e-3, atol=2e-3)
                              for end in ends)), key=lambda end: end[0])
    distinct = []
    for _, theta in ends:
        if not any(np.allclose(theta, other, rtol=1e-3, atol=1e-6) for other in distinct):
            distinct.append(theta)
    return [list(theta) for theta in distinct]


def _warm_starts(nominal):
    """The warm starts of the cases from the nominal task's result: every local optimum its
    multistart found (docs: theory, Modelling-error study, Warm starts).

    A case differs from the nominal by one small perturbation of the assumed inputs, which moves
    each non-degenerate local optimum a little (continuously in the inputs): the fit started at
    each optimum the nominal multistart found lands in that optimum's continuation, and the best
    of them is the one the full multistart finds (checked against it on the paper's cases in
    tests/studies/test_sensitivity.py). A fit that does not converge falls back to the full
    multistart (:func:`_estimate_task`), and so does one that ends on a search bound with more
    than twice the nominal's misfit, ξ_h1's upper bound alone excepted
    (:func:`_left_the_basin`): the sign that the perturbation was not small for this record (the
    paper example's structural frequency −5 % case: the warm fit slides to the bounds at 35
    times the misfit the multistart finds). Either alone is not: an end inside the bounds at a
    high misfit is the continuation the argument gives (a sharp resonance moved by 5 % misfits
    an hour's record by 50 times, the multistart ends there too), and so is an end on a bound at
    a misfit near the nominal's (issue 39, on the paper's cases: the same estimates to 2e-6, at
    a third of their cost).

    Returns
    -------
    (tuple of tuple, float)
        The warm starts and the misfit above which a warm-started fit is not trusted.
    """
    return (tuple(tuple(float(v) for v in theta) for theta in nominal.get("optima", ())),
            2.0 * nominal["cost"])


#: Keys of every result of :func:`_estimate_task` (a stored one lacking any is computed again).
_ESTIMATE_FIELDS = ("frequency", "damping_ratio", "mass_ratio", "cost", "relative_cost",
                    "success", "active_bounds", "optima")


def _run_warm_started(function, tasks, first, warm_start, *, executor, store, progress, fields):
    """Run a study's tasks (:func:`crowdvib.runner.tasks.run_tasks`), with ``warm_start`` the
    reference task ``tasks[first]`` (the nominal, the whole record) before the others, each
    then given its optima as warm starts (:func:`_warm_starts`): a task's key is its content,
    so a changed reference recomputes them. Name → result."""
    if not warm_start:
        return run_tasks(function, tasks, executor=executor, store=store, progress=progress,
                         fields=fields)
    total, (name, reference) = len(tasks), tasks[first]
    others = tasks[:first] + tasks[first + 1:]
    results = run_tasks(function, [(name, reference)], executor=executor, store=store,
                        progress=None if progress is None
                        else (lambda done, _: progress(done, total)), fields=fields)
    if "error" not in results[name]:
        warm, limit = _warm_starts(results[name])
        others = [(key, replace(task, warm=warm, warm_cost=limit)) for key, task in others]
    results.update(run_tasks(function, others, executor=executor, store=store,
                             progress=None if progress is None
                             else (lambda done, _: progress(done + 1, total)),
                             fields=fields))
    return results


@dataclass(frozen=True, eq=False)
class SensitivityResult(FieldsFromDict):
    """Estimation errors caused by modelling errors (paper Figures 11 and 19).

    Attributes
    ----------
    nominal : dict
        The estimate with the nominal inputs (``frequency``, ``damping_ratio``, ...).
    cases : tuple of dict
        Per error case: ``name``, ``kind``, ``level``, ``perturbations``, the estimate, and
        ``delta_frequency``/``delta_damping_ratio``, the estimation error Δ [%] relative to the
        nominal estimate (or ``error`` if the case failed).
    levels : dict
        The error levels used, parameter → fractions.
    """

    nominal: dict
    cases: tuple
    levels: dict = field(default_factory=dict)

    def bound(self, level=None):
        """Joint bound: the largest |Δ| [%] of the joint cases (all cases if none), per parameter.

        Parameters
        ----------
        level : int, optional
            Error level index (default the highest).
        """
        done = [c for c in self.cases if "error" not in c and c["kind"] != "nominal"]
        if not done:
            return {"frequency": np.nan, "damping_ratio": np.nan}
        level = max(c["level"] for c in done) if level is None else level
        chosen = [c for c in done if c["level"] == level and c["kind"] == "joint"] or \
                 [c for c in done if c["level"] == level]
        return {"frequency": max(abs(c["delta_frequency"]) for c in chosen),
                "damping_ratio": max(abs(c["delta_damping_ratio"]) for c in chosen)}

    def individual_effect(self, parameter, level=None):
        """Largest |Δ| [%] of the individual cases of one parameter, per estimated parameter.

        Parameters
        ----------
        parameter : str
            The perturbed input (a key of ``PAPER_ERROR_LEVELS``).
        level : int, optional
            Error level index (default all levels).
        """
        chosen = [c for c in self.cases if c["kind"] == "individual" and "error" not in c
                  and c["perturbations"][0][0] == parameter
                  and (level is None or c["level"] == level)]
        return {"frequency": max(abs(c["delta_frequency"]) for c in chosen),
                "damping_ratio": max(abs(c["delta_damping_ratio"]) for c in chosen)}

    def summary(self, level=None):
        """The paper's final result: nominal ± joint bound, in units of the parameters.

        Parameters
        ----------
        level : int, optional
            Error level index (default the highest).
        """
        bound = self.bound(level)
        return {name: {"nominal": self.nominal[name],
                       "bound": self.nominal[name] * bound[name] / 100.0,
                       "bound_percent": bound[name]}
                for name in ("frequency", "damping_ratio")}

    def combined(self, estimate, level=None):
        """The statistical interval of ``estimate`` and the modelling bound, together.

        Rule (docs: theory, Statistical uncertainty of an estimate): the statistical interval
        [low, high] of the nominal estimate, widened on each side by the joint modelling bound B:
        [low − B, high + B], kept within the search bounds. The paper's bound is the worst case
        over combinations of input errors, not a standard deviation, so it adds to the interval
        rather than in quadrature.

        Parameters
        ----------
        estimate : HSIEstimate
            The nominal estimate with its interval (``interval="profile"`` or ``"wald"``).
        level : float, optional
            Modelling-error level of the bound (default the highest).

        Returns
        -------
        dict
            Parameter → ``interval`` [low, high], ``bound`` B, ``combined`` [low − B, high + B],
            and ``level`` (confidence level of the statistical interval).
        """
        summary = self.summary(level)
        result = {}
        for name, row in summary.items():
            low, high = estimate.interval(name, estimate.interval_level)
            floor, ceiling = estimate.bounds[name]        # a widened end stays physical
            result[name] = {"interval": [low, high], "bound": row["bound"],
                            "combined": [max(low - row["bound"], floor),
                                         min(high + row["bound"], ceiling)],
                            "level": estimate.interval_level}
        return result

    def plot(self, *, axes=None, title=None):
        """Draw Δ per error case (see :func:`crowdvib.reporting.plotting.plot_estimation_errors`).

        Parameters
        ----------
        axes : sequence of two matplotlib.axes.Axes, optional
            Axes to draw on (default a new figure).
        title : str, optional
            The figure's title.
        """

        return plot_estimation_errors(self, axes=axes, title=title)

    def to_dict(self):
        """JSON-ready dict."""
        return {"nominal": self.nominal, "cases": list(self.cases),
                "levels": {k: list(np.atleast_1d(v)) for k, v in self.levels.items()},
                "summary": self.summary()}


def modelling_error_study(measured, structure, crowd, *, estimator, levels=None, joint=True,
                          executor=None, store=None, progress=None,
                          warm_start=True):
    """Estimation error caused by plausible modelling errors (paper Figures 11 and 19).

    The estimate is repeated with the assumed-known inputs perturbed by ±ε, one parameter at a
    time and all jointly, at each level; Δ = (θ̂_case − θ̂_nominal)/θ̂_nominal [%].

    Parameters
    ----------
    measured, structure, crowd
        As in :func:`crowdvib.estimate_hsi`.
    estimator : Estimator
        The estimator whose point estimate the study repeats
        (:class:`~crowdvib.identification.Estimator`, its ``band`` given; its interval choices
        are not used). Its defaults are :func:`crowdvib.estimate_hsi`'s: the likelihood with
        the fluctuating crowd and the step frequencies fitted, whose ε_μfs and ε_σfs cases then
        only move the fit's start.
    levels : dict, optional
        Parameter → relative error levels (fractions); default the paper's
        ``PAPER_ERROR_LEVELS`` (ε_f 1/5 %, ε_ξ 10/30 %, ε_m 2/5 %, ε_μfs = ε_σfs 2/5 %).
    joint : bool
        Include the joint cases (2⁵ sign combinations per level).
    executor : concurrent.futures.Executor, optional
        Where to run the estimations (default serially in this process).
    store : TaskStore or path, optional
        Where finished tasks are kept under keys made from their inputs; a study given the same
        store resumes, recomputing only the tasks whose inputs changed.
    progress : callable, optional
        ``progress(done, total)``.
    warm_start : bool
        Estimate the nominal case first and start each error case from the optima of its
        multistart instead of the estimator's starts (default; a third of the cost or less,
        the same estimates: docs: theory, Modelling-error study, Warm starts). False: every
        case from the estimator's own starts.

    Returns
    -------
    SensitivityResult

    See Also
    --------
    crowdvib.studies.parametric_study : the same errors over a family of structures.
    crowdvib.studies.record_length_study
    crowdvib.estimate_hsi

    References
    ----------
    K. Van Nimmen and P. Van den Broeck, "Using full-scale observations on footbridges to estimate
    the parameters governing human–structure interaction", *Journal of Bridge Engineering* 28(1),
    2023. The modelling-error study (Figures 11 and 19).

    The theory pages cite them (docs: theory, References).
    """
    options = _task_options(estimator)
    cases = error_cases(levels, joint=joint)
    tasks = [(case.name, _EstimationTask(measured, structure, crowd, case, options))
             for case in cases]
    results = _run_warm_started(_estimate_task, tasks, 0, warm_start, executor=executor,
                                store=store, progress=progress, fields=_ESTIMATE_FIELDS)
    nominal = results["nominal"]
    if "error" in nominal:
        raise CrowdvibError(f"the nominal estimation failed: {nominal['error']}")
    rows = []
    for case in cases:
        row = {"name": case.name, "label": case.label, "kind": case.kind, "level": case.level,
               "perturbations": [list(p) for p in case.perturbations], **results[case.name]}
        if "error" not in row:
            row["delta_frequency"] = 100.0 * (row["frequency"] / nominal["frequency"] - 1.0)
            row["delta_damping_ratio"] = 100.0 * (row["damping_ratio"]
                                                  / nominal["damping_ratio"] - 1.0)
        rows.append(row)
    return SensitivityResult(nominal=nominal, cases=tuple(rows),
                             levels=dict(PAPER_ERROR_LEVELS if levels is None else levels))


def _task_options(estimator):
    """A study's estimator as its tasks hold it: the choices of its point estimate as (name,
    value) pairs (each part of a task's key; a crowd's profile is in the task's crowd)."""
    chosen = check_estimator(estimator).options(point_only=True)
    return tuple((name, tuple(value) if name == "band" else value)
                 for name, value in chosen.items())


# ------------------------------------------------------------------------------ record length
@dataclass(frozen=True)
class _WindowCountTask:
    signals: np.ndarray              # the record's first ``duration`` seconds
    sample_rate: float
    duration: float
    window_length: float
    output_names: tuple
    lowpass: object
    structure: object
    crowd: object
    options: tuple
    warm: tuple = ()                 # as in _EstimationTask: the whole record's optima
    warm_cost: float = float("inf")


def _window_count_task(task):
    measured = welch_psd(task.signals, task.sample_rate,
                         window_length=task.window_length, output_names=task.output_names,
                         lowpass=task.lowpass)
    result = _estimate_task(_EstimationTask(measured, task.structure, task.crowd,
                                            ErrorCase("nominal", ()), task.options,
                                            task.warm, task.warm_cost))
    result["n_windows"] = measured.n_windows
    result["duration"] = task.duration
    return result


def record_length_study(signals, sample_rate, structure, crowd, *, window_length, estimator,
                        durations=None, output_names=None, lowpass=None, executor=None,
                        store=None, progress=None, warm_start=True):
    """Estimation error from PSD convergence: re-estimate on the first k·T seconds of the record.

    The paper does this for Waalse Krook (8 windows of 60 s): the estimate from fewer windows,
    relative to the estimate from the whole record, shows how much the unconverged PSD moves it.

    Parameters
    ----------
    signals : array_like, shape (n_outputs, n_samples)
        Accelerations [m/s²] (already cut, detrended, resampled).
    sample_rate : float
        [Hz].
    structure, crowd
        As in :func:`crowdvib.estimate_hsi`.
    window_length : float
        Welch segment T [s].
    estimator : Estimator
        As in :func:`modelling_error_study`.
    durations : sequence of float, optional
        Record lengths [s] to use; default k·T for up to eight k from 2 to n_T (and the whole
        record).
    output_names : sequence of str, optional
        Channel names (default the structure's outputs).
    lowpass : LowPassFilter, optional
    executor, store, progress
        As in :func:`modelling_error_study`.
    warm_start : bool
        Estimate on the whole record first and start each shorter record's fit from the
        optima of its multistart, with the modelling-error study's fallback to the full
        multistart (default; the same estimates: docs: theory, Modelling-error study, Warm
        starts). False: every record length from the estimator's own starts.

    Returns
    -------
    list of dict
        Per duration: ``duration`` [s], ``n_windows``, the estimate and ``delta_frequency``,
        ``delta_damping_ratio`` [%] relative to the whole record.

    See Also
    --------
    crowdvib.studies.modelling_error_study
    crowdvib.signals.psd_convergence
    """
    signals = np.atleast_2d(as_float_array("signals", signals))
    sample_rate = check_positive("sample_rate", sample_rate, unit="Hz")
    total = signals.shape[1] / sample_rate
    if durations is None:
        # k·T for up to eight window counts k, spaced geometrically from 2 to n_T: all of them
        # for a short record (Waalse Krook: 8 windows), a readable curve for a long one.
        count = int(total // window_length)
        counts = np.unique(np.round(np.geomspace(2, max(count, 2), 8)).astype(int))
        durations = [k * window_length for k in counts if k <= count]
    durations = sorted(set(float(d) for d in durations if d <= total) | {total})
    names = tuple(output_names or structure.output_names)
    settings = _task_options(estimator)
    # Each task holds only the samples it uses: its key then changes only if they do, and no
    # worker is sent the whole record for a short part of it.
    tasks = [(f"duration={d:.6g}",
              _WindowCountTask(signals[:, :int(round(d * sample_rate))], sample_rate, d,
                               window_length, names, lowpass, structure, crowd, settings))
             for d in durations]
    results = _run_warm_started(_window_count_task, tasks, len(tasks) - 1, warm_start,
                                executor=executor, store=store, progress=progress,
                                fields=_ESTIMATE_FIELDS + ("n_windows", "duration"))
    full = results[tasks[-1][0]]
    rows = []
    for key, _ in tasks:
        row = dict(results[key])
        if "error" not in row and "error" not in full:
            row["delta_frequency"] = 100.0 * (row["frequency"] / full["frequency"] - 1.0)
            row["delta_damping_ratio"] = 100.0 * (row["damping_ratio"]
                                                  / full["damping_ratio"] - 1.0)
        rows.append(row)
    return rows
