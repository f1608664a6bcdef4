"""The estimator a user gets without asking: one table, read by :func:`crowdvib.estimate_hsi`,
the joint estimate, the studies and case files (docs: theory, Calibration).

The Whittle likelihood with the fluctuating-crowd model of the expected PSD and the crowd's
step-frequency distribution fitted with the MSD is the default: on records of a Poisson crowd
made by crowdvib's simulator and by an independent code its mean errors lie within their
95 % intervals of zero and its intervals cover the truth at about their stated rate, and
fitting the step frequencies makes it immune to an error in the mean step frequency the user
states. The paper's least squares (Eq. 6) keeps the paper's smeared crowd and the crowd as
given, so ``method="least_squares"`` alone is the paper's estimator.

A joint fit of several records holds each record's crowd as given (one step-frequency
distribution cannot serve records of different crowds), where the likelihood is fragile to an
error in the mean step frequency: it keeps the paper's least squares by default.

The modelling-error study's default levels are the paper's, here too: the study perturbs the
inputs of this estimator, and the OMA cross-check (below the studies) states its errors at them.
"""

from .errors import ParameterError

__all__ = ["DEFAULT_METHOD", "DEFAULT_JOINT_METHOD", "METHOD_DEFAULTS", "DEFAULT_CROWD_MODEL",
           "check_method", "estimator_defaults", "DEFAULT_DENSITY_UNCERTAINTY",
           "check_density_uncertainty", "METHOD_WORDS", "PAPER_ERROR_LEVELS"]

#: The misfit of a single-record estimate when none is stated.
DEFAULT_METHOD = "likelihood"
#: The misfit of a joint estimate over several records when none is stated.
DEFAULT_JOINT_METHOD = "least_squares"
#: method → (crowd model, step frequencies fitted with the MSD) when not stated.
METHOD_DEFAULTS = {"likelihood": ("fluctuating", True), "least_squares": ("smeared", False)}
#: Each misfit in words, as the command line and the reports name it.
METHOD_WORDS = {"likelihood": "likelihood", "least_squares": "least squares"}
#: The relative standard uncertainty of a stated crowd density when none is stated: densities
#: counted in the field are rarely known better than ±10 %, and the estimate of ξ_h1 moves by a
#: third to a half for a density 10 % off (docs: theory, The crowd density's uncertainty).
DEFAULT_DENSITY_UNCERTAINTY = 0.1
#: Above this the interval's linearisation in ln ρ no longer holds (±2σ would reach ±100 %).
MAX_DENSITY_UNCERTAINTY = 0.5
#: The crowd model of the default estimator's expected PSD: also the default of the expected
#: PSDs made for users (:func:`crowdvib.response_psd`,
#: :class:`crowdvib.response.VaryingCrowdModel`), so that a noise-free synthetic PSD made
#: without options is what the default estimate fits.
DEFAULT_CROWD_MODEL = METHOD_DEFAULTS[DEFAULT_METHOD][0]


def check_method(method):
    """``method`` if it is one of :data:`METHOD_DEFAULTS`' misfits, else a ParameterError."""
    if method not in METHOD_DEFAULTS:
        raise ParameterError(f"method must be one of {list(METHOD_DEFAULTS)}, got {method!r}")
    return method


def estimator_defaults(method, crowd_model=None, free_step_frequencies=None):
    """(crowd model, free step frequencies): the stated ones, the method's own where None."""
    model, free = METHOD_DEFAULTS[check_method(method)]
    return (model if crowd_model is None else crowd_model,
            free if free_step_frequencies is None else free_step_frequencies)


def check_density_uncertainty(value):
    """``value`` as a float in [0, MAX_DENSITY_UNCERTAINTY], else a ParameterError."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = None
    if (isinstance(value, bool) or number is None
            or not 0.0 <= number <= MAX_DENSITY_UNCERTAINTY):
        raise ParameterError(
            f"density_uncertainty must be the relative standard uncertainty of the stated crowd "
            f"density, a number in [0, {MAX_DENSITY_UNCERTAINTY}] (0.1 for ±10 %), got {value!r}")
    return number


#: Modelling-error levels of the Eeklo and Waalse Krook studies (paper; docs: theory, The paper's
#: case studies): parameter → (lower level, higher level), as fractions.
PAPER_ERROR_LEVELS = {"frequencies": (0.01, 0.05), "damping_ratios": (0.10, 0.30),
                      "modal_masses": (0.02, 0.05), "step_frequency_mean": (0.02, 0.05),
                      "step_frequency_std": (0.02, 0.05)}
