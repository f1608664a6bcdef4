"""Frozen results of the frequency-domain models: FRFs and occupied modal properties.

Each documents its fields with units, offers ``to_dict()`` for JSON and, where a picture helps,
``plot()`` which delegates to :mod:`crowdvib.reporting.plotting` (imported only then).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..._validation import FieldsFromDict, frozen_array
from .plots import plot_frf

if TYPE_CHECKING:
    from matplotlib.axes import Axes


__all__ = ["FRF", "EffectiveModalProperties"]


@dataclass(frozen=True, eq=False)
class FRF:
    """Accelerance frequency-response functions between points of the deck.

    Attributes
    ----------
    frequency : ndarray, shape (n_frequencies,)
        Frequencies [Hz].
    values : ndarray of complex, shape (n_outputs, n_inputs, n_frequencies)
        Acceleration at each output per unit vertical force at each input [(m/s²)/N].
    output_names, input_names : tuple of str
    occupied : bool
        True when the crowd's apparent mass is included.
    unit : str
    """

    frequency: np.ndarray
    values: np.ndarray
    output_names: tuple
    input_names: tuple
    occupied: bool = False
    unit: str = "(m/s²)/N"

    def __post_init__(self):
        object.__setattr__(self, "frequency", frozen_array(self.frequency))
        object.__setattr__(self, "values", frozen_array(self.values, complex))

    def plot(self, occupied: FRF | None = None, *, output: str | None = None,
             input: str | None = None, band: tuple[float, float] | None = None,
             ax: Axes | None = None, title: str | None = None) -> Axes:
        """Draw |H| of one output/input pair, with an occupied FRF beside it if given
        (see :func:`crowdvib.reporting.plotting.plot_frf`).

        Parameters
        ----------
        occupied : FRF, optional
            The occupied structure's FRF, drawn beside.
        output, input : str, optional
            The pair drawn (default the first output, and input = output).
        band : (float, float), optional
            Frequency range drawn [Hz].
        ax : matplotlib.axes.Axes, optional
            Axes to draw on (default a new figure).
        title : str, optional
            The axes' title.

        Returns
        -------
        matplotlib.axes.Axes
        """

        return plot_frf(self, occupied, output=output, input=input, band=band, ax=ax,
                        title=title)

    def magnitude(self, output: str, input: str | None = None) -> np.ndarray:
        """|H| [(m/s²)/N] of one output/input pair (input defaults to the output itself).

        Parameters
        ----------
        output : str
            The output.
        input : str, optional
            The input (default ``output``).
        """
        o = self.output_names.index(output)
        i = self.input_names.index(output if input is None else input)
        return np.abs(self.values[o, i])


@dataclass(frozen=True, eq=False)
class EffectiveModalProperties(FieldsFromDict):
    """Modal properties of the occupied structure (smeared crowd of MSDs, docs: theory, The smeared crowd and the occupied bridge).

    Attributes
    ----------
    frequencies : ndarray, shape (n_modes,)
        Effective natural frequencies f = |λ|/2π [Hz], one per structural mode.
    damping_ratios : ndarray, shape (n_modes,)
        Effective damping ratios ξ = −Re λ/|λ| [-].
    participation : ndarray, shape (n_modes,)
        Share of the pole's modal kinetic energy in that structural mode [-]; near 1 for a
        structure-like pole.
    interaction_frequencies, interaction_damping_ratios : ndarray
        The remaining, MSD-like poles (the crowd's own resonance, tuned mass dampers), kept
        apart [Hz], [-].
    modal_masses : ndarray, shape (n_modes,), or None
        Engaged modal masses [kg]: the SDOF mass with the same pole and residue of the modal
        receptance, in the scaling of the structure's mode shapes.
    """

    frequencies: np.ndarray
    damping_ratios: np.ndarray
    participation: np.ndarray
    interaction_frequencies: np.ndarray
    interaction_damping_ratios: np.ndarray
    modal_masses: np.ndarray | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {name: (None if getattr(self, name) is None
                       else np.asarray(getattr(self, name)).tolist()) for name in
                ("frequencies", "damping_ratios", "participation", "interaction_frequencies",
                 "interaction_damping_ratios", "modal_masses")}
