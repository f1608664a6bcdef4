"""The window's comfort measures over the crowd's occupancy states (docs: theory, A year of
comfort, Where the Gaussian model holds).

A Poisson crowd does not keep its mean number of walkers on the deck: walkers come and go on
the time scale of a crossing (38 s on the paper's bridge), and with them the crowd influence
ψ(t) = Σ_k φ²(x_k(t)) that sets both the load and the mass the walkers add. The occupied mode
forgets in a few seconds, so within a ten-minute window the response passes through occupancy
states λ = ψ/ψ̄, each a stationary Gaussian response of the smeared crowd of density λ d (the
quasi-static states of :class:`crowdvib.response.FluctuatingSpectralModel`, whose occupancy law
:func:`crowdvib.response.frequency_domain.fluctuation.occupancy_law` is used here as it is). A level a is
crossed at the rate of the state the response is in, so over the window

    ν(a) = E_λ[ν_λ(a)] = Σ_j p_j ν(a; σ_j, ν0_j, δ_j),      P(peak ≤ a) = exp(−T ν(a)),

ν(a; ·) the clumped (or Poisson) crossing rate of one Gaussian state
(:mod:`crowdvib.comfort.measure`); likewise the running RMS's crossings. The average PSD's single
Gaussian law keeps E_λ[σ_λ²] but not the states with more walkers than on average, whose larger
σ_λ set the upper tail: at a thin crowd (λ spread widely) it reads the upper quantiles low; at a
dense crowd λ → 1 and the two laws agree (the law of one state).

The laws are computed at ``n_states`` occupancies spanning the law's support and interpolated
between them in σ²/λ, ν0, δ, σ_r/σ² and ν_z (smooth in λ); the occupancy law's own grid
(4096 points) carries the expectation. The states are quasi-static: the drift correction of
the mixture PSD (docs: theory, Beyond the quasi-static mixture) is left out, and the window's
crossings are taken as one Poisson stream of the mean rate (the states it visits are many:
a window is 15 crossings long).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import check_count
from ..response.frequency_domain.fluctuation import FluctuatingSpectralModel, occupancy_law
from ..response.frequency_domain.spectral import SpectralModel
from .measure import (WindowLaw, bisect_level, level_crossing_rate, running_rms_rate,
                      window_law)

__all__ = ["OccupiedLaw", "occupied_law", "occupied_peak_quantile",
           "occupied_running_rms_quantile", "OCCUPANCY_STATES"]

#: Occupancies at which the response is computed (interpolated between them).
OCCUPANCY_STATES = 9
#: The occupancy law's tails left out (each side): below any quantile asked of a window.
_TAIL = 1e-9


@dataclass(frozen=True)
class OccupiedLaw:
    """The window laws of a crowd's occupancy states.

    Attributes
    ----------
    probability : ndarray
        p_j of the occupancy states (sum 1).
    occupancy : ndarray
        λ_j = ψ/ψ̄ of the states [-].
    laws : WindowLaw
        One :class:`~crowdvib.comfort.measure.WindowLaw` whose fields are arrays over the
        states.
    """

    probability: np.ndarray
    occupancy: np.ndarray
    laws: WindowLaw

    @property
    def rms(self) -> float:
        """sqrt(E_λ σ_λ²) [m/s²], the RMS of the average PSD's state."""
        return float(np.sqrt(self.probability @ np.asarray(self.laws.rms) ** 2))


def occupied_law(structure, crowd, frequency, *, msd=None, output: int = 0, dampers=None,
                 force=None, rms_window: float = 1.0,
                 n_states: int = OCCUPANCY_STATES) -> OccupiedLaw:
    """:class:`OccupiedLaw` of a Poisson crowd on ``structure`` (module docstring).

    Parameters
    ----------
    structure, crowd, frequency
        As for :class:`crowdvib.response.FluctuatingSpectralModel` (the crowd's density > 0).
    msd : MSDModel, optional
        The walkers' MSD (None: moving forces, no HSI).
    output : int
        Index of the output judged.
    dampers, force
        As for :class:`crowdvib.response.SpectralModel`.
    rms_window : float
        τ of the running RMS [s].
    n_states : int
        Occupancies at which the response is computed, ≥ 2.
    """
    n_states = check_count("n_states", n_states, minimum=2)
    options = {"dampers": dampers, "force": force}
    # The occupied mode and its crossing kernel, as the fluctuating crowd's states have them.
    mixture = FluctuatingSpectralModel(structure, crowd, frequency, n_nodes=1, **options)
    values, probability = occupancy_law(structure, crowd.density, mixture.mode)
    cumulative = np.cumsum(probability)
    keep = (cumulative >= _TAIL) & (cumulative - probability <= 1 - _TAIL) & (values > 0)
    values, probability = values[keep], probability[keep] / probability[keep].sum()
    nodes = np.linspace(values[0], values[-1], n_states)
    laws = []
    for node in nodes:
        state = SpectralModel(structure, crowd.with_density(crowd.density * node), frequency,
                              crossing_spread=mixture.crossing_spread, **options)
        laws.append(window_law(state.frequency, state.psd_array(msd)[output],
                               rms_window=rms_window))
    table = np.array([[law.rms**2 / node, law.crossing_rate, law.spread,
                       law.ms_std / law.rms**2 if law.rms else 0.0, law.ms_rate]
                      for node, law in zip(nodes, laws)])
    columns = [np.interp(values, nodes, column) for column in table.T]
    rms = np.sqrt(columns[0] * values)
    return OccupiedLaw(probability, values,
                       WindowLaw(rms, columns[1], columns[2], columns[3] * rms**2, columns[4]))


def _peak_rate(level, law: OccupiedLaw, peak_model):
    """E_λ ν_λ(level) [Hz] (level an array: one rate per level)."""
    level = np.asarray(level, float)[..., None]
    states = law.laws
    return level_crossing_rate(states.rms, states.crossing_rate, states.spread, level,
                         peak_model) @ law.probability


def occupied_peak_cdf(level, law: OccupiedLaw, duration=600.0, peak_model="vanmarcke"):
    """P(max |a| over ``duration`` ≤ ``level``) over the occupancy states."""
    return np.exp(-duration * _peak_rate(level, law, peak_model))


def occupied_peak_quantile(probability, law: OccupiedLaw, duration=600.0,
                           peak_model="vanmarcke"):
    """The level [m/s²] the window's peak stays below with ``probability``."""
    top = 12 * float(np.max(law.laws.rms))
    return bisect_level(lambda x: occupied_peak_cdf(x, law, duration, peak_model),
                        probability, top)


def occupied_running_rms_quantile(probability, law: OccupiedLaw, duration=600.0):
    """The level [m/s²] the window's largest running RMS stays below with ``probability``."""
    states = law.laws

    def cdf(level):
        rate = running_rms_rate(np.asarray(level, float)[..., None], states.rms,
                                states.ms_std, states.ms_rate) @ law.probability
        return np.exp(-duration * rate)

    return bisect_level(cdf, probability, 12 * float(np.max(states.rms)))
