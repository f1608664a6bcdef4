"""Exceptions and warnings of crowdvib, and the foreign text their messages quote.

Every error derives from :class:`CrowdvibError` and also from the built-in it refines, so
``except ValueError`` keeps working for callers who do not know crowdvib. Messages name the
parameter, the rule and the offending value.

A name or value read from someone else's file reaches the user inside messages (issue 35 §1).
Raw, its control characters act on the terminal: ``ESC ] 0 ; … BEL`` retitles the window,
``ESC [ 2 J`` clears it, U+202E turns the rest of the line around. :func:`terminal_safe` writes
each of them as a Python escape (``\\x1b``, ``\\u202e``), the rest of the text unchanged; the
command line passes every line it prints through it, and the readers' messages quote file
content through it (:func:`excerpt`). Both are the package's, not in ``__all__``.
"""

import re

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


# ------------------------------------------------------------- foreign text in messages
#: C0 controls but tab and newline, DEL, C1 controls, and the bidirectional marks, embeddings,
#: overrides and isolates (and the line and paragraph separators, which break a line).
_UNSAFE = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u061c\u200e\u200f\u2028\u2029"
                     "\u202a-\u202e\u2066-\u2069]")


def _escaped(found):
    return repr(found.group())[1:-1]        # '\x1b' → \x1b, '\u202e' → \u202e


def terminal_safe(text, *, newlines=True):
    """``text`` with every terminal control and bidi override written as an escape.

    Tab and (with ``newlines``) newline are kept: the messages' own layout. A carriage return,
    which would let a line overwrite itself, is always escaped.
    """
    text = _UNSAFE.sub(_escaped, str(text))
    return text if newlines else text.replace("\n", "\\n")


def excerpt(text, limit=40):
    """At most ``limit`` characters of a foreign file's text, escaped, as one quoted line."""
    text = str(text)
    short = text[:limit] + ("…" if len(text) > limit else "")
    return f"'{terminal_safe(short, newlines=False)}'"
