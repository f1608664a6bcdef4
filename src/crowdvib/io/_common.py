"""What every reader shares: message prefixes, safe quoting, the read guard, time stamps → rate.

Every file problem reaches the user as a :class:`DataError` that names the file (and the channel,
sample or key where known) and quotes at most the offending value, shortened: never the file's
contents, never a foreign traceback (issue 9).
"""

import contextlib
from pathlib import Path

import numpy as np

from ..errors import terminal_safe
from ..errors import CrowdvibError, DataError, ParameterError

# Time stamps whose step differs from the median step by more than this fraction are non-uniform;
# a step of more than _GAP_FACTOR median steps is a gap (missing samples).
_JITTER_TOLERANCE = 1e-3
_GAP_FACTOR = 1.5
#: Longest quoted value in a message: enough for a misspelt name, too short to leak a file.
QUOTE_LIMIT = 40


def quote(value, limit=QUOTE_LIMIT):
    """``repr`` of a value from a file, shortened to ``limit`` characters (with an ellipsis)."""
    text = repr(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


def quote_names(names, limit=8):
    """Names from a file for a message: each shortened, at most ``limit`` of them (names come
    from a file's header line, which must not be echoed whole)."""
    names = list(names)
    shown = ", ".join(quote(n) for n in names[:limit])
    more = len(names) - limit
    return f"[{shown}{f', … ({more} more)' if more > 0 else ''}]"


def where(source, channel=None):
    """Message prefix ``"file.csv: channel 'a': "`` (``"record: "`` without a file)."""
    name = terminal_safe(Path(source).name) if source else "record"
    return f"{name}: " + ("" if channel is None else f"channel {quote(channel)}: ")


def named_file(path, where, shown=None):
    """``path`` if it is a regular file, else a :class:`DataError` saying that ``where`` (a case
    file's key, e.g. ``"c.toml: measurement.files[0]"``) names a directory or a missing file.

    ``shown`` is the value as the case file wrote it (quoted, with the resolved path beside it).
    """
    path = Path(path)
    text = terminal_safe(path if shown is None else f"{quote(shown)} (looked at {path})")
    if path.is_dir():
        raise DataError(f"{where} names a directory, expected a file: {text}")
    if not path.is_file():
        raise DataError(f"{where} names a file that does not exist: {text}")
    return path


@contextlib.contextmanager
def reading(path, what):
    """Guard one reader: any failure inside becomes a :class:`DataError` naming ``path``.

    ``what`` names the format with its article, as in "cannot be read as an NPZ file".

    crowdvib's own :class:`DataError` passes unchanged; a :class:`ParameterError` raised while
    reading (a bad value in the file, e.g. a negative sample rate) gets the file name in front;
    a third-party exception (``BadZipFile``, ``MatReadError``, ``UnicodeDecodeError``, h5py's
    ``OSError``, ``IndexError`` …) is chained as the cause, its type and a shortened message
    quoted. ``ImportError`` of an optional reader passes: it is an installation problem.
    """
    name = Path(path).name
    try:
        yield
    except DataError:
        raise
    except ParameterError as exc:
        text = str(exc)
        raise DataError(text if text.startswith(f"{name}: ") else f"{name}: {text}") from exc
    except (CrowdvibError, ImportError):
        raise
    except UnicodeDecodeError as exc:
        raise DataError(f"{name}: cannot be read as {what} file: not UTF-8 text (byte "
                        f"{exc.start})") from exc
    except Exception as exc:  # noqa: BLE001 — the one place third-party errors become ours
        raise DataError(f"{name}: cannot be read as {what} file ({type(exc).__name__}: "
                        f"{quote(str(exc))})") from exc


def same_rate(first, second):
    """Whether two sample rates [Hz] agree to 1e-6 (a rate written with 7 digits or more)."""
    return abs(first - second) <= 1e-6 * max(abs(first), abs(second))


def stated_rate(path, given, stored, stored_where):
    """(rate [Hz], where it comes from) of the rate the caller gave or the file stores, or
    (None, None); both, differing, is refused: one of them is wrong (issue 24)."""
    if given is not None and stored is not None and not same_rate(given, stored):
        raise DataError(f"{where(path)}{stored_where} states {stored:.9g} Hz but sample_rate "
                        f"{given:.9g} Hz was given (measurement.sample_rate): they must agree")
    if given is not None:
        return given, "the given sample_rate (measurement.sample_rate)"
    return stored, None if stored is None else stored_where


def sample_rate_from_time(time, source, channel=None):
    """Sample rate [Hz] of uniform, increasing time stamps; DataError naming the first bad step."""
    time = np.asarray(time, dtype=float)
    prefix = where(source, channel)
    if time.ndim != 1 or time.size < 2:
        raise DataError(f"{prefix}time must hold at least 2 stamps, got shape {time.shape}")
    bad = np.flatnonzero(~np.isfinite(time))
    if bad.size:
        raise DataError(f"{prefix}time stamp at sample index {bad[0]} is {time[bad[0]]}")
    step = np.diff(time)
    bad = np.flatnonzero(step <= 0)
    if bad.size:
        i = bad[0] + 1
        raise DataError(f"{prefix}time stamps must increase: sample index {i} has t = "
                        f"{time[i]:.9g} s after t = {time[i - 1]:.9g} s")
    median = float(np.median(step))
    bad = np.flatnonzero(step > _GAP_FACTOR * median)
    if bad.size:
        i = bad[0] + 1
        raise DataError(f"{prefix}gap in the time stamps before sample index {i}: "
                        f"{step[bad[0]]:.6g} s between samples, the median step is {median:.6g} s "
                        f"(about {int(round(step[bad[0]] / median)) - 1} sample(s) missing)")
    bad = np.flatnonzero(np.abs(step - median) > _JITTER_TOLERANCE * median)
    if bad.size:
        i = bad[0] + 1
        raise DataError(f"{prefix}time stamps must be uniform: the step before sample index {i} "
                        f"is {step[bad[0]]:.9g} s, the median step is {median:.9g} s")
    # The mean step over the record is more accurate than any single difference.
    rate = (time.size - 1) / (time[-1] - time[0])
    if not np.isfinite(rate):
        raise DataError(f"{prefix}time stamps {time[0]:.9g} … {time[-1]:.9g} s give no finite "
                        "sample rate")
    return rate


#: More channels than this, and more channels than samples, is a transposed table (one row per
#: channel): a footbridge test has tens of sensors, never thousands (issue 35 §2: a CSV of 1e5
#: columns took 71 s to read, `crowdvib init` drafted 100 000 placeholders).
MAX_CHANNELS = 1000


def refuse_transposed(source, n_channels, n_samples):
    """DataError for a record of more than MAX_CHANNELS channels, each shorter than that count:
    asks whether the file is transposed."""
    if n_channels > MAX_CHANNELS and n_samples < n_channels:
        raise DataError(f"{where(source)}must hold at most {MAX_CHANNELS} channels (one column "
                        f"or variable per sensor, one row per sample), got {n_channels} channels "
                        f"of {n_samples} sample(s) each: is the file transposed (one row per "
                        "channel)? Transpose it, or write one column per channel")
