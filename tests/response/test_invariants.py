"""Invariants of the spectral model that hold for every physical input (hypothesis)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from crowdvib import (Crowd, ModalModel, MSDModel, ZivanovicForce, effective_modal_properties, frf,
                      response_psd)

pytestmark = pytest.mark.properties

F = np.linspace(0.05, 12.0, 400)
settings.register_profile("crowdvib", max_examples=40, deadline=None)
settings.load_profile("crowdvib")

msds = st.builds(MSDModel, frequency=st.floats(0.5, 8.0), damping_ratio=st.floats(0.01, 1.0),
                 mass_ratio=st.floats(0.05, 0.99))
crowds = st.builds(Crowd, density=st.floats(0.05, 2.0), walking_speed=st.floats(0.6, 1.6),
                   step_frequency_mean=st.floats(1.4, 2.4),
                   step_frequency_std=st.floats(0.05, 0.3), body_mass=st.floats(40.0, 110.0))


@st.composite
def bridges(draw):
    n_modes = draw(st.integers(1, 3))
    return ModalModel.simply_supported_beam(
        span=draw(st.floats(10.0, 80.0)), width=draw(st.floats(1.5, 6.0)),
        frequency=sorted(draw(st.lists(st.floats(1.0, 9.0), min_size=n_modes,
                                       max_size=n_modes))),
        damping_ratio=draw(st.floats(0.001, 0.05)), modal_mass=draw(st.floats(5e3, 2e5)),
        n_modes=n_modes, outputs={"a": 3.0, "b": 5.0})


@given(bridges(), crowds, msds)
def test_psd_is_non_negative(bridge, crowd, msd):
    psd = response_psd(bridge, crowd, F, msd=msd, crowd_model="smeared").psd
    assert np.all(psd >= 0) and np.all(np.isfinite(psd))


@given(bridges(), crowds, msds, st.floats(0.1, 10.0))
def test_force_scale_scales_psd_quadratically(bridge, crowd, msd, scale):
    base = response_psd(bridge, crowd, F, msd=msd, crowd_model="smeared").psd
    scaled = response_psd(bridge, crowd, F, msd=msd, force=ZivanovicForce(scale=scale),
                          crowd_model="smeared").psd
    np.testing.assert_allclose(scaled, scale**2 * base, rtol=1e-9, atol=1e-300)


@given(bridges(), crowds, msds, st.data())
def test_flipping_a_mode_sign_changes_no_output_psd(bridge, crowd, msd, data):
    factors = np.array(data.draw(st.lists(st.sampled_from([-1.0, 1.0]), min_size=bridge.n_modes,
                                          max_size=bridge.n_modes)))
    a = response_psd(bridge, crowd, F, msd=msd, crowd_model="smeared").psd
    b = response_psd(bridge.rescaled(factors), crowd, F, msd=msd, crowd_model="smeared").psd
    np.testing.assert_allclose(b, a, rtol=1e-8, atol=1e-12 * a.max())


@given(bridges(), crowds, msds)
def test_no_msd_or_vanishing_density_gives_the_empty_structure(bridge, crowd, msd):
    empty = frf(bridge, F)
    # msd=None: the crowd is forces only, the structure is empty.
    np.testing.assert_array_equal(frf(bridge, F, crowd=crowd, msd=None).values, empty.values)
    # density → 0: the occupied FRF tends to the empty one (error ∝ d).
    faint = frf(bridge, F, crowd=crowd.with_density(1e-9), msd=msd)
    np.testing.assert_allclose(faint.values, empty.values, rtol=1e-5)
    # and the PSD per unit density tends to the no-HSI PSD per unit density, the gap ∝ d. The gap
    # is measured against the spectrum's peak: bin by bin it is not small where the outputs'
    # modes cancel (an anti-resonance, PSD 1e-7 of the peak), where a relative gap of 1e-9 grows
    # by the cancellation (hypothesis found 1.01e-5 there on Python 3.13's draws).
    def gap(d):
        a = response_psd(bridge, crowd.with_density(d), F, msd=msd, crowd_model="smeared").psd
        b = response_psd(bridge, crowd.with_density(d), F, msd=None, crowd_model="smeared").psd
        return np.max(np.abs(a - b)) / b.max()

    small = gap(1e-9)
    assert small < 1e-5
    # ten times the density, ten times the gap (to the round-off of the smaller one)
    assert gap(1e-8) == pytest.approx(10 * small, rel=0.05, abs=1e-12)


@given(bridges(), crowds, msds)
def test_occupied_poles_are_stable(bridge, crowd, msd):
    props = effective_modal_properties(bridge, crowd, msd)
    assert np.all(props.damping_ratios > 0)
    assert np.all(props.interaction_damping_ratios > 0)
    assert props.frequencies.shape == (bridge.n_modes,)


@pytest.mark.parametrize("density", [0.0])
def test_zero_density_gives_zero_psd(paper_bridge, paper_msd, density):
    crowd = Crowd(density=density, walking_speed=1.3, step_frequency_mean=1.89)
    assert np.all(response_psd(paper_bridge, crowd, F, msd=paper_msd,
                               crowd_model="smeared").psd == 0)
