"""Stochastic design prediction: RMS and expected peak acceleration of a crowd stream.

Not a code check: the response of a stationary stream of a given density follows from
crowdvib's own crowd model (the spectral model of :mod:`crowdvib.response.frequency_domain.spectral`, with and
without HSI), and its statistics from the response PSD G(f) (docs: theory, Stochastic design
prediction):

    σ² = ∫ G df,   ν0 = sqrt(∫ f² G df / ∫ G df),
    E[max |a| over T] ≈ g σ,   g = sqrt(2 ln(ν0 T)) + 0.5772 / sqrt(2 ln(ν0 T))

(Rice's mean zero up-crossing rate ν0 and Davenport's 1964 expected largest peak of a stationary
Gaussian process over T; ln(ν0 T) is floored at 1 for very short records). A separate function
rather than a ``design_check`` code: there is no code load, no mode-by-mode split and no code
limit; the result is per output, for a record length T, with the same three models of the
structure as the checks ("empty", "added_mass", "hsi").
"""

from dataclasses import dataclass

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from .._validation import FieldsFromDict, check_positive, check_type, frozen_array
from ..errors import ParameterError
from ..models.crowd import Crowd
from ..models.damper import as_dampers
from ..models.pedestrian import MSDModel
from ..models.structure import ModalModel
from ..response.frequency_domain.spectral import SpectralModel, effective_modal_properties
from .check import structure_models
from ..signals.weighting import wb_response

__all__ = ["ResponsePrediction", "predict_response", "davenport_peak_factor", "frequency_grid"]

EULER_GAMMA = 0.5772156649015329
#: Frequency steps per half-power half-width ξ f of the narrowest mode: a Lorentzian peak's
#: integral by the trapezoid rule is then within ~0.1 % (error ∝ (Δf / ξf)²).
STEPS_PER_HALF_WIDTH = 8
#: The PSD is integrated up to this multiple of the highest mode (and of the MSD frequency).
TOP_FREQUENCY_FACTOR = 1.5


def davenport_peak_factor(rate: ArrayLike, duration: float) -> np.ndarray:
    """Expected largest peak over σ of a stationary Gaussian process (Davenport 1964).

    g = sqrt(2 ln(ν T)) + 0.5772 / sqrt(2 ln(ν T)), ν the mean zero up-crossing rate [Hz] and T
    the duration [s]; ln(ν T) is floored at 1 (the asymptotic form needs many cycles).
    """
    x = np.sqrt(2 * np.maximum(np.log(np.asarray(rate, dtype=float) * duration), 1.0))
    return x + EULER_GAMMA / x


@dataclass(frozen=True, eq=False)
class ResponsePrediction(FieldsFromDict):
    """RMS and expected peak accelerations of a stationary crowd stream, per model and output.

    Attributes
    ----------
    models : tuple of str
        "empty" (moving forces), "added_mass", and with an MSD "hsi".
    output_names : tuple of str
    density : float
        Crowd density [persons/m²].
    duration : float
        Record length T of the peak factor [s].
    rms : ndarray, shape (n_models, n_outputs)
        σ [m/s²].
    crossing_rate : ndarray, shape (n_models, n_outputs)
        Mean zero up-crossing rate ν0 [Hz].
    peak_factor, expected_peak : ndarray, shape (n_models, n_outputs)
        g [-] and g σ [m/s²].
    weighted_rms : ndarray or None
        σ of the W_b-weighted acceleration [m/s²] (``weighting="Wb"``).
    """

    models: tuple
    output_names: tuple
    density: float
    duration: float
    rms: np.ndarray
    crossing_rate: np.ndarray
    peak_factor: np.ndarray
    expected_peak: np.ndarray
    weighted_rms: np.ndarray | None = None

    def __post_init__(self):
        for name in ("rms", "crossing_rate", "peak_factor", "expected_peak", "weighted_rms"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, frozen_array(getattr(self, name)))

    def to_dict(self) -> dict:
        """JSON-ready dict."""
        return {"models": list(self.models), "output_names": list(self.output_names),
                "density": self.density, "duration": self.duration,
                **{name: (None if getattr(self, name) is None else getattr(self, name).tolist())
                   for name in ("rms", "crossing_rate", "peak_factor", "expected_peak",
                                "weighted_rms")}}


def frequency_grid(structure, crowd, msd, dampers):
    """Frequencies [Hz] fine enough for the narrowest mode of every model, 0 to the top (an even
    grid from 0 Hz: the spectral moments by the trapezoid rule; also :mod:`crowdvib.comfort`)."""
    modal = effective_modal_properties(structure, None, None, dampers=dampers)
    widths = np.concatenate([modal.frequencies * modal.damping_ratios,
                             modal.interaction_frequencies * modal.interaction_damping_ratios])
    top = TOP_FREQUENCY_FACTOR * max(structure.frequencies.max(),
                                     0.0 if msd is None else msd.frequency)
    step = widths[widths > 0].min() / STEPS_PER_HALF_WIDTH
    return np.linspace(0.0, top, int(np.ceil(top / step)) + 1)


def predict_response(structure: ModalModel, crowd: Crowd, *, msd: MSDModel | None = None,
                     dampers: Sequence | None = None, duration: float = 600.0,
                     force: object = None, weighting: str | None = None,
                     frequency: ArrayLike | None = None) -> ResponsePrediction:
    """RMS and expected peak acceleration of a crowd stream from the spectral model.

    Parameters
    ----------
    structure : ModalModel
        The empty footbridge.
    crowd : Crowd
        The stream: density, speed, step frequencies, body mass.
    msd : MSDModel, optional
        Adds the "hsi" model (the crowd of MSDs, :func:`crowdvib.response_psd`).
    dampers : sequence of TunedMassDamper, optional
        Part of every model.
    duration : float
        Record length T [s] of the expected peak (default 10 minutes).
    force : ZivanovicForce or YoungForce, optional
        Walking force model (default Živanović 2007).
    weighting : {None, "Wb"}
        Also give σ of the W_b-weighted acceleration (:mod:`crowdvib.signals.weighting`).
    frequency : array_like, optional
        Integration grid [Hz] (default 0 to 1.5 × the highest mode, 8 steps per half-power
        half-width of the least damped mode).

    Returns
    -------
    ResponsePrediction

    See Also
    --------
    crowdvib.response_psd : the PSD behind the prediction.
    crowdvib.design_check

    References
    ----------
    S. O. Rice, "Mathematical analysis of random noise", *Bell System Technical Journal* 23:282–332,
    1944. The crossing rate of a Gaussian process.

    A. G. Davenport, "Note on the distribution of the largest value of a random function with
    application to gust loading", *Proceedings of the ICE* 28(2):187–196, 1964. The expected largest
    peak.

    The theory pages cite them (docs: theory, References).

    Examples
    --------
    >>> from crowdvib import Crowd, ModalModel, MSDModel
    >>> bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    >>> prediction = predict_response(bridge, Crowd.from_density(0.5), msd=MSDModel())
    >>> prediction.models
    ('empty', 'added_mass', 'hsi')
    """
    check_type("structure", structure, ModalModel)
    check_type("crowd", crowd, Crowd).check_stationary("predict_response")
    if msd is not None:
        check_type("msd", msd, MSDModel)
    if crowd.density <= 0:
        raise ParameterError(f"crowd.density must be > 0 persons/m² for a prediction, got "
                             f"{crowd.density:g}")
    duration = check_positive("duration", duration, unit="s")
    if weighting not in (None, "Wb"):
        raise ParameterError(f"weighting must be None or 'Wb', got {weighting!r}")
    dampers = as_dampers(dampers)
    grid = frequency_grid(structure, crowd, msd, dampers) if frequency is None else frequency
    columns: dict[str, list] = {"rms": [], "crossing_rate": [], "weighted_rms": []}
    models = structure_models(structure, crowd, crowd.density, msd)
    for model, _, model_msd in models.values():
        spectral = SpectralModel(model, crowd, grid, force=force, dampers=dampers)
        psd = spectral.psd_array(model_msd)
        f = spectral.frequency
        m0 = np.trapezoid(psd, f, axis=-1)
        m2 = np.trapezoid(psd * f**2, f, axis=-1)
        columns["rms"].append(np.sqrt(m0))
        columns["crossing_rate"].append(np.sqrt(m2 / m0))
        if weighting == "Wb":

            weighted = np.trapezoid(psd * np.abs(wb_response(f)) ** 2, f, axis=-1)
            columns["weighted_rms"].append(np.sqrt(weighted))
    rms, rate = np.array(columns["rms"]), np.array(columns["crossing_rate"])
    factor = davenport_peak_factor(rate, duration)
    return ResponsePrediction(
        models=tuple(models), output_names=structure.output_names, density=crowd.density,
        duration=duration, rms=rms, crossing_rate=rate, peak_factor=factor,
        expected_peak=factor * rms,
        weighted_rms=np.array(columns["weighted_rms"]) if weighting else None)
