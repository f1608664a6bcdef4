"""Moving pictures in the report: the mode shapes through their cycle and a replay of the crowd
crossing the deck (issue 38), inside the report's Content-Security-Policy.

Each picture is an inline SVG that crowdvib draws here in full, a still readable without
script (the mode shapes at their largest, the crossing at its largest deflection), with its
data beside it in a ``<script type="application/json">`` block (data, never run). One small
script of crowdvib's own (``animation.js``, shipped with the package) moves them: play,
pause and a slider.

The page is finished after everything else (:meth:`Animations.finish`): the report's blocks
hold only a placeholder with a token drawn for this page, which a template may place but
cannot forge; after the template's page has passed the allow-list
(:mod:`crowdvib.reporting.safe_html`), which leaves no script in it, the placeholder is
replaced by the pictures, the script is put before ``</body>`` and the policy's
``script-src`` names that script's SHA-256, so it runs and nothing else does.

Public: :func:`mode_shape_table` (what a command records of its modal model, under
``mode_shapes`` in results.json), :func:`mode_shape_animation` (the picture of such a table,
for a report section of one's own), :func:`report_animations` (every picture a results dict
holds) and :data:`SCRIPT`.
"""

import base64
import hashlib
import secrets
from importlib import resources

import numpy as np
from markupsafe import Markup

from .frames import INK, MAX_STATIONS, MUTED, frame, path_data, significant
from .html import html, join, number
from .safe_html import CSP_META, csp_meta, policy_with_scripts
from .replay_view import replay_animation
from ..response.frequency_domain.spectral import effective_modal_properties

__all__ = ["mode_shape_table", "mode_shape_animation", "report_animations", "Animations",
           "SCRIPT", "SCRIPT_HASH"]

#: crowdvib's script, exactly as the page holds it (the policy allows it by this text's hash).
SCRIPT = resources.files(__package__).joinpath("animation.js").read_text(encoding="utf-8")
#: ``sha256-…`` of :data:`SCRIPT`, as a policy names it.
SCRIPT_HASH = "sha256-" + base64.b64encode(hashlib.sha256(SCRIPT.encode("utf-8")).digest()
                                           ).decode("ascii")
#: Steps of one cycle of the mode-shape animation and its frames per second (1.5 s a cycle).
_PHASE_STEPS, _PHASE_RATE = 48, 32
#: Style of the controls, added once with the script.
_STYLE = (".cv-controls{display:flex;gap:10px;align-items:center;margin:4px 0 0}"
          ".cv-controls input{flex:1}.cv-label{font-variant-numeric:tabular-nums;"
          "min-width:14em;color:#5b6470}@media print{.cv-controls{display:none}}")
_LANE_COLOURS = ("#1f4e79", "#c0392b", "#2e7d32", "#8e44ad", "#d35400")


def mode_shape_table(structure, crowd=None, msd=None):
    """What a report draws of a modal model: frequencies, damping and the shapes at up to
    :data:`~crowdvib.reporting.frames.MAX_STATIONS` stations of each lane (JSON-ready), for
    ``results["mode_shapes"]``; with a crowd and its MSD, the occupied structure's too.

    Parameters
    ----------
    structure : ModalModel
    crowd : Crowd, optional
    msd : MSDModel, optional
        The crowd's MSD (the estimated one, the design's, the simulated one): the occupied
        structure's frequencies and damping ratios
        (:func:`~crowdvib.response.frequency_domain.spectral.effective_modal_properties`) go with the shapes.

    Returns
    -------
    dict
        ``frequencies`` [Hz], ``damping_ratios`` [-], ``positions`` [m], ``lanes`` [m],
        ``width`` [m], ``shapes`` (lane × station × mode, the model's scaling) and, with a
        crowd and its MSD, ``occupied`` (``frequencies``, ``damping_ratios``).
    """
    positions = np.asarray(structure.positions)
    keep = np.unique(np.r_[np.arange(0, positions.size, -(-positions.size // MAX_STATIONS)),
                           positions.size - 1])
    shapes = np.asarray(structure.mode_shapes)[:, keep, :]
    occupied = {}
    if crowd is not None and msd is not None and crowd.density > 0:

        found = effective_modal_properties(structure, crowd, msd)
        occupied = {"occupied": {"frequencies": [float(f) for f in found.frequencies],
                                 "damping_ratios": [float(x) for x in found.damping_ratios]}}
    return {**occupied, "frequencies": [float(f) for f in structure.frequencies],
            "damping_ratios": [float(x) for x in structure.damping_ratios],
            "positions": significant(positions[keep], 7),
            "lanes": [float(y) for y in structure.lanes], "width": float(structure.width),
            "shapes": [[significant(row) for row in lane] for lane in shapes.tolist()]}


def _numbers(values):
    """A list of floats from results.json (a received one's may be anything), or []."""
    try:
        return [float(v) for v in values]
    except (TypeError, ValueError):
        return []


def _describe_mode(j, frequencies, damping, occupied):
    text = html("mode {}: {} Hz, ξ = {} %", j + 1, number(frequencies[j], 4),
                number(100 * damping[j], 3))
    if occupied is not None and j < min(len(occupied[0]), len(occupied[1])):
        text += html("; occupied {} Hz, ξ = {} %", number(occupied[0][j], 4),
                     number(100 * occupied[1][j], 3))
    return text


def mode_shape_animation(table, occupied=None, *, title="Mode shapes", abscissa=None):
    """The mode shapes of a :func:`mode_shape_table` (or the identified shapes of an OMA), each
    along the walkway, every lane a line, swinging through its cycle.

    Parameters
    ----------
    table : dict
        :func:`mode_shape_table`'s keys: ``frequencies``, ``damping_ratios``, ``positions``,
        ``shapes`` (lane × station × mode); ``lanes`` optional.
    occupied : dict, optional
        ``frequencies`` and ``damping_ratios`` of the structure with its crowd (shown beside
        the empty ones).
    title : str
    abscissa : list of str, optional
        Names of the points (sensors) instead of positions along the walkway [m].

    Returns
    -------
    Markup
        The picture (a still without script); :meth:`Animations.finish` adds the script.
    """
    positions = np.asarray(table["positions"], dtype=float)
    shapes = np.asarray(table["shapes"], dtype=float)
    frequencies, damping = table["frequencies"], table["damping_ratios"]
    occupied = (None if not isinstance(occupied, dict) else
                (_numbers(occupied.get("frequencies")), _numbers(occupied.get("damping_ratios"))))
    n_lanes, _, n_modes = shapes.shape
    width, height, left, right = 720.0, 92.0, 56.0, 16.0
    span = positions[-1] - positions[0] or 1.0
    xs = left + (positions - positions[0]) / span * (width - left - right)
    panels, parts = [], []
    for j in range(n_modes):
        top = j * (height + 26)
        y0 = top + 26 + height / 2
        peak = np.max(np.abs(shapes[:, :, j])) or 1.0
        lanes = [list(np.round(-shapes[lane, :, j] / peak * (height / 2 - 6), 1))
                 for lane in range(n_lanes)]
        panels.append({"x": list(np.round(xs, 1)), "y0": round(y0, 1), "lanes": lanes})
        parts.append(html('<text x="{}" y="{}" font-size="13" fill="{}">{}</text>'
                          '<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="{}" '
                          'stroke-dasharray="4 3"/>', left, top + 16, INK,
                          _describe_mode(j, frequencies, damping, occupied), left, y0,
                          width - right, y0, MUTED))
        for lane, dy in enumerate(lanes):
            parts.append(html('<path data-cv-line="{} {}" d="{}" fill="none" stroke="{}" '
                              'stroke-width="2"/>', j, lane, path_data(xs, y0 + np.asarray(dy)),
                              _LANE_COLOURS[lane % len(_LANE_COLOURS)]))
    bottom = n_modes * (height + 26) + 8
    ticks = (list(zip(xs, abscissa)) if abscissa is not None else
             [(left + (x - positions[0]) / span * (width - left - right), f"{x:g} m")
              for x in np.linspace(positions[0], positions[-1], 6)])
    # The outer names inward, so a long sensor name stays on the picture.
    anchors = ["start"] + ["middle"] * (len(ticks) - 2) + ["end"]
    parts += [html('<text x="{}" y="{}" font-size="11" fill="{}" text-anchor="{}">{}</text>',
                   round(x, 1), bottom + 6, MUTED, anchor, name)
              for (x, name), anchor in zip(ticks, anchors)]
    svg = html('<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {} {}" width="100%" '
               'role="img" aria-label="{}">{}</svg>', width, bottom + 12, title, join(parts))
    lanes = table.get("lanes") or []
    lanes_text = (html(" Lines: the lanes at {} m across the walkway.",
                       ", ".join(f"{y:g}" for y in lanes)) if n_lanes > 1 else "")
    caption = html("Each mode along the walkway, scaled to its largest value (the still: the "
                   "shape at phase 0; with script, Play swings it through its cycle and the "
                   "slider sets the phase).{}", lanes_text)
    return frame("modes", "phase", title, svg,
                 {"kind": "modes", "steps": _PHASE_STEPS, "rate": _PHASE_RATE,
                  "panels": panels}, caption)


def _identified_table(results):
    """The OMA report's identified shapes (at the sensors, in their order) as a table."""
    modes = [m for m in results.get("modes") or [] if isinstance(m, dict)]
    names = results.get("sensor_names")
    if not modes or not isinstance(names, list) or len(names) < 2:
        return None
    try:
        shapes = np.array([[float(v) for v in m["mode_shape"]] for m in modes]).T
        table = {"frequencies": [float(m["frequency"]) for m in modes],
                 "damping_ratios": [float(m["damping_ratio"]) for m in modes],
                 "positions": list(range(len(names))), "shapes": [shapes.tolist()]}
    except (KeyError, TypeError, ValueError):
        return None
    if shapes.shape != (len(names), len(modes)) or not np.all(np.isfinite(shapes)):
        return None
    return table, [str(n) for n in names]


def _valid_table(table):
    """A ``mode_shapes`` table of results.json that draws (a received folder's may not)."""
    try:
        shapes = np.asarray(table["shapes"], dtype=float)
        positions = np.asarray(table["positions"], dtype=float)
        ok = (shapes.ndim == 3 and shapes.shape[1] == positions.size >= 2
              and len(table["frequencies"]) == len(table["damping_ratios"]) == shapes.shape[2]
              and np.all(np.isfinite(shapes)) and np.all(np.diff(positions) > 0))
        [float(v) for v in (*table["frequencies"], *table["damping_ratios"])]
    except (KeyError, TypeError, ValueError):
        return False
    return bool(ok)


def report_animations(results):
    """Every picture a results dict holds: its modal model's shapes (``mode_shapes``), an OMA's
    identified shapes (``modes``) and a crossing replay (``replay``)."""

    pictures = []
    table = results.get("mode_shapes")
    if isinstance(table, dict) and _valid_table(table):
        occupied = table.get("occupied", results.get("occupied_structure"))
        pictures.append(mode_shape_animation(table, occupied if isinstance(occupied, dict)
                                             else None, title="Mode shapes of the modal model"))
    identified = _identified_table(results)
    if identified is not None:
        pictures.append(mode_shape_animation(identified[0], title="Identified mode shapes "
                                             "(at the sensors)", abscissa=identified[1]))
    replay = results.get("replay")
    if isinstance(replay, dict):
        picture = replay_animation(replay)
        if picture is not None:
            pictures.append(picture)
    return Animations(pictures)


class Animations:
    """The pictures of one page: a placeholder for the report's blocks, then :meth:`finish`.

    Parameters
    ----------
    pictures : list of Markup
        :func:`frame`'s fragments.
    """

    def __init__(self, pictures):
        self.pictures = list(pictures)
        # Drawn for this page: a template (or a received results.json) cannot write it.
        self.token = secrets.token_hex(16)

    @property
    def slot(self):
        """The placeholder (empty without pictures), as the allow-list writes it out again."""
        if not self.pictures:
            return Markup("")
        return html('<div class="cv-slot">{}</div>', self.token)

    def finish(self, page):
        """``page`` (the built-in page or a template's, after the allow-list) with the pictures
        in place of the placeholder, crowdvib's script before ``</body>`` and the policy
        allowing that script by its hash; unchanged where no placeholder is found."""
        slot = str(self.slot)
        if not self.pictures or slot not in page:
            return page
        section = html('<section id="animations"><h2>Animations</h2>{}</section>',
                       join(self.pictures))
        page = page.replace(slot, str(section))
        own = f"<style>{_STYLE}</style><script>{SCRIPT}</script>"
        end = page.rfind("</body>")
        page = page + own if end < 0 else page[:end] + own + page[end:]
        # The first policy is crowdvib's own, first in <head> (safe_html puts it before any
        # content of a template's page); what follows it is the page's content.
        return page.replace(CSP_META, csp_meta(policy_with_scripts([SCRIPT_HASH])), 1)
