"""Plain-text forms of results shared by the command line and the HTML report."""

import math

__all__ = ["with_interval", "interval_of"]


def interval_of(estimate, parameter):
    """(low, high, level) of ``parameter`` from a results.json ``"estimate"`` dict, or None."""
    interval = estimate.get("interval") if isinstance(estimate, dict) else None
    if not isinstance(interval, dict):
        return None
    ends, level = interval.get(parameter), interval.get("level")
    if (not isinstance(ends, (list, tuple)) or len(ends) != 2
            or not all(isinstance(v, (int, float)) and math.isfinite(v) for v in ends)
            or not isinstance(level, (int, float))):
        return None
    return float(ends[0]), float(ends[1]), float(level)


def with_interval(value, interval=None, unit="", digits=3):
    """``"3.04 Hz (95 %: 2.96–3.11)"``: a value with its confidence interval, if any.

    Parameters
    ----------
    value : float
    interval : (low, high, level), optional
        As :func:`interval_of` returns it.
    unit : str
        Appended after the value ("" or "-" for none).
    digits : int
        Significant digits.
    """
    unit = "" if unit in ("", "-") else f" {unit}"
    text = f"{value:.{digits}g}{unit}"
    if interval is not None:
        low, high, level = interval
        text += f" ({100 * level:g} %: {low:.{digits}g}–{high:.{digits}g})"
    return text
