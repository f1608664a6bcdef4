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
"""

from .errors import ParameterError

__all__ = ["DEFAULT_METHOD", "DEFAULT_JOINT_METHOD", "METHOD_DEFAULTS", "DEFAULT_CROWD_MODEL",
           "check_method", "estimator_defaults"]

#: The misfit of a single-record estimate when none is stated.
DEFAULT_METHOD = "likelihood"
#: The misfit of a joint estimate over several records when none is stated.
DEFAULT_JOINT_METHOD = "least_squares"
#: method → (crowd model, step frequencies fitted with the MSD) when not stated.
METHOD_DEFAULTS = {"likelihood": ("fluctuating", True), "least_squares": ("smeared", False)}
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
