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

The RK4 step itself is in :mod:`._stages`; its sums over the walkers may be reassociated, in an
order that depends only on the number of walkers on the deck, so a run is reproducible bit for
bit.
"""

import numpy as np
from numba import njit

from ._slots import (END, INLINE, MID, NOW, OPTIONS, SEGMENT, cells_walk, earliest_leaving, enter,
                     gather_lanes, harmonic_forces, leave, replayed_forces, rows_uniform)
from ._stages import REST, mass_factors, modal_loads, step_forces, step_msd, step_msd_one_mode

__all__ = ["ENTRY_POINTS", "entry_point", "mass_factors"]

# Kinds of RK4 step and of shape-row look-up (constants of the entry points of _advance).
FORCES, MSD, MSD_ONE_MODE = range(3)
UNIFORM, GENERAL = range(2)


@njit(**INLINE)
def _advance(step_kind, rows_kind, first_step, n_steps, substeps, h, structure, walkers, state,
             records):
    """Advance the coupled system by ``n_steps`` RK4 steps of length ``h`` [s].

    ``step_kind`` (FORCES, MSD, MSD_ONE_MODE) and ``rows_kind`` (UNIFORM, GENERAL) are constants
    of each entry point below: numba prunes the branches of the other kinds before compiling, so
    a run compiles the functions it uses only.

    Global step n starts at t = n·h; ``first_step`` is the global index of the first step.
    Output sample i is taken at step n = i·substeps (n >= 0) from the first RK4 stage, so the
    accelerations ü_o = φ_oᵀ z̈ come from the equation of motion, not from differences.

    ``structure`` = (modal masses, damping, stiffness, the mode-shape table of
    :func:`._slots.shape_table`, stations, 1/Δx or 0, lanes, output shapes); ``walkers`` = the
    per-pedestrian arrays (t_on … two_cos, ``replay``), read only when a walker enters, and
    whether any has an unsprung mass (then the mass matrix changes with time);
    ``records`` = (accelerations, modal load, whether to record it, walkers on the deck, the
    index of the output sample in their first column): a long run records chunk by chunk.

    State carried between calls (so chunks reproduce a single call bit for bit):
    ``counters`` = [next pedestrian to enter, number of active slots], the slot tables ``slots``
    and ``index`` (:mod:`._slots`), z, ż, u, u̇, φ and the walking force at t
    (``phi[NOW]``, ``force[NOW]``; the other instants are scratch), the force components
    W α_c sin(ω_c (t − t_k) + θ_c) (component, slot) at t and t − h/2 with their
    2 cos(ω_c h/2) (``wave_cos``; an even number of rows, the last one zero if need be), and the
    Cholesky factor of the mass matrix at t (``factor[NOW]``; one mode with HSI sums its 1×1
    mass matrix in the RK4 step instead). A pedestrian with
    ``replay[0][k] >= 0`` adds a replayed measured force (``_slots.replayed``) to that sum.
    """
    (modal_masses, modal_damping, modal_stiffness, table, positions, inverse_spacing, n_lanes,
     output_shapes) = structure
    (t_on, t_off, t_arrival, x_start, velocity, lane_low, lane_weight, unsprung, sprung,
     stiffness, damping, static, amplitude, omega, phase, two_cos, replay, added_mass) = walkers
    (counters, slots, index, z, zd, u, ud, phi, force, wave_now, wave_prev, wave_cos,
     factor) = state
    acceleration, modal_load, record_load, n_on_deck, first_sample = records
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
    # Plain int64 arguments: a literal constant in a call compiles a version of its own.
    first_slot = np.int64(0)
    one_lane = np.int64(1)
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
    leaving = earliest_leaving(counters[1], slots)

    for step in range(n_steps):
        n = first_step + step
        t = n * h
        t_mid = (n + 0.5) * h
        t_end = (n + 1) * h
        next_pedestrian = counters[0]
        n_active = counters[1]

        # Pedestrians who have walked off leave; order of the others is kept (shift down).
        changed = False
        if t >= leaving:
            n_active = leave(t, n_active, slots, index, phi, force, wave_now, wave_prev, wave_cos,
                             u, ud, keep)
            leaving = earliest_leaving(n_active, slots)
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
            leaving = min(leaving, t_off[k])
            changed = True

        # Shapes and forces at t + h/2 and t + h.
        if rows_kind == UNIFORM:
            rows_uniform(n_active, t_mid, t_end, slots, index, positions, inverse_spacing,
                         one_lane, table, cell, frac, phi)
        elif inverse_spacing > 0.0:
            rows_uniform(n_active, t_mid, t_end, slots, index, positions, inverse_spacing,
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
        # The mass matrix and its factor at t + h/2 and t + h (and at t after a change); none
        # (from past END) without unsprung mass; one mode sums it in the RK4 step. The call is not under a branch taken at run
        # time: numba would count references to its arrays (atomic operations) at every step.
        if step_kind == MSD:
            first_factor = (NOW if changed else MID) if added_mass else END + 1
            mass_factors(modal_masses, phi, slots, n_active, first_factor, weighted, factor)
        sample = (n >= 0 and n % substeps == 0
                  and 0 <= n // substeps - first_sample < n_samples)
        if sample and record_load:
            modal_loads(phi, force, n_active, now, now, recorded)
        if step_kind == FORCES:
            # Moving forces only: the modal load at each instant is summed once.
            modal_loads(phi, force, n_active, now, end, load)

        # RK4 on (z, ż, u, u̇); the accelerations of the stage at t are a[0]. The step ends
        # with the shapes, forces and mass factor at t + h made those at t (the next step's).
        if step_kind == FORCES:
            step_forces(h, z, zd, a, b, u, ud, phi, force, factor, n_active, modal_damping,
                        modal_stiffness, load, zs, zds)
        elif step_kind == MSD_ONE_MODE:
            step_msd_one_mode(h, z, zd, a, b, u, ud, phi, force, factor, n_active,
                              modal_damping, modal_stiffness, load, zs, zds, slots, modal_masses)
        else:
            step_msd(h, z, zd, a, b, u, ud, phi, force, factor, n_active, modal_damping,
                     modal_stiffness, load, zs, zds, slots, dz, dzd, g)

        if sample:
            i = n // substeps - first_sample
            for o in range(n_outputs):
                acc = 0.0
                for j in range(n_modes):
                    acc += output_shapes[o, j] * a[0, j]
                acceleration[o, i] = acc
            n_on_deck[i] = n_active
            if record_load:
                for j in range(n_modes):
                    modal_load[j, i] = recorded[NOW, j]

        counters[0] = next_pedestrian
        counters[1] = n_active


# The entry points: one per kind of step and of shape-row look-up. nogil: simulate_many runs
# several records at once, one thread each, on their own state.

@njit(**OPTIONS)
def advance_forces(first_step, n_steps, substeps, h, structure, walkers, state, records):
    """:func:`_advance` for moving forces (no HSI) on a uniform single-lane station grid."""
    _advance(FORCES, UNIFORM, first_step, n_steps, substeps, h, structure, walkers, state,
             records)


@njit(**OPTIONS)
def advance_forces_general(first_step, n_steps, substeps, h, structure, walkers, state, records):
    """:func:`_advance` for moving forces (no HSI), lanes or non-uniform stations."""
    _advance(FORCES, GENERAL, first_step, n_steps, substeps, h, structure, walkers, state,
             records)


@njit(**OPTIONS)
def advance_msd_one_mode(first_step, n_steps, substeps, h, structure, walkers, state, records):
    """:func:`_advance` with HSI, one mode, a uniform single-lane station grid (the paper's case)."""
    _advance(MSD_ONE_MODE, UNIFORM, first_step, n_steps, substeps, h, structure, walkers, state,
             records)


@njit(**OPTIONS)
def advance_msd_one_mode_general(first_step, n_steps, substeps, h, structure, walkers, state,
                                 records):
    """:func:`_advance` with HSI, one mode, lanes or non-uniform stations."""
    _advance(MSD_ONE_MODE, GENERAL, first_step, n_steps, substeps, h, structure, walkers, state,
             records)


@njit(**OPTIONS)
def advance_msd(first_step, n_steps, substeps, h, structure, walkers, state, records):
    """:func:`_advance` with HSI and several modes on a uniform single-lane station grid."""
    _advance(MSD, UNIFORM, first_step, n_steps, substeps, h, structure, walkers, state, records)


@njit(**OPTIONS)
def advance_msd_general(first_step, n_steps, substeps, h, structure, walkers, state, records):
    """:func:`_advance` with HSI and several modes, lanes or non-uniform stations."""
    _advance(MSD, GENERAL, first_step, n_steps, substeps, h, structure, walkers, state, records)


ENTRY_POINTS = {(FORCES, UNIFORM): advance_forces, (FORCES, GENERAL): advance_forces_general,
                (MSD_ONE_MODE, UNIFORM): advance_msd_one_mode,
                (MSD_ONE_MODE, GENERAL): advance_msd_one_mode_general,
                (MSD, UNIFORM): advance_msd, (MSD, GENERAL): advance_msd_general}


def entry_point(hsi, n_modes, uniform, n_lanes):
    """The compiled kernel for a run: by HSI and mode count, and by the station grid's kind."""
    step_kind = MSD_ONE_MODE if hsi and n_modes == 1 else MSD if hsi else FORCES
    rows_kind = UNIFORM if uniform and n_lanes == 1 else GENERAL
    return ENTRY_POINTS[step_kind, rows_kind]
