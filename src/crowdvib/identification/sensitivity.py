"""Trust in the estimate: objective landscape and modelling-error studies (paper Figs. 4–6, 10, 11).

* :func:`objective_map` evaluates J(f_h1, ξ_h1) of paper Eq. (6) on a grid.
* :func:`modelling_error_study` re-estimates the MSD parameters with the inputs the method assumes
  known perturbed (structural frequencies ε_f, damping ratios ε_ξ, modal masses ε_m, mean and
  standard deviation of the step frequencies ε_μfs, ε_σfs), individually and jointly, and turns the
  spread into the paper's "nominal ± bound".
* :func:`parametric_study` repeats the paper's study of Figs. 5 and 6 over a family of structures.

Studies are lists of independent tasks run by :func:`crowdvib.identification.tasks.run_tasks` on any
``concurrent.futures.Executor`` (a local process pool, or a dask.distributed cluster through
``Client.get_executor()``), each finished task kept in a :class:`~crowdvib.identification.tasks.TaskStore`. The
tasks are deterministic: same inputs, same result, on any executor.
"""

import itertools
from dataclasses import dataclass, field, replace

import numpy as np

from .._validation import as_float_array, check_positive
from ..errors import CrowdvibError, ParameterError
from ..models.pedestrian import MSDModel
from .estimation import PSDObjective, estimate_hsi
from .tasks import TaskStore, run_tasks

__all__ = ["ObjectiveMap", "objective_map", "ErrorCase", "SensitivityResult",
           "modelling_error_study", "parametric_study", "TaskStore", "run_tasks",
           "record_length_study", "PAPER_ERROR_LEVELS"]


#: Modelling-error levels of the Eeklo and Waalse Krook studies (paper; physics.md §8.6):
#: parameter → (lower level, higher level), as fractions.
PAPER_ERROR_LEVELS = {"frequencies": (0.01, 0.05), "damping_ratios": (0.10, 0.30),
                      "modal_masses": (0.02, 0.05), "step_frequency_mean": (0.02, 0.05),
                      "step_frequency_std": (0.02, 0.05)}
#: Levels of the parametric study (paper Figs. 5 and 6).
PARAMETRIC_ERROR_LEVELS = {"frequencies": (0.01, 0.02), "damping_ratios": (0.10, 0.30),
                           "modal_masses": (0.02, 0.05), "step_frequency_mean": (0.01, 0.025),
                           "step_frequency_std": (0.01, 0.025)}
_STRUCTURE_PARAMETERS = ("frequencies", "damping_ratios", "modal_masses")
_CROWD_PARAMETERS = ("step_frequency_mean", "step_frequency_std")


# ------------------------------------------------------------------------------ objective map
@dataclass(frozen=True, eq=False)
class ObjectiveMap:
    """J(f_h1, ξ_h1) on a grid (paper Figs. 4 and 10).

    Attributes
    ----------
    frequencies : ndarray, shape (n_f,)
        Grid of f_h1 [Hz].
    damping_ratios : ndarray, shape (n_ξ,)
        Grid of ξ_h1 [-].
    cost : ndarray, shape (n_ξ, n_f)
        Objective J of paper Eq. (6) [-].
    cost_no_hsi : float
        J without HSI [-].
    mass_ratio : float
        μ_h1 held fixed [-].
    estimate : MSDModel or None
        The optimiser's solution, when one was given, to mark on the map.
    """

    frequencies: np.ndarray
    damping_ratios: np.ndarray
    cost: np.ndarray
    cost_no_hsi: float
    mass_ratio: float
    estimate: object = None

    @property
    def optimum(self):
        """Grid point of least cost as an :class:`MSDModel`."""
        row, col = np.unravel_index(np.argmin(self.cost), self.cost.shape)
        return MSDModel(float(self.frequencies[col]), float(self.damping_ratios[row]),
                        self.mass_ratio)

    def curvature_ratio(self):
        """How much steeper J is along f_h1 than along ξ_h1 around the grid optimum [-].

        Second differences of J over the relative parameter change, ∂²J/∂(ln f)² divided by
        ∂²J/∂(ln ξ)², at the grid minimum (interior grid points only).
        """
        row, col = np.unravel_index(np.argmin(self.cost), self.cost.shape)
        row = int(np.clip(row, 1, self.damping_ratios.size - 2))
        col = int(np.clip(col, 1, self.frequencies.size - 2))

        def second(values, grid, i):
            x = np.log(grid[i - 1:i + 2])
            return np.polyfit(x, values[i - 1:i + 2], 2)[0] * 2

        along_f = second(self.cost[row], self.frequencies, col)
        along_xi = second(self.cost[:, col], self.damping_ratios, row)
        return along_f / along_xi

    def plot(self, *, uncertainty=None, search_bounds=None, ax=None, title=None):
        """Draw the map with its optimum (see :func:`crowdvib.reporting.plotting.plot_objective_map`)."""
        from ..reporting.plotting import plot_objective_map

        return plot_objective_map(self, uncertainty=uncertainty, search_bounds=search_bounds,
                                  ax=ax, title=title)

    def to_dict(self):
        """JSON-ready dict."""
        optimum = self.optimum
        return {"frequencies": self.frequencies.tolist(),
                "damping_ratios": self.damping_ratios.tolist(), "cost": self.cost.tolist(),
                "cost_no_hsi": self.cost_no_hsi, "mass_ratio": self.mass_ratio,
                "grid_optimum": optimum.to_dict(),
                "estimate": None if self.estimate is None else self.estimate.to_dict()}


def objective_map(measured, structure, crowd, *, frequencies, damping_ratios, band,
                  outputs=None, output_weights=None, frequency_weights=None, mass_ratio=0.95,
                  force=None, match_welch=True, estimate=None):
    """Objective J(f_h1, ξ_h1) of paper Eq. (6) on a grid → :class:`ObjectiveMap`.

    The forward model's θ-independent parts are built once (:class:`~crowdvib.response.spectral.SpectralModel`),
    so each grid point costs one PSD evaluation vectorised over frequency.

    Parameters
    ----------
    measured, structure, crowd, band, outputs, output_weights, frequency_weights, force, match_welch
        As in :func:`crowdvib.estimate_hsi`.
    frequencies : array_like
        Grid of f_h1 [Hz], > 0 (the paper: 1–6 Hz).
    damping_ratios : array_like
        Grid of ξ_h1 [-], fractions (the paper: 0.1–0.8).
    mass_ratio : float
        μ_h1 held fixed.
    estimate : MSDModel or HSIEstimate, optional
        An optimiser's solution to carry along and mark on plots.
    """
    frequencies = check_positive("frequencies", as_float_array("frequencies", frequencies, ndim=1),
                                 unit="Hz")
    damping_ratios = as_float_array("damping_ratios", damping_ratios, ndim=1)
    for value in damping_ratios:
        MSDModel(damping_ratio=value)          # validates each ξ with the model's own rule
    objective = PSDObjective(measured, structure, crowd, band=band, force=force, outputs=outputs,
                             output_weights=output_weights, frequency_weights=frequency_weights,
                             match_welch=match_welch)
    cost = np.array([[objective.cost(MSDModel(f, xi, mass_ratio)) for f in frequencies]
                     for xi in damping_ratios])
    if estimate is not None and not isinstance(estimate, MSDModel):
        estimate = estimate.msd
    return ObjectiveMap(frequencies=frequencies, damping_ratios=damping_ratios, cost=cost,
                        cost_no_hsi=objective.cost(None), mass_ratio=mass_ratio,
                        estimate=estimate)


# ------------------------------------------------------------------------------ error cases
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

    def apply(self, structure, crowd):
        """The structure and crowd with this case's relative errors applied."""
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
    """Everything one re-estimation needs, in one picklable object."""

    measured: object
    structure: object
    crowd: object
    case: ErrorCase
    options: tuple


def _estimate_task(task):
    structure, crowd = task.case.apply(task.structure, task.crowd)
    import warnings

    from ..errors import BoundWarning

    with warnings.catch_warnings():
        # An active bound is reported in the result; a warning per task would only be noise.
        warnings.simplefilter("ignore", BoundWarning)
        estimate = estimate_hsi(task.measured, structure, crowd, **dict(task.options))
    return {"frequency": estimate.msd.frequency, "damping_ratio": estimate.msd.damping_ratio,
            "mass_ratio": estimate.msd.mass_ratio, "cost": estimate.cost,
            "relative_cost": estimate.relative_cost, "success": estimate.success,
            "active_bounds": list(estimate.active_bounds)}


@dataclass(frozen=True, eq=False)
class SensitivityResult:
    """Estimation errors caused by modelling errors (paper Figs. 11 and 19).

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
        """Largest |Δ| [%] of the individual cases of one parameter, per estimated parameter."""
        chosen = [c for c in self.cases if c["kind"] == "individual" and "error" not in c
                  and c["perturbations"][0][0] == parameter
                  and (level is None or c["level"] == level)]
        return {"frequency": max(abs(c["delta_frequency"]) for c in chosen),
                "damping_ratio": max(abs(c["delta_damping_ratio"]) for c in chosen)}

    def summary(self, level=None):
        """The paper's final result: nominal ± joint bound, in units of the parameters."""
        bound = self.bound(level)
        return {name: {"nominal": self.nominal[name],
                       "bound": self.nominal[name] * bound[name] / 100.0,
                       "bound_percent": bound[name]}
                for name in ("frequency", "damping_ratio")}

    def plot(self, *, axes=None, title=None):
        """Draw Δ per error case (see :func:`crowdvib.reporting.plotting.plot_estimation_errors`)."""
        from ..reporting.plotting import plot_estimation_errors

        return plot_estimation_errors(self, axes=axes, title=title)

    def to_dict(self):
        """JSON-ready dict."""
        return {"nominal": self.nominal, "cases": list(self.cases),
                "levels": {k: list(np.atleast_1d(v)) for k, v in self.levels.items()},
                "summary": self.summary()}


def modelling_error_study(measured, structure, crowd, *, band, levels=None, joint=True,
                          executor=None, store=None, progress=None, outputs=None,
                          output_weights=None, frequency_weights=None, starts=None, bounds=None,
                          mass_ratio=0.95, force=None, match_welch=True):
    """Estimation error caused by plausible modelling errors (paper Figs. 11 and 19).

    The estimate is repeated with the assumed-known inputs perturbed by ±ε, one parameter at a
    time and all jointly, at each level; Δ = (θ̂_case − θ̂_nominal)/θ̂_nominal [%].

    Parameters
    ----------
    measured, structure, crowd, band
        As in :func:`crowdvib.estimate_hsi`.
    levels : dict, optional
        Parameter → relative error levels (fractions); default the paper's
        ``PAPER_ERROR_LEVELS`` (ε_f 1/5 %, ε_ξ 10/30 %, ε_m 2/5 %, ε_μfs = ε_σfs 2/5 %).
    joint : bool
        Include the joint cases (2⁵ sign combinations per level).
    executor : concurrent.futures.Executor, optional
        Where to run the estimations (default serially in this process).
    store : TaskStore or path, optional
        Where finished tasks are kept; a study given the same store resumes.
    progress : callable, optional
        ``progress(done, total)``.
    outputs, output_weights, frequency_weights, starts, bounds, mass_ratio, force, match_welch
        Passed to :func:`crowdvib.estimate_hsi`.

    Returns
    -------
    SensitivityResult
    """
    options = (("band", tuple(band)), ("outputs", outputs), ("output_weights", output_weights),
               ("frequency_weights", frequency_weights), ("starts", starts), ("bounds", bounds),
               ("mass_ratio", mass_ratio), ("force", force), ("match_welch", match_welch))
    cases = error_cases(levels, joint=joint)
    if store is not None and not isinstance(store, TaskStore):
        store = TaskStore(store)
    tasks = [(case.name, _EstimationTask(measured, structure, crowd, case, options))
             for case in cases]
    results = run_tasks(_estimate_task, tasks, executor=executor, store=store, progress=progress)
    nominal = results["nominal"]
    if "error" in nominal:
        raise CrowdvibError(f"the nominal estimation failed: {nominal['error']}")
    rows = []
    for case in cases:
        row = {"name": case.name, "kind": case.kind, "level": case.level,
               "perturbations": [list(p) for p in case.perturbations], **results[case.name]}
        if "error" not in row:
            row["delta_frequency"] = 100.0 * (row["frequency"] / nominal["frequency"] - 1.0)
            row["delta_damping_ratio"] = 100.0 * (row["damping_ratio"]
                                                  / nominal["damping_ratio"] - 1.0)
        rows.append(row)
    return SensitivityResult(nominal=nominal, cases=tuple(rows),
                             levels=dict(PAPER_ERROR_LEVELS if levels is None else levels))


# ------------------------------------------------------------------------------ parametric study
@dataclass(frozen=True)
class _ParametricTask:
    structure_frequency: float
    structure_damping: float
    mass_ratio: float
    case: ErrorCase
    truth: MSDModel
    crowd: object


def _paper_family_structure(frequency, damping_ratio, mass_ratio, crowd):
    """The paper example's 50 m × 3 m beam with f_1, ξ_1 and a modal mass giving μ_m (Figs. 5–6)."""
    from ..models.structure import ModalModel

    reference = ModalModel.simply_supported_beam(50.0, 3.0, frequency, damping_ratio, 1.0)
    psi = reference.influence_matrix(crowd.density)[0, 0]
    return reference.replace(modal_masses=[crowd.body_mass * psi / mass_ratio])


def _parametric_task(task):
    from ..response.spectral import response_psd

    structure = _paper_family_structure(task.structure_frequency, task.structure_damping,
                                        task.mass_ratio, task.crowd)
    grid = np.arange(0, 601) / 60.0
    measured = response_psd(structure, task.crowd, grid, msd=task.truth)
    result = _estimate_task(_EstimationTask(measured, structure, task.crowd, task.case,
                                            (("band", (0.0, 10.0)),)))
    result["frequency_ratio"] = result["frequency"] / task.truth.frequency
    result["damping_ratio_ratio"] = result["damping_ratio"] / task.truth.damping_ratio
    return result


@dataclass(frozen=True, eq=False)
class ParametricResult:
    """Ratio estimated/true of f_h1 and ξ_h1 across a family of structures (paper Figs. 5, 6).

    Attributes
    ----------
    rows : tuple of dict
        One per structure and error case: ``structure_frequency`` [Hz], ``structure_damping`` [-],
        ``structure_mass_ratio`` μ_m [-], ``parameter``, ``epsilon``, ``level``, the estimate
        (``frequency``, ``damping_ratio``, ``mass_ratio`` μ_h1), ``frequency_ratio``,
        ``damping_ratio_ratio``, ``active_bounds`` (or ``error``).
    truth : dict
        The MSD parameters the "measurements" were made with.
    """

    rows: tuple
    truth: dict

    def select(self, **criteria):
        """Rows matching every ``key=value`` given."""
        return [r for r in self.rows if all(np.isclose(r[k], v) if isinstance(v, float)
                                            else r[k] == v for k, v in criteria.items())]

    def plot(self, *, parameters=None, axes=None, title=None):
        """Draw estimated/true ratios (see :func:`crowdvib.reporting.plotting.plot_parametric_ratios`)."""
        from ..reporting.plotting import plot_parametric_ratios

        return plot_parametric_ratios(self, parameters=parameters, axes=axes, title=title)

    def to_dict(self):
        """JSON-ready dict."""
        return {"truth": self.truth, "rows": list(self.rows)}


def parametric_study(*, structure_frequencies=None, structure_damping_ratios=(0.005, 0.02),
                     mass_ratios=(0.025, 0.05, 0.10), msd=None, crowd=None, levels=None,
                     executor=None, store=None, progress=None):
    """The paper's parametric study of modelling errors (Figs. 5 and 6).

    For each structure of the family (the paper example's beam with f_1 = 1…6 Hz in 0.5 Hz steps,
    ξ_1 ∈ {0.5, 2.0} %, crowd-to-structure mass ratio μ_m ∈ {2.5, 5, 10} %), a noise-free PSD is
    made with the true MSD and re-estimated with one input perturbed by +ε at each level
    (ε_f 1/2 %, ε_ξ 10/30 %, ε_m 2/5 %, ε_μfs = ε_σfs 1/2.5 %): 66 structures × 10 cases.

    Parameters
    ----------
    structure_frequencies : array_like, optional
        f_1 [Hz]; default 1.0, 1.5, …, 6.0.
    structure_damping_ratios : sequence of float
        ξ_1 [-].
    mass_ratios : sequence of float
        μ_m [-].
    msd : MSDModel, optional
        The truth (default 3.0 Hz, 0.30, 0.95).
    crowd : Crowd, optional
        Default: the paper example's crowd (0.5 p/m², 1.30 m/s, N(1.89, 0.175) Hz, 70 kg).
    levels : dict, optional
        Default ``PARAMETRIC_ERROR_LEVELS``.
    executor, store, progress
        As in :func:`modelling_error_study`.

    Returns
    -------
    ParametricResult
    """
    from ..models.examples import paper_example

    example = paper_example()
    msd = example.msd if msd is None else msd
    crowd = example.crowd if crowd is None else crowd
    frequencies = (np.arange(1.0, 6.01, 0.5) if structure_frequencies is None
                   else check_positive("structure_frequencies",
                                       np.atleast_1d(structure_frequencies), unit="Hz"))
    cases = [c for c in error_cases(PARAMETRIC_ERROR_LEVELS if levels is None else levels,
                                    joint=False, signs=(+1,)) if c.kind == "individual"]
    tasks = []
    for f1, xi1, mu in itertools.product(frequencies, structure_damping_ratios, mass_ratios):
        for case in cases:
            key = f"f1={f1:g}|xi1={xi1:g}|mu={mu:g}|{case.name}"
            tasks.append((key, _ParametricTask(float(f1), float(xi1), float(mu), case, msd, crowd)))
    results = run_tasks(_parametric_task, tasks, executor=executor,
                        store=store if store is None or isinstance(store, TaskStore)
                        else TaskStore(store), progress=progress)
    rows = []
    for key, task in tasks:
        (parameter, epsilon), = task.case.perturbations
        rows.append({"structure_frequency": task.structure_frequency,
                     "structure_damping": task.structure_damping,
                     "structure_mass_ratio": task.mass_ratio,
                     "parameter": parameter, "epsilon": epsilon, "level": task.case.level,
                     **results[key]})
    return ParametricResult(rows=tuple(rows), truth=msd.to_dict())


# ------------------------------------------------------------------------------ record length
@dataclass(frozen=True)
class _WindowCountTask:
    signals: np.ndarray
    sample_rate: float
    duration: float
    window_length: float
    output_names: tuple
    lowpass: object
    structure: object
    crowd: object
    options: tuple


def _window_count_task(task):
    from ..signals import welch_psd

    samples = int(round(task.duration * task.sample_rate))
    measured = welch_psd(task.signals[:, :samples], task.sample_rate,
                         window_length=task.window_length, output_names=task.output_names,
                         lowpass=task.lowpass)
    result = _estimate_task(_EstimationTask(measured, task.structure, task.crowd,
                                            ErrorCase("nominal", ()), task.options))
    result["n_windows"] = measured.n_windows
    result["duration"] = task.duration
    return result


def record_length_study(signals, sample_rate, structure, crowd, *, window_length, band,
                        durations=None, output_names=None, lowpass=None, executor=None,
                        store=None, progress=None, **options):
    """Estimation error from PSD convergence: re-estimate on the first k·T seconds of the record.

    The paper does this for Waalse Krook (8 windows of 60 s): the estimate from fewer windows,
    relative to the estimate from the whole record, shows how much the unconverged PSD moves it.

    Parameters
    ----------
    signals : array_like, shape (n_outputs, n_samples)
        Accelerations [m/s²] (already cut, detrended, resampled).
    sample_rate : float
        [Hz].
    structure, crowd, band
        As in :func:`crowdvib.estimate_hsi`.
    window_length : float
        Welch segment T [s].
    durations : sequence of float, optional
        Record lengths [s] to use; default k·T for up to eight k from 2 to n_T (and the whole
        record).
    output_names : sequence of str, optional
        Channel names (default the structure's outputs).
    lowpass : LowPassFilter, optional
    executor, store, progress
        As in :func:`modelling_error_study`.
    **options
        Further keyword arguments of :func:`crowdvib.estimate_hsi` (outputs, output_weights,
        starts, bounds, mass_ratio).

    Returns
    -------
    list of dict
        Per duration: ``duration`` [s], ``n_windows``, the estimate and ``delta_frequency``,
        ``delta_damping_ratio`` [%] relative to the whole record.
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
    settings = (("band", tuple(band)),) + tuple(sorted(options.items()))
    tasks = [(f"duration={d:.6g}", _WindowCountTask(signals, sample_rate, d, window_length,
                                                     names, lowpass, structure, crowd, settings))
             for d in durations]
    if store is not None and not isinstance(store, TaskStore):
        store = TaskStore(store)
    results = run_tasks(_window_count_task, tasks, executor=executor, store=store,
                        progress=progress)
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
