"""Spectra and the processing of acceleration records (docs: theory, Welch PSDs, filters and convergence).

``spectrum`` (ResponsePSD, the container measured and modelled PSDs share) → ``welch`` (filter,
Welch PSD and its expectation kernel) → ``conditioning`` (detrend, resample, time frames) →
``convergence`` (PSD against record length); ``weighting`` (W_b frequency weighting and the
running RMS of the comfort criteria).
"""

from .conditioning import detrend, resample, select_time_frame, stationary_time_frame
from .convergence import PSDConvergence, psd_convergence
from .spectrum import ResponsePSD
from .weighting import running_rms, weight_wb, wb_response
from .welch import (LowPassFilter, synthetic_welch_psd, welch_degrees_of_freedom, welch_kernel,
                    welch_psd, welch_segment_count)

__all__ = ["ResponsePSD", "LowPassFilter", "welch_psd", "welch_kernel", "welch_segment_count",
           "welch_degrees_of_freedom", "synthetic_welch_psd", "detrend", "resample",
           "select_time_frame", "stationary_time_frame", "PSDConvergence", "psd_convergence",
           "running_rms", "weight_wb", "wb_response"]
