"""The walkers on the deck as contiguous arrays (docs: theory, Walkers on the deck as arrays).

Private numerics of :mod:`crowdvib.response._kernels`: the per-walker work of a time step, written
so that the loops over walkers vectorise (SIMD). Everything a step needs about the walkers on the
deck lives in *slot order*, slots 0 … n_active − 1 contiguous:

* ``slots[FIELD, slot]`` — the constants of the walker in that slot (position at arrival, signed
  speed, arrival and leaving times, k_h1, c_h1, 1/m_h1, m_h0, static weight, lane weight), copied
  from the per-pedestrian arrays when the walker enters;
* ``index[PEDESTRIAN | LANE | SEGMENT, slot]`` — its pedestrian number, first lane, and the
  segment of the station grid it was on last (non-uniform grids only);
* ``phi[instant, j, slot]`` and ``force[instant, slot]`` at the three instants of an RK4 step
  (NOW = t, MID = t + h/2, END = t + h); ``wave[c, slot]`` (force component, slot); u, u̇.

A walker who leaves is removed by shifting the later slots down (their order is kept, so the sums
over slots run in order of entry). The loops over slots then read consecutive memory with no
branch and no indirect index, and LLVM vectorises them; only the look-up of the mode-shape table
(a gather) stays scalar.

The functions the step loop calls at every step are leaves with no branch around their loops:
numba passes arrays to a call with reference counting (atomic operations) unless it can prove them
unneeded, and a call inside a loop, under a branch taken at run time or before an early return
defeats that proof. Helpers marked ``INLINE`` are merged into their caller by numba, but their
arrays are counted the same way when the merge lands inside a loop or between loops, so the leaves
of the paper's path (``rows_uniform``, ``_stages.step_msd_one_mode``) are written out instead.
Inputs are trusted, as in ``_kernels``.
"""

import math

import numpy as np
from numba import njit

# Rows of ``slots`` (float64, (N_FIELDS, capacity)).
X_START, VELOCITY, ARRIVAL, T_OFF, STIFFNESS, DAMPING, INV_SPRUNG, UNSPRUNG, STATIC, LANE_WEIGHT = \
    range(10)
N_FIELDS = 10
# Rows of ``index`` (int64, (N_INDICES, capacity)).
PEDESTRIAN, LANE, SEGMENT = range(3)
N_INDICES = 3
# The instants of an RK4 step (first axis of phi, force and the mass factors).
NOW, MID, END = range(3)

# error_model="numpy": a division never raises, so no branch in a vectorised loop.
OPTIONS = {"cache": True, "nogil": True, "error_model": "numpy"}
# Inlined into the caller by numba (part of its leaf; it takes the caller's fastmath flags).
INLINE = dict(OPTIONS, inline="always")


def slot_capacity(t_on, t_off):
    """Slots enough for the most walkers ever on the deck at once, padded for the cache.

    A walker is integrated at step t when t_on <= t < t_off, so at most the largest number of
    half-open intervals [t_on, t_off) sharing a point, which is reached at some t_on. The row
    length is rounded up to whole 64-byte lines, and kept off multiples of 4 KiB, where the rows
    of an (n, capacity) array would all fall in the same cache sets.
    """
    if t_on.size == 0:
        return 8
    on = np.sort(t_on)
    off = np.sort(t_off)
    most = int(np.max(np.searchsorted(on, on, side="right") - np.searchsorted(off, on, side="right")))
    capacity = 8 * (max(most, 1) // 8 + 1)
    if capacity % 512 == 0:
        capacity += 8
    return capacity


def aligned_zeros(shape, dtype=np.float64):
    """Zeros whose first element sits on a 64-byte boundary (a cache line, an AVX-512 vector)."""
    itemsize = np.dtype(dtype).itemsize
    size = int(np.prod(shape))
    raw = np.zeros(size * itemsize + 64, dtype=np.uint8)
    start = -raw.ctypes.data % 64
    return raw[start:start + size * itemsize].view(dtype).reshape(shape)


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
    """Segment s with positions[s] <= x <= positions[s + 1] (clipped to the walkway), by bisection."""
    low = 0
    high = positions.size - 2
    while low < high:
        middle = (low + high + 1) // 2
        if positions[middle] <= x:
            low = middle
        else:
            high = middle - 1
    return low


@njit(**OPTIONS)
def cells_walk(start, stop, t, slots, index, positions, n_lanes, segment_in, segment_out, cell,
               frac):
    """As the uniform-grid cells on any grid: the segment ``segment_in`` is walked to x.

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
def gather_lanes(start, stop, cell, frac, slots, table, n_positions, phi, instant):
    """Mode-shape rows φ[instant, j, slot] by linear interpolation in x from the table, then
    linearly across the two lanes either side of the walker."""
    for j in range(phi.shape[1]):
        for slot in range(start, stop):
            c = cell[slot]
            a = frac[slot]
            low = table[j, c] + a * (table[j, c + 1] - table[j, c])
            c += n_positions
            high = table[j, c] + a * (table[j, c + 1] - table[j, c])
            phi[instant, j, slot] = low + slots[LANE_WEIGHT, slot] * (high - low)


@njit(**OPTIONS)
def rows_uniform(n_active, t_mid, t_end, slots, index, positions, inverse_spacing, n_lanes, table,
                 cell, frac, phi):
    """Shape rows at t + h/2 and t + h on a uniform station grid, in one call.

    The segment is s = ⌊(x − x₀)/Δx⌋ (at most the last); off the walkway the zero lane, fraction
    0; then the linear interpolation in x and, across lanes, that of :func:`gather_lanes`.
    Written out: helpers inlined by numba would count references to their arrays (atomic
    operations) at every step.
    """
    n_positions = positions.size
    first = positions[0]
    last = positions[n_positions - 1]
    top = n_positions - 2
    off = n_lanes * n_positions
    for instant in range(MID, END + 1):
        t = t_mid if instant == MID else t_end
        for slot in range(n_active):
            x = slots[X_START, slot] + slots[VELOCITY, slot] * (t - slots[ARRIVAL, slot])
            a = (x - first) * inverse_spacing
            s = min(max(int(a), 0), top)
            on = (x >= first) & (x <= last)
            cell[slot] = index[LANE, slot] * n_positions + s if on else off
            frac[slot] = a - s if on else 0.0
        for j in range(phi.shape[1]):
            for slot in range(n_active):
                c = cell[slot]
                low = table[j, c] + frac[slot] * (table[j, c + 1] - table[j, c])
                if n_lanes > 1:
                    c += n_positions
                    high = table[j, c] + frac[slot] * (table[j, c + 1] - table[j, c])
                    low = low + slots[LANE_WEIGHT, slot] * (high - low)
                phi[instant, j, slot] = low


@njit(**OPTIONS)
def harmonic_forces(n_active, slots, wave_now, wave_prev, two_cos, force):
    """Walking forces at t + h/2 and t + h; the components advance by δ = ω_c h/2 twice.

    sin(θ + δ) = 2 cos δ · sin θ − sin(θ − δ) (Chebyshev recurrence): no sine in the loop. The sum
    over components runs in component order, the static weight first, two components per pass
    (half the read-modify-writes of the sums, same order); an odd count ends on a zero component.
    """
    for slot in range(n_active):
        force[MID, slot] = slots[STATIC, slot]
        force[END, slot] = slots[STATIC, slot]
    for c in range(0, wave_now.shape[0], 2):
        for slot in range(n_active):
            now = wave_now[c, slot]
            mid = two_cos[c, slot] * now - wave_prev[c, slot]
            end = two_cos[c, slot] * mid - now
            wave_prev[c, slot] = mid
            wave_now[c, slot] = end
            now2 = wave_now[c + 1, slot]
            mid2 = two_cos[c + 1, slot] * now2 - wave_prev[c + 1, slot]
            end2 = two_cos[c + 1, slot] * mid2 - now2
            wave_prev[c + 1, slot] = mid2
            wave_now[c + 1, slot] = end2
            force[MID, slot] = (force[MID, slot] + mid) + mid2
            force[END, slot] = (force[END, slot] + end) + end2



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
def replayed_forces(n_active, t_mid, t_end, slots, index, replay, force):
    """Add the replayed measured forces at t + h/2 and t + h (walkers with a record only)."""
    record = replay[0]
    for slot in range(n_active):
        k = index[PEDESTRIAN, slot]
        if record[k] >= 0:
            force[MID, slot] += replayed(k, t_mid - slots[ARRIVAL, slot], replay)
            force[END, slot] += replayed(k, t_end - slots[ARRIVAL, slot], replay)


@njit(**OPTIONS)
def enter(k, t, half, slot, z, zd, t_off, t_arrival, x_start, velocity, lane_low, lane_weight,
           unsprung, sprung, stiffness, damping, static, amplitude, omega, phase, two_cos, replay,
           table, positions, inverse_spacing, n_lanes, slots, index, phi, u, ud, force, wave_now,
           wave_prev, wave_cos):
    """Pedestrian k takes ``slot`` at time t: its constants copied in, its MSD at rest on the deck."""
    slots[X_START, slot] = x_start[k]
    slots[VELOCITY, slot] = velocity[k]
    slots[ARRIVAL, slot] = t_arrival[k]
    slots[T_OFF, slot] = t_off[k]
    slots[STIFFNESS, slot] = stiffness[k]
    slots[DAMPING, slot] = damping[k]
    slots[INV_SPRUNG, slot] = 1.0 / sprung[k]
    slots[UNSPRUNG, slot] = unsprung[k]
    slots[STATIC, slot] = static[k]
    slots[LANE_WEIGHT, slot] = lane_weight[k]
    index[PEDESTRIAN, slot] = k
    index[LANE, slot] = lane_low[k]
    elapsed = t - t_arrival[k]
    # The shape row at t: the arithmetic of the cells and gathers above, for one walker.
    x = x_start[k] + velocity[k] * elapsed
    n_positions = positions.size
    s = locate(x, positions)
    index[SEGMENT, slot] = s
    on = (x >= positions[0]) & (x <= positions[n_positions - 1])
    if inverse_spacing > 0.0:
        a = (x - positions[0]) * inverse_spacing
        s = min(max(int(a), 0), n_positions - 2)
        a -= s
    else:
        a = (x - positions[s]) / (positions[s + 1] - positions[s])
    c = lane_low[k] * n_positions + s if on else n_lanes * n_positions
    a = a if on else 0.0
    for j in range(z.size):
        low = table[j, c] + a * (table[j, c + 1] - table[j, c])
        if n_lanes > 1:                 # (one lane: the weight is 0, the same value)
            high = (table[j, c + n_positions]
                    + a * (table[j, c + n_positions + 1] - table[j, c + n_positions]))
            low = low + lane_weight[k] * (high - low)
        phi[NOW, j, slot] = low
    dz = 0.0
    dzd = 0.0
    for j in range(z.size):
        dz += phi[NOW, j, slot] * z[j]
        dzd += phi[NOW, j, slot] * zd[j]
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
    force[NOW, slot] = p


@njit(**OPTIONS)
def earliest_leaving(n_active, slots):
    """The earliest t_off of the walkers on the deck (inf on an empty deck): nobody leaves
    before it, so a step compares t with this one number instead of every walker's t_off."""
    earliest = np.inf
    for slot in range(n_active):
        earliest = min(earliest, slots[T_OFF, slot])
    return earliest


@njit(**OPTIONS)
def leave(t, n_active, slots, index, phi, force, wave_now, wave_prev, two_cos, u, ud, keep):
    """Remove the walkers with t >= t_off; the others shift down in order. Returns n_active.

    Only the state at t (phi[NOW], force[NOW]) is kept; the other instants are recomputed.
    """
    kept = 0
    for slot in range(n_active):
        if t < slots[T_OFF, slot]:
            keep[kept] = slot
            kept += 1
    # keep[i] >= i and increasing: an in-place forward copy is safe.
    for array in (slots, phi[NOW], wave_now, wave_prev, two_cos):
        for row in range(array.shape[0]):
            for i in range(kept):
                array[row, i] = array[row, keep[i]]
    for row in range(index.shape[0]):
        for i in range(kept):
            index[row, i] = index[row, keep[i]]
    for array in (u, ud, force[NOW]):
        for i in range(kept):
            array[i] = array[keep[i]]
    return kept
