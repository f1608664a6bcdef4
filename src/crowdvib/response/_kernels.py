"""Numba kernel of the time-domain crowd–structure simulation (docs: theory, The coupled time-domain model).

Private numerics behind :func:`crowdvib.simulate`: inputs are trusted (validated at the public
boundary), arrays are contiguous float64/int64, nothing here allocates per step.

The kernel advances the coupled system

    M(t) z̈ + C ż + K z = Σ_k φ_k [p_k + k_h1 (u_k − φ_kᵀz) + c_h1 (u̇_k − φ_kᵀż)],
    M(t) = M_s + Σ_k m_h0 φ_k φ_kᵀ,
    m_h1 ü_k = −k_h1 (u_k − φ_kᵀz) − c_h1 (u̇_k − φ_kᵀż)

with classical fixed-step RK4. Only the pedestrians on the deck ("active slots") are integrated,
kept as contiguous arrays in slot order (:mod:`._slots`; docs: theory, Walkers on the deck as
arrays) so that the per-walker loops vectorise. The RK4 stages sit at t, t + h/2 (twice) and
t + h, so mode-shape rows, forces and the factored mass matrix are evaluated at three instants per
step and the one at t + h is reused as the next step's t.

Sums over the walkers (the modal force Σ φ_k g_k and the added mass Σ m_h0 φ_k φ_kᵀ) are the only
reductions; they may be reassociated (``fastmath={"reassoc"}``) so that they vectorise too. The
order of the partial sums then depends only on the number of walkers on the deck, never on the
data, the chunking or the thread, so a run is reproducible bit for bit.
"""

import math

import numpy as np
from numba import njit

from ._slots import (ARRIVAL, DAMPING, LANE, LANE_WEIGHT, OPTIONS, PEDESTRIAN, SEGMENT, SPRUNG,
                     STATIC, STIFFNESS, T_OFF, UNSPRUNG, VELOCITY, X_START, harmonic_forces,
                     leave, locate, replayed, replayed_forces, shape_rows)

__all__ = ["advance", "mass_factor"]

# Sums over walkers: reassociation lets LLVM split them into SIMD partial sums.
_REDUCTION = dict(OPTIONS, fastmath={"reassoc"})


@njit(**_REDUCTION)
def _project(phi, g, n_active, out):
    """out[j] += Σ_slot φ[j, slot] g[slot] (modal force of the walkers)."""
    for j in range(phi.shape[0]):
        acc = 0.0
        for slot in range(n_active):
            acc += phi[j, slot] * g[slot]
        out[j] += acc


@njit(**_REDUCTION)
def _added_mass(modal_masses, phi, slots, n_active, weighted, factor):
    """Lower triangle of M = diag(m_j) + Σ_slots m_h0 φ φᵀ into ``factor`` (upper set to 0)."""
    n_modes = modal_masses.size
    for i in range(n_modes):
        for slot in range(n_active):
            weighted[slot] = slots[UNSPRUNG, slot] * phi[i, slot]
        for j in range(i + 1):
            acc = 0.0
            for slot in range(n_active):
                acc += weighted[slot] * phi[j, slot]
            factor[i, j] = acc
        factor[i, i] += modal_masses[i]
        for j in range(i + 1, n_modes):
            factor[i, j] = 0.0


@njit(**OPTIONS)
def _cholesky(factor):
    """Lower Cholesky factor of the symmetric matrix held in the lower triangle, in place."""
    n_modes = factor.shape[0]
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


@njit(**OPTIONS)
def mass_factor(modal_masses, phi, slots, n_active, weighted, factor):
    """Lower Cholesky factor of M = diag(m_j) + Σ_slots m_h0 φ φᵀ, in place into ``factor``."""
    _added_mass(modal_masses, phi, slots, n_active, weighted, factor)
    _cholesky(factor)


@njit(**OPTIONS)
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


@njit(**OPTIONS)
def _contact(z, zd, u, ud, phi, force, n_active, slots, dz, dzd, udd, g):
    """Per slot: the MSD acceleration ü and the force on the deck g = p + contact force."""
    for slot in range(n_active):
        dz[slot] = 0.0
        dzd[slot] = 0.0
    for j in range(z.size):
        zj = z[j]
        zdj = zd[j]
        for slot in range(n_active):
            dz[slot] += phi[j, slot] * zj
            dzd[slot] += phi[j, slot] * zdj
    for slot in range(n_active):
        contact = (slots[STIFFNESS, slot] * (u[slot] - dz[slot])
                   + slots[DAMPING, slot] * (ud[slot] - dzd[slot]))
        udd[slot] = -contact / slots[SPRUNG, slot]
        g[slot] = force[slot] + contact


@njit(**OPTIONS)
def _stage(z, zd, u, ud, phi, force, load, n_active, slots, hsi, modal_damping, modal_stiffness,
           factor, dz, dzd, g, rhs, zdd, udd):
    """Structural (z̈) and sprung-mass (ü) accelerations at one RK4 stage (docs: theory, Equations of motion).

    Without HSI the walkers only load the deck: ``load`` = Σ φ p at the stage time, computed once.
    """
    for j in range(z.size):
        rhs[j] = -modal_damping[j] * zd[j] - modal_stiffness[j] * z[j]
    if hsi:
        _contact(z, zd, u, ud, phi, force, n_active, slots, dz, dzd, udd, g)
        _project(phi, g, n_active, rhs)
    else:
        for j in range(z.size):
            rhs[j] += load[j]
    _solve(factor, rhs, zdd)


@njit(**OPTIONS)
def _stage_state(n, x, xd, b_pos, b_vel, scale, inner, out, outd):
    """RK4 stage state: out = x + scale (ẋ + inner · b_pos), outd = ẋ + scale · b_vel."""
    for i in range(n):
        out[i] = x[i] + scale * (xd[i] + inner * b_pos[i])
        outd[i] = xd[i] + scale * b_vel[i]


@njit(**OPTIONS)
def _rk4_update(n, h, x, xd, b1, b2, b3, b4):
    """x += h ẋ + h²/6 (b1 + b2 + b3), ẋ += h/6 (b1 + 2 b2 + 2 b3 + b4)."""
    sixth = h / 6.0
    for i in range(n):
        x[i] += h * xd[i] + h * sixth * (b1[i] + b2[i] + b3[i])
        xd[i] += sixth * (b1[i] + 2.0 * b2[i] + 2.0 * b3[i] + b4[i])


@njit(**OPTIONS)
def _enter(k, t, half, slot, z, zd, t_off, t_arrival, x_start, velocity, lane_low, lane_weight,
           unsprung, sprung, stiffness, damping, static, amplitude, omega, phase, two_cos, replay,
           table, positions, inverse_spacing, n_lanes, slots, index, segment, cell, frac,
           phi, u, ud, force, wave_now, wave_prev, wave_cos):
    """Pedestrian k takes ``slot`` at time t: its constants copied in, its MSD at rest on the deck."""
    slots[X_START, slot] = x_start[k]
    slots[VELOCITY, slot] = velocity[k]
    slots[ARRIVAL, slot] = t_arrival[k]
    slots[T_OFF, slot] = t_off[k]
    slots[STIFFNESS, slot] = stiffness[k]
    slots[DAMPING, slot] = damping[k]
    slots[SPRUNG, slot] = sprung[k]
    slots[UNSPRUNG, slot] = unsprung[k]
    slots[STATIC, slot] = static[k]
    slots[LANE_WEIGHT, slot] = lane_weight[k]
    index[PEDESTRIAN, slot] = k
    index[LANE, slot] = lane_low[k]
    elapsed = t - t_arrival[k]
    segment[slot] = locate(x_start[k] + velocity[k] * elapsed, positions)
    shape_rows(slot, slot + 1, t, slots, index, table, positions, inverse_spacing, n_lanes,
               segment, segment, cell, frac, phi)
    dz = 0.0
    dzd = 0.0
    for j in range(z.size):
        dz += phi[j, slot] * z[j]
        dzd += phi[j, slot] * zd[j]
    u[slot] = dz
    ud[slot] = dzd
    p = static[k]
    for c in range(amplitude.shape[1]):
        angle = omega[k, c] * elapsed + phase[k, c]
        wave_now[c, slot] = amplitude[k, c] * math.sin(angle)
        wave_prev[c, slot] = amplitude[k, c] * math.sin(angle - omega[k, c] * half)
        wave_cos[c, slot] = two_cos[k, c]
        p += wave_now[c, slot]
    if replay[0][k] >= 0:
        p += replayed(k, elapsed, replay)
    force[slot] = p


# nogil: simulate_many runs several records at once, one thread each, on their own state.
@njit(**OPTIONS)
def advance(first_step, n_steps, substeps, h,
            modal_masses, modal_damping, modal_stiffness, table, positions, inverse_spacing,
            n_lanes, output_shapes,
            t_on, t_off, t_arrival, x_start, velocity, lane_low, lane_weight,
            unsprung, sprung, stiffness, damping, static, amplitude, omega, phase,
            two_cos, replay, hsi, added_mass,
            counters, slots, index, z, zd, u, ud, phi_now, force_now, wave_now, wave_prev,
            wave_cos, factor_now, acceleration, modal_load, record_load, n_on_deck):
    """Advance the coupled system by ``n_steps`` RK4 steps of length ``h`` [s].

    Global step n starts at t = n·h; ``first_step`` is the global index of the first step.
    Output sample i is taken at step n = i·substeps (n >= 0) from the first RK4 stage, so the
    accelerations ü_o = φ_oᵀ z̈ come from the equation of motion, not from differences.

    ``table`` is the mode-shape table of :func:`._slots.shape_table` (``n_lanes`` lanes); the
    per-pedestrian arrays (t_on … two_cos, ``replay``) are read only when a walker enters.

    State carried between calls (so chunks reproduce a single call bit for bit):
    ``counters`` = [next pedestrian to enter, number of active slots], the slot tables ``slots``
    and ``index`` (:mod:`._slots`), z, ż, u, u̇, φ (mode, slot) and the walking force at the
    current time per slot, the force components W α_c sin(ω_c (t − t_k) + θ_c) (component,
    slot) at t and t − h/2 with their 2 cos(ω_c h/2) (``wave_cos``), and the Cholesky factor of
    the mass matrix at the current time. A pedestrian with ``replay[0][k] >= 0`` adds a replayed
    measured force (``_slots.replayed``) to that sum.
    """
    n_modes = z.size
    n_pedestrians = t_on.size
    n_outputs = output_shapes.shape[0]
    n_samples = n_on_deck.size
    capacity = slots.shape[1]
    replaying = False
    for k in range(n_pedestrians):
        if replay[0][k] >= 0:
            replaying = True
            break
    segment = index[SEGMENT]

    phi_mid = np.zeros((n_modes, capacity))
    phi_end = np.zeros((n_modes, capacity))
    force_mid = np.zeros(capacity)
    force_end = np.zeros(capacity)
    us = np.zeros(capacity)
    uds = np.zeros(capacity)
    b1 = np.zeros(capacity)
    b2 = np.zeros(capacity)
    b3 = np.zeros(capacity)
    b4 = np.zeros(capacity)
    dz = np.zeros(capacity)
    dzd = np.zeros(capacity)
    g = np.zeros(capacity)
    frac = np.zeros(capacity)
    weighted = np.zeros(capacity)
    cell = np.zeros(capacity, dtype=np.int64)
    segment_mid = np.zeros(capacity, dtype=np.int64)
    keep = np.zeros(capacity, dtype=np.int64)
    factor_mid = np.zeros((n_modes, n_modes))
    factor_end = np.zeros((n_modes, n_modes))
    zs = np.zeros(n_modes)
    zds = np.zeros(n_modes)
    rhs = np.zeros(n_modes)
    a1 = np.zeros(n_modes)
    a2 = np.zeros(n_modes)
    a3 = np.zeros(n_modes)
    a4 = np.zeros(n_modes)
    load_now = np.zeros(n_modes)
    load_mid = np.zeros(n_modes)
    load_end = np.zeros(n_modes)
    half = 0.5 * h

    for step in range(n_steps):
        n = first_step + step
        t = n * h
        t_mid = (n + 0.5) * h
        t_end = (n + 1) * h
        next_pedestrian = counters[0]
        n_active = counters[1]

        # Pedestrians who have walked off leave; order of the others is kept (shift down).
        before = n_active
        n_active = leave(t, n_active, slots, index, phi_now, wave_now, wave_prev, wave_cos, u, ud,
                         force_now, keep)
        changed = n_active != before

        # Newcomers enter at the end of the list, their MSD at rest relative to the deck.
        while next_pedestrian < n_pedestrians and t_on[next_pedestrian] <= t:
            k = next_pedestrian
            next_pedestrian += 1
            if t >= t_off[k]:
                continue
            _enter(k, t, half, n_active, z, zd, t_off, t_arrival, x_start, velocity, lane_low,
                   lane_weight, unsprung, sprung, stiffness, damping, static, amplitude, omega,
                   phase, two_cos, replay, table, positions, inverse_spacing, n_lanes, slots,
                   index, segment, cell, frac, phi_now, u, ud, force_now, wave_now, wave_prev,
                   wave_cos)
            n_active += 1
            changed = True

        if changed and added_mass:
            mass_factor(modal_masses, phi_now, slots, n_active, weighted, factor_now)

        # Shapes and forces at t + h/2 and t + h.
        shape_rows(0, n_active, t_mid, slots, index, table, positions, inverse_spacing, n_lanes,
                   segment, segment_mid, cell, frac, phi_mid)
        shape_rows(0, n_active, t_end, slots, index, table, positions, inverse_spacing, n_lanes,
                   segment_mid, segment, cell, frac, phi_end)
        harmonic_forces(n_active, slots, wave_now, wave_prev, wave_cos, force_mid, force_end)
        if replaying:
            replayed_forces(n_active, t_mid, t_end, slots, index, replay, force_mid, force_end)
        if added_mass:
            mass_factor(modal_masses, phi_mid, slots, n_active, weighted, factor_mid)
            mass_factor(modal_masses, phi_end, slots, n_active, weighted, factor_end)
        else:
            # Constant mass matrix: the factor never changes.
            for i in range(n_modes):
                for j in range(n_modes):
                    factor_mid[i, j] = factor_now[i, j]
                    factor_end[i, j] = factor_now[i, j]
        sample = n >= 0 and n % substeps == 0 and n // substeps < n_samples
        if not hsi or (sample and record_load):
            load_now[:] = 0.0
            _project(phi_now, force_now, n_active, load_now)
        if not hsi:
            # Moving forces only: the modal load at each stage time is summed once.
            load_mid[:] = 0.0
            load_end[:] = 0.0
            _project(phi_mid, force_mid, n_active, load_mid)
            _project(phi_end, force_end, n_active, load_end)

        # RK4 on (z, ż, u, u̇); the velocity stages are written out.
        _stage(z, zd, u, ud, phi_now, force_now, load_now, n_active, slots, hsi, modal_damping,
               modal_stiffness, factor_now, dz, dzd, g, rhs, a1, b1)

        if sample:
            i = n // substeps
            for o in range(n_outputs):
                acc = 0.0
                for j in range(n_modes):
                    acc += output_shapes[o, j] * a1[j]
                acceleration[o, i] = acc
            n_on_deck[i] = n_active
            if record_load:
                for j in range(n_modes):
                    modal_load[j, i] = load_now[j]

        _stage_state(n_modes, z, zd, a1, a1, half, 0.0, zs, zds)
        if hsi:
            _stage_state(n_active, u, ud, b1, b1, half, 0.0, us, uds)
        _stage(zs, zds, us, uds, phi_mid, force_mid, load_mid, n_active, slots, hsi,
               modal_damping, modal_stiffness, factor_mid, dz, dzd, g, rhs, a2, b2)

        _stage_state(n_modes, z, zd, a1, a2, half, half, zs, zds)
        if hsi:
            _stage_state(n_active, u, ud, b1, b2, half, half, us, uds)
        _stage(zs, zds, us, uds, phi_mid, force_mid, load_mid, n_active, slots, hsi,
               modal_damping, modal_stiffness, factor_mid, dz, dzd, g, rhs, a3, b3)

        _stage_state(n_modes, z, zd, a2, a3, h, half, zs, zds)
        if hsi:
            _stage_state(n_active, u, ud, b2, b3, h, half, us, uds)
        _stage(zs, zds, us, uds, phi_end, force_end, load_end, n_active, slots, hsi,
               modal_damping, modal_stiffness, factor_end, dz, dzd, g, rhs, a4, b4)

        _rk4_update(n_modes, h, z, zd, a1, a2, a3, a4)
        if hsi:
            _rk4_update(n_active, h, u, ud, b1, b2, b3, b4)

        # The end of this step is the start of the next.
        for j in range(n_modes):
            for slot in range(n_active):
                phi_now[j, slot] = phi_end[j, slot]
        for slot in range(n_active):
            force_now[slot] = force_end[slot]
        if added_mass:
            for i in range(n_modes):
                for j in range(n_modes):
                    factor_now[i, j] = factor_end[i, j]
        counters[0] = next_pedestrian
        counters[1] = n_active
