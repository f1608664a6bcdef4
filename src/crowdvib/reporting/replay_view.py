"""The crossing replay in the report (issue 38): the deck in plan with its walkers, the deck in
elevation with its deflection (exaggerated, the scale stated) and the walkers riding on it,
and the acceleration at each output with the comfort classes' bounds and a cursor.

:func:`replay_table` turns a :class:`~crowdvib.response.time_domain.replay.Replay` into what results.json
keeps (``replay``): frames decimated, walkers as their arrival, speed and lane (positions are
computed where drawn: x = x_k + v_k (t − t_k)), the traces as a min/max envelope and, with
HSI, each walker's MSD motion relative to the deck, u − φᵀz, quantised to one character a
frame (:data:`MSD_ALPHABET`: 61 steps of one ``unit`` per replay, the largest motion 30 of
them), so the motion of some 70 walkers on the deck adds 1.4 kB a second of replay (as
JSON numbers, some 4 kB).
:func:`replay_animation` draws it: a still at the frame of largest deflection, which
``animation.js`` moves through every frame.
"""

import numpy as np
from markupsafe import Markup

from ..design.codes import COMFORT_CLASSES
from .frames import INK, LINE, MAX_STATIONS, MUTED, frame, path_data, significant
from .html import html, join, number

__all__ = ["replay_table", "replay_animation", "msd_motion", "TRACE_BINS_PER_SECOND",
           "REPLAY_GEOMETRY", "MSD_ALPHABET"]

#: Envelope bins per second of each acceleration trace: 720 px over 30 s is 24 px a second,
#: so a min and a max every 50 ms keep every peak the picture can show.
TRACE_BINS_PER_SECOND = 20
#: Layout of the picture [px]: width, margins, the plan strip, the elevation's deck line, the
#: height of an output's trace, the largest drawn deflection, the walkers' lift and bob (a
#: mark of the step frequency without HSI) and, with HSI, the largest drawn MSD motion (the
#: walkers lifted by it as well, so none sinks into the deck).
REPLAY_GEOMETRY = {"width": 720.0, "left": 56.0, "right": 16.0, "plan_top": 36.0,
                   "plan_height": 36.0, "deck_y": 140.0, "trace_top": 222.0,
                   "trace_height": 84.0, "deflection": 30.0, "lift": 4.0, "bob": 1.5,
                   "msd": 8.0}
#: The MSD motion's codes: character i is the integer i − 30 (−30 … 30) times the replay's
#: ``unit`` [m]; letters and digits only, so JSON writes each as one byte.
MSD_ALPHABET = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxy"
_MSD_ZERO = len(MSD_ALPHABET) // 2
_WALKER_COLOURS = ("#1f4e79", "#c0392b")   # walking forward, walking back


def replay_table(replay, structure, *, busiest=True):
    """What results.json keeps of a replay (JSON-ready).

    Parameters
    ----------
    replay : Replay
    structure : ModalModel
        The model it was simulated on (its shapes at mid-width, at up to
        :data:`~crowdvib.reporting.frames.MAX_STATIONS` stations).
    busiest : bool
        The stretch is the busiest of the record (else one asked for), as the caption says.

    Returns
    -------
    dict
    """
    positions = np.linspace(structure.positions[0], structure.positions[-1], MAX_STATIONS)
    shapes = structure.shapes_at(positions)                      # station × mode, mid-width
    deflection = shapes @ replay.modal_displacement              # station × frame [m]
    scale = float(np.max(np.abs(replay.modal_displacement))) or 1.0
    rate = round(1.0 / (replay.time[1] - replay.time[0]), 6) if replay.n_frames > 1 else 1.0
    bins = max(1, int(round((replay.trace_time.size / (replay.trace_time[-1] - replay.trace_time[0]
                                                       + 1e-12)) / TRACE_BINS_PER_SECOND)))
    n = replay.acceleration.shape[1] // bins * bins
    envelope = replay.acceleration[:, :n].reshape(replay.acceleration.shape[0], -1, bins)
    walkers = {name: [round(float(v), 3) for v in np.minimum(getattr(replay, name), 1e9)]
               for name in ("arrival", "x_start", "velocity", "lateral", "step_frequency",
                            "t_on", "t_off")}
    moving = ({} if not replay.hsi or replay.msd_displacement is None
              else {"msd": _msd_table(replay.msd_displacement)})
    return {**moving, "t0": float(replay.time[0]), "frame_rate": float(rate),
            "seed": int(replay.seed), "busiest": bool(busiest),
            "hsi": bool(replay.hsi), "width": float(structure.width),
            "positions": significant(positions, 7),
            "shapes": [significant(shapes[:, j] * scale) for j in range(structure.n_modes)],
            "q": [[round(float(v), 4) for v in column]
                  for column in (replay.modal_displacement / scale).T],
            "largest_deflection": float(np.max(np.abs(deflection))),
            "walkers": walkers, "output_names": list(replay.output_names),
            "trace_t0": float(replay.trace_time[0]),
            "trace_dt": float(bins * (replay.trace_time[1] - replay.trace_time[0])),
            "trace_min": [significant(row, 4) for row in envelope.min(axis=2)],
            "trace_max": [significant(row, 4) for row in envelope.max(axis=2)]}


def _msd_table(motion):
    """Each walker's MSD motion relative to the deck (walker × frame [m], NaN off the deck) as
    ``unit`` [m], the alphabet and, per walker, its first frame on the deck and one code a
    frame from there to its last (the nearest multiple of ``unit``)."""
    finite = np.isfinite(motion)
    largest = float(np.max(np.abs(motion[finite]))) if finite.any() else 0.0
    unit = largest / _MSD_ZERO if largest > 0 else 1.0
    first, codes = [], []
    for row, on in zip(motion, finite):
        frames = np.flatnonzero(on)
        if frames.size == 0:
            first.append(0)
            codes.append("")
            continue
        steps = np.rint(np.nan_to_num(row[frames[0]:frames[-1] + 1]) / unit).astype(int)
        first.append(int(frames[0]))
        codes.append("".join(MSD_ALPHABET[_MSD_ZERO + n] for n in steps))
    return {"unit": unit, "alphabet": MSD_ALPHABET, "first": first, "codes": codes}


def msd_motion(msd, n_walkers, n_frames):
    """The MSD motion [m] (walker × frame, 0 where no code is given) of a replay table's
    ``msd`` (:func:`replay_table`).

    Raises
    ------
    KeyError, TypeError, ValueError
        A table that does not decode (a received results.json may hold anything).
    """
    unit = float(msd["unit"])
    first, codes = [int(v) for v in msd["first"]], [str(c) for c in msd["codes"]]
    if not (unit > 0 and msd["alphabet"] == MSD_ALPHABET and len(first) == len(codes)
            == n_walkers):
        raise ValueError("msd: a positive unit, crowdvib's alphabet, one code string a walker")
    motion = np.zeros((n_walkers, n_frames))
    for k, (start, code) in enumerate(zip(first, codes)):
        if start < 0 or start + len(code) > n_frames:
            raise ValueError("msd: codes beyond the replay's frames")
        motion[k, start:start + len(code)] = [MSD_ALPHABET.index(c) - _MSD_ZERO for c in code]
    return unit * motion


def _arrays(table):
    """The table's arrays, checked (a received results.json is data); None if they do not
    draw."""
    try:
        found = {"positions": np.asarray(table["positions"], dtype=float),
                 "shapes": np.asarray(table["shapes"], dtype=float),
                 "q": np.asarray(table["q"], dtype=float),
                 "low": np.asarray(table["trace_min"], dtype=float),
                 "high": np.asarray(table["trace_max"], dtype=float),
                 "walkers": {k: np.asarray(table["walkers"][k], dtype=float) for k in
                             ("arrival", "x_start", "velocity", "lateral", "step_frequency",
                              "t_on", "t_off")},
                 "names": [str(n) for n in table["output_names"]]}
        scalars = {k: float(table[k]) for k in ("t0", "frame_rate", "width", "trace_t0",
                                                 "trace_dt", "largest_deflection")}
        sizes = {v.size for v in found["walkers"].values()}
        found["msd"] = (None if "msd" not in table else
                        msd_motion(table["msd"], min(sizes), len(found["q"])))
    except (KeyError, TypeError, ValueError):
        return None
    numbers = [found[k] for k in ("positions", "shapes", "q", "low", "high")]
    numbers += list(found["walkers"].values()) + [np.array(list(scalars.values()))]
    numbers += [] if found["msd"] is None else [found["msd"]]
    ok = (found["positions"].ndim == 1 and found["positions"].size >= 2
          and found["shapes"].shape[1:] == found["positions"].shape
          and found["q"].ndim == 2 and found["q"].shape[0] >= 1
          and found["q"].shape[1] == found["shapes"].shape[0]
          and found["low"].shape == found["high"].shape and found["low"].ndim == 2
          and found["low"].shape[0] == len(found["names"]) and len(sizes) == 1
          and scalars["frame_rate"] > 0 and scalars["width"] > 0 and scalars["trace_dt"] > 0
          and all(np.all(np.isfinite(v)) for v in numbers))
    return {**found, **scalars} if ok else None


def replay_animation(table):
    """The replay of a :func:`replay_table` as a picture (a still without script), or None if
    the table does not draw."""
    found = _arrays(table)
    if found is None:
        return None
    g = REPLAY_GEOMETRY
    x, q, w = found["positions"], found["q"], found["walkers"]
    inner = g["width"] - g["left"] - g["right"]
    bx = inner / (x[-1] - x[0])
    ax = g["left"] - bx * x[0]
    deflection = found["shapes"].T @ q.T                           # station × frame, [m]
    largest = float(np.max(np.abs(deflection))) or 1.0
    pixels = g["deflection"] / largest                              # px per m of deflection
    still = int(np.argmax(np.max(np.abs(deflection), axis=0)))
    length = q.shape[0] / found["frame_rate"]
    n_outputs = len(found["names"])
    data = {"kind": "replay", "rate": found["frame_rate"], "t0": found["t0"],
            "x": significant(ax + bx * x, 5), "y0": g["deck_y"],
            "shapes": [significant(-row * pixels, 4) for row in found["shapes"]],
            "q": q.tolist(), "walkers": {k: v.tolist() for k, v in w.items()},
            "ax": ax, "bx": bx, "lift": g["lift"], "bob": g["bob"],
            "plan_y0": g["plan_top"], "plan_by": g["plan_height"] / found["width"],
            "trace_x0": g["left"], "trace_bx": inner / length,
            "colours": list(_WALKER_COLOURS)}
    t = found["t0"] + still / found["frame_rate"]
    deck_y = g["deck_y"] + (found["shapes"].T * -pixels) @ q[still]
    motion, moving = found["msd"], Markup("")
    if motion is not None:
        # With HSI each walker's dot is lifted by its MSD's motion (the largest drawn
        # g["msd"] px) in place of the bob, and by g["msd"] more, so none sinks into the deck.
        largest_msd = float(np.max(np.abs(motion))) or 1.0
        msd_pixels = g["msd"] / largest_msd                          # px per m of MSD motion
        data["lift"] = g["lift"] + g["msd"]
        data["msd"] = {"unit": float(table["msd"]["unit"]),
                       "px": msd_pixels * float(table["msd"]["unit"]), "zero": _MSD_ZERO,
                       "alphabet": MSD_ALPHABET,
                       "first": [int(v) for v in table["msd"]["first"]],
                       "codes": [str(c) for c in table["msd"]["codes"]]}
        moving = html(" lifted by their MSD's motion relative to the deck, u − φ<sup>T</sup>z "
                      "(paper Eq. 2), exaggerated × {} (largest {} mm, kept to {} mm)",
                      number(msd_pixels / bx, 3), number(1e3 * largest_msd, 3),
                      number(1e3 * float(table["msd"]["unit"]), 2))
        motion = msd_pixels * motion[:, still]
    parts = [_plan(g, found["width"]), _elevation(g, x, ax, bx, deck_y),
             _walkers(data, w, t, deck_y, motion), _traces(found, g, length, n_outputs, t)]
    height = g["trace_top"] + n_outputs * (g["trace_height"] + 22) + 14
    svg = html('<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {} {}" width="100%" '
               'role="img" aria-label="crossing replay">{}</svg>', g["width"], height,
               join(parts))
    exaggeration = pixels / bx
    caption = html(
        "{} s of the simulated record from t = {} s ({}; seed {}), {} frames a second{}. Top: "
        "the deck in plan, each walker where its "
        "arrival time and speed put it (blue walking forward, red back). Middle: the deck's "
        "deflection w = Σ φ<sub>j</sub> z<sub>j</sub> from the modal coordinates, exaggerated "
        "× {} (largest {} mm), the walkers on it{}. Bottom: the "
        "acceleration at each output (envelope of the record) with the comfort classes' "
        "bounds (CL1 {} m/s², CL2 {} m/s², HiVoSS). The still shows t = {} s, the largest "
        "deflection; with script, Play runs the replay and the slider sets the time.",
        number(length, 3), number(found["t0"], 5),
        "the stretch with the most walkers on the deck" if table.get("busiest", True)
        else "the stretch asked for", number(table.get("seed")),
        number(found["frame_rate"], 3),
        Markup(", walkers as MSDs (HSI)") if table.get("hsi") else "",
        number(exaggeration, 3), number(1e3 * largest, 3),
        moving or Markup(" bobbing at their step frequency"), number(COMFORT_CLASSES[0][1]),
        number(COMFORT_CLASSES[1][1]), number(t, 5))
    return frame("replay", "time", "Crossing replay", svg, data, caption)


def _plan(g, width):
    right = g["width"] - g["right"]
    return html('<text x="{}" y="{}" font-size="12" fill="{}">plan</text>'
                '<rect x="{}" y="{}" width="{}" height="{}" fill="#f3f5f8" stroke="{}"/>'
                '<text x="{}" y="{}" font-size="11" fill="{}" text-anchor="end">{} m</text>'
                '<g data-cv-plan=""></g>', 4, g["plan_top"] + 22, MUTED, g["left"],
                g["plan_top"], right - g["left"], g["plan_height"], LINE, g["left"] - 4,
                g["plan_top"] + g["plan_height"], MUTED, number(width, 3))


def _elevation(g, x, ax, bx, deck_y):
    y0, right = g["deck_y"], g["width"] - g["right"]
    supports = join(html('<path d="M{} {}l-6 10h12z" fill="{}"/>', round(ax + bx * end, 1),
                         y0 + 2, MUTED) for end in (x[0], x[-1]))
    ticks = join(html('<text x="{}" y="{}" font-size="11" fill="{}" text-anchor="middle">'
                      "{} m</text>", round(ax + bx * v, 1), y0 + 48, MUTED, number(v, 4))
                 for v in np.linspace(x[0], x[-1], 6))
    return html('<text x="{}" y="{}" font-size="12" fill="{}">elevation</text>'
                '<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="{}" stroke-dasharray="4 3"/>'
                '{}{}<path data-cv-deck="" d="{}" fill="none" stroke="{}" stroke-width="3"/>',
                4, y0 - 4, MUTED, g["left"], y0, right, y0, MUTED, supports, ticks,
                path_data(ax + bx * x, deck_y), INK)


def _walkers(data, w, t, deck_y, motion):
    """The walkers on the deck at ``t`` (as the script draws them) in elevation and in plan;
    ``motion`` their MSD's [px] (every walker's), None without HSI."""
    on = np.flatnonzero((w["t_on"] <= t) & (t < w["t_off"]))
    px = data["ax"] + data["bx"] * (w["x_start"][on] + w["velocity"][on] * (t - w["arrival"][on]))
    bob = (data["bob"] * np.sin(2 * np.pi * w["step_frequency"][on] * (t - w["arrival"][on]))
           if motion is None else motion[on])
    cy = np.interp(px, data["x"], deck_y) - data["lift"] - bob
    plan_y = data["plan_y0"] + data["plan_by"] * w["lateral"][on]
    colour = [data["colours"][0 if v >= 0 else 1] for v in w["velocity"][on]]
    dots = join(html('<circle r="2.5" cx="{:.1f}" cy="{:.1f}" fill="{}"/>', a, b, c)
                for a, b, c in zip(px, cy, colour))
    marks = join(html('<circle r="2" cx="{:.1f}" cy="{:.1f}" fill="{}"/>', a, b, c)
                 for a, b, c in zip(px, plan_y, colour))
    # The still's dots; the script draws its own over them (the still ones are hidden).
    return html('<g class="cv-still">{}{}</g><g data-cv-walkers=""></g>', dots, marks)


def _traces(found, g, length, n_outputs, t):
    left, right = g["left"], g["width"] - g["right"]
    bx = (right - left) / length
    parts = []
    for o in range(n_outputs):
        top = g["trace_top"] + o * (g["trace_height"] + 22)
        mid = top + g["trace_height"] / 2
        low, high = found["low"][o], found["high"][o]
        reach = max(float(np.max(np.abs([low, high]))), COMFORT_CLASSES[0][1]) * 1.15
        by = g["trace_height"] / 2 / reach
        times = left + (found["trace_t0"] - found["t0"] + np.arange(low.size)
                        * found["trace_dt"]) * bx
        # The envelope as one closed band: the maxima forward, the minima back.
        band = path_data(np.r_[times, times[::-1]], mid - by * np.r_[high, low[::-1]]) + "Z"
        limits = join(html('<path d="M{} {:.1f}H{}M{} {:.1f}H{}" stroke="#c47f00" '
                           'stroke-dasharray="5 3"/><text x="{}" y="{:.1f}" font-size="10" '
                           'fill="#c47f00" text-anchor="end">{} bound ±{}</text>', left,
                           mid - by * bound, right, left, mid + by * bound, right, right - 2,
                           mid - by * bound - 2, name, number(bound))
                      for name, bound in COMFORT_CLASSES[:2] if bound <= reach)
        x = left + (t - found["t0"]) * bx
        parts.append(html(
            '<text x="{}" y="{}" font-size="12" fill="{}">acceleration at {} [m/s²], ±{} '
            "shown</text>"
            '<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="{}"/>'
            '<path d="{}" fill="#1f4e79" fill-opacity="0.55" stroke="none"/>{}'
            '<line data-cv-cursor="" x1="{:.1f}" x2="{:.1f}" y1="{}" y2="{}" stroke="#c0392b" '
            'stroke-width="1.5"/>', left, top - 4, MUTED, found["names"][o], number(reach, 3),
            left, top, right - left, g["trace_height"], LINE, band, limits, x, x, top,
            top + g["trace_height"]))
    bottom = g["trace_top"] + n_outputs * (g["trace_height"] + 22) - 8
    parts += [html('<text x="{:.1f}" y="{}" font-size="11" fill="{}" text-anchor="middle">'
                   "{} s</text>", left + (v - found["t0"]) * bx, bottom, MUTED, number(v, 5))
              for v in np.linspace(found["t0"], found["t0"] + length, 7)]
    return join(parts)
