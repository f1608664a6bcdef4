"""Bad input gets a ParameterError (also a ValueError) naming parameter, rule and value (issue 2)."""

import numpy as np
import pytest

from crowdvib import (Crowd, DataError, ModalModel, MSDModel, ParameterError, ResponsePSD,
                      estimate_hsi, frf, response_psd)

pytestmark = pytest.mark.badinput


def beam(**changes):
    arguments = dict(span=50.0, width=3.0, frequency=2.0, damping_ratio=0.005, modal_mass=50e3)
    arguments.update(changes)
    return ModalModel.simply_supported_beam(**arguments)


def test_parameter_error_is_a_value_error():
    assert issubclass(ParameterError, ValueError) and issubclass(DataError, ParameterError)


@pytest.mark.parametrize("changes, match", [
    (dict(frequency=0.0), r"frequencies must be > 0 Hz, got 0"),
    (dict(frequency=-2.0), r"frequencies must be > 0 Hz, got -2"),
    (dict(modal_mass=0.0), r"modal_masses must be > 0 kg, got 0"),
    (dict(modal_mass=-5.0), r"modal_masses must be > 0 kg, got -5"),
    (dict(damping_ratio=2.0), r"damping_ratios must be >= 0 and < 1 \(fractions, not percent\), got 2"),
    (dict(span=-50.0), r"span must be > 0 m, got -50"),
    (dict(width=0.0), r"width must be > 0 m, got 0"),
])
def test_bad_structure(changes, match):
    with pytest.raises(ParameterError, match=match):
        beam(**changes)


def test_mismatched_mode_shapes():
    good = beam()
    with pytest.raises(ParameterError, match=r"mode_shapes must have shape \(n_positions, n_modes\)"):
        good.replace(mode_shapes=good.mode_shapes[0, :-1])
    with pytest.raises(ParameterError, match=r"damping_ratios must have one entry per mode \(1\)"):
        good.replace(damping_ratios=[0.01, 0.02])
    with pytest.raises(ParameterError, match=r"output_shapes must have shape"):
        good.replace(output_shapes=[[1.0, 0.5]])


@pytest.mark.parametrize("kwargs, match", [
    (dict(frequency=0.0), r"frequency must be > 0 Hz, got 0"),
    (dict(damping_ratio=30.0), r"damping_ratio must be > 0 and < 2 \(fractions, not percent\), got 30"),
    (dict(damping_ratio=0.0), r"damping_ratio must be > 0"),
    (dict(mass_ratio=1.0), r"mass_ratio must lie in the open interval \(0, 1\), got 1"),
    (dict(mass_ratio=0.0), r"mass_ratio must lie in the open interval \(0, 1\), got 0"),
    (dict(mass_ratio=95.0), r"mass_ratio must lie in the open interval \(0, 1\), got 95"),
])
def test_bad_msd(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        MSDModel(**kwargs)


@pytest.mark.parametrize("kwargs, match", [
    (dict(density=-0.5), r"density must be >= 0 persons/m², got -0.5"),
    (dict(density=6.0), r"density must be < the jam density 5.4"),
    (dict(body_mass=0.0), r"body_mass must be > 0 kg, got 0"),
    (dict(step_frequency_std=-0.1), r"step_frequency_std must be > 0 Hz, got -0.1"),
])
def test_bad_crowd(kwargs, match):
    arguments = dict(density=0.5, walking_speed=1.3, step_frequency_mean=1.89)
    arguments.update(kwargs)
    with pytest.raises(ParameterError, match=match):
        Crowd(**arguments)


def test_bad_frequency_grid(paper_bridge, paper_crowd):
    with pytest.raises(ParameterError, match=r"frequency must be >= 0 Hz, got -1"):
        response_psd(paper_bridge, paper_crowd, [-1.0, 1.0])
    with pytest.raises(ParameterError, match=r"frequency must be a non-empty, strictly increasing"):
        response_psd(paper_bridge, paper_crowd, [2.0, 1.0])


def test_unknown_output_name(paper_bridge, paper_crowd):
    with pytest.raises(ParameterError, match=r"output name must be one of \['midspan'\], got 'quarter'"):
        response_psd(paper_bridge, paper_crowd, [1.0, 2.0], outputs=["quarter"])
    with pytest.raises(ParameterError, match=r"got 'side'"):
        frf(paper_bridge, [1.0], inputs=["side"])


def test_msd_without_crowd(paper_bridge, paper_msd):
    with pytest.raises(ParameterError, match="crowd must be given when msd is given"):
        frf(paper_bridge, [1.0], msd=paper_msd)


@pytest.fixture
def measured(paper_bridge, paper_crowd, paper_msd, welch_grid):
    return response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd)


@pytest.mark.parametrize("band, match", [
    ((8.0, 2.0), r"band must have lower < upper, got \(8, 2\) Hz"),
    ((1.0, 12.0), r"band must lie within the measured frequency grid \[0, 10\] Hz, got \(1, 12\)"),
    ((-1.0, 5.0), r"band must lie within the measured frequency grid"),
    ((2.0, 2.02), r"band \(2, 2.02\) Hz must hold at least 3 frequencies"),
    ((2.0,), r"band must be a pair"),
])
def test_bad_band(measured, paper_bridge, paper_crowd, band, match):
    with pytest.raises(ParameterError, match=match):
        estimate_hsi(measured, paper_bridge, paper_crowd, band=band)


@pytest.mark.parametrize("value, match", [(np.nan, "got nan"), (-1e-3, "got -0.001"),
                                          (np.inf, "got inf")])
def test_bad_measured_psd(measured, paper_bridge, paper_crowd, value, match):
    psd = measured.psd.copy()
    psd[0, 100] = value
    bad = ResponsePSD(frequency=measured.frequency, psd=psd, output_names=measured.output_names)
    with pytest.raises(ParameterError, match=r"measured PSD of output 'midspan' must be finite "
                                             r"and >= 0, .*" + match + r" at 1.66667 Hz"):
        estimate_hsi(bad, paper_bridge, paper_crowd, band=(0.0, 10.0))


def test_psd_shape_mismatch():
    with pytest.raises(ParameterError, match=r"psd must have shape \(n_outputs, n_frequencies\) "
                                             r"= \(1, 3\), got \(1, 4\)"):
        ResponsePSD(frequency=[1.0, 2.0, 3.0], psd=[[1.0, 2.0, 3.0, 4.0]], output_names=["a"])


def test_measured_output_not_in_structure(measured, paper_bridge, paper_crowd):
    renamed = ResponsePSD(frequency=measured.frequency, psd=measured.psd, output_names=["deck"])
    with pytest.raises(ParameterError, match=r"output name must be one of \['midspan'\], got 'deck'"):
        estimate_hsi(renamed, paper_bridge, paper_crowd, band=(0.0, 10.0))


def test_zero_density_crowd_in_estimator(measured, paper_bridge, paper_crowd):
    with pytest.raises(ParameterError, match=r"crowd.density must be > 0 to estimate HSI.*got 0"):
        estimate_hsi(measured, paper_bridge, paper_crowd.with_density(0.0), band=(0.0, 10.0))


@pytest.mark.parametrize("kwargs, match", [
    (dict(output_weights=[1.0, 2.0]), r"output_weights must have 1 entries, got 2"),
    (dict(output_weights=[-1.0]), r"output_weights must be > 0, got -1"),
    (dict(bounds={"frequency": (5.0, 1.0)}), r"bounds\['frequency'\] must satisfy 0 < lower < upper"),
    (dict(bounds={"stiffness": (1.0, 2.0)}), r"bounds keys must be among"),
    (dict(mass_ratio=1.5), r"mass_ratio must lie in the open interval \(0, 1\), got 1.5"),
    # The default estimator fits (f_h1, ξ_h1, μ_fs, σ_fs): four values a start, or two.
    (dict(starts=[(3.0, 0.3, 1.9, 0.2, 1.0)]), r"starts must hold 4 values"),
    (dict(starts=[(3.0, 0.3, 0.9, 1.0)], method="least_squares"), r"starts must hold 2 values"),
])
def test_bad_estimator_options(measured, paper_bridge, paper_crowd, kwargs, match):
    with pytest.raises(ParameterError, match=match):
        estimate_hsi(measured, paper_bridge, paper_crowd, band=(0.0, 10.0), **kwargs)
