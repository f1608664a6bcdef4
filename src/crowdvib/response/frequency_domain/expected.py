"""The protocol every model of the expected response PSD follows (issue 34 §4).

:class:`~crowdvib.response.SpectralModel` (the paper's smeared crowd),
:class:`~crowdvib.response.FluctuatingSpectralModel` (a Poisson crowd's occupancy) and
:class:`~crowdvib.response.VaryingCrowdModel` (a crowd that changes over the record) are used
by the estimator, the studies and the averages over densities through
:class:`ExpectedPSDModel` alone (docs: theory, Response PSD with HSI; The fluctuating crowd).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np

from ...signals import ResponsePSD

if TYPE_CHECKING:
    from ...models.crowd import Crowd
    from ...models.pedestrian import MSDModel
    from ...signals.lowpass import LowPassFilter

__all__ = ["ExpectedPSDModel", "model_psd"]


@runtime_checkable
class ExpectedPSDModel(Protocol):
    """What every model of the expected response PSD offers (:class:`SpectralModel`, the
    smeared crowd; :class:`~crowdvib.response.FluctuatingSpectralModel`, a Poisson crowd's
    occupancy; :class:`~crowdvib.response.VaryingCrowdModel`, a crowd that changes): the
    estimator, the studies and the averages over densities use them through this alone."""

    frequency: np.ndarray
    output_names: tuple
    crowd: Crowd
    welch_window_length: float | None
    lowpass: LowPassFilter | None

    def psd_array(self, msd: MSDModel | None = None) -> np.ndarray:
        """Expected PSD [(m/s²)²/Hz], shape (n_outputs, n_frequencies).

        Parameters
        ----------
        msd : MSDModel, optional
            The pedestrians' MSD; None for the crowd as moving forces only (no HSI).
        """

    def cross_psd_array(self, msd: MSDModel | None = None) -> np.ndarray:
        """Expected cross-spectral matrix, shape (n_outputs, n_outputs, n_frequencies).

        Parameters
        ----------
        msd : MSDModel, optional
            The pedestrians' MSD; None for the crowd as moving forces only (no HSI).
        """

    def psd(self, msd: MSDModel | None = None) -> ResponsePSD:
        """The expected PSD as a :class:`~crowdvib.ResponsePSD`.

        Parameters
        ----------
        msd : MSDModel, optional
            The pedestrians' MSD; None for the crowd as moving forces only (no HSI).
        """

    def with_step_frequencies(self, crowd: Crowd) -> ExpectedPSDModel:
        """The same model for walkers that differ only in their step frequencies.

        Parameters
        ----------
        crowd : Crowd
            The walkers with other step frequencies (same density, speed and body mass).
        """

    def details(self) -> dict[str, Any]:
        """What the model is made of, for a report (empty for the smeared crowd)."""


def model_psd(model: ExpectedPSDModel, msd: MSDModel | None) -> ResponsePSD:
    """``model``'s expected PSD at ``msd`` as a :class:`~crowdvib.ResponsePSD` (what every
    model's ``psd`` returns)."""
    return ResponsePSD(frequency=model.frequency, psd=model.psd_array(msd),
                       output_names=model.output_names,
                       window_length=model.welch_window_length, lowpass=model.lowpass,
                       source="model")
