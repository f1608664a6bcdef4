"""One RK4 step of the coupled system over the walkers on the deck (docs: theory, Time stepping).

Private numerics of :mod:`crowdvib.response._kernels`: the mass factors at the instants of a step,
the four stages and the update, for moving forces only (``step_forces``), with HSI and several
modes (``step_msd``) or one mode (``step_msd_one_mode``). The walkers are the slots of
:mod:`._slots`; every function here is a leaf (see there why).

Sums over the walkers (the modal force Σ φ_k g_k and the added mass Σ m_h0 φ_k φ_kᵀ) are the only
reductions; the functions holding them may reassociate (``fastmath={"reassoc"}``) so that they
vectorise too. The order of the partial sums then depends only on the number of walkers on the
deck, never on the data, the chunking or the thread (docs: theory, Walkers on the deck as arrays).
"""

import math

from numba import njit

from ._slots import DAMPING, END, INLINE, INV_SPRUNG, MID, NOW, OPTIONS, STIFFNESS, UNSPRUNG

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
def modal_loads(phi, force, n_active, first, last, load):
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


@njit(**INLINE)
def _next_instant(phi, force, factor, n_active):
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
    _next_instant(phi, force, factor, n_active)


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
    _next_instant(phi, force, factor, n_active)


@njit(**_REDUCTION)
def step_msd_one_mode(h, z, zd, a, b, u, ud, phi, force, factor, n_active, modal_damping,
                      modal_stiffness, load, zs, zds, slots, modal_masses):
    """:func:`step_msd` for one mode (the common footbridge case): the same arithmetic, one pass
    over the walkers per stage, which also sums the added mass Σ m_h0 φ² at the stage's instant,
    so the 1×1 mass matrix needs no factor (nor a pass of its own). Written out: helpers inlined
    by numba inside the stage loop would count references to their arrays (atomic operations)
    at every stage."""
    for stage in range(4):
        instant, pos, vel, scale, inner = _stage_plan(stage, h)
        z0 = z[0] + scale * (zd[0] + inner * a[pos, 0])
        zd0 = zd[0] + scale * a[vel, 0]
        acc = 0.0
        added = 0.0
        for slot in range(n_active):
            p = phi[instant, 0, slot]
            us = u[slot] + scale * (ud[slot] + inner * b[pos, slot])
            uds = ud[slot] + scale * b[vel, slot]
            contact = (slots[STIFFNESS, slot] * (us - p * z0)
                       + slots[DAMPING, slot] * (uds - p * zd0))
            b[stage, slot] = -contact * slots[INV_SPRUNG, slot]
            acc += p * (force[instant, slot] + contact)
            added += (slots[UNSPRUNG, slot] * p) * p
        total = (-modal_damping[0] * zd0 - modal_stiffness[0] * z0 + load[instant, 0]) + acc
        a[stage, 0] = total / (modal_masses[0] + added)
    _rk4_update(h, z, zd, a, n_active, u, ud, b)
    _next_instant(phi, force, factor, n_active)
