"""One estimator value, one set of defaults (issue 34 §2).

Reference: :class:`crowdvib.identification.Estimator`'s defaults are the estimator a user gets
without asking (docs: theory, Calibration; ``crowdvib._estimators``). Every entry point that
takes an estimator's choice must default it the same way, so that a landscape, a study or a
case file describes the estimate ``estimate_hsi`` makes by default (issue 33 §3 found
``objective_map`` defaulting to least squares while ``estimate_hsi`` used the likelihood).
The studies and the case pipelines take the value itself (issue 34 §2), so they hold no copy.
"""

import dataclasses
import importlib
import inspect
import pkgutil

import numpy as np
import pytest

import crowdvib
from crowdvib import ParameterError, estimate_hsi, response_psd
from crowdvib._estimators import DEFAULT_JOINT_METHOD, estimator_defaults
from crowdvib.cases import case_estimator
from crowdvib.identification import (Estimator, PSDObjective, estimate_hsi_joint,
                                     estimate_step_frequencies)
from crowdvib.io import load_case
from crowdvib.io.casespecs import EstimationSpec
from crowdvib.models.loading import ZivanovicForce
from crowdvib.studies import modelling_error_study, objective_map, record_length_study
from crowdvib.studies.season import season_study
from tests.conftest import EXAMPLES

DEFAULTS = {item.name: item.default for item in dataclasses.fields(Estimator)}
#: Deliberate differences, each stated in its docstring: a joint fit holds each record's crowd,
#: where the likelihood is fragile, so it keeps the paper's least squares.
DELIBERATE = {("estimate_hsi_joint", "method"): DEFAULT_JOINT_METHOD}


#: The entry points that spell the choices out as keywords: the convenience calls over the
#: Estimator and the misfit itself. Every other entry point takes an Estimator.
SPELLED_OUT = (estimate_hsi, estimate_hsi_joint, PSDObjective)


@pytest.mark.parametrize("entry", SPELLED_OUT, ids=lambda entry: entry.__name__)
def test_every_entry_point_defaults_each_choice_as_the_estimator_does(entry):
    # band has no default anywhere (the record's band is the user's to state)
    shared = {name: parameter.default
              for name, parameter in inspect.signature(entry).parameters.items()
              if name in DEFAULTS and name != "band"}
    assert "method" in shared                    # every entry point chooses the misfit
    for name, default in shared.items():
        expected = DELIBERATE.get((entry.__name__, name), DEFAULTS[name])
        assert default == expected, (entry.__name__, name, default, expected)


def _public_callables():
    """Every public function and non-dataclass class of every module's __all__ (a dataclass
    is a value, its fields are not choices it defaults)."""
    found = {}
    for info in pkgutil.walk_packages(crowdvib.__path__, "crowdvib."):
        if "._" in info.name or info.name.endswith("__main__"):
            continue
        module = importlib.import_module(info.name)
        for name in getattr(module, "__all__", ()):
            entry = getattr(module, name, None)
            if callable(entry) and not dataclasses.is_dataclass(entry):
                found[f"{entry.__module__}.{entry.__qualname__}"] = entry
    return found


def _parameters(entry):
    try:
        return set(inspect.signature(entry).parameters)
    except ValueError:              # an exception class has no signature of its own
        return set()


def test_no_other_entry_point_repeats_the_estimators_choices():
    # Issue 34 §2: the studies and case pipelines take one Estimator, so no second copy of a
    # choice's default exists. Found by introspection over the public API, so a new entry
    # point that spells the choices out again fails here. estimate_step_frequencies is the
    # crowd's own estimator (the low band without HSI: its band, bounds and starts are of
    # another problem).
    # (the forward model's own choices, crowd_model, force and outputs, are left out:
    # response_psd and the comfort tables take them without estimating anything)
    choices = set(DEFAULTS) - {"band", "crowd_model", "force", "outputs"}
    allowed = {entry.__name__ for entry in SPELLED_OUT} | {estimate_step_frequencies.__name__}
    repeating = {key for key, entry in _public_callables().items()
                 if entry.__name__ not in allowed
                 and len(choices & _parameters(entry)) >= 3}
    assert repeating == set()


@pytest.mark.parametrize("study", [modelling_error_study, record_length_study, objective_map,
                                   season_study], ids=lambda entry: entry.__name__)
def test_the_studies_take_the_estimator_as_one_value(study):
    parameters = inspect.signature(study).parameters
    assert parameters["estimator"].kind is inspect.Parameter.KEYWORD_ONLY
    assert not set(parameters) & set(DEFAULTS)          # not even the band


def test_estimate_hsi_takes_every_choice_of_the_estimator():
    assert set(DEFAULTS) <= set(inspect.signature(estimate_hsi).parameters)


def test_a_case_file_that_states_nothing_resolves_to_the_estimators_defaults():
    # EstimationSpec.resolved() fills the method's crowd model and step-frequency choice as
    # estimate_hsi does (estimator_defaults); the case's band is the paper's 0–10 Hz.
    spec = EstimationSpec().resolved()
    model, _ = estimator_defaults(DEFAULTS["method"])
    for name in ("method", "interval", "level", "n_boot", "density_uncertainty", "check_level",
                 "match_welch"):
        assert getattr(spec, name) == DEFAULTS[name], name
    assert spec.crowd_model == model == "fluctuating"


def _resolved(estimator):
    """The estimator with the choices its method fills (None → the method's crowd model and
    step-frequency choice: estimator_defaults) and the default force model stated."""
    model, free = estimator_defaults(estimator.method, estimator.crowd_model,
                                     estimator.free_step_frequencies)
    return estimator.replace(crowd_model=model, free_step_frequencies=free,
                             force=estimator.force or ZivanovicForce())


def test_a_case_file_that_states_nothing_fits_with_the_default_estimator(tmp_path):
    # The paper example's case file without its [estimation] table, [hsi] table and stated
    # density uncertainty: the estimator every command of it fits with (case_estimator) is
    # Estimator()'s, over the case file's default band (the paper's 0–10 Hz), choice by choice.
    text = (EXAMPLES / "paper_example.toml").read_text(encoding="utf-8")
    for table in ("[hsi]\nmass_ratio = 0.95", "[estimation]\nband = [0.0, 10.0]"):
        text = text.replace(table, "")
    text = text.replace("density_uncertainty = 0.0", "")
    (tmp_path / "bare.toml").write_text(text, encoding="utf-8")
    (tmp_path / "paper_example_record.npz").write_bytes(
        (EXAMPLES / "paper_example_record.npz").read_bytes())
    case = load_case(tmp_path / "bare.toml")
    found = case_estimator(case)
    assert isinstance(found, Estimator)
    assert _resolved(found) == _resolved(Estimator(band=(0.0, 10.0)))
    # the comparison sees a difference: a stated choice does not pass for the default
    assert _resolved(found.replace(level=0.9)) != _resolved(Estimator(band=(0.0, 10.0)))


def test_a_study_given_least_squares_runs_least_squares(paper_bridge, paper_crowd, paper_msd,
                                                        welch_grid):
    # The nominal of a modelling-error study is the estimator's own estimate (the same
    # computation, to the last digit): with Estimator(method="least_squares") the paper's
    # least squares (Eq. 6), whose misfit at its optimum differs from the likelihood's; and
    # the map of that estimator is the least-squares misfit (PSDObjective's, independently).
    measured = response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd,
                            welch_window_length=60.0, crowd_model="smeared")
    paper = Estimator(band=(0.0, 10.0), method="least_squares")
    study = modelling_error_study(measured, paper_bridge, paper_crowd, estimator=paper,
                                  levels={"frequencies": (0.01,)}, joint=False,
                                  warm_start=False)
    squares = estimate_hsi(measured, paper_bridge, paper_crowd, band=(0.0, 10.0),
                           method="least_squares", interval=None)
    likelihood = estimate_hsi(measured, paper_bridge, paper_crowd, band=(0.0, 10.0),
                              interval=None)
    assert study.nominal["cost"] == squares.cost != likelihood.cost
    assert study.nominal["frequency"] == squares.msd.frequency
    landscape = objective_map(measured, paper_bridge, paper_crowd, frequencies=[2.5, 3.0],
                              damping_ratios=[0.3], estimator=paper)
    misfit = PSDObjective(measured, paper_bridge, paper_crowd, band=(0.0, 10.0),
                          method="least_squares")
    assert landscape.cost[0, 1] == misfit.cost(paper_msd)
    assert landscape.cost[0, 1] != PSDObjective(measured, paper_bridge, paper_crowd,
                                                band=(0.0, 10.0)).cost(paper_msd)


def test_fit_is_estimate_hsi_with_the_same_choices(paper_bridge, paper_crowd, paper_msd,
                                                   welch_grid):
    # Noise-free PSD of the paper's example: the value and the call make the same estimate,
    # to the last digit (the same computation).
    measured = response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd,
                            welch_window_length=60.0, crowd_model="smeared")
    paper = Estimator(band=(0.0, 10.0), method="least_squares", interval=None)
    found = paper.fit(measured, paper_bridge, paper_crowd)
    direct = estimate_hsi(measured, paper_bridge, paper_crowd, band=(0.0, 10.0),
                          method="least_squares", interval=None)
    assert found.msd == direct.msd
    assert found.msd.frequency == pytest.approx(3.0, rel=1e-3)     # the truth (noise-free)
    # and the joint fit of the record with itself: the same MSD (the misfits add)
    joint = paper.fit_joint([measured, measured], paper_bridge, [paper_crowd] * 2)
    assert np.isclose(joint.msd.frequency, direct.msd.frequency, rtol=1e-4)


def test_an_estimator_needs_a_band_and_a_known_method():
    with pytest.raises(ParameterError, match="band must be given"):
        Estimator().fit(None, None, None)
    with pytest.raises(ParameterError, match="method must be one of"):
        Estimator(method="ml")
    with pytest.raises(ParameterError, match="free_step_frequencies must not be True for a "
                                             "joint fit"):
        Estimator(band=(1, 2), free_step_frequencies=True).fit_joint([], None, [])
    assert Estimator(band=(1, 2)).replace(level=0.9).level == 0.9
