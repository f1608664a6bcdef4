"""Numba kernel of the time-domain crowd–structure simulation (docs: theory, The coupled time-domain model).

Private numerics behind :func:`crowdvib.simulate`: inputs are trusted (validated at the public
boundary), arrays are contiguous float64/int64, nothing here allocates per step.

The kernel advances the coupled system

    M(t) z̈ + C ż + K z = Σ_k φ_k [p_k + k_h1 (u_k − φ_kᵀz) + c_h1 (u̇_k − φ_kᵀż)],
    M(t) = M_s + Σ_k m_h0 φ_k φ_kᵀ,
    m_h1 ü_k = −k_h1 (u_k − φ_kᵀz) − c_h1 (u̇_k − φ_kᵀż)

with classical fixed-step RK4. Only the pedestrians on the deck ("active slots") are integrated.
The RK4 stages sit at t, t + h/2 (twice) and t + h, so mode-shape rows, forces and the factored
mass matrix are evaluated at three instants per step and the one at t + h is reused as the next
step's t.
"""

import math

import numpy as np
from numba import njit

__all__ = ["advance", "cholesky_mass"]



@njit(cache=True)
def _locate(x, positions):
    """Segment s with positions[s] <= x <= positions[s + 1] (clipped to the walkway)."""
    s = np.searchsorted(positions, x) - 1
    if s < 0:
        s = 0
    if s > positions.size - 2:
        s = positions.size - 2
    return s


@njit(cache=True)
def _shape_row(x, s, lane_low, lane_weight, shapes, positions, inverse_spacing, out, row):
    """Mode-shape row φ(x, y) into ``out[row]`` by linear interpolation; 0 off the walkway.

    On a uniform station grid (``inverse_spacing`` = 1/Δx > 0) the segment is computed directly;
    otherwise ``s``, the segment found last time, is walked to x — walkers move monotonically, so
    that is O(1) too. Returns the segment for next time. (``out`` and ``row`` rather than a view
    ``out[row]``: a view per call costs reference counting in the innermost loop.)
    """
    n_positions = positions.size
    n_modes = out.shape[1]
    if x < positions[0] or x > positions[n_positions - 1]:
        for j in range(n_modes):
            out[row, j] = 0.0
        return s
    if inverse_spacing > 0.0:
        a = (x - positions[0]) * inverse_spacing
        s = int(a)
        if s > n_positions - 2:
            s = n_positions - 2
        a -= s
    else:
        while s < n_positions - 2 and x > positions[s + 1]:
            s += 1
        while s > 0 and x < positions[s]:
            s -= 1
        a = (x - positions[s]) / (positions[s + 1] - positions[s])
    if lane_weight == 0.0:
        for j in range(n_modes):
            out[row, j] = shapes[lane_low, s, j] + a * (shapes[lane_low, s + 1, j]
                                                         - shapes[lane_low, s, j])
    else:
        lane_high = lane_low + 1
        for j in range(n_modes):
            low = shapes[lane_low, s, j] + a * (shapes[lane_low, s + 1, j] - shapes[lane_low, s, j])
            high = shapes[lane_high, s, j] + a * (shapes[lane_high, s + 1, j]
                                                  - shapes[lane_high, s, j])
            out[row, j] = low + lane_weight * (high - low)
    return s


@njit(cache=True)
def cholesky_mass(modal_masses, phi, unsprung, active, n_active, factor):
    """Lower Cholesky factor of M = diag(m_j) + Σ_slots m_h0 φ φᵀ, in place into ``factor``."""
    n_modes = modal_masses.size
    for i in range(n_modes):
        for j in range(n_modes):
            factor[i, j] = 0.0
        factor[i, i] = modal_masses[i]
    for slot in range(n_active):
        m = unsprung[active[slot]]
        if m == 0.0:
            continue
        for i in range(n_modes):
            mi = m * phi[slot, i]
            if mi == 0.0:
                continue
            for j in range(i + 1):
                factor[i, j] += mi * phi[slot, j]
    for j in range(n_modes):
        d = factor[j, j]
        for p in range(j):
            d -= factor[j, p] * factor[j, p]
        d = math.sqrt(d)
        factor[j, j] = d
        for i in range(j + 1, n_modes):
            v = factor[i, j]
            for p in range(j):
                v -= factor[i, p] * factor[j, p]
            factor[i, j] = v / d


@njit(cache=True)
def _solve(factor, rhs, out):
    """Solve L Lᵀ out = rhs for the lower factor L."""
    n = rhs.size
    for i in range(n):
        v = rhs[i]
        for p in range(i):
            v -= factor[i, p] * out[p]
        out[i] = v / factor[i, i]
    for i in range(n - 1, -1, -1):
        v = out[i]
        for p in range(i + 1, n):
            v -= factor[p, i] * out[p]
        out[i] = v / factor[i, i]


@njit(cache=True)
def _accelerations(z, zd, u, ud, phi, force, n_active, active, sprung, stiffness, damping,
                   modal_damping, modal_stiffness, factor, hsi, rhs, zdd, udd):
    """Structural (z̈) and sprung-mass (ü) accelerations at one RK4 stage (docs: theory, Equations of motion)."""
    n_modes = z.size
    for j in range(n_modes):
        rhs[j] = -modal_damping[j] * zd[j] - modal_stiffness[j] * z[j]
    for slot in range(n_active):
        f = force[slot]
        if hsi:
            k = active[slot]
            dz = 0.0
            dzd = 0.0
            for j in range(n_modes):
                dz += phi[slot, j] * z[j]
                dzd += phi[slot, j] * zd[j]
            contact = stiffness[k] * (u[slot] - dz) + damping[k] * (ud[slot] - dzd)
            udd[slot] = -contact / sprung[k]
            f += contact
        if f != 0.0:
            for j in range(n_modes):
                rhs[j] += phi[slot, j] * f
    _solve(factor, rhs, zdd)


# --- Measured-force replay (table look-up), kept apart from the harmonic path ---------------
# ``replay`` = (record, offset, speed, weight, table): per pedestrian k the table row record[k]
# (-1: no replay, the harmonic sum alone), the start offset[k] [table samples] at the arrival time,
# speed[k] [table samples per second] and weight[k] [N] (s_k W_k); table[r] holds F_r/F̄_r − 1.
# The force is weight · table[r](offset + speed (t − t_k)), periodically continued and linearly
# interpolated (docs: theory, Measured walking forces); models/measured.py ``replay_value`` is
# the numpy twin. Harmonic-only runs pass record = -1 everywhere and add nothing: bit-identical.


@njit(cache=True)
def _replayed(k, elapsed, replay):
    """Replayed dynamic force [N] of pedestrian k at ``elapsed`` = t − t_k [s]."""
    record, offset, speed, weight, table = replay
    n = table.shape[1]
    position = offset[k] + speed[k] * elapsed
    position -= n * math.floor(position / n)
    low = int(position)
    if low > n - 1:
        low = n - 1
    high = low + 1 if low + 1 < n else 0
    row = record[k]
    return weight[k] * (table[row, low] + (position - low) * (table[row, high] - table[row, low]))


# nogil: simulate_many runs several records at once, one thread each, on their own state.
@njit(cache=True, nogil=True)
def advance(first_step, n_steps, substeps, h,
            modal_masses, modal_damping, modal_stiffness, shapes, positions, inverse_spacing,
            output_shapes,
            t_on, t_off, t_arrival, x_start, velocity, lane_low, lane_weight,
            unsprung, sprung, stiffness, damping, static, amplitude, omega, phase,
            two_cos, replay, hsi, added_mass,
            counters, active, z, zd, u, ud, seg, phi_now, force_now, wave_now, wave_prev, factor_now,
            acceleration, modal_load, record_load, n_on_deck):
    """Advance the coupled system by ``n_steps`` RK4 steps of length ``h`` [s].

    Global step n starts at t = n·h; ``first_step`` is the global index of the first step.
    Output sample i is taken at step n = i·substeps (n >= 0) from the first RK4 stage, so the
    accelerations ü_o = φ_oᵀ z̈ come from the equation of motion, not from differences.

    State carried between calls (so chunks reproduce a single call bit for bit):
    ``counters`` = [next pedestrian to enter, number of active slots], ``active`` (pedestrian
    index per slot, in order of entry), z, ż, u, u̇, the segment per slot, φ and the walking force
    at the current time per slot, the force components W α_c sin(ω_c (t − t_k) + θ_c) per slot at
    t and t − h/2 (advanced by the Chebyshev recurrence, ``two_cos`` = 2 cos(ω_c h/2): no sine
    in the loop), and the Cholesky factor of the mass matrix at the current time. A pedestrian
    with ``replay[0][k] >= 0`` adds a replayed measured force (``_replayed``) to that sum.
    """
    replay_record = replay[0]
    n_modes = z.size
    n_components = amplitude.shape[1]
    n_pedestrians = t_on.size
    n_outputs = output_shapes.shape[0]
    n_samples = n_on_deck.size
    capacity = active.size

    phi_mid = np.zeros((capacity, n_modes))
    phi_end = np.zeros((capacity, n_modes))
    force_mid = np.zeros(capacity)
    force_end = np.zeros(capacity)
    factor_mid = np.zeros((n_modes, n_modes))
    factor_end = np.zeros((n_modes, n_modes))
    zs = np.zeros(n_modes)
    zds = np.zeros(n_modes)
    rhs = np.zeros(n_modes)
    a1 = np.zeros(n_modes)
    a2 = np.zeros(n_modes)
    a3 = np.zeros(n_modes)
    a4 = np.zeros(n_modes)
    us = np.zeros(capacity)
    uds = np.zeros(capacity)
    b1 = np.zeros(capacity)
    b2 = np.zeros(capacity)
    b3 = np.zeros(capacity)
    b4 = np.zeros(capacity)
    half = 0.5 * h

    for step in range(n_steps):
        n = first_step + step
        t = n * h
        t_mid = (n + 0.5) * h
        t_end = (n + 1) * h
        next_pedestrian = counters[0]
        n_active = counters[1]
        changed = False

        # Pedestrians who have walked off leave; order of the others is kept (shift down).
        slot = 0
        while slot < n_active:
            if t >= t_off[active[slot]]:
                for s in range(slot, n_active - 1):
                    active[s] = active[s + 1]
                    u[s] = u[s + 1]
                    ud[s] = ud[s + 1]
                    seg[s] = seg[s + 1]
                    force_now[s] = force_now[s + 1]
                    for j in range(n_modes):
                        phi_now[s, j] = phi_now[s + 1, j]
                    for c in range(n_components):
                        wave_now[s, c] = wave_now[s + 1, c]
                        wave_prev[s, c] = wave_prev[s + 1, c]
                n_active -= 1
                changed = True
            else:
                slot += 1

        # Newcomers enter at the end of the list, their MSD at rest relative to the deck.
        while next_pedestrian < n_pedestrians and t_on[next_pedestrian] <= t:
            k = next_pedestrian
            next_pedestrian += 1
            if t >= t_off[k]:
                continue
            slot = n_active
            n_active += 1
            changed = True
            active[slot] = k
            elapsed = t - t_arrival[k]
            x = x_start[k] + velocity[k] * elapsed
            seg[slot] = _shape_row(x, _locate(x, positions), lane_low[k], lane_weight[k],
                                   shapes, positions, inverse_spacing, phi_now, slot)
            dz = 0.0
            dzd = 0.0
            for j in range(n_modes):
                dz += phi_now[slot, j] * z[j]
                dzd += phi_now[slot, j] * zd[j]
            u[slot] = dz
            ud[slot] = dzd
            p = static[k]
            for c in range(n_components):
                angle = omega[k, c] * elapsed + phase[k, c]
                wave_now[slot, c] = amplitude[k, c] * math.sin(angle)
                wave_prev[slot, c] = amplitude[k, c] * math.sin(angle - omega[k, c] * half)
                p += wave_now[slot, c]
            if replay_record[k] >= 0:
                p += _replayed(k, elapsed, replay)
            force_now[slot] = p

        if changed and added_mass:
            cholesky_mass(modal_masses, phi_now, unsprung, active, n_active, factor_now)

        # Shapes and forces at t + h/2 and t + h; the force components advance by ω_c h/2 twice.
        for slot in range(n_active):
            k = active[slot]
            s = _shape_row(x_start[k] + velocity[k] * (t_mid - t_arrival[k]), seg[slot],
                           lane_low[k], lane_weight[k], shapes, positions, inverse_spacing, phi_mid,
                           slot)
            seg[slot] = _shape_row(x_start[k] + velocity[k] * (t_end - t_arrival[k]), s,
                                   lane_low[k], lane_weight[k], shapes, positions, inverse_spacing,
                                   phi_end, slot)
            p_mid = static[k]
            p_end = static[k]
            for c in range(n_components):
                # sin(θ + δ) = 2 cos δ · sin θ − sin(θ − δ), δ = ω_c h/2 (Chebyshev recurrence)
                y_mid = two_cos[k, c] * wave_now[slot, c] - wave_prev[slot, c]
                y_end = two_cos[k, c] * y_mid - wave_now[slot, c]
                p_mid += y_mid
                p_end += y_end
                wave_prev[slot, c] = y_mid
                wave_now[slot, c] = y_end
            if replay_record[k] >= 0:
                p_mid += _replayed(k, t_mid - t_arrival[k], replay)
                p_end += _replayed(k, t_end - t_arrival[k], replay)
            force_mid[slot] = p_mid
            force_end[slot] = p_end
        if added_mass:
            cholesky_mass(modal_masses, phi_mid, unsprung, active, n_active, factor_mid)
            cholesky_mass(modal_masses, phi_end, unsprung, active, n_active, factor_end)
        else:
            # Constant mass matrix: the factor never changes.
            for i in range(n_modes):
                for j in range(n_modes):
                    factor_mid[i, j] = factor_now[i, j]
                    factor_end[i, j] = factor_now[i, j]

        # RK4 on (z, ż, u, u̇); the velocity stages are written out.
        _accelerations(z, zd, u, ud, phi_now, force_now, n_active, active, sprung, stiffness,
                       damping, modal_damping, modal_stiffness, factor_now, hsi, rhs, a1, b1)

        if n >= 0 and n % substeps == 0:
            i = n // substeps
            if i < n_samples:
                for o in range(n_outputs):
                    acc = 0.0
                    for j in range(n_modes):
                        acc += output_shapes[o, j] * a1[j]
                    acceleration[o, i] = acc
                n_on_deck[i] = n_active
                if record_load:
                    for j in range(n_modes):
                        q = 0.0
                        for slot in range(n_active):
                            q += phi_now[slot, j] * force_now[slot]
                        modal_load[j, i] = q

        for j in range(n_modes):
            zs[j] = z[j] + half * zd[j]
            zds[j] = zd[j] + half * a1[j]
        if hsi:
            for slot in range(n_active):
                us[slot] = u[slot] + half * ud[slot]
                uds[slot] = ud[slot] + half * b1[slot]
        _accelerations(zs, zds, us, uds, phi_mid, force_mid, n_active, active, sprung, stiffness,
                       damping, modal_damping, modal_stiffness, factor_mid, hsi, rhs, a2, b2)

        for j in range(n_modes):
            zs[j] = z[j] + half * (zd[j] + half * a1[j])
            zds[j] = zd[j] + half * a2[j]
        if hsi:
            for slot in range(n_active):
                us[slot] = u[slot] + half * (ud[slot] + half * b1[slot])
                uds[slot] = ud[slot] + half * b2[slot]
        _accelerations(zs, zds, us, uds, phi_mid, force_mid, n_active, active, sprung, stiffness,
                       damping, modal_damping, modal_stiffness, factor_mid, hsi, rhs, a3, b3)

        for j in range(n_modes):
            zs[j] = z[j] + h * (zd[j] + half * a2[j])
            zds[j] = zd[j] + h * a3[j]
        if hsi:
            for slot in range(n_active):
                us[slot] = u[slot] + h * (ud[slot] + half * b2[slot])
                uds[slot] = ud[slot] + h * b3[slot]
        _accelerations(zs, zds, us, uds, phi_end, force_end, n_active, active, sprung, stiffness,
                       damping, modal_damping, modal_stiffness, factor_end, hsi, rhs, a4, b4)

        sixth = h / 6.0
        for j in range(n_modes):
            z[j] += h * zd[j] + h * sixth * (a1[j] + a2[j] + a3[j])
            zd[j] += sixth * (a1[j] + 2.0 * a2[j] + 2.0 * a3[j] + a4[j])
        if hsi:
            for slot in range(n_active):
                u[slot] += h * ud[slot] + h * sixth * (b1[slot] + b2[slot] + b3[slot])
                ud[slot] += sixth * (b1[slot] + 2.0 * b2[slot] + 2.0 * b3[slot] + b4[slot])

        # The end of this step is the start of the next.
        for slot in range(n_active):
            force_now[slot] = force_end[slot]
            for j in range(n_modes):
                phi_now[slot, j] = phi_end[slot, j]
        if added_mass:
            for i in range(n_modes):
                for j in range(n_modes):
                    factor_now[i, j] = factor_end[i, j]
        counters[0] = next_pedestrian
        counters[1] = n_active
