"""The crossing replay agrees with the record it replays (issue 38, "Must show"): walkers where
the simulator's arrival times and speeds put them, the deflection from the modal coordinates
that give the record's accelerations."""

import numpy as np
import pytest

from crowdvib import ParameterError, simulate
from crowdvib.response.time_domain.replay import busiest_stretch, crossing_replay
from crowdvib.response.time_domain.traffic import generate_traffic

DURATION, WARM_UP, RATE, SEED = 120.0, 30.0, 100.0, 11


@pytest.fixture(scope="module")
def run():
    """The paper example (docs: theory, The paper's numerical example), a record and a replay
    of 10 s of it at every sample (frame rate = sample rate)."""
    from crowdvib.models.examples import paper_example

    case = paper_example()
    options = dict(msd=case.msd, sample_rate=RATE, rng=SEED, warm_up=WARM_UP)
    record = simulate(case.structure, case.crowd, DURATION, **options)
    replay = crossing_replay(case.structure, case.crowd, DURATION, start=40.0, length=10.0,
                             frame_rate=RATE, **options)
    return case, record, replay


def test_the_stretch_is_the_records_own(run):
    # The replay is the same run made again from its seed: the record's samples, bit for bit
    # (simulate is bit-identical for any chunking, docs of crowdvib.simulate).
    _, record, replay = run
    first = int(round(40.0 * RATE))
    assert replay.trace_time[0] == 40.0 and replay.trace_time.size == int(10.0 * RATE)
    np.testing.assert_array_equal(replay.acceleration,
                                  record.acceleration[:, first:first + replay.trace_time.size])


def test_walkers_are_where_their_arrival_and_speed_put_them(run):
    # Reference: the simulator's own stream as explicit pedestrians (generate_traffic, the same
    # seed and warm-up): each on the deck at t at x = x_k + v_k (t − t_k).
    case, record, replay = run
    people = generate_traffic(case.structure, case.crowd, DURATION, rng=SEED, warm_up=WARM_UP)
    length = case.structure.length
    for t in (40.0, 43.37, 49.99):
        k = int(round((t - 40.0) * RATE))
        t = replay.time[k]
        expected = []
        for p in people:
            x = p.position + p.direction * p.walking_speed * (t - p.arrival_time)
            if p.arrival_time <= t and 0.0 <= x <= length:
                expected.append(x)
        _, found = replay.positions(t)
        assert found.size == len(expected) == record.n_on_deck[int(round(t * RATE))]
        np.testing.assert_allclose(np.sort(found), np.sort(expected), atol=1e-9)


def test_deflection_from_the_modal_coordinates_gives_the_records_acceleration(run):
    # w_o(t) = φ_o z(t) at the output; its second difference at the sample rate is the record's
    # acceleration to O((ω Δt)²/12): 0.3 % at the 2 Hz mode, 3 % at the 5th step harmonic
    # (~9.5 Hz), which carries little of the response; the RMS of the difference stays < 1 %.
    case, record, replay = run
    w = case.structure.output_shapes @ replay.modal_displacement
    second = (w[:, 2:] - 2 * w[:, 1:-1] + w[:, :-2]) * RATE**2
    first = int(round(replay.time[1] * RATE))
    measured = record.acceleration[:, first:first + second.shape[1]]
    error = np.sqrt(np.mean((second - measured) ** 2)) / np.sqrt(np.mean(measured**2))
    assert error < 0.01


def test_the_default_stretch_is_the_busiest():
    # Closed form: windows of 3 samples over [1, 1, 5, 5, 5, 1, 9, 0]: sums 7, 11, 15, 11, 15, 10
    # → the first 15, at sample 2.
    assert busiest_stretch([1, 1, 5, 5, 5, 1, 9, 0], 10.0, 0.3) == pytest.approx(0.2)
    assert busiest_stretch([1, 2], 10.0, 5.0) == 0.0          # the record is shorter


def test_a_stretch_outside_the_record_is_refused(run):
    case = run[0]
    with pytest.raises(ParameterError, match=r"start must lie within the record \[0, 120\)"):
        crossing_replay(case.structure, case.crowd, DURATION, start=130.0, msd=case.msd,
                        sample_rate=RATE, rng=SEED)
    with pytest.raises(ParameterError, match="frame_rate must not exceed the sample rate 100"):
        crossing_replay(case.structure, case.crowd, DURATION, frame_rate=200.0,
                        sample_rate=RATE, rng=SEED)


def test_each_msd_moves_as_its_equation_of_motion_says(run):
    # Paper Eq. 2 (docs: theory, Equations of motion): m_h1 ü + c_h1 (u̇ − φᵀż) + k_h1 (u − φᵀz)
    # = 0, φ = φ(x_k(t)) the row under the walker (the convective v ∂φ/∂x neglected, as the
    # simulator does). From the replay: u − φᵀz (msd_displacement) and z; u = r + φᵀz; each
    # derivative a central difference at the sample rate (error O((ω Δt)²/12): 0.3 % at
    # f_h1 = 3 Hz, 3 % at the 5th step harmonic near 9.5 Hz, which carries little).
    case, _, replay = run
    msd, mass = case.msd, case.crowd.body_mass
    m, c, k = msd.sprung_mass(mass), msd.damping(mass), msd.stiffness(mass)
    dt = 1.0 / RATE
    checked = 0
    for i in range(replay.arrival.size):
        frames = np.flatnonzero(np.isfinite(replay.msd_displacement[i]))
        if frames.size < 200:
            continue
        frames = frames[5:-5]                         # off the entry and the exit
        t = replay.time[frames]
        x = replay.x_start[i] + replay.velocity[i] * (t - replay.arrival[i])
        phi = case.structure.shapes_at(x, np.full(x.shape, replay.lateral[i]))   # (f, mode)
        z = replay.modal_displacement[:, frames].T
        r = replay.msd_displacement[i, frames]
        u = r + np.einsum("fj,fj->f", phi, z)
        u_dot = (u[2:] - u[:-2]) / (2 * dt)
        u_ddot = (u[2:] - 2 * u[1:-1] + u[:-2]) / dt**2
        deck_dot = np.einsum("fj,fj->f", phi[1:-1], (z[2:] - z[:-2]) / (2 * dt))
        residual = m * u_ddot + c * (u_dot - deck_dot) + k * r[1:-1]
        assert np.sqrt(np.mean(residual**2)) < 0.01 * np.sqrt(np.mean((k * r[1:-1]) ** 2))
        checked += 1
    assert checked >= 20
    assert replay.msd_displacement.shape == (replay.arrival.size, replay.n_frames)
