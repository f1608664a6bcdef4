"""The paper's parametric study of modelling errors over a family of structures (Figs. 5 and 6)."""

import itertools
from dataclasses import dataclass

import numpy as np

from .._plausibility import derived
from .._validation import FieldsFromDict, check_positive
from ..models.pedestrian import MSDModel
from .modelling_error import ErrorCase, _EstimationTask, _estimate_task, error_cases
from ..runner.tasks import run_tasks
from ..models.structure import ModalModel
from ..response.frequency_domain.fluctuation import response_psd
from ..models.examples import paper_example
from .plots import plot_parametric_ratios

__all__ = ["ParametricResult", "parametric_study", "PARAMETRIC_ERROR_LEVELS"]

#: Levels of the parametric study (paper Figs. 5 and 6).
PARAMETRIC_ERROR_LEVELS = {"frequencies": (0.01, 0.02), "damping_ratios": (0.10, 0.30),
                           "modal_masses": (0.02, 0.05), "step_frequency_mean": (0.01, 0.025),
                           "step_frequency_std": (0.01, 0.025)}


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

    with derived():        # a scaffold of 1 kg, rescaled below to the family's modal mass
        reference = ModalModel.simply_supported_beam(50.0, 3.0, frequency, damping_ratio, 1.0)
    psi = reference.influence_matrix(crowd.density)[0, 0]
    return reference.replace(modal_masses=[crowd.body_mass * psi / mass_ratio])


def _parametric_task(task):
    structure = _paper_family_structure(task.structure_frequency, task.structure_damping,
                                        task.mass_ratio, task.crowd)
    grid = np.arange(0, 601) / 60.0
    measured = response_psd(structure, task.crowd, grid, msd=task.truth, crowd_model="smeared")
    # The paper's study, with the paper's estimator (normalised least squares, Eq. 6).
    result = _estimate_task(_EstimationTask(measured, structure, task.crowd, task.case,
                                            (("band", (0.0, 10.0)),
                                             ("method", "least_squares"))))
    result["frequency_ratio"] = result["frequency"] / task.truth.frequency
    result["damping_ratio_ratio"] = result["damping_ratio"] / task.truth.damping_ratio
    return result


@dataclass(frozen=True, eq=False)
class ParametricResult(FieldsFromDict):
    """Ratio estimated/true of f_h1 and ξ_h1 across a family of structures (paper Figures 5 and 6).

    Attributes
    ----------
    rows : tuple of dict
        One per structure and error case: ``structure_frequency`` [Hz], ``structure_damping`` [-],
        ``structure_mass_ratio`` μ_m [-], ``parameter``, ``epsilon`` (|ε|), ``level``,
        ``frequency_ratio`` and ``damping_ratio_ratio`` (each the worse of +ε and −ε, the one
        farther from 1), ``active_bounds`` of either, and ``signs``: the estimate for each sign
        (``"+"``, ``"−"``); or ``error``.
    truth : dict
        The MSD parameters the "measurements" were made with.
    """

    rows: tuple
    truth: dict

    def select(self, **criteria):
        """Rows matching every ``key=value`` given.

        Parameters
        ----------
        **criteria
            Column → value; a row is kept when it has every one.

        Returns
        -------
        list of dict
        """
        return [r for r in self.rows if all(np.isclose(r[k], v) if isinstance(v, float)
                                            else r[k] == v for k, v in criteria.items())]

    def plot(self, *, parameters=None, axes=None, title=None):
        """Draw estimated/true ratios (see :func:`crowdvib.reporting.plotting.plot_parametric_ratios`).

        Parameters
        ----------
        parameters : sequence of str, optional
            Perturbed inputs to show (default all in the result).
        axes : array of matplotlib.axes.Axes, optional
            Axes to draw on (default a new figure).
        title : str, optional
            The figure's title.
        """

        return plot_parametric_ratios(self, parameters=parameters, axes=axes, title=title)

    def to_dict(self):
        """JSON-ready dict."""
        return {"truth": self.truth, "rows": list(self.rows)}


def parametric_study(*, structure_frequencies=None, structure_damping_ratios=(0.005, 0.02),
                     mass_ratios=(0.025, 0.05, 0.10), msd=None, crowd=None, levels=None,
                     executor=None, store=None, progress=None):
    """The paper's parametric study of modelling errors (Figures 5 and 6).

    For each structure of the family (the paper example's beam with f_1 = 1…6 Hz in 0.5 Hz steps,
    ξ_1 ∈ {0.5, 2.0} %, crowd-to-structure mass ratio μ_m ∈ {2.5, 5, 10} %), a noise-free PSD is
    made with the true MSD and re-estimated with one input perturbed by +ε and by −ε at each
    level (ε_f 1/2 %, ε_ξ 10/30 %, ε_m 2/5 %, ε_μfs = ε_σfs 1/2.5 %), keeping the worse of the
    two as the paper's figures do: 66 structures × 10 rows of 2 estimations.

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

    See Also
    --------
    crowdvib.studies.modelling_error_study : the same errors on one structure.
    crowdvib.estimate_hsi

    References
    ----------
    K. Van Nimmen and P. Van den Broeck, "Using full-scale observations on footbridges to estimate
    the parameters governing human–structure interaction", *Journal of Bridge Engineering* 28(1),
    2023. The parametric study (Figures 5 and 6).

    The theory pages cite them (docs: theory, References).
    """

    example = paper_example()
    msd = example.msd if msd is None else msd
    crowd = example.crowd if crowd is None else crowd
    frequencies = (np.arange(1.0, 6.01, 0.5) if structure_frequencies is None
                   else check_positive("structure_frequencies",
                                       np.atleast_1d(structure_frequencies), unit="Hz"))
    cases = [c for c in error_cases(PARAMETRIC_ERROR_LEVELS if levels is None else levels,
                                    joint=False, signs=(+1, -1)) if c.kind == "individual"]
    tasks = []
    for f1, xi1, mu in itertools.product(frequencies, structure_damping_ratios, mass_ratios):
        for case in cases:
            key = f"f1={f1:g}|xi1={xi1:g}|mu={mu:g}|{case.name}"
            tasks.append((key, _ParametricTask(float(f1), float(xi1), float(mu), case, msd, crowd)))
    results = run_tasks(_parametric_task, tasks, executor=executor, store=store,
                        progress=progress)
    # The paper applies each error both ways and shows the worse of the two: one row per
    # structure, input and level, each ratio the one farther from 1, both signs kept beside it.
    groups = {}
    for key, task in tasks:
        (parameter, epsilon), = task.case.perturbations
        group = (task.structure_frequency, task.structure_damping, task.mass_ratio, parameter,
                 task.case.level)
        groups.setdefault(group, {})["+" if epsilon > 0 else "−"] = (abs(epsilon), results[key])
    rows = []
    for (f1, xi1, mu, parameter, level), signs in groups.items():
        epsilon = next(iter(signs.values()))[0]
        both = {sign: result for sign, (_, result) in signs.items()}
        row = {"structure_frequency": f1, "structure_damping": xi1, "structure_mass_ratio": mu,
               "parameter": parameter, "epsilon": epsilon, "level": level, "signs": both}
        failed = [r["error"] for r in both.values() if "error" in r]
        if failed:
            row["error"] = failed[0]
        else:
            for ratio in ("frequency_ratio", "damping_ratio_ratio"):
                row[ratio] = max((r[ratio] for r in both.values()), key=lambda v: abs(v - 1))
            row["active_bounds"] = sorted({b for r in both.values() for b in r["active_bounds"]})
        rows.append(row)
    return ParametricResult(rows=tuple(rows), truth=msd.to_dict())
