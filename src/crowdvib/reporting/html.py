"""HTML building blocks of the report that escape every value by construction.

Every fragment is a :class:`markupsafe.Markup`. Fragments are only ever combined through
:func:`html` (a ``str.format`` template whose arguments are escaped unless they are already
Markup) and :func:`join`, so a string read from a ``results.json`` reaches the page escaped
whatever path it takes; no f-string builds markup.
"""

import json

import numpy as np
from markupsafe import Markup, escape

from ..quantities import describe
from .safe_html import CSP_META

__all__ = ["html", "join", "escape", "number", "value", "label", "span", "table", "page", "CSS"]


def html(template, *args, **kwargs):
    """``template`` (trusted markup written here) with its ``{}`` fields filled, escaped."""
    return Markup(template).format(*args, **kwargs)


def join(parts, separator=""):
    """The parts one after the other; plain strings among them are escaped."""
    return Markup(separator).join(parts)


def number(value, digits=4):
    """A number for a table cell (``—`` for missing or non-finite); anything else escaped."""
    if value is None:
        return Markup("—")
    if isinstance(value, bool):
        return Markup("yes" if value else "no")
    if isinstance(value, (int, np.integer)):
        return escape(str(value))
    if isinstance(value, (float, np.floating)):
        return escape(f"{value:.{digits}g}") if np.isfinite(value) else Markup("—")
    return escape(str(value))


_TITLES = {"hsi": "HSI (MSD model)", "msd": "MSD model", "crowd_used": "crowd used",
           "units": "record units", "classes": "traffic class per code",
           "codes": "design codes", "k1": "site usage k1", "k2": "route redundancy k2",
           "k3": "height of the deck k3", "site_factors": "UK NA site factors",
           "truth": "truth (MSD of the synthetic measurement)"}


def label(key):
    """A JSON key as a human label with its unit, e.g. "walking speed [m/s]" (plain text)."""
    key = str(key)
    return _TITLES.get(key) or describe(key)


def value(data, depth=0):
    """Compact HTML of a JSON value: long lists summarised, nested dicts as small tables."""
    if isinstance(data, dict):
        if not data:
            return Markup("—")
        if depth >= 2:
            return escape(json.dumps(data, default=str)[:200])
        rows = join(html("<tr><th>{}</th><td>{}</td></tr>", label(k), value(v, depth + 1))
                    for k, v in data.items())
        return html('<table class="kv">{}</table>', rows)
    if isinstance(data, list):
        if not data:
            return Markup("—")
        flat = [v for v in data if isinstance(v, (int, float)) and not isinstance(v, bool)]
        if len(data) > 6 and len(flat) == len(data):
            return html("{} values, {} … {}", len(data), number(min(flat)), number(max(flat)))
        if len(data) > 6:
            return html("{} items: {}, …", len(data), join((value(v, 2) for v in data[:3]), ", "))
        return join((value(v, depth + 1) for v in data), ", ")
    return number(data, 6)


def span(data):
    """A [lower, upper] pair as "lower – upper" (any other value as :func:`value`)."""
    if isinstance(data, (list, tuple)) and len(data) == 2:
        return html("{} – {}", number(data[0]), number(data[1]))
    return value(data)


def table(header, rows, css=""):
    """A table; header and cells are Markup or plain text (escaped)."""
    head = join(html("<th>{}</th>", h) for h in header)
    body = join(html("<tr>{}</tr>", join(html("<td>{}</td>", c) for c in row)) for row in rows)
    return html('<table class="{}"><thead><tr>{}</tr></thead><tbody>{}</tbody></table>',
                css, head, body)


def page(title, generator, body):
    """The whole document around the sections, its Content-Security-Policy first in <head>."""
    return html('<!DOCTYPE html>\n<html lang="en">\n<head>\n' + CSP_META
                + '\n<meta charset="utf-8">\n'
                '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
                '<meta name="generator" content="{}">\n<title>{}</title>\n<style>{}</style>\n'
                "</head>\n<body>\n<main>\n{}\n</main>\n</body>\n</html>\n",
                generator, title, CSS, join(body, "\n"))


#: The page's style, inline so the file stands alone (no external resources).
CSS = Markup("""
:root { --ink: #1b1f24; --muted: #5b6470; --line: #d9dee4; --accent: #1f4e79;
        --warn-bg: #fff5d6; --warn: #7a5200; --ok-bg: #e8f5ec; --ok: #1d6531;
        --fail-bg: #fde8e8; --fail: #8a1c1c; }
* { box-sizing: border-box; }
body { margin: 0; background: #eef0f3; color: var(--ink);
       font: 15px/1.5 system-ui, -apple-system, "Segoe UI", Roboto, "Helvetica Neue", Arial,
             sans-serif; }
main { max-width: 1080px; margin: 0 auto; padding: 28px 36px 56px; background: #fff;
       min-height: 100vh; }
header h1 { margin: 0 0 4px; font-size: 1.7em; color: var(--accent); }
.kicker { margin: 0; text-transform: uppercase; letter-spacing: .08em; font-size: .78em;
          color: var(--muted); }
h2 { margin: 34px 0 12px; padding-bottom: 4px; border-bottom: 2px solid var(--line);
     font-size: 1.3em; color: var(--accent); }
h3 { margin: 20px 0 8px; font-size: 1.05em; }
.muted { color: var(--muted); }
nav.toc { display: flex; flex-wrap: wrap; gap: 6px 18px; margin: 14px 0 0; padding: 8px 0;
          border-top: 1px solid var(--line); border-bottom: 1px solid var(--line); }
nav.toc a { color: var(--accent); text-decoration: none; font-weight: 600; font-size: .92em; }
ul.headline { list-style: none; padding: 0; margin: 0 0 12px; display: flex; flex-wrap: wrap;
              gap: 8px 28px; font-size: 1.2em; }
.callout { border-radius: 6px; padding: 10px 14px; margin: 10px 0; }
.callout ul { margin: 6px 0 0; padding-left: 20px; }
.callout.warn { background: var(--warn-bg); color: var(--warn); border-left: 5px solid #e0a800; }
.callout.ok { background: var(--ok-bg); color: var(--ok); border-left: 5px solid #2e9e4f; }
.callout.fail { background: var(--fail-bg); color: var(--fail); border-left: 5px solid #c62828; }
.badge { display: inline-block; padding: 0 6px; border-radius: 4px; font-size: .82em; }
.badge.warn { background: var(--warn-bg); color: var(--warn); border: 1px solid #e0a800; }
table { border-collapse: collapse; margin: 6px 0 12px; font-variant-numeric: tabular-nums; }
table.data { width: 100%; }
table.narrow { width: auto; min-width: 50%; }
th, td { padding: 5px 10px; text-align: left; vertical-align: top; overflow-wrap: break-word;
         border-bottom: 1px solid var(--line); }
/* A header breaks between words only, never inside one ("estima|te"; issue 27 §4), and a cell
   only a word wider than the whole table (break-word, unlike anywhere, keeps each column as
   wide as its longest word); code (paths, hashes) breaks anywhere. */
th { hyphens: manual; word-break: keep-all; overflow-wrap: normal; }
thead th { background: #f3f5f8; font-size: .88em; color: var(--muted); font-weight: 600; }
table.provenance thead { display: none; }
table.kv { width: 100%; margin: 0; font-size: .92em; }
table.kv th { width: 42%; color: var(--muted); font-weight: 500; }
table.kv table.kv th { width: 50%; }
table.letterhead { width: auto; min-width: 50%; margin: 12px 0 0; font-size: .95em; }
table.letterhead th { width: auto; padding-right: 24px; }
.cards { display: grid; grid-template-columns: repeat(auto-fill, minmax(310px, 1fr));
         gap: 14px; }
.card { border: 1px solid var(--line); border-radius: 6px; padding: 4px 12px 8px; }
.card h3 { margin: 8px 0 4px; }
.default { color: #8a6d00; font-size: .82em; font-style: italic; }
figure { margin: 18px 0 26px; }
figure img { display: block; max-width: 100%; height: auto; margin: 0 auto;
             border: 1px solid var(--line); }
figcaption { margin-top: 6px; font-size: .92em; }
details summary { cursor: pointer; font-weight: 600; margin: 12px 0 6px; }
code { font-family: ui-monospace, "SFMono-Regular", Menlo, Consolas, monospace; font-size: .88em;
       overflow-wrap: anywhere; }
@media (max-width: 720px) { main { padding: 16px; } ul.headline { font-size: 1.05em; } }
@page { size: A4; margin: 15mm 13mm; }
@media print {
  body { background: #fff; font-size: 10pt; }
  main { max-width: none; padding: 0; min-height: 0; }
  nav.toc { display: none; }
  h2 { break-after: avoid; page-break-after: avoid; }
  figure, table, .callout, .card { break-inside: avoid; page-break-inside: avoid; }
  figure img { max-height: 120mm; width: auto; border: none; }
  .callout { border: 1px solid #999; }
  details > summary { list-style: none; }
  a { color: inherit; text-decoration: none; }
}
""")
