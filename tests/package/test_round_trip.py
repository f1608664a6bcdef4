"""Every public result class comes back from its dict (issue 34 §1, docs: Results).

The classes are found by introspection: every class of a ``crowdvib`` module's ``__all__`` with a
``to_dict`` method. Each must have a ``from_dict`` with ``from_dict(to_dict(x))`` equal to ``x``
as far as the dict holds it (their dicts equal after a JSON round trip, which is what a
results.json keeps) and of the same class, so a new result class without its ``from_dict``
fails here, not in a user's notebook. The computations of ``crowdvib.cases`` (``Case*``,
:class:`~crowdvib.cases.results.AsResults`) hold records and arrays beside what they write:
their dict is a results.json, which :class:`~crowdvib.Results` rebuilds (checked too).
"""

import importlib
import inspect
import json
import pkgutil
from dataclasses import replace

import numpy as np
import pytest

import crowdvib
from crowdvib import estimate_hsi, response_psd
from crowdvib._files import json_default
from crowdvib.cases.results import AsResults, Results
from crowdvib.errors import DataError


def _public_classes_with_to_dict():
    found = {}
    for info in pkgutil.walk_packages(crowdvib.__path__, "crowdvib."):
        if info.name.startswith("crowdvib.cli") or info.name.endswith("__main__"):
            continue
        module = importlib.import_module(info.name)
        for name in getattr(module, "__all__", ()):
            value = getattr(module, name, None)
            if inspect.isclass(value) and value.__module__.startswith("crowdvib.") \
                    and callable(getattr(value, "to_dict", None)):
                found[f"{value.__module__}.{value.__qualname__}"] = value
    return found


CLASSES = _public_classes_with_to_dict()


def _json(data):
    """What a results.json keeps of ``data``: JSON types, NaN as null (crowdvib's writer)."""
    return json.loads(json.dumps(data, default=json_default), parse_constant=lambda _: None)


# ------------------------------------------------------------------------------ examples
@pytest.fixture(scope="module")
def example():
    from crowdvib.models.examples import paper_example

    paper = paper_example()
    return paper.structure, paper.crowd, paper.msd


@pytest.fixture(scope="module")
def measured(example):
    from crowdvib.signals.welch import synthetic_welch_psd

    structure, crowd, msd = example
    grid = np.arange(1, 601) / 60.0
    expected = response_psd(structure, crowd, grid, msd=msd, welch_window_length=60.0)
    return synthetic_welch_psd(expected, n_windows=59, rng=1)


@pytest.fixture(scope="module")
def hsi_estimate(example, measured):
    structure, crowd, _ = example
    return estimate_hsi(measured, structure, crowd, band=(1.0, 8.0), interval="wald")


def _mode_identification(cross_check=None):
    from crowdvib.oma.modeid import ModeIdentification

    return ModeIdentification(np.array([2.1, 3.4]), np.array([0.01, np.nan]),
                              np.array([0.01, 0.02]), np.array([0.001, 0.002]),
                              np.array([[1.0, 0.5], [0.7, -1.0], [0.2, 0.3]]),
                              ("a", "b", "c"), 50.0, {}, method="ssi-cov",
                              cross_check=cross_check, settings={"order": 40},
                              missed=({"frequency": 5.0, "why": "unstable"},))


def _examples(name, request):
    """One instance of the class named ``name`` (module.qualname), made the way users get it."""
    structure, crowd, msd = request.getfixturevalue("example")
    if name.endswith(".MSDModel"):
        return msd
    if name.endswith(".Crowd"):
        return replace(crowd, body_mass_std=7.0, forward_fraction=0.6)
    if name.endswith(".CrowdProfile"):
        from crowdvib.models import CrowdProfile
        return CrowdProfile([0.0, 600.0, 1200.0], [0.3, 0.9, 0.1], "step")
    if name.endswith(".TunedMassDamper"):
        from crowdvib.models.damper import TunedMassDamper
        return TunedMassDamper(mass=500.0, frequency=2.9, damping_ratio=0.08, position=25.0)
    if name.endswith(".LowPassFilter"):
        from crowdvib.signals.welch import LowPassFilter
        return LowPassFilter(cutoff=8.0, order=6, sample_rate=50.0)
    if name.endswith(".DesignCheck"):
        from crowdvib.design.check import design_check
        return design_check(structure, "ukna", msd=msd, traffic_class="B")
    if name.endswith(".ResponsePrediction"):
        from crowdvib.design.stochastic import predict_response
        return predict_response(structure, crowd, msd=msd)
    if name.endswith(".EffectiveModalProperties"):
        from crowdvib.response import effective_modal_properties
        return effective_modal_properties(structure, crowd, msd)
    if name.endswith(".ResponsePSD"):
        from crowdvib.signals.welch import LowPassFilter, welch_psd
        rng = np.random.default_rng(3)
        signals = rng.standard_normal((2, 6000))
        signals[1] += 0.5 * signals[0]
        return welch_psd(signals, 50.0, window_length=20.0, output_names=("a", "b"),
                         cross=True, lowpass=LowPassFilter(cutoff=10.0, sample_rate=50.0))
    if name.endswith(".PSDConvergence"):
        from crowdvib.signals.convergence import psd_convergence
        rng = np.random.default_rng(4)
        return psd_convergence(rng.standard_normal(6000), 50.0, window_length=20.0)
    if name.endswith(".HSIEstimate"):
        return request.getfixturevalue("hsi_estimate")
    if name.endswith(".StepFrequencyEstimate"):
        from crowdvib.identification.step_frequencies import estimate_step_frequencies
        from crowdvib.signals.welch import LowPassFilter
        lowpass = LowPassFilter(cutoff=2.3, sample_rate=100.0)
        low = response_psd(structure, crowd, np.arange(1, 601) / 60.0, msd=msd,
                           welch_window_length=60.0, lowpass=lowpass)
        return estimate_step_frequencies(low, structure, crowd)
    if name.endswith(".ModeIdentification"):
        from crowdvib.oma.modeid import compare_identifications
        other = _mode_identification()
        return _mode_identification(compare_identifications(other, replace(
            other, frequencies=other.frequencies * 1.01)))
    if name.endswith(".ModeCrossCheck"):
        from crowdvib.oma.modeid import compare_identifications
        other = _mode_identification()
        return compare_identifications(other, replace(other, frequencies=other.frequencies
                                                      * 1.01))
    if name.endswith(".ObjectiveMap"):
        from crowdvib.identification import Estimator
        from crowdvib.studies.landscape import objective_map
        return objective_map(request.getfixturevalue("measured"), structure, crowd,
                             frequencies=[2.5, 3.0, 3.5], damping_ratios=[0.2, 0.3],
                             estimator=Estimator(band=(1.0, 8.0)), estimate=msd)
    if name.endswith(".SensitivityResult"):
        from crowdvib.studies.modelling_error import SensitivityResult
        cases = [{"name": f"frequencies{sign}{level}", "kind": "individual",
                  "parameter": "frequencies", "level": level, "sign": s,
                  "delta_frequency": s * 10 * level, "delta_damping_ratio": -s * 40 * level,
                  "active_bounds": [], "success": True}
                 for level in (0.01, 0.05) for sign, s in (("+", 1), ("-", -1))]
        return SensitivityResult(nominal={"frequency": 3.0, "damping_ratio": 0.3},
                                 cases=tuple(cases), levels={"frequencies": [0.01, 0.05]})
    if name.endswith(".ParametricResult"):
        from crowdvib.studies.parametric import ParametricResult
        return ParametricResult(rows=({"structure_frequency": 2.0, "ratio_frequency": 1.01},),
                                truth={"frequency": 3.0})
    if name.endswith(".MSDBox"):
        from crowdvib.design import MSDBox
        return MSDBox.from_estimate(request.getfixturevalue("hsi_estimate"))
    if name.endswith(".Traffic"):
        from crowdvib.comfort import Traffic
        return Traffic.from_profile([0.0] * 7 + [0.3, 0.6, 0.2] * 5 + [0.1, 0.0])
    if name.endswith(".ComfortYear"):
        from crowdvib.comfort import Traffic, comfort_year
        return comfort_year(structure, crowd, Traffic.from_table([0.2, 0.6], [500.0, 100.0]),
                            msd=msd, n_densities=3)
    if name.endswith(".SimulatedWindows"):
        from crowdvib.comfort.simulated import SimulatedWindows
        return SimulatedWindows((0.2, 0.5), (np.array([0.11, 0.13]), np.array([0.3, 0.35])),
                                (np.array([0.05, 0.06]), np.array([0.12, 0.14])), cpu=3.5)
    if name.endswith(".SeasonResult"):
        from crowdvib.studies.season import SeasonResult
        row = {"name": "r1", "row": 1, "density": 0.5, "frequency": 3.0, "damping_ratio": 0.3,
               "mass_ratio": 0.95, "interval": {"frequency": [2.9, 3.1],
                                                "damping_ratio": [0.2, 0.4], "level": 0.95},
               "relative_cost": 0.01, "success": True, "active_bounds": [], "warnings": []}
        return SeasonResult(rows=(row,), joint=request.getfixturevalue("hsi_estimate"))
    return None


# ----------------------------------------------------------------------------------- tests
def test_introspection_finds_the_result_classes():
    # The classes issue 34 named as unable to come back are among those found.
    names = {name.rsplit(".", 1)[1] for name in CLASSES}
    assert {"DesignCheck", "PSDConvergence", "StepFrequencyEstimate", "ModeIdentification",
            "HSIEstimate", "ResponsePSD", "EstimateResults"} <= names


#: The results.json classes and the cases' computations: checked by the test after the next.
FILE_CLASSES = {name for name, cls in CLASSES.items() if issubclass(cls, (Results, AsResults))}


@pytest.mark.parametrize("name", sorted(set(CLASSES) - FILE_CLASSES))
def test_every_public_result_class_comes_back_from_its_dict(name, request):
    cls = CLASSES[name]
    assert callable(getattr(cls, "from_dict", None)), f"{name} has to_dict but no from_dict"
    value = _examples(name, request)
    assert value is not None, f"no example of {name} in this test: add one to _examples"
    assert type(value) is cls
    written = _json(value.to_dict())
    back = cls.from_dict(written)
    assert type(back) is cls
    assert _json(back.to_dict()) == written


def test_a_crowd_whose_density_is_a_profile_comes_back_equal(example):
    # issue 34 §3: the density is one value, a number or a profile; the dict keeps the profile's
    # table exactly (JSON floats are the doubles' shortest repr) and the crowd compares (and
    # hashes) by value.
    from crowdvib.models import Crowd, CrowdProfile

    profile = CrowdProfile([-60.0, 0.0, 1800.0 / 7], [0.2, 1.0 / 3, 0.45], "linear")
    crowd = replace(example[1], density=profile, body_mass_std=7.0)
    back = Crowd.from_dict(_json(crowd.to_dict()))
    assert back == crowd and hash(back) == hash(crowd)
    assert isinstance(back.density, CrowdProfile) and back.density.kind == "linear"
    assert np.array_equal(back.profile.time, profile.time)
    assert np.array_equal(back.profile.density, profile.density)
    # A number stays a number (the stationary crowd's dict is unchanged: density a float).
    assert _json(example[1].to_dict())["density"] == example[1].density


def test_every_results_json_class_is_a_kind_that_load_results_rebuilds():
    # A Results subclass is the class of one results.json kind; a computation of crowdvib.cases
    # gives its Results (AsResults.results), which tests/cases/test_results_roundtrip.py
    # round-trips through the file for every command.
    from crowdvib.cases.resultfile import _CLASSES
    from crowdvib.cases.schema import KINDS

    for name in FILE_CLASSES:
        cls = CLASSES[name]
        if issubclass(cls, Results):
            assert cls.kind == "" or (cls.kind in KINDS and _CLASSES[cls.kind] is cls), name
        else:
            assert callable(getattr(cls, "results", None)), name


def test_a_dict_without_a_field_is_a_data_error_naming_it():
    from crowdvib.signals.convergence import PSDConvergence

    with pytest.raises(DataError, match="PSDConvergence.from_dict: the dict lacks 'error'"):
        PSDConvergence.from_dict({"n_windows": [1], "duration": [60.0], "output_names": ["a"],
                                  "window_length": 60.0, "band": [1, 2], "norm": "2"})
    with pytest.raises(DataError, match="needs a dict, got list"):
        PSDConvergence.from_dict([1, 2])
