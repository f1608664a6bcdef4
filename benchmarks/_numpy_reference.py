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
