"""Plausible ranges of the physical inputs and the unit mix-ups they catch (docs: theory,
Plausible ranges).

One table, :data:`RANGES`, holds every range with its source; :func:`warn_if_implausible` is the
one helper the constructors and entry points call. A value outside its range is legal (crowdvib
computes with it) but doubtful, so it gets a :class:`~crowdvib.errors.PlausibilityWarning` that
names the value, the likely unit mix-up and the value it would then be, in the style of the
estimator's level guard. The ranges are wide on purpose: they catch factors of 2π, 60, 100 or
1000, not unusual bridges or crowds.
"""

from __future__ import annotations

import contextlib
import contextvars
import math
import warnings
from dataclasses import dataclass

import numpy as np

from .errors import PlausibilityWarning

__all__ = ["PlausibleRange", "RANGES", "implausibility", "warn_if_implausible", "warn_notes",
           "derived", "far_outside"]

#: True while the library derives a model from one already checked (a rescaled bridge, a crowd
#: at another density): its values were named once, where the user built it. Per thread.
_DERIVED = contextvars.ContextVar("crowdvib_plausibility_derived", default=False)


@contextlib.contextmanager
def derived():
    """Build models inside without plausibility warnings: they derive from checked ones."""
    token = _DERIVED.set(True)
    try:
        yield
    finally:
        _DERIVED.reset(token)


@dataclass(frozen=True)
class PlausibleRange:
    """A plausible range of one quantity and the mix-ups that leave it.

    Attributes
    ----------
    low, high : float or None
        Bounds [``unit``]; None = no bound on that side (no mix-up lands there).
    unit : str
        The SI unit crowdvib expects ("" for fractions).
    what : str
        The words after "unusual for" in the message ("a footbridge mode").
    mixups : tuple of (float, str, str)
        (factor, cause, unit of the mix-up): ``value × factor`` is the value in ``unit`` had it
        been given in the mix-up's unit. The first whose corrected value is plausible is named.
    source : str
        Where the range comes from (also in the docs' table).
    hard_high : float or None
        The hard tier: a value above it is so far outside any plausible range that the
        estimators refuse it (:func:`far_outside`) unless told to go on; None: no hard tier.
    """

    low: float | None
    high: float | None
    unit: str
    what: str
    mixups: tuple
    source: str
    hard_high: float | None = None

    def contains(self, value: float) -> bool:
        return ((self.low is None or value >= self.low)
                and (self.high is None or value <= self.high))


_MM = ((1e-3, "millimetres instead of metres", "mm"), (1e-2, "centimetres instead of metres", "cm"))
_PER_SECOND = ((1 / (2 * math.pi), "rad/s instead of Hz", "rad/s"),
               (1 / 60, "steps per minute instead of Hz", "per minute"))

#: quantity → plausible range (docs: theory, Plausible ranges: the same table with its sources).
RANGES = {
    "damping_ratio": PlausibleRange(
        None, 0.10, "", "a footbridge mode", ((0.01, "percent instead of fraction", "%"),),
        "Sétra (2006) damping table: 0.1–1.5 % by deck type (recalled); the paper's bridges "
        "0.25–0.86 % [VNVdB23]", hard_high=0.2),
    "lowest_frequency": PlausibleRange(
        None, 10.0, " Hz", "the lowest vertical mode of a footbridge",
        ((1 / (2 * math.pi), "rad/s instead of Hz", "rad/s"),),
        "Sétra (2006): vertical modes above 5 Hz are out of the risk ranges; HiVoSS (2008): "
        "critical range 1.25–4.6 Hz; a bridge with no mode below 10 Hz is beyond the 4th "
        "walking harmonic"),
    "deck_mass": PlausibleRange(
        20.0, 1e5, " kg/m²", "a footbridge deck", ((1e3, "tonnes instead of kg", "t/m²"),),
        "light FRP or timber decks from ~50 kg/m², heavy concrete decks a few t/m² (docs: "
        "theory, Conventions); modes moving little of the walkway weigh more"),
    "length": PlausibleRange(
        None, 1000.0, " m", "a footbridge walkway", _MM,
        "the longest pedestrian suspension bridges span about 720 m (Sky Bridge 721, 2022)"),
    "width": PlausibleRange(
        None, 30.0, " m", "a footbridge walkway", _MM,
        "footbridge decks are 1.5–6 m wide"),
    "body_mass": PlausibleRange(
        30.0, 120.0, " kg", "the mean body mass of a crowd",
        ((1e3, "tonnes instead of kg", "t"), (1e-3, "grams instead of kg", "g"),
         (0.45359237, "pounds instead of kg", "lb")),
        "adult means by region 58–81 kg (Walpole et al. 2012); the paper's crowds 72–75 kg"),
    "step_frequency_mean": PlausibleRange(
        None, 3.5, " Hz", "a crowd's mean step frequency", _PER_SECOND,
        "walking 1.6–2.4 Hz, running 2.0–3.5 Hz (Bachmann & Ammann 1987); mean 1.8 Hz, "
        "σ 0.11 Hz on a footbridge (Pachi & Ji 2005)"),
    "step_frequency_std": PlausibleRange(
        None, 0.6, " Hz", "the spread of a crowd's step frequencies", _PER_SECOND,
        "0.11 Hz (Pachi & Ji 2005), 0.175 Hz (Sétra 2006), the paper's crowds 0.13–0.19 Hz"),
    "walking_speed": PlausibleRange(
        None, 3.0, " m/s", "a walking crowd", ((1 / 3.6, "km/h instead of m/s", "km/h"),),
        "free walking 1.34 m/s (Weidmann 1993); UK NA joggers 3 m/s (BS EN 1991-2 NA.2.44)"),
    "density": PlausibleRange(
        None, 2.0, " persons/m²", "a design crowd", (),
        "densest design classes: Sétra (2006) class I 1.0, HiVoSS (2008) TC5 1.5 persons/m²; "
        "walking stops at the jam density 5.4 persons/m² (Weidmann 1993), an error"),
    "msd_frequency": PlausibleRange(
        None, 15.0, " Hz", "a walking person's MSD (f_h1)",
        ((1 / (2 * math.pi), "rad/s instead of Hz", "rad/s"),),
        "the paper's estimates 2.8–3.1 Hz on two footbridges, searched up to 10 Hz "
        "[VNVdB23]"),
    "damper_frequency": PlausibleRange(
        None, 10.0, " Hz", "a footbridge's tuned mass damper",
        ((1 / (2 * math.pi), "rad/s instead of Hz", "rad/s"),),
        "a damper is tuned just below the mode it controls (Den Hartog 1956), and footbridge "
        "modes that need one lie within 1–5 Hz (Sétra 2006, HiVoSS 2008)"),
    "damper_mass": PlausibleRange(
        10.0, None, " kg", "a footbridge's tuned mass damper",
        ((1e3, "tonnes instead of kg", "t"),),
        "footbridge TMDs move 1–5 % of a modal mass of tens of tonnes: hundreds of kg to a few "
        "tonnes (HiVoSS 2008; Den Hartog 1956); below 10 kg a damper does nothing on a deck"),
    "mass_ratio": PlausibleRange(
        None, 0.2, "", "a tuned mass damper (typically 0.01–0.05)",
        ((0.01, "percent instead of fraction", "%"),),
        "TMD mass ratios 1–5 % on footbridges (HiVoSS 2008; Den Hartog 1956)"),
}


def _format(value, digits=6):
    return f"{value:.{digits}g}"


def implausibility(quantity: str, value: float, name: str | None = None) -> str | None:
    """The note for ``value`` of ``quantity`` outside its range, or None when plausible.

    The note reads "<name> = <value> is above <high>, unusual for <what>: <cause>? (<value>
    <mix-up unit> is <corrected>)", naming the first mix-up of :data:`RANGES` whose corrected
    value lies within the range (or asking to check the unit when none does).
    """
    plausible = RANGES[quantity]
    value = float(value)
    if plausible.contains(value):
        return None
    name = quantity if name is None else name
    unit = plausible.unit
    side = (f"above {plausible.high:g}{unit}" if plausible.high is not None
            and value > plausible.high else f"below {plausible.low:g}{unit}")
    for factor, cause, mixed in plausible.mixups:
        if plausible.contains(value * factor):
            return (f"{name} = {_format(value)}{unit} is {side}, unusual for {plausible.what}: "
                    f"{cause}? ({_format(value)} {mixed} is {_format(value * factor, 4)}{unit})")
    return (f"{name} = {_format(value)}{unit} is {side}, unusual for {plausible.what}: "
            "check the value and its unit")


def far_outside(quantity: str, value: float, name: str | None = None) -> str | None:
    """The note of :func:`implausibility` for a value beyond the hard tier of ``quantity``
    (``hard_high`` of :data:`RANGES`: a bridge damping ratio of 0.6, 60 %), else None.

    Such a value is legal but no bridge has it: the estimators refuse it before any fit (a fit
    to it runs for minutes to a warning), with an override.
    """
    hard = RANGES[quantity].hard_high
    if hard is None or not float(value) > hard:
        return None
    return f"{implausibility(quantity, value, name)}; far above any plausible value (> {hard:g})"


def warn_if_implausible(quantity: str, value, name: str | None = None, *,
                        stacklevel: int = 3) -> list[str]:
    """Warn (:class:`PlausibilityWarning`) for each entry of ``value`` outside the range of
    ``quantity``; return the notes.

    Parameters
    ----------
    quantity : str
        A key of :data:`RANGES`.
    value : float or array_like
        The value(s) in the unit of the range; an array is checked entry by entry, named
        ``name[i]``.
    name : str, optional
        The parameter's name in the message (default ``quantity``).
    stacklevel : int
        As for :func:`warnings.warn`, counted from the caller of this function.
    """
    name = quantity if name is None else name
    array = np.asarray(value, dtype=float)
    if array.ndim == 0:
        notes = [implausibility(quantity, array, name)]
    else:
        notes = [implausibility(quantity, v, f"{name}[{i}]") for i, v in enumerate(array.ravel())]
    notes = [note for note in notes if note is not None]
    warn_notes(notes, stacklevel=stacklevel + 1)
    return notes


def warn_notes(notes, *, stacklevel=3):
    """One :class:`PlausibilityWarning` per note (none inside :func:`derived`); ``stacklevel``
    as for :func:`warn_if_implausible`."""
    if _DERIVED.get():
        return
    for note in notes:
        warnings.warn(note, PlausibilityWarning, stacklevel=stacklevel + 1)
