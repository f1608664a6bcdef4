"""The walkers on the deck as contiguous arrays (docs: theory, Walkers on the deck as arrays).

Private numerics of :mod:`crowdvib.response._kernels`: the per-walker work of a time step, written
so that the loops over walkers vectorise (SIMD). Everything a step needs about the walkers on the
deck lives in *slot order*, slots 0 … n_active − 1 contiguous:

* ``slots[FIELD, slot]`` — the constants of the walker in that slot (position at arrival, signed
  speed, arrival and leaving times, k_h1, c_h1, m_h1, m_h0, static weight, lane weight), copied
  from the per-pedestrian arrays when the walker enters;
* ``index[PEDESTRIAN | LANE | SEGMENT, slot]`` — its pedestrian number, first lane, and the
  segment of the station grid it was on last (non-uniform grids only);
* ``phi[j, slot]`` (mode, slot), ``wave[c, slot]`` (force component, slot), ``u``, ``u̇``, force.

A walker who leaves is removed by shifting the later slots down (their order is kept, so the sums
over slots run in order of entry). The loops over slots then read consecutive memory with no
branch and no indirect index, and LLVM vectorises them; only the look-up of the mode-shape table
(a gather) stays scalar. Inputs are trusted, as in ``_kernels``.
"""

import math

import numpy as np
from numba import njit

# Rows of ``slots`` (float64, (N_FIELDS, capacity)).
X_START, VELOCITY, ARRIVAL, T_OFF, STIFFNESS, DAMPING, SPRUNG, UNSPRUNG, STATIC, LANE_WEIGHT = \
    range(10)
N_FIELDS = 10
# Rows of ``index`` (int64, (N_INDICES, capacity)).
PEDESTRIAN, LANE, SEGMENT = range(3)
N_INDICES = 3

# error_model="numpy": a division never raises, so no branch in a vectorised loop.
OPTIONS = {"cache": True, "nogil": True, "error_model": "numpy"}


def shape_table(shapes):
    """The kernel's mode-shape table: (n_modes, (n_lanes + 2) · n_positions), two zero lanes last.

    Lane l, station s, mode j sits at column l · n_positions + s of row j. A point off the walkway
    is looked up at the first zero lane with fraction 0, so its row is exactly 0 with no branch
    (the lane above it, for a two-lane interpolation, is zero too).
    """
    n_lanes, n_positions, n_modes = shapes.shape
    table = np.zeros((n_modes, n_lanes + 2, n_positions))
    table[:, :n_lanes] = np.transpose(shapes, (2, 0, 1))
    return np.ascontiguousarray(table.reshape(n_modes, -1))


@njit(**OPTIONS)
def locate(x, positions):
    """Segment s with positions[s] <= x <= positions[s + 1] (clipped to the walkway)."""
    s = np.searchsorted(positions, x) - 1
    return min(max(s, 0), positions.size - 2)


@njit(**OPTIONS)
def cells_uniform(start, stop, t, slots, index, positions, inverse_spacing, n_lanes, cell, frac):
    """Table column and fraction of each slot's point at time t, on a uniform station grid.

    The segment is s = ⌊(x − x₀)/Δx⌋ (at most the last); off the walkway the zero lane, fraction 0.
    """
    n_positions = positions.size
    first = positions[0]
    last = positions[n_positions - 1]
    top = n_positions - 2
    off = n_lanes * n_positions
    for slot in range(start, stop):
        x = slots[X_START, slot] + slots[VELOCITY, slot] * (t - slots[ARRIVAL, slot])
        a = (x - first) * inverse_spacing
        s = min(max(int(a), 0), top)
        on = (x >= first) & (x <= last)
        cell[slot] = index[LANE, slot] * n_positions + s if on else off
        frac[slot] = a - s if on else 0.0


@njit(**OPTIONS)
def cells_walk(start, stop, t, slots, index, positions, n_lanes, segment_in, segment_out, cell,
               frac):
    """As :func:`cells_uniform` on any grid: the segment ``segment_in`` is walked to x.

    Walkers move monotonically, so that is O(1) per step. Off the walkway the segment is kept.
    """
    n_positions = positions.size
    first = positions[0]
    last = positions[n_positions - 1]
    for slot in range(start, stop):
        x = slots[X_START, slot] + slots[VELOCITY, slot] * (t - slots[ARRIVAL, slot])
        s = segment_in[slot]
        if x < first or x > last:
            cell[slot] = n_lanes * n_positions
            frac[slot] = 0.0
            segment_out[slot] = s
            continue
        while s < n_positions - 2 and x > positions[s + 1]:
            s += 1
        while s > 0 and x < positions[s]:
            s -= 1
        segment_out[slot] = s
        cell[slot] = index[LANE, slot] * n_positions + s
        frac[slot] = (x - positions[s]) / (positions[s + 1] - positions[s])


@njit(**OPTIONS)
def gather_rows(start, stop, cell, frac, slots, table, n_positions, two_lanes, out):
    """Mode-shape rows φ[j, slot] by linear interpolation in x (and across lanes) from the table."""
    n_modes = out.shape[0]
    if two_lanes:
        for j in range(n_modes):
            for slot in range(start, stop):
                c = cell[slot]
                a = frac[slot]
                low = table[j, c] + a * (table[j, c + 1] - table[j, c])
                c += n_positions
                high = table[j, c] + a * (table[j, c + 1] - table[j, c])
                out[j, slot] = low + slots[LANE_WEIGHT, slot] * (high - low)
    else:
        for j in range(n_modes):
            for slot in range(start, stop):
                c = cell[slot]
                out[j, slot] = table[j, c] + frac[slot] * (table[j, c + 1] - table[j, c])


@njit(**OPTIONS)
def shape_rows(start, stop, t, slots, index, table, positions, inverse_spacing, n_lanes,
               segment_in, segment_out, cell, frac, out):
    """Mode-shape rows of slots start … stop − 1 at time t into ``out[:, slot]``."""
    if inverse_spacing > 0.0:
        cells_uniform(start, stop, t, slots, index, positions, inverse_spacing, n_lanes, cell, frac)
    else:
        cells_walk(start, stop, t, slots, index, positions, n_lanes, segment_in, segment_out,
                   cell, frac)
    gather_rows(start, stop, cell, frac, slots, table, positions.size, n_lanes > 1, out)


@njit(**OPTIONS)
def harmonic_forces(n_active, slots, wave_now, wave_prev, two_cos, force_mid, force_end):
    """Walking forces at t + h/2 and t + h; the components advance by δ = ω_c h/2 twice.

    sin(θ + δ) = 2 cos δ · sin θ − sin(θ − δ) (Chebyshev recurrence): no sine in the loop. The sum
    over components runs in component order, the static weight first.
    """
    for slot in range(n_active):
        force_mid[slot] = slots[STATIC, slot]
        force_end[slot] = slots[STATIC, slot]
    for c in range(wave_now.shape[0]):
        for slot in range(n_active):
            now = wave_now[c, slot]
            y_mid = two_cos[c, slot] * now - wave_prev[c, slot]
            y_end = two_cos[c, slot] * y_mid - now
            force_mid[slot] += y_mid
            force_end[slot] += y_end
            wave_prev[c, slot] = y_mid
            wave_now[c, slot] = y_end


# --- Measured-force replay (table look-up), kept apart from the harmonic path ---------------
# ``replay`` = (record, offset, speed, weight, table): per pedestrian k the table row record[k]
# (-1: no replay, the harmonic sum alone), the start offset[k] [table samples] at the arrival time,
# speed[k] [table samples per second] and weight[k] [N] (s_k W_k); table[r] holds F_r/F̄_r − 1.
# The force is weight · table[r](offset + speed (t − t_k)), periodically continued and linearly
# interpolated (docs: theory, Measured walking forces); models/measured.py ``replay_value`` is
# the numpy twin. Harmonic-only runs pass record = -1 everywhere and add nothing: bit-identical.


@njit(**OPTIONS)
def replayed(k, elapsed, replay):
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


@njit(**OPTIONS)
def replayed_forces(n_active, t_mid, t_end, slots, index, replay, force_mid, force_end):
    """Add the replayed measured forces at t + h/2 and t + h (walkers with a record only)."""
    record = replay[0]
    for slot in range(n_active):
        k = index[PEDESTRIAN, slot]
        if record[k] >= 0:
            force_mid[slot] += replayed(k, t_mid - slots[ARRIVAL, slot], replay)
            force_end[slot] += replayed(k, t_end - slots[ARRIVAL, slot], replay)


@njit(**OPTIONS)
def leave(t, n_active, slots, index, phi, wave_now, wave_prev, two_cos, u, ud, force, keep):
    """Remove the walkers with t >= t_off; the others shift down in order. Returns n_active."""
    leaving = 0
    for slot in range(n_active):
        leaving += t >= slots[T_OFF, slot]
    if leaving == 0:
        return n_active
    kept = 0
    for slot in range(n_active):
        if t < slots[T_OFF, slot]:
            keep[kept] = slot
            kept += 1
    # keep[i] >= i and increasing: an in-place forward copy is safe.
    for array in (slots, phi, wave_now, wave_prev, two_cos):
        for row in range(array.shape[0]):
            for i in range(kept):
                array[row, i] = array[row, keep[i]]
    for row in range(index.shape[0]):
        for i in range(kept):
            index[row, i] = index[row, keep[i]]
    for array in (u, ud, force):
        for i in range(kept):
            array[i] = array[keep[i]]
    return kept
