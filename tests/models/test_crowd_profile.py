"""CrowdProfile: a crowd's density against time (crowdvib.models.profile; docs: theory, A crowd
that changes; issue 28 §1)."""

import numpy as np
import pytest

from crowdvib import CrowdProfile, ModalModel, ParameterError

RAMP = CrowdProfile([0.0, 3600.0], [0.2, 1.0])
DAY = CrowdProfile([0.0, 900.0, 1800.0, 2700.0], [0.3, 0.9, 0.5, 0.15], "step")


def test_ramp_values_and_integral():
    # Closed form of a linear ramp d(t) = 0.2 + 0.8 t/3600, held outside [0, 3600] s.
    t = np.array([-100.0, 0.0, 900.0, 3600.0, 4000.0])
    assert RAMP.density_at(t) == pytest.approx([0.2, 0.2, 0.4, 1.0, 1.0])
    exact = np.array([-20.0, 0.0, 0.2 * 900 + 0.8 * 900**2 / 7200, 0.6 * 3600,
                      0.6 * 3600 + 400.0])
    assert RAMP.cumulative(t) == pytest.approx(exact, rel=1e-12)
    assert RAMP.mean(0.0, 3600.0) == pytest.approx(0.6, rel=1e-12)


def test_step_values_and_integral():
    # Piecewise constant: each value holds from its time to the next (counts per interval).
    assert DAY.density_at([-1.0, 0.0, 899.9, 900.0, 2000.0, 1e5]) == pytest.approx(
        [0.3, 0.3, 0.3, 0.9, 0.5, 0.15])
    # ∫_0^3600 d = 900 (0.3 + 0.9 + 0.5 + 0.15)
    assert DAY.cumulative(3600.0) == pytest.approx(900 * 1.85, rel=1e-12)


@pytest.mark.parametrize("profile", [RAMP, DAY, CrowdProfile([0, 100, 200], [0.5, 0.0, 1.0])],
                         ids=["ramp", "step", "through zero"])
def test_inverse_cumulative_undoes_cumulative(profile):
    # Inversion of the cumulative rate draws the non-homogeneous stream: C⁻¹(C(t)) = t where
    # d(t) > 0 (docs: theory, A crowd that changes).
    t = np.linspace(-300.0, 4000.0, 2001)
    t = t[profile.density_at(t) > 0]
    assert profile.inverse_cumulative(profile.cumulative(t)) == pytest.approx(t, abs=1e-8)


def test_deck_density_of_a_ramp_lags_half_a_crossing():
    # The mean over the last crossing τ of a linear ramp is its value τ/2 earlier (closed form).
    tau = 40.0
    t = np.array([100.0, 1800.0, 3000.0])
    assert RAMP.deck_density(t, tau) == pytest.approx(RAMP.density_at(t - tau / 2), rel=1e-12)


def test_counts_per_interval_become_densities():
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    profile = CrowdProfile.from_counts([0, 60, 120], [30, 75, 0], bridge.area)
    # density = count/(L·B), L·B = 150 m², held over each interval
    assert profile.kind == "step"
    assert profile.density == pytest.approx([0.2, 0.5, 0.0])
    assert not profile.is_constant and CrowdProfile.constant(0.4).is_constant
    assert profile.scaled(2.0).density == pytest.approx([0.4, 1.0, 0.0])


@pytest.mark.parametrize("arguments, message", [
    (([0, 10, 5], [0.1, 0.2, 0.3]), r"time must be finite and strictly increasing"),
    (([0, 10], [0.1]), r"density must have one value per time \(2\), got 1"),
    (([0, 10], [0.1, -0.2]), r"density must be finite and >= 0 persons/m², got -0.2"),
    (([0, 10], [0.1, 60.0]), r"jam density 5.4 persons/m², got 60 \(a count per interval\?"),
    (([0, 10], [0.1, 0.2], "spline"), r"kind must be one of \['linear', 'step'\], got 'spline'"),
    (([], []), r"time must hold at least one point"),
])
def test_bad_profile(arguments, message):
    with pytest.raises(ParameterError, match=message):
        CrowdProfile(*arguments)


def test_bad_counts():
    with pytest.raises(ParameterError, match=r"count must stay below the jam density × area = "
                                             r"810 people on 150 m², got 900"):
        CrowdProfile.from_counts([0, 60], [10, 900], 150.0)
    with pytest.raises(ParameterError, match=r"count must be finite and >= 0 people, got -3"):
        CrowdProfile.from_counts([0, 60], [10, -3], 150.0)
    with pytest.raises(ParameterError, match=r"area must be > 0 m²"):
        CrowdProfile.from_counts([0, 60], [10, 3], 0.0)


def test_times_in_minutes_are_doubted():
    # A table that ends within the first thirtieth of the record but spans it ×60 or ×3600 is
    # likely in minutes or hours (common rules: PlausibilityWarning naming the value, the mix-up
    # and the value it would then be).
    assert CrowdProfile([0, 30, 60], [0.2, 0.5, 1.0]).implausibilities(3600.0) == [
        "crowd profile times end at 60 s of a 3600 s record: in minutes? (they would span "
        "3600 s)"]
    assert "in hours?" in CrowdProfile([0, 1], [0.2, 1.0]).implausibilities(3600.0)[0]
    assert RAMP.implausibilities(3600.0) == [] and DAY.implausibilities(600.0) == []
    # A profile of one point, or one ending before t = 0, has no span to doubt.
    assert CrowdProfile.constant(0.5).implausibilities(3600.0) == []
