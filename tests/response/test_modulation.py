"""The slow-modulation correction to the quasi-static mixture (docs: theory, The fluctuating
crowd, Beyond the quasi-static mixture)."""

import dataclasses
import warnings

import numpy as np
import pytest

from crowdvib import (Crowd, ModalModel, MSDModel, TunedMassDamper,
                      effective_modal_properties)
from crowdvib.errors import ParameterError, PlausibilityWarning
import crowdvib.response.frequency_domain._modulation as module
from crowdvib.response.frequency_domain._modulation import (OccupancyPath, _OccupiedMode, drift_spectrum,
                                           modulation_correction, occupancy_rate_variance)
from crowdvib.response.frequency_domain.fluctuation import FluctuatingSpectralModel, occupancy_cumulants
from crowdvib.response.frequency_domain.spectral import SpectralModel

GRID = np.arange(601) / 60.0


def test_rate_variance_of_a_half_sine(paper_bridge):
    # Campbell: Var ψ̇ = d v² ∫(∂φ²/∂x)² dA = d v² B π²/(2L) and ψ̄ = d B L / 2 for φ = sin(πx/L),
    # so Var λ̇ = 2π² v² / (d B L³); the stations' differences reach it to 1e-4.
    for density, speed in ((0.25, 1.34), (1.0, 0.8)):
        expected = 2 * np.pi**2 * speed**2 / (density * 3.0 * 50.0**3)
        assert occupancy_rate_variance(paper_bridge, density, speed, 0) == pytest.approx(
            expected, rel=1e-4)


def _half_sine_correlation(lag, speed, length=50.0):
    """Campbell's ρ(u) = ∫ sin²(πx/L) sin²(π(x + vu)/L) dx / (3L/8) in closed form, θ = πvu/L:
    [(2π − 2θ)(1 + cos 2θ / 2) + (3/2) sin 2θ] / (3π) while vu < L, else 0."""
    theta = np.minimum(np.pi * speed * np.abs(lag) / length, np.pi)
    return ((2 * np.pi - 2 * theta) * (1 + np.cos(2 * theta) / 2)
            + 1.5 * np.sin(2 * theta)) / (3 * np.pi)


def _paper_path(bridge, density, speed):
    return OccupancyPath(bridge, speed, 0, variance=occupancy_cumulants(bridge, density, 0, 2)[1],
                         rate_variance=occupancy_rate_variance(bridge, density, speed, 0))


def test_correlation_of_a_half_sine(paper_bridge):
    # ρ from the stations (interpolated φ²) against the closed form, to 1e-4; it vanishes once
    # the walkers present have crossed, and −σ² ρ''(0) is the rate variance (both Campbell;
    # the difference quotient over 1 s, a few stations, is within 2 % of ρ''(0) at 1.34 m/s).
    path = _paper_path(paper_bridge, 0.25, 1.34)
    lags = np.linspace(0.0, 45.0, 91)
    np.testing.assert_allclose(path.correlation(lags), _half_sine_correlation(lags, 1.34),
                               atol=1e-4)
    h = 1.0
    curvature = (path.correlation(np.array([h]))[0] - 1.0) * 2 / h**2
    assert -path.variance * curvature == pytest.approx(path.rate_variance, rel=2e-2)


def _monte_carlo(path, speed, mean_pole, slopes, omega, count=6000, step=0.2, duration=110.0):
    """E|G|² − E|G_frozen|² over stationary Gaussian paths λ(t) with the half sine's ρ
    (Cholesky of the covariance: no conditioning, no cumulants, no Filon), for poles
    p = p̄ + p₁ (λ − 1): G = ∫ exp(∫₀^u (p(λ) − iω) dτ) du along each path, G_frozen with λ held
    at λ(0). → mean and standard error per slope and frequency."""
    t = np.arange(0.0, duration + step / 2, step)
    covariance = path.variance * _half_sine_correlation(np.subtract.outer(t, t), speed)
    factor = np.linalg.cholesky(covariance + 1e-12 * np.eye(t.size))
    weights = np.full(t.size, step)
    weights[[0, -1]] = step / 2
    rng = np.random.default_rng(12)
    differences = [[] for _ in slopes]
    for _ in range(count // 1000):
        paths = 1.0 + rng.standard_normal((1000, t.size)) @ factor.T
        for found, slope in zip(differences, slopes):
            poles = mean_pole + slope * (paths - 1.0)
            exponent = np.concatenate([np.zeros((len(paths), 1)), np.cumsum(
                (poles[:, 1:] + poles[:, :-1]) * step / 2, axis=1)], axis=1)
            moving = np.exp(exponent[:, np.newaxis, :] - 1j * omega[:, np.newaxis] * t)
            frozen = np.exp(np.multiply.outer(poles[:, :1] - 1j * omega, t))
            found.append(np.abs(moving @ weights) ** 2 - np.abs(frozen @ weights) ** 2)
    differences = [np.concatenate(found) for found in differences]
    return ([d.mean(axis=0) for d in differences],
            [d.std(axis=0, ddof=1) / np.sqrt(len(d)) for d in differences])


def test_drift_against_gaussian_paths(paper_bridge):
    # Fast walkers, so the effect is large: 3 m/s on the paper's bridge at 0.25 P/m² (ε ≈ 4),
    # poles linear in λ with the paper's slope there. The formula is averaged over
    # λ₀ ~ N(1, σ²) (Gauss–Hermite), the pole followed along the mean path from λ₀.
    speed = 3.0
    path = _paper_path(paper_bridge, 0.25, speed)
    mean_pole = -0.11 + 2j * np.pi * 1.96
    slopes = (-0.23j, -0.04 - 0.23j)
    omega = 2 * np.pi * np.array([1.93, 1.955, 1.96, 1.965, 1.99])
    simulated, errors = _monte_carlo(path, speed, mean_pole, slopes, omega)
    nodes, weights = np.polynomial.hermite_e.hermegauss(20)
    occupancy = 1.0 + np.sqrt(path.variance) * nodes
    levels = occupancy[:, np.newaxis] + (1.0 - occupancy[:, np.newaxis]) * module._TRACK
    frozen_peak = 1 / 0.11**2
    for slope, mean, error in zip(slopes, simulated, errors):
        spectra = drift_spectrum(mean_pole + slope * (levels - 1.0),
                                 np.full(levels.shape, slope), path, omega)
        predicted = weights / weights.sum() @ spectra
        assert np.abs(predicted).max() > 0.04 * frozen_peak        # a large effect …
        if slope.real == 0:
            # … exact when the occupancy moves the frequency only (the cumulant of a Gaussian
            # phase): within three standard errors of the Monte Carlo,
            np.testing.assert_array_less(np.abs(predicted - mean), 3 * error)
        else:
            # … and with the damping moving too, whose squared fluctuation is left out (it
            # would let rare paths of the linearised pole go undamped): 6 % of the effect here.
            np.testing.assert_array_less(np.abs(predicted - mean),
                                         3 * error + 0.1 * np.abs(mean).max())


def test_quadrature_converges(paper_bridge, paper_msd, monkeypatch):
    # The grid follows the path, the exponentials are integrated exactly and the h² error is
    # extrapolated away: ten times the points and a longer memory move the correction by
    # 7e-4 of its own peak (1e-5 of the PSD's) on the paper example; the bound is 2e-3.
    crowd = Crowd.from_density(0.25)
    model = FluctuatingSpectralModel(paper_bridge, crowd, GRID)
    args = (paper_bridge, model._base._attached(paper_msd), model._base._shapes, 0,
            model.nodes, model.weights, model._path, GRID)
    default = modulation_correction(*args)
    monkeypatch.setattr(module, "_PER_SCALE", 64)
    monkeypatch.setattr(module, "_MEMORIES", 16.0)
    fine = modulation_correction(*args)
    assert np.abs(fine - default).max() < 2e-3 * np.abs(fine).max()


def test_poles_along_the_mean_path(paper_bridge, paper_msd):
    # The single pole r/(iω − p) against the occupied system's transfer C(iω − A)⁻¹b near its
    # peak: within 3 % (what the other, heavily damped pole adds there). The track ends at the
    # mean crowd's pole (λ = 1) from either side, and the slope matches wider differences.
    attached = SpectralModel(paper_bridge, Crowd.from_density(0.5), GRID)._attached(paper_msd)
    occupied = _OccupiedMode(paper_bridge, attached, 0)
    track, slope, residue, node = occupied.drifting_poles(np.array([0.8, 1.2]))
    assert node.tolist() == [0, 1]
    mean = np.linalg.eigvals(occupied.system(1.0)[0])
    for i, occupancy in enumerate((0.8, 1.2)):
        state, load = occupied.system(occupancy)
        pole = track[i, 0]
        for f in pole.imag / (2 * np.pi) + np.array([-0.01, 0.0, 0.01]):
            omega = 2 * np.pi * f
            direct = abs((np.linalg.solve(1j * omega * np.eye(4) - state, load))[0, 0]) ** 2
            assert residue[i] / abs(1j * omega - pole) ** 2 == pytest.approx(direct, rel=0.03)
        assert np.min(np.abs(mean - track[i, -1])) < 1e-12 * abs(track[i, -1])
        for k in (0, 8):
            level = occupancy + (1.0 - occupancy) * module._TRACK[k]
            h = 0.02
            near = [p[np.argmin(abs(p - track[i, k]))] for p in (
                np.linalg.eigvals(occupied.system(level + j * h)[0]) for j in (-1, 1))]
            assert slope[i, k] == pytest.approx((near[1] - near[0]) / (2 * h), rel=1e-3)


def test_correction_is_left_out_without_hsi_or_with_one_node(paper_bridge, paper_crowd,
                                                             paper_msd):
    # Without MSDs nothing in the system depends on λ but the load's intensity, whose mean is
    # the mixture's: the correction is zero. One node is the smeared model, by definition.
    on = FluctuatingSpectralModel(paper_bridge, paper_crowd, GRID, welch_window_length=60.0)
    off = FluctuatingSpectralModel(paper_bridge, paper_crowd, GRID, welch_window_length=60.0,
                                   modulation=False)
    assert on.rate_variance > 0 and off.rate_variance == 0
    np.testing.assert_array_equal(on.psd_array(None), off.psd_array(None))
    one = FluctuatingSpectralModel(paper_bridge, paper_crowd, GRID, welch_window_length=60.0,
                                   n_nodes=1)
    np.testing.assert_array_equal(
        one.psd_array(paper_msd),
        SpectralModel(paper_bridge, paper_crowd, GRID, welch_window_length=60.0,
                      crossing_spread=one.crossing_spread).psd_array(paper_msd))
    # With HSI it moves the occupied resonance by a few tenths of a per cent of the peak at
    # 0.5 P/m² and 1.30 m/s (0.45 % here; docs: the band table, 0.3–0.5 % at 0.5 P/m²).
    a, b = on.psd_array(paper_msd)[0], off.psd_array(paper_msd)[0]
    assert 0.002 < np.abs(a - b).max() / b.max() < 0.05


def test_no_lightly_damped_pole_no_correction(paper_msd):
    # A structure damped at 25 %: no pole of the occupied system is below the 0.2 damping ratio
    # that carries the correction, so the model is the mixture alone (and does not fail).
    with pytest.warns(PlausibilityWarning, match="damping_ratios"):    # on purpose (issue 24)
        bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.25, 50e3)
    crowd = Crowd.from_density(0.25)
    model = FluctuatingSpectralModel(bridge, crowd, GRID, welch_window_length=60.0)
    plain = FluctuatingSpectralModel(bridge, crowd, GRID, welch_window_length=60.0,
                                     modulation=False)
    assert model.rate_variance > 0
    np.testing.assert_array_equal(model.psd_array(paper_msd), plain.psd_array(paper_msd))
    np.testing.assert_array_equal(model.cross_psd_array(paper_msd),
                                  plain.cross_psd_array(paper_msd))


def test_cross_spectral_matrix_carries_the_same_correction(paper_msd):
    # Two outputs of a two-mode beam: the diagonal of the corrected cross-spectral matrix is the
    # corrected PSD, and the matrix stays Hermitian.
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3, n_modes=2,
                                              outputs={"mid": 25.0, "quarter": 12.5})
    crowd = Crowd.from_density(0.5)
    model = FluctuatingSpectralModel(bridge, crowd, GRID, welch_window_length=60.0)
    assert model.rate_variance > 0
    cross = model.cross_psd_array(paper_msd)
    np.testing.assert_allclose(np.einsum("aaf->af", cross).real, model.psd_array(paper_msd),
                               rtol=1e-9, atol=1e-12 * cross.real.max())
    np.testing.assert_allclose(cross, np.conj(np.swapaxes(cross, 0, 1)),
                               atol=1e-12 * np.abs(cross).max())


def test_correction_is_negligible_beyond_its_reach(paper_bridge, paper_msd, monkeypatch):
    # Computed within 40 half-power widths of the occupied pole: against a reach of 400, the
    # truncated part is below 1e-3 of the PSD's peak.
    crowd = Crowd.from_density(0.25)
    model = FluctuatingSpectralModel(paper_bridge, crowd, GRID)
    attached = model._base._attached(paper_msd)
    args = (paper_bridge, attached, model._base._shapes, 0, model.nodes, model.weights,
            model._path, GRID)
    default = modulation_correction(*args)
    monkeypatch.setattr(module, "_REACH", 400.0)
    monkeypatch.setattr(module, "_MIN_REACH", 5.0)
    wide = modulation_correction(*args)
    mixture = FluctuatingSpectralModel(paper_bridge, crowd, GRID, modulation=False)
    weight = model._base._weight_at(GRID)
    assert np.abs((wide - default) * weight).max() < 1e-3 * mixture.psd_array(paper_msd).max()
    assert np.abs(default).max() > 0


def test_expansion_parameter_from_independent_pieces(paper_bridge):
    # ε = Var λ̇ / (Var λ Γ²) with Var λ̇ = 2π²v²/(dBL³) and Var λ = 3/(2n), n = dBL walkers
    # (Campbell, closed forms for the half sine), Γ = ξ 2πf of the occupied mode with the
    # paper's MSD (effective_modal_properties, the smeared model's own poles).
    crowd = Crowd.from_density(0.25)
    occupied = effective_modal_properties(paper_bridge, crowd, MSDModel())
    decay = occupied.damping_ratios[0] * 2 * np.pi * occupied.frequencies[0]
    walkers = crowd.density * 3.0 * 50.0
    for speed in (crowd.walking_speed, 3.0):
        model = FluctuatingSpectralModel(paper_bridge,
                                         dataclasses.replace(crowd, walking_speed=speed), GRID)
        expected = (2 * np.pi**2 * speed**2 / (crowd.density * 3.0 * 50.0**3)
                    / (1.5 / walkers * decay**2))
        assert model.modulation_parameter == pytest.approx(expected, rel=2e-3)


def test_fast_walkers_narrow_the_mixture_to_the_mean_crowd(paper_bridge, paper_msd):
    # Kubo's motional narrowing: when the occupancy changes much faster than the mode forgets
    # (30 m/s, ε ≈ 400), the resonance sees the mean crowd, and mixture + correction tends to
    # the smeared model (same crossing kernel); at walking pace it stays near the mixture.
    crowd = Crowd.from_density(0.25)
    frequency = np.arange(1.85, 2.05, 0.002)

    def gaps(speed):
        if speed > 3.0:      # beyond walking on purpose: the crowd says so (issue 24)
            with pytest.warns(PlausibilityWarning, match=f"walking_speed = {speed:g} m/s"):
                fast = dataclasses.replace(crowd, walking_speed=speed)
        else:
            fast = dataclasses.replace(crowd, walking_speed=speed)
        with warnings.catch_warnings():
            warnings.simplefilter("error")        # no range warning at any speed
            model = FluctuatingSpectralModel(paper_bridge, fast, frequency)
        mixture = FluctuatingSpectralModel(paper_bridge, fast, frequency, modulation=False)
        smeared = SpectralModel(paper_bridge, fast, frequency,
                                crossing_spread=model.crossing_spread)
        a, b, c = (m.psd_array(paper_msd)[0] for m in (model, mixture, smeared))
        return np.abs(a - c).max() / c.max(), np.abs(b - c).max() / c.max(), model

    to_smeared, mixture_gap, model = gaps(30.0)
    assert model.modulation_parameter > 100
    assert to_smeared < 0.25 * mixture_gap
    to_smeared, mixture_gap, model = gaps(crowd.walking_speed)
    assert to_smeared > 0.5 * mixture_gap


def test_with_step_frequencies_keeps_the_correction(paper_bridge, paper_msd):
    # The estimator's free step frequencies rebuild the models: the corrected PSD must equal a
    # model built directly for that crowd.
    crowd = Crowd.from_density(0.25)
    other = dataclasses.replace(crowd, step_frequency_mean=1.95, step_frequency_std=0.2)
    model = FluctuatingSpectralModel(paper_bridge, crowd, GRID, welch_window_length=60.0)
    direct = FluctuatingSpectralModel(paper_bridge, other, GRID, welch_window_length=60.0)
    first = model.psd_array(paper_msd)     # its correction per unit load is kept, and shared
    np.testing.assert_allclose(model.with_step_frequencies(other).psd_array(paper_msd),
                               direct.psd_array(paper_msd), rtol=1e-12)
    assert np.abs(direct.psd_array(paper_msd) - first).max() > 0.01 * first.max()


def _kappa_from_pieces(bridge, crowd):
    """κ = σ_λ |dω_p/dλ| / Γ from independent pieces: σ_λ² = 3/(2n) for a half sine with n = dBL
    walkers (Campbell), the occupied mode's damped frequency and decay from
    effective_modal_properties (the smeared model's poles) with the density scaled by λ = 1 ± h,
    the paper's MSD."""
    walkers = crowd.density * bridge.width * bridge.length
    poles = []
    for level in (1 - 1e-3, 1.0, 1 + 1e-3):
        occupied = effective_modal_properties(bridge, crowd.with_density(crowd.density * level),
                                              MSDModel())
        f, xi = occupied.frequencies[0], occupied.damping_ratios[0]
        poles.append(2 * np.pi * f * (-xi + 1j * np.sqrt(1 - xi**2)))
    slope = (poles[2] - poles[0]) / 2e-3
    return np.sqrt(1.5 / walkers) * abs(slope.imag) / -poles[1].real


def test_correction_applied_where_checked_against_the_simulator(paper_bridge, paper_msd):
    # κ, the occupied resonance's shift over one standard deviation of the occupancy in
    # half-power half-widths, against independent pieces (within 1 %). The paper's bridge
    # (κ ≈ 0.42, where the correction matches the simulator) gets the correction by default; a
    # 20 m bridge whose 12 walkers carry 10 % of the modal mass (κ ≈ 1.4, where the simulator
    # reads the mixture alone: docs, Beyond the quasi-static mixture) does not, unless asked.
    small = ModalModel.simply_supported_beam(20.0, 2.0, 2.0, 0.005, 4200.0)
    few = Crowd(density=0.3, walking_speed=1.3, step_frequency_mean=1.95,
                step_frequency_std=0.175, body_mass=70.0)
    for bridge, crowd, applied in ((paper_bridge, Crowd.from_density(0.25), True),
                                   (small, few, False)):
        model = FluctuatingSpectralModel(bridge, crowd, GRID, welch_window_length=60.0)
        expected = _kappa_from_pieces(bridge, crowd)
        assert model.spread_parameter == pytest.approx(expected, rel=0.01)
        assert model.modulation is applied and bool(expected < 0.5) is applied
        forced = FluctuatingSpectralModel(bridge, crowd, GRID, welch_window_length=60.0,
                                          modulation=True)
        plain = FluctuatingSpectralModel(bridge, crowd, GRID, welch_window_length=60.0,
                                         modulation=False)
        assert forced.modulation and not plain.modulation
        assert plain.spread_parameter == 0.0
        on, off = forced.psd_array(paper_msd)[0], plain.psd_array(paper_msd)[0]
        assert np.abs(on - off).max() > 1e-3 * off.max()
        np.testing.assert_array_equal(model.psd_array(paper_msd)[0], on if applied else off)
    with pytest.raises(ParameterError, match="modulation"):
        FluctuatingSpectralModel(paper_bridge, few, GRID, modulation="yes")


# ------------------------------------------------------------------ the computation before its
# speed-up (issue 25 §1), kept as the reference: src/crowdvib/response/_modulation.py at commit
# 0e6e805 — scipy's trapezoids, the full N × N integrand, complex running products, and the
# slope from three eigenvalue problems per level.
def _reference_on_grid(track, slope, path, omega, u, rho, covariance):
    from scipy.integrate import cumulative_trapezoid

    def cumulative(values):
        return cumulative_trapezoid(values, dx=u[1], axis=-1, initial=0)

    def powers(base):
        factors = np.repeat(base[:, np.newaxis], u.size, axis=-1)
        factors[:, 0] = 1.0
        return np.cumprod(factors, axis=-1)

    pole, step, count = track[:, :1], u[1], u.size
    along, rate = (np.array([np.interp(1.0 - rho, module._TRACK, x.real)
                             + 1j * np.interp(1.0 - rho, module._TRACK, x.imag) for x in rows])
                   for rows in (track, slope))

    def moment(left, right):
        inner = cumulative(left[:, :, np.newaxis] * path.variance * covariance
                           * right[:, np.newaxis, :])
        return cumulative(inner.swapaxes(-1, -2)).swapaxes(-1, -2)

    yy, xy = moment(rate.imag, rate.imag), moment(rate.real, rate.imag)
    exponent = (cumulative(along) - 1j * pole.imag * u
                + np.diagonal(2j * xy - yy, axis1=-2, axis2=-1) / 2)
    envelope = np.exp(pole.real * u)
    weighted = (np.exp(exponent[:, :, np.newaxis] + exponent.conj()[:, np.newaxis, :]
                       + yy + 1j * (np.swapaxes(xy, -1, -2) - xy))
                - envelope[:, :, np.newaxis] * envelope[:, np.newaxis, :])
    sums = np.array([[np.trace(w, offset=-lag) for lag in range(count)] for w in weighted])
    rotation = powers(np.exp(-1j * omega * step))
    spin = powers(np.exp(1j * pole.imag[:, 0] * step))
    total = sums[:, :1].real + 2 * ((sums[:, 1:] * spin[:, 1:]) @ rotation[:, 1:].T).real
    z = pole - 1j * omega
    hat = step * (np.sinh(z * step / 2) / (z * step / 2)) ** 2
    first = (np.expm1(z * step) - z * step) / (z**2 * step)
    row = (weighted[:, 0, :] * spin.conj()) @ rotation.conj().T
    return np.abs(hat) ** 2 * (total + 2 * ((first / hat - 1.0) * row).real)


def _reference_drift_spectrum(track, slope, path, omega):
    u, rho = module._path_grid(path, float(-track.real.max()))
    lag = np.abs(np.subtract.outer(np.arange(u.size), np.arange(u.size)))
    covariance = rho[lag] - np.multiply.outer(rho, rho)    # the linear prediction's error
    fine = _reference_on_grid(track, slope, path, omega, u, rho, covariance)
    coarse = _reference_on_grid(track, slope, path, omega, u[::2], rho[::2],
                                covariance[::2, ::2])
    return (4 * fine - coarse) / 3


def _reference_slopes(occupied, nodes):
    """dp/dλ along the track as central differences of the poles at λ ± h (the nearest to the
    previous point of the track)."""
    levels = nodes[:, np.newaxis] + (1.0 - nodes[:, np.newaxis]) * module._TRACK
    step = module._STEP * np.maximum(levels, module._STEP)[..., np.newaxis]
    poles = np.linalg.eigvals(occupied.system(levels[..., np.newaxis]
                                              + np.array([-1, 0, 1]) * step)[0])
    centre = poles[:, 0, 1]
    node, which = np.nonzero(module._is_light(centre))
    current, slopes = centre[node, which], []
    for k in range(module._TRACK.size):
        near = np.abs(poles[node, k] - current[:, np.newaxis, np.newaxis]).argmin(axis=-1)
        below, current, above = (poles[node, k, j, near[:, j]] for j in range(3))
        slopes.append((above - below) / (2 * step[node, k, 0]))
    return np.array(slopes).T


def test_drift_spectrum_is_the_reference_rearranged(paper_bridge, paper_msd):
    # The speed-up only rearranges the arithmetic (running sums as a trapezoid matrix, the
    # Hermitian integrand's lower triangle by lag, real products, powers by doubling, Filon's
    # weights from one expm1): the reference above to 1e-10 of the peak, for the paper's poles
    # at 0.25 and 1.0 P/m² and for walkers at 3 m/s (a path faster than the memory).
    omega = 2 * np.pi * np.linspace(1.7, 2.2, 41)
    for density, speed in ((0.25, 1.34), (1.0, 0.8), (0.25, 3.0)):
        crowd = dataclasses.replace(Crowd.from_density(density), walking_speed=speed)
        model = FluctuatingSpectralModel(paper_bridge, crowd, GRID, modulation=True)
        occupied = _OccupiedMode(paper_bridge, model._base._attached(paper_msd), 0)
        track, slope, _, _ = occupied.drifting_poles(model.nodes)
        expected = _reference_drift_spectrum(track, slope, model._path, omega)
        obtained = drift_spectrum(track, slope, model._path, omega)
        assert np.abs(expected).max() > 0
        np.testing.assert_allclose(obtained, expected, rtol=0,
                                   atol=1e-10 * np.abs(expected).max())


def test_slopes_by_perturbation_keep_the_quadrature_accuracy(paper_bridge, paper_msd):
    # dp/dλ from one eigen-decomposition per level (first-order perturbation of the state
    # matrix's central difference) against the poles' own central differences (the reference
    # above): both err as h² (h = 1e-3 λ), here within 1e-5, and the correction moves by less
    # than the 7e-4 of its quadrature (module docstring of _modulation): three MSDs, and a
    # tuned mass damper beside the MSD tuned near the mode (two light poles per node).
    damper = TunedMassDamper(mass=1000.0, frequency=1.95, damping_ratio=0.06, position=25.0)
    for msd, dampers in ((paper_msd, ()), (MSDModel(1.9, 0.1, 0.95), ()),
                         (MSDModel(2.5, 0.5, 0.95), ()), (MSDModel(2.0, 0.15, 0.95), (damper,))):
        model = FluctuatingSpectralModel(paper_bridge, Crowd.from_density(0.25), GRID,
                                         dampers=dampers, modulation=True)
        occupied = _OccupiedMode(paper_bridge, model._base._attached(msd), 0)
        track, slope, _, _ = occupied.drifting_poles(model.nodes)
        reference = _reference_slopes(occupied, model.nodes)
        np.testing.assert_allclose(slope, reference, rtol=0, atol=1e-5 * np.abs(reference).max())
        omega = 2 * np.pi * np.linspace(1.7, 2.2, 41)
        expected = drift_spectrum(track, reference, model._path, omega)
        np.testing.assert_allclose(drift_spectrum(track, slope, model._path, omega), expected,
                                   rtol=0, atol=7e-4 * np.abs(expected).max())


def test_a_walker_pole_of_a_long_memory_leaves_the_bridges_correction_finite():
    # An estimate's level check tries the MSD at the corners of its bounds (f_h1 = 1 mHz,
    # ξ_h1 = 1e-3: a walker's pole whose memory, 1/Γ = 1.6e5 s, is 1e4 times the bridge's).
    # One grid in u for both stepped an hour, Filon's weights of the bridge's pole overflowed
    # and the expected PSD was NaN (12 RuntimeWarnings of a season). Each pole group on its own
    # grid: finite, no warning, and the poles of comparable memory (the paper's MSD, and a
    # lightly damped one whose pole is 20–26 times the bridge's Γ) keep their one grid, so
    # their correction is the batched drift_spectrum's to the last bit.
    from crowdvib.models.examples import paper_example

    paper = paper_example()
    here = paper.crowd.with_density(0.3)
    frequency = np.arange(601) / 100.0
    model = FluctuatingSpectralModel(paper.structure, here, frequency)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        slow = model.psd_array(MSDModel(1e-3, 1e-3, 0.95))
    assert np.all(np.isfinite(slow)) and slow.sum() > 0
    for msd in (paper.msd, MSDModel(3.0, 0.1, 0.95)):
        occupied = _OccupiedMode(paper.structure, model._base._attached(msd), model.mode)
        track, slope, residue, node = occupied.drifting_poles(model.nodes)
        assert len(module._memory_groups(track)) == 1
        near = module._near_resonances(track[:, 0], frequency)
        batched = (model.weights[node] * residue) @ drift_spectrum(
            track, slope, model._path, 2 * np.pi * frequency[near])
        found = module.modulation_correction(
            paper.structure, model._base._attached(msd), model._base._shapes, model.mode,
            model.nodes, model.weights, model._path, frequency)
        assert np.array_equal(found[0, near], model._base._shapes[0, model.mode] ** 2 * batched)


def test_the_path_grid_of_a_short_memory_does_not_depend_on_its_last_bit(paper_bridge):
    # docs: theory, Beyond the quasi-static mixture. A memory 1/Γ shorter than the occupancy's
    # time scale is stepped _PER_SCALE times per memory out to _MEMORIES memories:
    # 2 · 12 · 6 / 2 + 1 = 73 points for every such Γ. Formed from the step, the count was 75
    # for 11 of these 2000 decays (the ceiling of 36 plus a rounding), and the correction then
    # jumped by 2e-4 between MSDs a Jacobian's step apart.
    path = _paper_path(paper_bridge, 0.5, 1.30)
    decays = np.random.default_rng(1).uniform(1.0 / path.time_scale, 50.0, 2000)
    sizes = {module._path_grid(path, decay)[0].size for decay in decays}
    assert sizes == {2 * module._MEMORIES * module._PER_SCALE / 2 + 1} == {73}
