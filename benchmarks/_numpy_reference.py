"""Plain-numpy reference implementations the benchmarks compare crowdvib against (issue 14).

Written straight from the formulas (docs: theory, Response PSD with HSI; What a Welch estimate
sees: the expectation kernel), with numpy's batched ``linalg.solve`` and no precomputation: what
a careful first implementation would do. Not used by crowdvib itself.
"""

import numpy as np


def exact_psd(structure, crowd, msd, frequency, outputs, force):
    """G_ü(f) = ω⁴ s(f) Σ_r |Φ_o H(ω) B|² with H = [K − ω²(M + M_app(ω) Ψ) + iωC]⁻¹."""
    omega = 2 * np.pi * np.asarray(frequency, dtype=float)
    m = structure.modal_masses
    wn = 2 * np.pi * structure.frequencies
    stiffness = np.diag(m * wn**2)
    damping = np.diag(2 * structure.damping_ratios * m * wn)
    mass = np.diag(m)
    psi = structure.influence_matrix(crowd.density)
    values, vectors = np.linalg.eigh(psi)
    keep = values > values.max() * 1e-12
    factor = vectors[:, keep] * np.sqrt(values[keep])
    shapes = structure.output_shapes[structure.output_index(outputs)]
    if msd is None:
        apparent = np.zeros_like(omega, dtype=complex)
    else:
        body = crowd.body_mass
        m1, k1, c1 = msd.sprung_mass(body), msd.stiffness(body), msd.damping(body)
        # Apparent mass of a base-driven MSD: m0 + m1 (k + iωc)/(k − ω² m1 + iωc).
        apparent = (body - m1) + m1 * (k1 + 1j * omega * c1) / (k1 - omega**2 * m1
                                                                 + 1j * omega * c1)
    dynamic = (stiffness[np.newaxis] + 1j * omega[:, None, None] * damping
               - omega[:, None, None] ** 2 * (mass + apparent[:, None, None] * psi))
    response = np.linalg.solve(dynamic, np.broadcast_to(factor, (omega.size,) + factor.shape))
    projected = shapes @ response                               # (n_f, n_out, rank)
    load = force.load_spectrum(frequency, crowd)
    return (np.abs(projected) ** 2).sum(axis=-1).T * omega**4 * load


def hann_kernel(offset, window_length):
    """K_T(ν) = (8T/3) [sin(πνT) / (2πνT (1 − ν²T²))]² with its removable limits."""
    x = np.asarray(offset, dtype=float) * window_length
    with np.errstate(divide="ignore", invalid="ignore"):
        amplitude = np.sin(np.pi * x) / (2 * np.pi * x * (1 - x * x))
    amplitude[np.abs(x) < 1e-9] = 0.5
    amplitude[np.abs(np.abs(x) - 1) < 1e-9] = 0.25
    return 8 * window_length / 3 * amplitude**2


def welch_expectation(structure, crowd, msd, frequency, outputs, force, window_length,
                      points_per_bin=16, half_width_bins=8):
    """E[Ĝ](f) = ∫ K_T(f − ν) G(ν) dν by a rectangle rule on a uniform grid of the exact PSD."""
    frequency = np.asarray(frequency, dtype=float)
    step = 1.0 / (window_length * points_per_bin)
    reach = half_width_bins / window_length
    low = max(frequency[0] - reach, 0.0)
    grid = np.arange(low, frequency[-1] + reach + step, step)
    psd = exact_psd(structure, crowd, msd, grid, outputs, force)
    out = np.empty((psd.shape[0], frequency.size))
    for i, f in enumerate(frequency):
        near = np.abs(grid - f) <= reach
        out[:, i] = psd[:, near] @ hann_kernel(f - grid[near], window_length) * step
    return out


def simulate_rk4(integrator, n_steps):
    """The coupled time-domain model by plain numpy, one RK4 step at a time (docs: theory, Equations of motion).

    ``integrator`` is crowdvib's prepared run (``response.time_domain._integrator.prepare``), used only for
    its walkers and parameters, so both implementations see the same crowd. Every stage
    interpolates the mode shapes (``np.interp``), evaluates the forces with ``np.sin`` and solves
    M(t) z̈ = Σ φ (p + contact) − C ż − K z with ``np.linalg.solve``; a walker enters at rest on
    the deck and leaves at the first step after t_off. Returns the output accelerations at the
    steps that are output samples, shape (n_outputs, n_samples).
    """
    run, w = integrator, integrator.walkers
    h, substeps, first = run.h, run.substeps, run.step
    mass, damping, stiffness = (np.diag(run.modal_masses), np.diag(run.modal_damping),
                                np.diag(run.modal_stiffness))
    n_modes = mass.shape[0]
    lanes = run.shapes.shape[0]

    def shapes_at(t, k):
        """φ (walkers × modes) at time t: linear along each lane, then across; 0 off the deck."""
        x = w.x_start[k] + w.velocity[k] * (t - w.arrival[k])
        low = run.lane_low[k]
        high = np.minimum(low + 1, lanes - 1)
        walkers = np.arange(k.size)
        phi = np.empty((k.size, n_modes))
        for j in range(n_modes):
            along = np.array([np.interp(x, run.positions, run.shapes[lane, :, j], left=0.0,
                                        right=0.0) for lane in range(lanes)])
            first, second = along[low, walkers], along[high, walkers]
            phi[:, j] = first + run.lane_weight[k] * (second - first)
        return phi

    def derivatives(t, k, z, zd, u, ud):
        phi = shapes_at(t, k)
        p = run.static[k] + np.sum(run.amplitude[k] * np.sin(
            run.omega[k] * (t - w.arrival[k])[:, None] + w.phase[k]), axis=1)
        contact = run.stiffness[k] * (u - phi @ z) + run.damping[k] * (ud - phi @ zd)
        matrix = mass + (phi.T * run.unsprung[k]) @ phi
        zdd = np.linalg.solve(matrix, phi.T @ (p + contact) - damping @ zd - stiffness @ z)
        return zdd, -contact / run.sprung[k]

    z, zd = np.zeros(n_modes), np.zeros(n_modes)
    active = np.zeros(0, dtype=np.int64)
    u, ud = np.zeros(0), np.zeros(0)
    entered = 0
    samples = []
    for n in range(first, first + n_steps):
        t = n * h
        stay = t < w.t_off[active]
        active, u, ud = active[stay], u[stay], ud[stay]
        newcomers = np.arange(entered, np.searchsorted(w.t_on, t, side="right"))
        entered += newcomers.size
        newcomers = newcomers[t < w.t_off[newcomers]]
        phi_new = shapes_at(t, newcomers)
        active = np.concatenate([active, newcomers])
        u, ud = np.concatenate([u, phi_new @ z]), np.concatenate([ud, phi_new @ zd])
        a1, b1 = derivatives(t, active, z, zd, u, ud)
        if n >= 0 and n % substeps == 0:
            samples.append(run.output_shapes @ a1)
        a2, b2 = derivatives(t + h / 2, active, z + h / 2 * zd, zd + h / 2 * a1,
                             u + h / 2 * ud, ud + h / 2 * b1)
        a3, b3 = derivatives(t + h / 2, active, z + h / 2 * (zd + h / 2 * a1), zd + h / 2 * a2,
                             u + h / 2 * (ud + h / 2 * b1), ud + h / 2 * b2)
        a4, b4 = derivatives(t + h, active, z + h * (zd + h / 2 * a2), zd + h * a3,
                             u + h * (ud + h / 2 * b2), ud + h * b3)
        z, zd = (z + h * zd + h * h / 6 * (a1 + a2 + a3),
                 zd + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4))
        if run.hsi:
            u, ud = (u + h * ud + h * h / 6 * (b1 + b2 + b3),
                     ud + h / 6 * (b1 + 2 * b2 + 2 * b3 + b4))
    return np.array(samples).T
