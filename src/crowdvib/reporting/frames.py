"""The pieces every moving picture of the report is made of (issue 38): its numbers kept short,
its SVG path data, its JSON data block and the figure that holds them
(:mod:`crowdvib.reporting.animation`, :mod:`crowdvib.reporting.replay_view`)."""

import json

import numpy as np
from markupsafe import Markup

from .html import html

__all__ = ["significant", "path_data", "data_block", "frame", "MAX_STATIONS", "INK", "MUTED",
           "LINE"]

#: The pictures' colours: the report's ink, muted text and rule lines (html.CSS's).
INK, MUTED, LINE = "#1b1f24", "#5b6470", "#d9dee4"

#: Stations kept of a modal model's shapes (an FE export may have thousands): every
#: ⌈n/MAX⌉-th, both ends kept, at their exact values; a line of 100 points draws any mode a
#: footbridge walker excites.
MAX_STATIONS = 101


def significant(values, digits=5):
    """Plain floats rounded to ``digits`` significant digits (JSON stays short)."""
    return [float(f"{v:.{digits}g}") for v in np.ravel(values)]


def data_block(data):
    """``data`` as a JSON data block (never run); ``<``, ``>`` and ``&`` escaped so no string
    in it can end the element."""
    text = json.dumps(data, separators=(",", ":"), allow_nan=False)
    text = text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")
    return Markup('<script type="application/json" class="cv-data">' + text + "</script>")


def frame(kind, slider, title, svg, data, caption):
    """One picture: its still SVG, its data and caption, which the script makes move."""
    return html('<figure class="cv-anim" data-cv-kind="{}" data-cv-slider="{}">'
                "<h3>{}</h3>{}{}<figcaption>{}</figcaption></figure>",
                kind, slider, title, svg, data_block(data), caption)


def path_data(xs, ys):
    """SVG path data of the polyline through (xs, ys) [px], to 0.1 px."""
    return "".join(f"{'L' if i else 'M'}{x:.1f} {y:.1f}" for i, (x, y) in enumerate(zip(xs, ys)))
