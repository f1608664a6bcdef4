"""``crowdvib sensitivity``'s work on a case: the modelling-error study of its record (nominal ±
bound, paper Figs. 11 and 19), the re-estimates on shorter parts of the record, and the record's
own estimate with its interval (docs: :ref:`theory-estimator`)."""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from .._version import __version__
from .results import ESTIMATION_TABLES, AsResults, software_versions
from .schema import schema_header
from ..runner import TaskStore
from ..studies import modelling_error_study, record_length_study
from .estimate import CaseRecordFit, case_crowd, case_estimator, measure_case
from ..errors import CrowdvibWarning
from .._files import require_file
from .._manifest import verified_file
from ..errors import DataError
from ..oma.identify import identified_error_levels

if TYPE_CHECKING:
    from collections.abc import Callable

    from ..identification.result import HSIEstimate
    from ..io.casefile import Case
    from ..studies.modelling_error import SensitivityResult
    from .estimate import CaseRecordFit

__all__ = ["CaseStudy", "study_case", "identified_levels", "STUDY_STORES"]

#: Task-store subfolders of a study's folder: the modelling-error and record-length tasks.
STUDY_STORES = ("tasks", "record_length")


@dataclass(frozen=True)
class CaseStudy(AsResults):
    """What ``crowdvib sensitivity`` computes for a case (:func:`study_case`).

    Attributes
    ----------
    case : Case
    record : CaseRecordFit
        The record, its PSD and the crowd the study uses.
    study : SensitivityResult
        The modelling-error study (:func:`~crowdvib.studies.modelling_error_study`).
    lengths : list of dict or None
        The re-estimates on shorter parts of the record (None: not asked for).
    nominal : HSIEstimate
        The record's estimate with the case's interval options.
    """

    case: Case
    record: CaseRecordFit
    study: SensitivityResult
    lengths: list | None
    nominal: HSIEstimate

    @property
    def combined(self) -> dict | None:
        """The statistical interval widened by the modelling bound (None without an interval):
        :meth:`~crowdvib.studies.SensitivityResult.combined`."""
        return self.study.combined(self.nominal) if self.nominal.covariance is not None else None

    def to_dict(self) -> dict:
        """The results ``crowdvib sensitivity`` writes to results.json, without its figures and
        provenance."""
        case, study = self.case, self.study
        return {
            **schema_header("sensitivity"), "command": "sensitivity",
            "crowdvib_version": __version__, "versions": software_versions(),
            "seed": case.seed, "case": str(case.path), "inputs": case.inputs(ESTIMATION_TABLES),
            "estimate": {"frequency": study.nominal["frequency"],
                         "damping_ratio": study.nominal["damping_ratio"],
                         "mass_ratio": study.nominal["mass_ratio"],
                         **{key: value for key, value in self.nominal.to_dict()["estimate"].items()
                            if key in ("interval", "standard_error")}},
            "combined": self.combined,
            "expected": dict(case.expected), "sensitivity": study.to_dict(),
            "record_length": self.lengths}


def study_case(case: Case, *, record=None, levels: dict | None = None, joint: bool = True,
               record_length: bool = True, executor=None, directory: str | Path | None = None,
               progress: Callable[[str], Callable[[int, int], None] | None] | None = None
               ) -> CaseStudy:
    """Run ``crowdvib sensitivity``'s study on a loaded case, without writing results.

    Parameters
    ----------
    case : Case
        One ``[measurement]``.
    record : CaseRecordFit, optional
        The case's record, PSD and crowd if already computed (default: :func:`measure_case` and
        :func:`case_crowd`).
    levels : dict, optional
        Error levels of the structure's frequencies and damping ratios
        (:func:`identified_levels`; default the paper's).
    joint : bool
        Also the 2⁵ joint sign combinations (else individual errors only).
    record_length : bool
        Also re-estimate on shorter parts of the record.
    executor : concurrent.futures.Executor, optional
        Where the tasks run (:func:`~crowdvib.runner.study_executor`; default this process).
    directory : str or pathlib.Path, optional
        Folder of the task stores (:data:`STUDY_STORES`): finished tasks are kept there and not
        run again (resume); default none kept.
    progress : callable, optional
        ``progress(stage)`` → the ``progress(done, total)`` callback of a stage
        (``"estimations"``, ``"record lengths"``).

    Returns
    -------
    CaseStudy
        The study's warnings, the workers' included, are raised here in this process.
    """

    if record is None:
        measurement = measure_case(case)
        record = CaseRecordFit(case, measurement, *case_crowd(case, measurement.record))

    def store(name):        # made when used: a TaskStore makes its folder
        return None if directory is None else TaskStore(Path(directory) / name)

    stage = progress or (lambda name: None)
    measured, data, crowd = record.measurement.psd, record.measurement.record, record.crowd
    estimator = case_estimator(case)      # a counted crowd carries its profile (case_crowd)
    # The record's own estimate with its interval, beside the studies on a worker (it was the
    # longest step left in this process, measured in issue 14).
    nominal_task = (estimator, measured, case.structure, crowd, case.seed)
    pending = (executor.submit(_estimate_with_warnings, *nominal_task)
               if executor is not None else None)
    # The studies compare point estimates: they leave out the estimator's interval choices.
    study = modelling_error_study(measured, case.structure, crowd, estimator=estimator,
                                  levels=levels, joint=joint, executor=executor,
                                  store=store("tasks"), progress=stage("estimations"))
    lengths = None
    if record_length:
        lengths = record_length_study(
            data.data, data.sample_rate, case.structure, crowd,
            window_length=case.measurement.window_length, estimator=estimator,
            output_names=data.channel_names, lowpass=record.measurement.lowpass,
            executor=executor, store=store("record_length"),
            progress=stage("record lengths"))
    nominal, caught = (pending.result() if pending is not None
                       else _estimate_with_warnings(*nominal_task))
    for category, message in caught:
        warnings.warn(message, category, stacklevel=2)
    return CaseStudy(case, record, study, lengths, nominal)


def _estimate_with_warnings(estimator, measured, structure, crowd, rng):
    """The record's estimate and the crowdvib warnings it gave ``(category, message)``, for
    the calling process to raise (a worker's warnings would not reach the user)."""

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", CrowdvibWarning)
        estimate = estimator.fit(measured, structure, crowd, rng=rng)
    return estimate, [(w.category, str(w.message)) for w in caught
                      if issubclass(w.category, CrowdvibWarning)]


def identified_levels(directory: str | Path) -> dict:
    """Error levels of a study from the results.json of ``crowdvib modes`` in ``directory``:
    1 and 2 relative standard deviations of the least certain identified mode
    (:func:`~crowdvib.oma.identified_error_levels`).

    Parameters
    ----------
    directory : str or os.PathLike
        The output folder of ``crowdvib modes``.

    Raises
    ------
    DataError
        The folder holds no results.json of ``crowdvib modes`` with the modes' frequencies,
        damping ratios and their standard deviations, or one changed since crowdvib wrote it
        (its folder's manifest records another SHA-256; without a manifest: an
        :class:`~crowdvib.errors.UnverifiedWarning`).
    """
    import json


    require_file(Path(directory) / "results.json", "crowdvib modes results")
    path = verified_file(directory, "results.json", "--modes-from")
    try:
        results = json.loads(path.read_text(encoding="utf-8"))
        modes = results["modes"] if results.get("command") == "modes" else None
        columns = {key: [float(mode[key]) for mode in modes] for key in
                   ("frequency", "frequency_std", "damping_ratio", "damping_std")}
    except (ValueError, KeyError, TypeError, AttributeError, RecursionError,
            UnicodeDecodeError) as exc:   # AttributeError: a JSON list, not an object
        raise DataError(f"{path}: is not the results.json of `crowdvib modes` (a 'modes' list "
                        f"with frequency, frequency_std, damping_ratio, damping_std): "
                        f"{type(exc).__name__}: {exc}") from None
    return identified_error_levels(columns["frequency"], columns["frequency_std"],
                                   columns["damping_ratio"], columns["damping_std"])
