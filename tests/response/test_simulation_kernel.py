"""The simulation kernel's paths: several modes with HSI, non-uniform stations, lanes, slots (issue 14).

The one-mode, uniform-grid path is what the paper example runs; these tests hold the other paths
of ``response/_kernels.py`` and ``response/_slots.py`` to independent references.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from crowdvib import Crowd, ModalModel, MSDModel, Pedestrian, simulate
from crowdvib.errors import PlausibilityWarning
from crowdvib.response.time_domain import _slots


def test_standing_msd_on_two_modes_matches_an_ode_solver():
    # Reference: scipy's DOP853 (rtol 1e-11) on the same equations of motion (docs: theory,
    # Equations of motion), written out here for one standing walker at x = 15 m of a two-mode
    # beam, so that both modes carry it and the unsprung mass couples them:
    #   (M_s + m_h0 φφᵀ) z̈ + C ż + K z = φ [p + k (u − φᵀz) + c (u̇ − φᵀż)]
    #   m_h1 ü = −k (u − φᵀz) − c (u̇ − φᵀż),   p = W α sin(2π f t),
    # the walker at rest relative to the still deck at t = 0. RK4 at h = 2 ms (ω h <= 0.06 for
    # the 4.6 Hz mode) is within ~1e-6 of the peak; the tolerance is 1e-4 of the peak.
    with pytest.warns(PlausibilityWarning, match="kg/m²"):  # light on purpose: one walker shows
        bridge = ModalModel.simply_supported_beam(50.0, 3.0, [2.0, 4.6], [0.01, 0.02],
                                                  [800.0, 600.0], n_modes=2,
                                                  outputs={"x20": 20.0})
    msd = MSDModel(3.0, 0.30, 0.80)
    body, f, dlf = 70.0, 2.1, 0.3
    walker = Pedestrian(0.0, 0.0, f, body, harmonics=[(1.0, dlf, 0.0)], position=15.0)
    record = simulate(bridge, duration=20.0, pedestrians=[walker], msd=msd, rng=0,
                      sample_rate=500.0)

    phi = np.sin(np.pi * np.array([1, 2]) * 15.0 / 50.0)
    out = np.sin(np.pi * np.array([1, 2]) * 20.0 / 50.0)
    m1, k, c = msd.sprung_mass(body), msd.stiffness(body), msd.damping(body)
    wn = 2 * np.pi * np.array([2.0, 4.6])
    ms = np.array([800.0, 600.0])
    mass = np.diag(ms) + (body - m1) * np.outer(phi, phi)
    damping = np.diag(2 * np.array([0.01, 0.02]) * ms * wn)
    stiffness = np.diag(ms * wn**2)

    def accelerations(t, y):
        z, u, zd, ud = y[:2], y[2], y[3:5], y[5]
        contact = k * (u - phi @ z) + c * (ud - phi @ zd)
        p = body * 9.81 * dlf * np.sin(2 * np.pi * f * t)
        zdd = np.linalg.solve(mass, phi * (p + contact) - damping @ zd - stiffness @ z)
        return zdd, -contact / m1

    def rhs(t, y):
        zdd, udd = accelerations(t, y)
        return np.concatenate([y[3:6], zdd, [udd]])

    times = record.time
    solution = solve_ivp(rhs, (0.0, times[-1]), np.zeros(6), method="DOP853", t_eval=times,
                         rtol=1e-11, atol=1e-14)
    expected = np.array([out @ accelerations(t, y)[0] for t, y in zip(times, solution.y.T)])
    peak = np.abs(expected).max()
    assert peak > 0.05                                  # a real response, not a trivial zero
    np.testing.assert_allclose(record.acceleration[0], expected, rtol=0, atol=1e-4 * peak)


def _two_lane_bridge(positions):
    """Two modes over two lanes, sampled at ``positions`` from the same piecewise-linear shapes."""
    grid = np.linspace(0.0, 40.0, 21)
    bend = np.sin(np.pi * grid / 40.0)
    second = np.sin(2 * np.pi * grid / 40.0)
    shapes = np.empty((2, positions.size, 2))
    for lane, sign in enumerate((-1.0, 1.0)):
        shapes[lane, :, 0] = np.interp(positions, grid, bend)
        shapes[lane, :, 1] = np.interp(positions, grid, 0.6 * second + 0.4 * sign * bend)
    return ModalModel(frequencies=[2.0, 3.1], damping_ratios=[0.01, 0.01],
                      modal_masses=[2e3, 3e3], positions=positions, mode_shapes=shapes,
                      width=3.0, lanes=[0.0, 3.0], output_names=("a", "b"),
                      output_shapes=[[1.0, 0.5], [0.2, -1.0]])


def test_non_uniform_stations_give_the_same_record():
    # Reference: the same piecewise-linear shapes sampled at extra stations on their own
    # segments are the same functions (linear interpolation reproduces a linear segment), so
    # the segment walk of a non-uniform grid must give the record of the uniform grid's direct
    # look-up up to rounding. Two modes, two lanes, HSI: the general paths of the kernel.
    uniform = np.linspace(0.0, 40.0, 21)
    extra = np.array([1.0, 3.5, 11.0, 11.5, 27.25, 39.0])
    uneven = np.union1d(uniform, extra)
    crowd = Crowd(density=0.4, walking_speed=1.3, step_frequency_mean=1.9,
                  step_frequency_std=0.15, body_mass=70.0)
    options = {"msd": MSDModel(3.0, 0.3, 0.9), "rng": 5, "warm_up": 2.0,
               "record_modal_load": True}
    direct = simulate(_two_lane_bridge(uniform), crowd, 30.0, **options)
    walked = simulate(_two_lane_bridge(uneven), crowd, 30.0, **options)
    assert direct.n_on_deck.max() > 10
    np.testing.assert_array_equal(direct.n_on_deck, walked.n_on_deck)
    scale = np.abs(direct.acceleration).max()
    np.testing.assert_allclose(walked.acceleration, direct.acceleration, rtol=0,
                               atol=1e-9 * scale)
    np.testing.assert_allclose(walked.modal_load, direct.modal_load, rtol=0,
                               atol=1e-9 * np.abs(direct.modal_load).max())


def test_slot_capacity_covers_the_most_walkers_at_once():
    # Reference: a brute-force count of the half-open intervals [t_on, t_off) holding each
    # t_on (the kernel integrates a walker at step t when t_on <= t < t_off), with ties where
    # one walker steps off as another steps on.
    rng = np.random.default_rng(3)
    t_on = np.sort(np.round(rng.uniform(0.0, 100.0, 400), 1))
    t_off = t_on + np.round(rng.uniform(0.5, 30.0, 400), 1)
    t_off[::7] = np.inf                                   # standing walkers stay
    most = max(np.sum((t_on <= t) & (t < t_off)) for t in t_on)
    capacity = _slots.slot_capacity(t_on, t_off)
    assert most < capacity <= most + 16
    assert capacity % 8 == 0 and capacity % 512 != 0


def test_chunks_reproduce_one_call_on_the_general_path():
    # Reference: the same run in one kernel call (the documented contract of chunk_duration,
    # here for two modes, two lanes and non-uniform stations, whose sums over the walkers are
    # split into vector partial sums: their order must not depend on the chunking).
    bridge = _two_lane_bridge(np.union1d(np.linspace(0.0, 40.0, 21), [2.5, 17.0, 33.3]))
    crowd = Crowd(density=0.4, walking_speed=1.3, step_frequency_mean=1.9,
                  step_frequency_std=0.15, body_mass=70.0)
    options = {"msd": MSDModel(3.0, 0.3, 0.9), "rng": 11, "record_modal_load": True}
    whole = simulate(bridge, crowd, 40.0, chunk_duration=100.0, **options)
    chunked = simulate(bridge, crowd, 40.0, chunk_duration=0.37, **options)
    np.testing.assert_array_equal(chunked.acceleration, whole.acceleration)
    np.testing.assert_array_equal(chunked.modal_load, whole.modal_load)
    assert np.abs(whole.acceleration).max() > 0


def test_walkers_on_the_deck_are_those_between_their_on_and_off_times():
    # Reference: the kernel integrates walker k at step t exactly when t_on <= t < t_off
    # (docs: theory, Walkers on the deck as arrays), counted here by brute force from the run's
    # own arrival and leaving times. The kernel decides who leaves by comparing t with the
    # earliest t_off on the deck, kept across kernel calls: a run in short chunks (0.37 s) and
    # a crowd with walkers in both directions (different leaving orders) exercise both.
    from crowdvib.response.time_domain._integrator import prepare
    from crowdvib.response.time_domain.simulation import checked_run

    crowd = Crowd(density=0.3, walking_speed=1.3, step_frequency_mean=1.9,
                  step_frequency_std=0.15, body_mass=70.0, forward_fraction=0.5)
    bridge = _two_lane_bridge(np.linspace(0.0, 40.0, 21))
    record = simulate(bridge, crowd, 60.0, msd=MSDModel(3.0, 0.3, 0.9), rng=4,
                      chunk_duration=0.37)
    run = prepare(checked_run(bridge, crowd, 60.0, msd=MSDModel(3.0, 0.3, 0.9), rng=4))
    t_on, t_off = run.walkers.t_on, run.walkers.t_off       # everybody of a short run
    times = np.arange(record.n_on_deck.size) / 100.0
    expected = [np.sum((t_on <= t) & (t < t_off)) for t in times]
    assert max(expected) > 15 and np.ptp(expected) > 10      # walkers come and go
    np.testing.assert_array_equal(record.n_on_deck, expected)


def test_the_paper_path_agrees_with_the_general_kernel():
    # Reference: the general entry point (several-mode RK4 step, segment walk) on the same run.
    # The paper's path (one mode, uniform grid: response/_stages.step_msd_one_mode and
    # _slots.rows_uniform, written out for speed) solves the same equations; it divides by the
    # 1×1 mass matrix instead of twice by its Cholesky factor, and the compiler may group the
    # vector partial sums over the walkers differently, so the records agree to rounding: within
    # 1e-9 of the RMS (issue 28 §4; ~1e-14 measured against the code before the change).
    from crowdvib.models.examples import paper_example
    from crowdvib.response.time_domain import _kernels
    from crowdvib.response.time_domain._integrator import prepare
    from crowdvib.response.time_domain.simulation import checked_run

    case = paper_example()
    records = []
    for kind in (None, (_kernels.MSD, _kernels.GENERAL)):
        spec = checked_run(case.structure, case.crowd, 20.0, msd=case.msd, rng=3,
                           include_static_weight=True)
        run, n_samples = prepare(spec), spec.n_samples
        if kind is not None:
            assert run.kernel is not _kernels.ENTRY_POINTS[kind]
            run.kernel = _kernels.ENTRY_POINTS[kind]
        run.advance(n_samples * run.substeps)
        records.append(run.acceleration[:, :n_samples].copy())
    fast, general = records
    rms = np.sqrt(np.mean(general**2))
    assert rms > 0.05                                     # a real response
    np.testing.assert_allclose(fast, general, rtol=0, atol=1e-9 * rms)
