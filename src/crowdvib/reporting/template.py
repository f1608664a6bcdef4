"""Report templates: a consultancy's own page (its letterhead) around the report's blocks (issue
27 §4).

A template is a Jinja2 HTML file named by the case file's ``[report] template`` (or
:func:`crowdvib.reporting.report.write_report`'s ``template``). It receives:

* the report's blocks, each finished HTML: ``header``, ``nav``, ``summary``, ``estimate``,
  ``diagnostics``, ``figures``, ``inputs``, ``provenance``, and ``body`` (all of them in order);
* ``title``, ``generator``, ``css`` (the report's own style, to keep or to extend);
* ``report``: the case's ``[report]`` table (``report.client``, ``report.project``, …; a key the
  case file left out is empty);
* ``embed(name)``: a PNG, JPEG, GIF or SVG file beside the template (a logo) as a ``data:`` URI.

Every value is escaped (autoescaping; the blocks are already markup), the template runs in
Jinja2's sandbox, and a name it does not know is an error rather than an empty string. The page
must open without a network, as the built-in one does: a template that loads anything from
elsewhere (a ``src`` other than ``data:``, a ``<link>``, ``url(…)``, ``@import``) or adds a
script is refused. Jinja2 is needed only when a template is used (``pip install jinja2``).
"""

import base64
import re
from pathlib import Path

from markupsafe import Markup

from .._files import child_path
from ..errors import DataError, ParameterError
from .sections import REPORT_FIELDS

__all__ = ["render_template", "BLOCKS"]

#: The report's blocks a template places, in the order of the built-in page.
BLOCKS = ("header", "nav", "summary", "estimate", "diagnostics", "figures", "inputs",
          "provenance")
_IMAGES = {".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg",
           ".gif": "image/gif", ".svg": "image/svg+xml"}
#: What makes a page load something from elsewhere, or run code, with the reason it is refused.
_OUTSIDE = ((re.compile(r"<\s*script\b", re.I), "a script (the report runs no code)"),
            (re.compile(r"<\s*link\b", re.I), "a <link> (put the style in <style>)"),
            (re.compile(r"<\s*(?:iframe|object|embed)\b", re.I), "an embedded page or object"),
            (re.compile(r"\bsrc\s*=\s*(?![\"']?\s*data:)", re.I),
             "a src other than data: (embed a logo with embed(\"logo.png\"))"),
            (re.compile(r"url\(\s*(?![\"']?\s*(?:data:|#))", re.I), "a url(…) other than data:"),
            (re.compile(r"@import\b", re.I), "an @import"))


def render_template(path, blocks, *, title, generator, css, report=None):
    """The report's page laid out by the template at ``path``.

    Parameters
    ----------
    path : str or pathlib.Path
        The Jinja2 template (HTML).
    blocks : dict
        Block name (:data:`BLOCKS`) → its HTML (Markup).
    title, generator : str
    css : Markup
        The report's style.
    report : dict, optional
        The case's ``[report]`` table.

    Returns
    -------
    str

    Raises
    ------
    DataError
        If the template file is missing or Jinja2 is not installed.
    ParameterError
        If the template is not valid Jinja2, uses a name it is not given, embeds a file it may
        not, or makes the page load something from elsewhere; the message names the template.
    """
    path = Path(path)
    if not path.is_file():
        raise DataError(f"report template {path} does not exist")
    try:
        from jinja2 import StrictUndefined, TemplateError
        from jinja2.sandbox import ImmutableSandboxedEnvironment
    except ImportError:
        raise DataError(f"report template {path.name}: templates need Jinja2, which is not "
                        "installed (pip install jinja2)") from None
    environment = ImmutableSandboxedEnvironment(autoescape=True, undefined=StrictUndefined)
    given = report if isinstance(report, dict) else {}
    context = {**{name: Markup(blocks.get(name, "")) for name in BLOCKS},
               "body": Markup("\n").join(Markup(blocks.get(name, "")) for name in BLOCKS),
               "title": title, "generator": generator, "css": Markup(css),
               "report": {key: str(given.get(key) or "") for key, _ in REPORT_FIELDS},
               "embed": lambda name: _embedded(path, name)}
    try:
        text = environment.from_string(path.read_text(encoding="utf-8")).render(context)
    except TemplateError as error:
        line = f" (line {error.lineno})" if getattr(error, "lineno", None) else ""
        raise ParameterError(f"report template {path.name}{line}: {error}") from None
    # The template's own markup, not the report's blocks and values (escaped, figures as data:
    # URIs), is what may reach outside: checked with those left out.
    own = environment.from_string(path.read_text(encoding="utf-8")).render(
        {**context, **dict.fromkeys((*BLOCKS, "body", "css"), Markup("")),
         "report": {key: "" for key, _ in REPORT_FIELDS}})
    for pattern, why in _OUTSIDE:
        found = pattern.search(own)
        if found:
            raise ParameterError(
                f"report template {path.name}: holds {why}, at {own[found.start():][:60]!r}: "
                "a report must open as one file, without a network")
    return text


def _embedded(template, name):
    """A file beside the template as a data: URI (Markup)."""
    found = child_path(template.parent, name)
    kind = None if found is None else _IMAGES.get(found.suffix.lower())
    if found is None or kind is None or not found.is_file():
        raise ParameterError(f"report template {template.name}: embed({name!r}) must name a "
                             f"{'/'.join(s[1:] for s in _IMAGES)} file beside the template")
    data = base64.b64encode(found.read_bytes()).decode("ascii")
    return Markup(f"data:{kind};base64,{data}")
