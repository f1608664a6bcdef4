"""A case file drafted from a record: what ``crowdvib init RECORD`` finds and writes (issue 27 §2).

:func:`inspect_record` reads a record with :func:`crowdvib.io.read_record`'s own machinery (the
formats table, the time-header recognition, the checks) and reports its channels, time base,
length and a guess of its units. :func:`draft_case` renders a commented TOML case file from it:
``[measurement]`` filled in, the bridge, the crowd and the band as placeholders. A placeholder is
a string ``"REPLACE: what it is [unit]"`` where a number belongs, so :func:`crowdvib.load_case`
refuses the draft, naming the key, until every one is replaced. :func:`write_draft` writes it and
never replaces an existing file.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._files import require_file
from .._version import __version__
from ..errors import DataError, ParameterError
from ..models.loading import STANDARD_GRAVITY
from ._common import quote_names
from .formats import suffix_format
from .gaps import describe_gaps, dropouts
from .headers import output_name
from .records import _format_of, _read_record, check_record
from .units import UNITS, _unit_key

__all__ = ["ChannelSummary", "RecordSummary", "inspect_record", "guess_units", "draft_case",
           "new_case_path", "write_draft", "PLACEHOLDER"]

#: How every placeholder value of a draft starts.
PLACEHOLDER = "REPLACE:"
#: The gravity offset of a vertical accelerometer that keeps it, in the units load_case reads.
_GRAVITY = {units: STANDARD_GRAVITY / scale for units, scale in UNITS.items()}
#: RMS of footbridge accelerations, from an ambient test to a dense crowd, in each unit a logger
#: may write: about 0.01–2 m/s², 0.001–0.2 g, 1–200 mg, 10–2000 mm/s².
_LEVELS = (("g", 1e-3, 0.2), ("m/s2", 0.01, 2.0), ("mg", 1.0, 200.0), ("mm/s2", 10.0, 2000.0))
#: The dropouts a draft proposes to bridge (measurement.max_gap's default [s]); longer: cut.
_MAX_GAP = 0.1
#: The Welch window a draft proposes (the case files' default T [s]).
_WINDOW = 60.0


@dataclass(frozen=True)
class ChannelSummary:
    """One channel as stored in the file (before any unit conversion)."""

    name: str
    #: Mean of the samples, in the file's units (the gravity offset, if the sensor keeps it).
    mean: float
    #: RMS of the fluctuation about the mean, in the file's units.
    rms: float
    #: The units it looks to be in: "g", "mg", "m/s2", "mm/s2" (names measurement.units
    #: takes), or None: the unit its header states, else a guess from the samples.
    units: str | None
    #: Why (the header, the mean or the level it rests on), or why crowdvib cannot tell.
    reason: str
    #: The output name the draft gives it (the header without its unit and the words
    #: "acceleration", axis: ``"Acc Z midspan [g]"`` → ``"midspan"``).
    output: str = ""
    #: Where the header's unit and the samples disagree (the samples' guess), else "".
    doubt: str = ""


@dataclass(frozen=True)
class RecordSummary:
    """What :func:`inspect_record` found in a record."""

    path: Path
    format: str
    channels: tuple
    #: The column (variable) of time stamps, or None.
    time_column: str | None
    sample_rate: float
    #: Where the rate comes from: "time stamps", "given" (the caller) or "file" (stated in it).
    rate_source: str
    duration: float
    n_samples: int
    #: The units of the whole record ("g", "m/s2"), or None when crowdvib cannot tell.
    units: str | None
    units_reason: str
    #: Whether the file states its units (else they are guessed from the samples).
    units_stated: bool = False
    #: CSV: the header row's line number (from 1), and the metadata lines above it skipped.
    header_line: int | None = None
    skipped: tuple = ()
    #: The dropouts (sample index, length) and in words ("" when none).
    gaps: tuple = ()
    gaps_text: str = ""

    @property
    def channel_names(self) -> tuple:
        return tuple(channel.name for channel in self.channels)

    @property
    def doubts(self) -> tuple:
        """What the draft is unsure of, in words: units crowdvib cannot tell, a header's unit
        the samples contradict (``crowdvib init`` prints each; ``--strict`` fails on any)."""
        found = [f"units unsure: {self.units_reason}"] if self.units is None else []
        return tuple(found + [f"channel {c.name!r}: {c.doubt}" for c in self.channels
                              if c.doubt])

    @property
    def gap_mode(self) -> str | None:
        """What the draft proposes for the dropouts: "bridge" when each lasts up to
        ``max_gap`` (0.1 s) and none is at an end, else "cut"; None without dropouts."""
        if not self.gaps:
            return None
        short = max(length for _, length in self.gaps) / self.sample_rate <= _MAX_GAP
        inside = self.gaps[0][0] > 0 and sum(self.gaps[-1]) < self.n_samples
        return "bridge" if short and inside else "cut"


def _offset_units(mean, rms):
    """The units whose gravity offset ``mean`` is (±15 %: a sensor tilted by up to ~30°), or
    None; a fluctuation of half of it or more is no accelerometer at rest under a bridge."""
    return next((units for units, gravity in _GRAVITY.items()
                 if abs(abs(mean) - gravity) <= 0.15 * gravity and rms < 0.5 * gravity), None)


def guess_units(mean: float, rms: float) -> tuple[str | None, str]:
    """(units or None, why) of a channel of mean ``mean`` and fluctuation RMS ``rms``.

    A mean near ±1 is the gravity offset in g, near ±9.81 in m/s² (a sensor tilted by up to
    about 30° still shows it). Without an offset only the level speaks: footbridge accelerations
    have an RMS of about 0.01–2 m/s², i.e. 0.001–0.2 g or 10–2000 mm/s²; a level inside two of
    these ranges (or none) is "unsure" (None).
    """
    units = _offset_units(mean, rms)
    if units is not None:
        return units, (f"mean {mean:.3f} is the gravity offset "
                       f"{'-' if mean < 0 else ''}{_GRAVITY[units]:g} {units}")
    fits = [(units, low, high) for units, low, high in _LEVELS if low <= rms <= high]
    ranges = ", ".join(f"{low:g}–{high:g} {units}" for units, low, high in (fits or _LEVELS))
    if len(fits) != 1:
        return None, (f"RMS {rms:.3g} fits {'none' if not fits else 'each'} of the usual "
                      f"footbridge levels {ranges}")
    return fits[0][0], f"RMS {rms:.3g} fits the usual footbridge level {ranges}"


def _channel(name, mean, rms, stated):
    """A channel's summary: the unit its header states over the guess from its samples, the
    disagreement said (a logger set to g writing "[mg]" is 1000 times off one way or the other)."""
    guess, why = guess_units(mean, rms)
    output = output_name(name)
    if stated is None:
        return ChannelSummary(name, mean, rms, guess, why, output)
    doubt = "" if guess in (None, stated) else (
        f"its header states {stated!r} but its samples look like {guess!r} ({why}): check the "
        "logger's unit setting")
    return ChannelSummary(name, mean, rms, stated, f"its header states {stated!r}", output, doubt)


def _outputs(names):
    """Unique output names (a second "midspan" becomes "midspan_2")."""
    found = []
    for name in names:
        unique, number = name or "channel", 1
        while unique in found:
            number += 1
            unique = f"{name}_{number}"
        found.append(unique)
    return found


def _record_units(channels, stated, path, headers):
    """(units, why) of the whole record from its channels' guesses (or the unit it states: in a
    comment, or in the column headers)."""
    if stated and not headers:
        return _unit_key(stated, f"{path.name}: its stated "), f"the file states {stated!r}"
    if stated:
        return stated, (f"the column headers state {stated!r}" + "".join(
            f"; but channel {c.name!r}: {c.doubt}" for c in channels if c.doubt))
    # The gravity offset is the stronger sign; the level decides only where no channel has one.
    offset = [c for c in channels if _offset_units(c.mean, c.rms)]
    decided = offset or [c for c in channels if c.units]
    found = {c.units for c in decided}
    if len(found) == 1:
        first = decided[0]
        return first.units, (f"channel {first.name!r}: {first.reason}"
                             + (f" (and {len(decided) - 1} more)" if len(decided) > 1 else ""))
    if found:
        return None, "the channels disagree (" + "; ".join(
            f"{c.name!r}: {c.units}" for c in decided) + ")"
    return None, f"channel {channels[0].name!r}: {channels[0].reason}"


def inspect_record(path: str | os.PathLike, *, format: str | None = None,
                   sample_rate: float | None = None, time_column: str = "time") -> RecordSummary:
    """Read a record and report its channels, time base, length and units guess.

    Parameters
    ----------
    path : str or Path
        The record (any format :func:`crowdvib.io.read_record` reads).
    format, sample_rate, time_column
        As for :func:`crowdvib.io.read_record`.

    Returns
    -------
    RecordSummary
        Means and RMS in the file's own units: the samples are read unconverted.

    Raises
    ------
    DataError
        A missing file, a directory, a file that is no record, NaN samples (the file named).

    Warns
    -----
    DataWarning
        Flat or clipped stretches (:func:`crowdvib.io.check_record`).
    """
    path = Path(path)
    require_file(path, "record")     # before the suffix: a folder is named as one
    kind = _format_of(path, format)
    # "m/s2" reads the samples as stored (no conversion), whatever unit the file states.
    record, meta = _read_record(path, format=format, units="m/s2", sample_rate=sample_rate,
                                time_column=time_column)
    gaps = dropouts(record)
    if gaps:
        # Measured around the dropouts; the draft proposes to bridge or cut them (issue 36 §2).
        record = record.replace(data=np.where(np.isnan(record.data), 0.0, record.data))
    check_record(record)
    if time_column != "time" and meta.get("time") is None:
        # read_record takes a missing named column for a file without one: here it was asked for
        raise DataError(f"{path.name}: has no time column {time_column!r}; its columns are "
                        f"{quote_names(record.channel_names)}")
    missing = np.zeros(record.n_samples, bool)
    for start, length in gaps:
        missing[start:start + length] = True
    headers = meta.get("header_units") or {}
    channels = []
    for name, row in zip(record.channel_names, record.data):
        mean = float(np.mean(row[~missing]))
        rms = float(np.std(row[~missing]))
        channels.append(_channel(name, mean, rms, headers.get(name)))
    channels = [c.__class__(**{**c.__dict__, "output": unique})
                for c, unique in zip(channels, _outputs([c.output for c in channels]))]
    source = ("time stamps" if meta.get("time") is not None
              else "given" if sample_rate is not None else "file")
    units, reason = _record_units(channels, meta.get("units"), path, headers)
    return RecordSummary(path=path, format=kind, channels=tuple(channels),
                         time_column=meta.get("time_name") if source == "time stamps" else None,
                         sample_rate=record.sample_rate, rate_source=source,
                         duration=record.duration, n_samples=record.n_samples, units=units,
                         units_reason=reason, units_stated=bool(meta.get("units")),
                         header_line=meta.get("header_line"),
                         skipped=tuple(meta.get("skipped") or ()), gaps=tuple(gaps),
                         gaps_text=describe_gaps(record, gaps) if gaps else "")


# ------------------------------------------------------------------------------------ the draft
def _string(text):
    """A TOML basic string (JSON's escapes are TOML's; TOML also wants DEL escaped)."""
    return json.dumps(str(text), ensure_ascii=False).replace("\x7f", "\\u007f")


def _placeholder(what):
    return _string(f"{PLACEHOLDER} {what}")


def _relative(path, folder):
    """``path`` relative to ``folder`` in the file's forward slashes (absolute across drives)."""
    try:
        return Path(os.path.relpath(Path(path).resolve(), Path(folder).resolve())).as_posix()
    except ValueError:
        return Path(path).resolve().as_posix()


#: Metadata lines above the header the draft quotes.
_SHOWN = 6


def _comment(text):
    """A line of the file as a TOML comment's text (control characters shown escaped)."""
    return json.dumps(str(text), ensure_ascii=False)[1:-1][:100]


def _gap_lines(summary):
    """``gaps`` proposed for a record with dropouts (none without)."""
    mode = summary.gap_mode
    if mode is None:
        return []
    other = "cut" if mode == "bridge" else "bridge"
    return [f"gaps = {_string(mode)}   # found: {summary.gaps_text}",
            f"# \"{other}\" instead " + (
                "keeps only the longest stretch without a dropout" if other == "cut" else
                f"interpolates dropouts up to max_gap = {_MAX_GAP:g} s [s]") + "; the results "
            "state what was done"]


def draft_case(summary: RecordSummary, case_path: str | os.PathLike) -> str:
    """The commented TOML case-file draft for a record (paths relative to ``case_path``'s folder).

    ``[measurement]`` holds what :func:`inspect_record` found: the file, its format when the
    suffix does not tell it, the time column, the sample rate only when the file has no time
    stamps, the units guess (a placeholder when unsure) and one output per channel. The bridge
    (a simply supported beam, the modal-file form in a comment), the crowd density, the outputs'
    positions and the estimation band are placeholders.
    """
    case_path = Path(case_path)
    name = summary.path.name
    nyquist = summary.sample_rate / 2
    windows = int(summary.duration // _WINDOW)
    row = suffix_format(summary.path, "record")
    description = (f"{name}: {len(summary.channels)} channel(s), {summary.duration:g} s at "
                   f"{summary.sample_rate:g} Hz")
    lines = [
        f"# Case file drafted by `crowdvib init` {__version__} from {name}.",
        f'# Replace every value "{PLACEHOLDER} …": crowdvib refuses this file, naming the key, '
        "until then.",
        "# Check the values marked \"found\" and \"guess\". Every key, its unit and default: "
        "docs, Case files.",
        f"# Then run:  crowdvib estimate {case_path.name}",
        f"name = {_string(case_path.stem)}",
        f"description = {_string(description)}",
        "",
        "[structure]",
        "# The empty bridge as a simply supported beam: frequency, damping_ratio and modal_mass",
        "# take one value per mode (a list). A modal model from FE exports replaces the beam keys",
        "# by modal_table, mode_shapes and output_points (docs, Case files: [structure]).",
        'type = "simply_supported_beam"',
        f"span = {_placeholder('span [m]')}",
        f"width = {_placeholder('width of the walkway [m]')}",
        f"frequency = {_placeholder('natural frequency of the vertical mode [Hz]')}",
        f"damping_ratio = {_placeholder('damping ratio of the empty bridge, a fraction (0.005 is 0.5 %)')}",
        f"modal_mass = {_placeholder('modal mass [kg] of the unity-scaled sine mode')}",
        "",
        "[structure.outputs]",
        "# One output per channel of the record: the sensor's position along the span [m].",
        *(f"{_string(c.output)} = {_placeholder('position of this sensor along the span [m]')}"
          for c in summary.channels),
        "",
        "[crowd]",
        "# The pedestrians on the bridge during the record.",
        f"density = {_placeholder('pedestrian density during the record [persons/m²]')}",
        "# walking_speed = 1.3         # [m/s]; default from the density (Weidmann)",
        "# step_frequency_mean = 1.9   # [Hz]; default from the walking speed (Bruno & Venuti)",
        "# step_frequency_std = 0.175  # [Hz] (default)",
        "# body_mass = 70.0            # [kg] (default)",
        "",
        "[hsi]",
        "# mu_h1, the pedestrians' MSD mass as a fraction of their body mass: held at this value",
        "# while f_h1 and xi_h1 are estimated (0.95 is the default, the paper's).",
        "mass_ratio = 0.95",
        "",
        "[measurement]",
        f"files = [{_string(_relative(summary.path, case_path.parent))}]   # relative to this "
        "file",
    ]
    if row is None or row.name != summary.format:
        lines.append(f"format = {_string(summary.format)}")
    if summary.skipped:
        lines.append(f"header_row = {summary.header_line}   # found: the "
                     f"{len(summary.skipped)} line(s) of metadata above it are skipped")
        lines += [f"#   {_comment(line)}" for line in summary.skipped[:_SHOWN]]
        if len(summary.skipped) > _SHOWN:
            lines.append(f"#   … and {len(summary.skipped) - _SHOWN} more")
    if summary.time_column is not None:
        lines.append(f"time_column = {_string(summary.time_column)}   # found: "
                     f"{summary.sample_rate:.6g} Hz from its time stamps")
    elif summary.rate_source == "given":
        lines.append(f"sample_rate = {summary.sample_rate!r}   # [Hz], given: the file has no "
                     "time stamps")
    units = (_string(summary.units) if summary.units else
             _placeholder("'m/s2', 'g', 'mg' or 'mm/s2': crowdvib could not tell (see the "
                          "comment)"))
    lines += [
        f"units = {units}   # "
        f"{'found' if summary.units_stated else 'guess' if summary.units else 'unsure'}: "
        f"{summary.units_reason}",
        "# (a gravity offset is removed with the mean: detrend = \"constant\", the default)",
        *_gap_lines(summary),
        f"window_length = {_WINDOW!r}   # T [s] of the Welch PSD; " + (
            f"the record holds {windows} such window(s)" if windows else
            f"the record is shorter ({summary.duration:g} s): choose a shorter one"),
        "# filter = { cutoff = 10.0, order = 4 }   # low-pass [Hz], applied to record and model",
        "",
        "[measurement.channels]",
        "# output name (as in [structure.outputs]) = channel in the record; drop what is no",
        "# acceleration of the deck.",
        *(f"{_string(c.output)} = {_string(c.name)}   # found: mean {c.mean:.4g}, RMS "
          f"{c.rms:.3g} in the file's units" for c in summary.channels),
        "",
        "[estimation]",
        "# method, crowd_model, interval and the rest keep their defaults (docs, Case files).",
        "band = " + _placeholder(
            f"[lower, upper] frequency band [Hz] of the fit around the mode, e.g. [0.0, "
            f"{min(10.0, 0.8 * nyquist):.1f}]; upper below the Nyquist frequency "
            f"{nyquist:g} Hz"),
        "",
        "# [report]",
        "# Who and what the reports are for, shown in their header (each optional; uncomment):",
        '# client = "..."',
        '# project = "..."',
        '# bridge = "..."',
        '# location = "..."',
        '# engineer = "..."',
        "# measurement_date = 2024-05-01",
    ]
    return "\n".join(lines) + "\n"


def _exists(case_path):
    return ParameterError(f"{case_path} exists: crowdvib init never overwrites a file; choose "
                          "another name with -o or remove it")


def new_case_path(record: str | os.PathLike, case_path: str | os.PathLike | None = None) -> Path:
    """The case file to draft for ``record``: ``case_path``, by default the record's name with
    ``.toml`` beside it (the case and its record travel together); refused if it exists."""
    case_path = Path(record).with_suffix(".toml") if case_path is None else Path(case_path)
    if case_path.exists():
        raise _exists(case_path)
    return case_path


def write_draft(summary: RecordSummary, case_path: str | os.PathLike) -> Path:
    """Write :func:`draft_case` to ``case_path``, which must not exist (never overwritten).

    Raises
    ------
    ParameterError
        ``case_path`` exists.
    """
    case_path = Path(case_path)
    text = draft_case(summary, case_path)
    try:
        # "x": created only if absent, in one step (no window for another writer).
        with open(case_path, "x", encoding="utf-8") as handle:
            handle.write(text)
    except FileExistsError:
        raise _exists(case_path) from None
    return case_path
