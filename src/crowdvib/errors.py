"""Exceptions and warnings of crowdvib.

Every error derives from :class:`CrowdvibError` and also from the built-in it refines, so
``except ValueError`` keeps working for callers who do not know crowdvib. Messages name the
parameter, the rule and the offending value.
"""

__all__ = [
    "CrowdvibError",
    "ParameterError",
    "DataError",
    "EstimationError",
    "OutputError",
    "CrowdvibWarning",
    "BoundWarning",
    "ConvergenceWarning",
    "ResolutionWarning",
    "DataWarning",
    "PlausibilityWarning",
    "IdentifiabilityWarning",
    "StudyWarning",
    "UnverifiedWarning",
]


class CrowdvibError(Exception):
    """Base class of every error raised by crowdvib."""


class ParameterError(CrowdvibError, ValueError):
    """A parameter breaks a rule (sign, range, unit, shape, name)."""


class DataError(ParameterError):
    """A measured record or PSD cannot be used as it is (a bad input, hence a ParameterError)."""


class EstimationError(CrowdvibError, RuntimeError):
    """The estimation problem cannot be solved (non-finite objective, singular model)."""


class OutputError(CrowdvibError, OSError):
    """Results cannot be written: the message names the path and the cause (disk full, read-only
    or immutable folder, file-size limit); nothing half-written is left."""


class CrowdvibWarning(UserWarning):
    """Base class of crowdvib's warnings: doubtful but usable input or results."""


class BoundWarning(CrowdvibWarning):
    """An estimated parameter sits on a bound of the search region."""


class ConvergenceWarning(CrowdvibWarning):
    """An optimiser or a PSD estimate did not converge."""


class ResolutionWarning(CrowdvibWarning):
    """A frequency resolution or record length is too coarse for what is asked."""


class DataWarning(CrowdvibWarning):
    """A measured record is usable but doubtful (flat or clipped stretches)."""


class PlausibilityWarning(CrowdvibWarning):
    """A value is legal but implausible for a footbridge or for the model: likely a unit, a
    percentage given for a fraction, a gain or a channel mix-up. The message names the likely
    cause."""


class IdentifiabilityWarning(CrowdvibWarning):
    """The data do not determine the estimated parameters separately (near-perfect correlation
    of their estimates, as for μ_h1 with ξ_h1 from one record)."""


class StudyWarning(CrowdvibWarning):
    """Stored tasks of a study cannot be reused (damaged file, changed inputs): they are redone."""


class UnverifiedWarning(CrowdvibWarning):
    """A file of another run is used without being verified: no crowdvib manifest beside it
    holds its SHA-256 (an edited file with a manifest is refused instead)."""
