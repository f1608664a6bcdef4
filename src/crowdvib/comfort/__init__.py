"""A year of comfort: how often a footbridge is uncomfortable, from its traffic and its crowd's
HSI, with the uncertainty of both (issue 37; docs: theory, A year of comfort).

``traffic`` holds the year's crowd as a distribution (:class:`Traffic`: a design table, a daily
profile, or a season's measured windows); ``measure`` the law of the comfort measures of one
crowd state over a window by the spectral route (the 10-minute peak and the largest 1-s running
RMS of a stationary Gaussian response, from its spectral moments); ``year`` the hours a year in
each comfort class, the probability that a window exceeds a limit and the week's map, per model
of the structure, with bands (:func:`comfort_year` → :class:`ComfortYear`); ``simulated`` the
same windows from the time-domain simulator, to check the spectral route and to stand in for it
where the response is not Gaussian.
"""

from .measure import (PEAK_MODELS, WindowLaw, peak_cdf, peak_quantile, running_rms_cdf,
                      running_rms_quantile, window_law)
from .traffic import HOURS_PER_YEAR, UNMEASURED_RULES, WEEK_HOURS, Traffic
from .year import (CLASS_BOUNDS, CLASS_NAMES, LIMITS, MODEL_LABELS, QUANTILES, ComfortYear,
                   comfort_year, loudest_output, response_table)

__all__ = ["Traffic", "HOURS_PER_YEAR", "WEEK_HOURS", "UNMEASURED_RULES", "WindowLaw",
           "window_law", "PEAK_MODELS", "peak_cdf", "peak_quantile", "running_rms_cdf",
           "running_rms_quantile", "ComfortYear", "comfort_year", "response_table",
           "MODEL_LABELS", "CLASS_NAMES", "CLASS_BOUNDS", "LIMITS", "QUANTILES", "loudest_output"]
