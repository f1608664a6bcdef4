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
step (NOW, MID, END) and the one at t + h is reused as the next step's t.

Sums over the walkers (the modal force Σ φ_k g_k and the added mass Σ m_h0 φ_k φ_kᵀ) are the only
reductions; the functions holding them may reassociate (``fastmath={"reassoc"}``) so that they
vectorise too. The order of the partial sums then depends only on the number of walkers on the
deck, never on the data, the chunking or the thread, so a run is reproducible bit for bit.
"""

import math

import numpy as np
from numba import njit

from ._slots import (END, INLINE, MID, NOW, OPTIONS, SEGMENT, STIFFNESS, DAMPING, INV_SPRUNG,
                     UNSPRUNG, cells_walk, count_leaving, enter, gather_lanes, harmonic_forces,
                     leave, replayed_forces, rows_uniform, rows_uniform_lanes)

__all__ = ["advance", "mass_factors"]

# Sums over walkers: reassociation lets LLVM split them into SIMD partial sums.
_REDUCTION = dict(OPTIONS, fastmath={"reassoc"})
# Rows of the stage-derivative arrays a (modes) and b (MSDs): the four RK4 stages, then a row of
# zeros for the stage at t (which takes no increment).
REST = 4


@njit(**INLINE)
def _solve(factor, instant, x, row):
    """Solve L Lᵀ y = x[row] for the lower factor L = factor[instant], in place (x[row] = y)."""
    n = x.shape[1]
    for i in range(n):
        v = x[row, i]
        for p in range(i):
            v -= factor[instant, i, p] * x[row, p]
        x[row, i] = v / factor[instant, i, i]
    for r in range(n):
        i = n - 1 - r
        v = x[row, i]
        for p in range(i + 1, n):
            v -= factor[instant, p, i] * x[row, p]
        x[row, i] = v / factor[instant, i, i]


@njit(**_REDUCTION)
def mass_factors(modal_masses, phi, slots, n_active, first, weighted, factor):
    """Lower Cholesky factors of M = diag(m_j) + Σ_slots m_h0 φ φᵀ at instants first … END.

    ``factor[instant]`` (upper triangle 0) from ``phi[instant]``.
    """
    n_modes = modal_masses.size
    for instant in range(first, END + 1):
        for i in range(n_modes):
            for slot in range(n_active):
                weighted[slot] = slots[UNSPRUNG, slot] * phi[instant, i, slot]
            # Four columns per pass over the walkers (fewer passes for many modes).
            j = 0
            while j + 3 <= i:
                acc0 = 0.0
                acc1 = 0.0
                acc2 = 0.0
                acc3 = 0.0
                for slot in range(n_active):
                    w = weighted[slot]
                    acc0 += w * phi[instant, j, slot]
                    acc1 += w * phi[instant, j + 1, slot]
                    acc2 += w * phi[instant, j + 2, slot]
                    acc3 += w * phi[instant, j + 3, slot]
                factor[instant, i, j] = acc0
                factor[instant, i, j + 1] = acc1
                factor[instant, i, j + 2] = acc2
                factor[instant, i, j + 3] = acc3
                j += 4
            while j <= i:
                acc = 0.0
                for slot in range(n_active):
                    acc += weighted[slot] * phi[instant, j, slot]
                factor[instant, i, j] = acc
                j += 1
            factor[instant, i, i] += modal_masses[i]
            for j in range(i + 1, n_modes):
                factor[instant, i, j] = 0.0
        for j in range(n_modes):
            d = factor[instant, j, j]
            for p in range(j):
                d -= factor[instant, j, p] * factor[instant, j, p]
            d = math.sqrt(d)
            factor[instant, j, j] = d
            for i in range(j + 1, n_modes):
                v = factor[instant, i, j]
                for p in range(j):
                    v -= factor[instant, i, p] * factor[instant, j, p]
                factor[instant, i, j] = v / d


@njit(**_REDUCTION)
def _modal_loads(phi, force, n_active, first, last, load):
    """load[instant, j] = Σ_slot φ[instant, j, slot] p[instant, slot] for instants first … last."""
    for instant in range(first, last + 1):
        for j in range(phi.shape[1]):
            acc = 0.0
            for slot in range(n_active):
                acc += phi[instant, j, slot] * force[instant, slot]
            load[instant, j] = acc


@njit(**INLINE)
def _modal_stage(stage, instant, pos, vel, scale, inner, z, zd, modal_damping, modal_stiffness,
                 load, a, zs, zds):
    """Modal stage state zs = z + scale (ż + inner · a[pos]), żs = ż + scale · a[vel], and
    a[stage] = −C żs − K zs + load[instant] (the walkers' modal load, or 0 with HSI)."""
    for j in range(z.size):
        zs[j] = z[j] + scale * (zd[j] + inner * a[pos, j])
        zds[j] = zd[j] + scale * a[vel, j]
        a[stage, j] = (-modal_damping[j] * zds[j] - modal_stiffness[j] * zs[j]
                       + load[instant, j])


@njit(**INLINE)
def _stage_plan(stage, h):
    """Instant, rows (pos, vel) of the previous derivatives, scale and inner of an RK4 stage.

    The stage state is x + scale (ẋ + inner · d[pos]), ẋ + scale · d[vel] (d = a for the modes,
    b for the MSDs): t (from the zero row REST), t + h/2 twice, t + h.
    """
    half = 0.5 * h
    if stage == 0:
        return NOW, REST, REST, 0.0, 0.0
    if stage == 1:
        return MID, 0, 0, half, 0.0
    if stage == 2:
        return MID, 0, 1, half, half
    return END, 1, 2, h, half


@njit(**INLINE)
def _rk4_update(h, z, zd, a, n_msd, u, ud, b):
    """x += h ẋ + h²/6 (d1 + d2 + d3), ẋ += h/6 (d1 + 2 d2 + 2 d3 + d4) for the modes (d = a)
    and ``n_msd`` MSDs (d = b)."""
    sixth = h / 6.0
    for j in range(z.size):
        z[j] += h * zd[j] + h * sixth * (a[0, j] + a[1, j] + a[2, j])
        zd[j] += sixth * (a[0, j] + 2.0 * a[1, j] + 2.0 * a[2, j] + a[3, j])
    for slot in range(n_msd):
        u[slot] += h * ud[slot] + h * sixth * (b[0, slot] + b[1, slot] + b[2, slot])
        ud[slot] += sixth * (b[0, slot] + 2.0 * b[1, slot] + 2.0 * b[2, slot] + b[3, slot])


@njit(**OPTIONS)
def next_instant(phi, force, factor, n_active):
    """The shape rows, forces and mass factor at t + h become those at t (the next step's)."""
    for j in range(phi.shape[1]):
        for slot in range(n_active):
            phi[NOW, j, slot] = phi[END, j, slot]
    for slot in range(n_active):
        force[NOW, slot] = force[END, slot]
    for i in range(factor.shape[1]):
        for j in range(factor.shape[2]):
            factor[NOW, i, j] = factor[END, i, j]


@njit(**INLINE)
def _project(phi, instant, g, n_active, a, stage):
    """a[stage, j] += Σ_slot φ[instant, j, slot] g[slot], four modes per pass over the walkers."""
    n_modes = phi.shape[1]
    j = 0
    while j + 3 < n_modes:
        acc0 = 0.0
        acc1 = 0.0
        acc2 = 0.0
        acc3 = 0.0
        for slot in range(n_active):
            gs = g[slot]
            acc0 += phi[instant, j, slot] * gs
            acc1 += phi[instant, j + 1, slot] * gs
            acc2 += phi[instant, j + 2, slot] * gs
            acc3 += phi[instant, j + 3, slot] * gs
        a[stage, j] += acc0
        a[stage, j + 1] += acc1
        a[stage, j + 2] += acc2
        a[stage, j + 3] += acc3
        j += 4
    while j < n_modes:
        acc = 0.0
        for slot in range(n_active):
            acc += phi[instant, j, slot] * g[slot]
        a[stage, j] += acc
        j += 1


# One RK4 step per call (the four stages and the update): a call passes every array as a
# structure of its fields, which costs more than a stage's loops when few walkers are on the deck.

@njit(**_REDUCTION)
def step_forces(h, z, zd, a, b, u, ud, phi, force, factor, n_active, modal_damping,
                modal_stiffness, load, zs, zds):
    """One RK4 step of moving forces only (no HSI): a[stage] = z̈ (docs: theory, Equations of motion)."""
    for stage in range(4):
        instant, pos, vel, scale, inner = _stage_plan(stage, h)
        _modal_stage(stage, instant, pos, vel, scale, inner, z, zd, modal_damping,
                     modal_stiffness, load, a, zs, zds)
        _solve(factor, instant, a, stage)
    _rk4_update(h, z, zd, a, 0, u, ud, b)


@njit(**_REDUCTION)
def step_msd(h, z, zd, a, b, u, ud, phi, force, factor, n_active, modal_damping, modal_stiffness,
             load, zs, zds, slots, dz, dzd, g):
    """One RK4 step with HSI: a[stage] = z̈ and b[stage] = ü (docs: theory, Equations of motion).

    Per stage and slot, with the MSD's stage state formed on the fly: the contact force
    k_h1 (u − φᵀz) + c_h1 (u̇ − φᵀż), ü = −contact · (1/m_h1) and the force on the deck
    g = p + contact; then Σ φ g and the solve with the mass factor at the stage's instant.
    """
    n_modes = z.size
    for stage in range(4):
        instant, pos, vel, scale, inner = _stage_plan(stage, h)
        _modal_stage(stage, instant, pos, vel, scale, inner, z, zd, modal_damping,
                     modal_stiffness, load, a, zs, zds)
        for slot in range(n_active):
            dz[slot] = 0.0
            dzd[slot] = 0.0
        j = 0
        while j + 1 < n_modes:           # two modes per pass, the same order of the sums
            z0 = zs[j]
            z1 = zs[j + 1]
            zd0 = zds[j]
            zd1 = zds[j + 1]
            for slot in range(n_active):
                p0 = phi[instant, j, slot]
                p1 = phi[instant, j + 1, slot]
                dz[slot] = (dz[slot] + p0 * z0) + p1 * z1
                dzd[slot] = (dzd[slot] + p0 * zd0) + p1 * zd1
            j += 2
        if j < n_modes:
            for slot in range(n_active):
                dz[slot] += phi[instant, j, slot] * zs[j]
                dzd[slot] += phi[instant, j, slot] * zds[j]
        for slot in range(n_active):
            us = u[slot] + scale * (ud[slot] + inner * b[pos, slot])
            uds = ud[slot] + scale * b[vel, slot]
            contact = (slots[STIFFNESS, slot] * (us - dz[slot])
                       + slots[DAMPING, slot] * (uds - dzd[slot]))
            b[stage, slot] = -contact * slots[INV_SPRUNG, slot]
            g[slot] = force[instant, slot] + contact
        _project(phi, instant, g, n_active, a, stage)
        _solve(factor, instant, a, stage)
    _rk4_update(h, z, zd, a, n_active, u, ud, b)


@njit(**_REDUCTION)
def step_msd_one_mode(h, z, zd, a, b, u, ud, phi, force, factor, n_active, modal_damping,
                      modal_stiffness, load, zs, zds, slots):
    """:func:`step_msd` for one mode (the common footbridge case): the same arithmetic, one pass
    over the walkers per stage."""
    for stage in range(4):
        instant, pos, vel, scale, inner = _stage_plan(stage, h)
        _modal_stage(stage, instant, pos, vel, scale, inner, z, zd, modal_damping,
                     modal_stiffness, load, a, zs, zds)
        z0 = zs[0]
        zd0 = zds[0]
        acc = 0.0
        for slot in range(n_active):
            p = phi[instant, 0, slot]
            us = u[slot] + scale * (ud[slot] + inner * b[pos, slot])
            uds = ud[slot] + scale * b[vel, slot]
            contact = (slots[STIFFNESS, slot] * (us - p * z0)
                       + slots[DAMPING, slot] * (uds - p * zd0))
            b[stage, slot] = -contact * slots[INV_SPRUNG, slot]
            acc += p * (force[instant, slot] + contact)
        a[stage, 0] += acc
        _solve(factor, instant, a, stage)
    _rk4_update(h, z, zd, a, n_active, u, ud, b)


# nogil: simulate_many runs several records at once, one thread each, on their own state.
@njit(**OPTIONS)
def advance(first_step, n_steps, substeps, h,
            modal_masses, modal_damping, modal_stiffness, table, positions, inverse_spacing,
            n_lanes, output_shapes,
            t_on, t_off, t_arrival, x_start, velocity, lane_low, lane_weight,
            unsprung, sprung, stiffness, damping, static, amplitude, omega, phase,
            two_cos, replay, hsi, added_mass,
            counters, slots, index, z, zd, u, ud, phi, force, wave_now, wave_prev, wave_cos,
            factor, acceleration, modal_load, record_load, n_on_deck):
    """Advance the coupled system by ``n_steps`` RK4 steps of length ``h`` [s].

    Global step n starts at t = n·h; ``first_step`` is the global index of the first step.
    Output sample i is taken at step n = i·substeps (n >= 0) from the first RK4 stage, so the
    accelerations ü_o = φ_oᵀ z̈ come from the equation of motion, not from differences.

    ``table`` is the mode-shape table of :func:`._slots.shape_table` (``n_lanes`` lanes); the
    per-pedestrian arrays (t_on … two_cos, ``replay``) are read only when a walker enters.

    State carried between calls (so chunks reproduce a single call bit for bit):
    ``counters`` = [next pedestrian to enter, number of active slots], the slot tables ``slots``
    and ``index`` (:mod:`._slots`), z, ż, u, u̇, φ and the walking force at t
    (``phi[NOW]``, ``force[NOW]``; the other instants are scratch), the force components
    W α_c sin(ω_c (t − t_k) + θ_c) (component, slot) at t and t − h/2 with their
    2 cos(ω_c h/2) (``wave_cos``; an even number of rows, the last one zero if need be), and the
    Cholesky factor of the mass matrix at t (``factor[NOW]``). A pedestrian with
    ``replay[0][k] >= 0`` adds a replayed measured force (``_slots.replayed``) to that sum.
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
    uniform = inverse_spacing > 0.0
    one_mode = n_modes == 1
    segment = index[SEGMENT]
    # Plain int64 arguments: a literal constant in a call compiles a version of its own.
    first_slot = np.int64(0)
    now = np.int64(NOW)
    mid = np.int64(MID)
    end = np.int64(END)

    a = np.zeros((REST + 1, n_modes))
    b = np.zeros((REST + 1, capacity))
    load = np.zeros((3, n_modes))
    recorded = np.zeros((3, n_modes))
    zs = np.zeros(n_modes)
    zds = np.zeros(n_modes)
    dz = np.zeros(capacity)
    dzd = np.zeros(capacity)
    g = np.zeros(capacity)
    frac = np.zeros(capacity)
    weighted = np.zeros(capacity)
    cell = np.zeros(capacity, dtype=np.int64)
    segment_mid = np.zeros(capacity, dtype=np.int64)
    keep = np.zeros(capacity, dtype=np.int64)
    half = 0.5 * h

    for step in range(n_steps):
        n = first_step + step
        t = n * h
        t_mid = (n + 0.5) * h
        t_end = (n + 1) * h
        next_pedestrian = counters[0]
        n_active = counters[1]

        # Pedestrians who have walked off leave; order of the others is kept (shift down).
        changed = False
        if count_leaving(t, n_active, slots) > 0:
            n_active = leave(t, n_active, slots, index, phi, force, wave_now, wave_prev, wave_cos,
                             u, ud, keep)
            changed = True

        # Newcomers enter at the end of the list, their MSD at rest relative to the deck.
        while next_pedestrian < n_pedestrians and t_on[next_pedestrian] <= t:
            k = next_pedestrian
            next_pedestrian += 1
            if t >= t_off[k]:
                continue
            if n_active == capacity:
                raise RuntimeError("simulation kernel: more walkers on the deck than slots")
            enter(k, t, half, n_active, z, zd, t_off, t_arrival, x_start, velocity, lane_low,
                  lane_weight, unsprung, sprung, stiffness, damping, static, amplitude, omega,
                  phase, two_cos, replay, table, positions, inverse_spacing, n_lanes, slots,
                  index, phi, u, ud, force, wave_now, wave_prev, wave_cos)
            n_active += 1
            changed = True

        # Shapes and forces at t + h/2 and t + h.
        if uniform and n_lanes == 1:
            rows_uniform(n_active, t_mid, t_end, slots, index, positions, inverse_spacing, table,
                         cell, frac, phi)
        elif uniform:
            rows_uniform_lanes(n_active, t_mid, t_end, slots, index, positions, inverse_spacing,
                               n_lanes, table, cell, frac, phi)
        else:
            cells_walk(first_slot, n_active, t_mid, slots, index, positions, n_lanes, segment,
                       segment_mid, cell, frac)
            gather_lanes(first_slot, n_active, cell, frac, slots, table, positions.size, phi, mid)
            cells_walk(first_slot, n_active, t_end, slots, index, positions, n_lanes, segment_mid,
                       segment, cell, frac)
            gather_lanes(first_slot, n_active, cell, frac, slots, table, positions.size, phi, end)
        harmonic_forces(n_active, slots, wave_now, wave_prev, wave_cos, force)
        if replaying:
            replayed_forces(n_active, t_mid, t_end, slots, index, replay, force)
        # The mass matrix and its factor at t + h/2 and t + h (and at t after a change).
        if added_mass:
            mass_factors(modal_masses, phi, slots, n_active, NOW if changed else MID, weighted,
                         factor)
        sample = n >= 0 and n % substeps == 0 and n // substeps < n_samples
        if sample and record_load:
            _modal_loads(phi, force, n_active, now, now, recorded)
        if not hsi:
            # Moving forces only: the modal load at each instant is summed once.
            _modal_loads(phi, force, n_active, now, end, load)

        # RK4 on (z, ż, u, u̇); the accelerations of the stage at t are a[0].
        if not hsi:
            step_forces(h, z, zd, a, b, u, ud, phi, force, factor, n_active, modal_damping,
                        modal_stiffness, load, zs, zds)
        elif one_mode:
            step_msd_one_mode(h, z, zd, a, b, u, ud, phi, force, factor, n_active,
                              modal_damping, modal_stiffness, load, zs, zds, slots)
        else:
            step_msd(h, z, zd, a, b, u, ud, phi, force, factor, n_active, modal_damping,
                     modal_stiffness, load, zs, zds, slots, dz, dzd, g)

        if sample:
            i = n // substeps
            for o in range(n_outputs):
                acc = 0.0
                for j in range(n_modes):
                    acc += output_shapes[o, j] * a[0, j]
                acceleration[o, i] = acc
            n_on_deck[i] = n_active
            if record_load:
                for j in range(n_modes):
                    modal_load[j, i] = recorded[NOW, j]

        # The end of this step is the start of the next.
        next_instant(phi, force, factor, n_active)
        counters[0] = next_pedestrian
        counters[1] = n_active
