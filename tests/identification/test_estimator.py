"""One estimator value, one set of defaults (issue 34 §2).

Reference: :class:`crowdvib.identification.Estimator`'s defaults are the estimator a user gets
without asking (docs: theory, Calibration; ``crowdvib._estimators``). Every entry point that
takes an estimator's choice must default it the same way, so that a landscape, a study or a
case file describes the estimate ``estimate_hsi`` makes by default (issue 33 §3 found
``objective_map`` defaulting to least squares while ``estimate_hsi`` used the likelihood).
"""

import dataclasses
import inspect

import numpy as np
import pytest

from crowdvib import ParameterError, estimate_hsi, response_psd
from crowdvib._estimators import DEFAULT_JOINT_METHOD, estimator_defaults
from crowdvib.identification import Estimator, PSDObjective, estimate_hsi_joint
from crowdvib.io.casespecs import EstimationSpec
from crowdvib.studies import modelling_error_study, objective_map

DEFAULTS = {item.name: item.default for item in dataclasses.fields(Estimator)}
#: Deliberate differences, each stated in its docstring: a joint fit holds each record's crowd,
#: where the likelihood is fragile, so it keeps the paper's least squares.
DELIBERATE = {("estimate_hsi_joint", "method"): DEFAULT_JOINT_METHOD}


@pytest.mark.parametrize("entry", [estimate_hsi, estimate_hsi_joint, modelling_error_study,
                                   objective_map, PSDObjective],
                         ids=lambda entry: entry.__name__)
def test_every_entry_point_defaults_each_choice_as_the_estimator_does(entry):
    # band has no default anywhere (the record's band is the user's to state)
    shared = {name: parameter.default
              for name, parameter in inspect.signature(entry).parameters.items()
              if name in DEFAULTS and name != "band"}
    assert "method" in shared                    # every entry point chooses the misfit
    for name, default in shared.items():
        expected = DELIBERATE.get((entry.__name__, name), DEFAULTS[name])
        assert default == expected, (entry.__name__, name, default, expected)


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
    assert Estimator(band=(1, 2)).replace(level=0.9).level == 0.9
