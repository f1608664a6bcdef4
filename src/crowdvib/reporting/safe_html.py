"""What a report may hold: a Content-Security-Policy every report carries, and an allow-list
that a report template's page passes through (issue 35 §1).

A template comes from someone else: it is data, never instructions. Its rendered page is parsed
with :mod:`html.parser` and written out again from the parsed tokens alone, each one checked
against an allow-list, so the browser reads exactly what was checked (no parser differential
can smuggle a tag past a pattern):

* tags of :data:`_TAGS` only (no script, link, base, iframe, object, embed, svg, video, form …);
* attributes of :data:`_GLOBAL` or of the tag's own list only: no event handler (``on…``), no
  ``srcset``, ``poster``, ``action``, ``formaction``, ``xlink:href``, ``data`` …; an ``href`` is
  ``#fragment`` or ``mailto:``, an image's ``src`` a ``data:image/…;base64`` URI (``embed()``);
* ``<meta>`` with ``charset`` or ``name``/``content`` only (no ``http-equiv``: refresh or a
  policy of its own);
* CSS (``<style>`` and ``style=``) without ``url(``, ``image-set(`` and the other ways to fetch
  or run something, looked for after CSS escapes (``u\\72l(``) and comments are undone;
* text escaped again, comments dropped, only ``<!DOCTYPE html>`` as a declaration.

Whatever the allow-list missed, :data:`CSP` forbids: it is put first in ``<head>`` of every
report, the built-in page's (:func:`crowdvib.reporting.html.page`) and a template's.
"""

import html
import re
from html.parser import HTMLParser

from markupsafe import escape

from ..errors import ParameterError
from ..errors import terminal_safe

__all__ = ["CSP", "CSP_META", "csp_meta", "policy_with_scripts", "checked_page"]

#: The report's Content-Security-Policy. Nothing is fetched (``default-src 'none'``): images only
#: as ``data:`` URIs (the figures, a logo), styles only inline (the report's own ``<style>``, a
#: template's, and ``style=``), no script (a report with moving pictures allows crowdvib's own
#: script alone, by its hash: :func:`policy_with_scripts`), no form to send, no
#: ``<base>`` to move relative links. A ``<meta>`` policy cannot hold ``frame-ancestors`` or
#: ``sandbox``; navigation (``<meta http-equiv="refresh">``) it cannot stop: the allow-list does.
CSP = ("default-src 'none'; img-src data:; style-src 'unsafe-inline'; script-src 'none'; "
       "form-action 'none'; base-uri 'none'")


def csp_meta(policy):
    """A policy as the first element of ``<head>``."""
    return f'<meta http-equiv="Content-Security-Policy" content="{policy}">'


#: The policy as the first element of ``<head>``.
CSP_META = csp_meta(CSP)


def policy_with_scripts(digests):
    """:data:`CSP` allowing the inline scripts of these ``sha256-…`` digests and no other:
    crowdvib's own script (:mod:`crowdvib.reporting.animation`), put in after the page passed
    the allow-list; every other directive as it is."""
    sources = " ".join(f"'{digest}'" for digest in digests)
    return CSP.replace("script-src 'none'", f"script-src {sources}")

_VOID = {"br", "hr", "img", "meta", "col", "wbr"}
_TAGS = {"html", "head", "body", "title", "meta", "style", "main", "header", "footer",
         "section", "article", "aside", "nav", "div", "span", "p", "br", "hr", "wbr",
         "h1", "h2", "h3", "h4", "h5", "h6", "address", "blockquote", "pre", "figure",
         "figcaption", "details", "summary", "a", "abbr", "b", "strong", "i", "em", "u", "s",
         "small", "sub", "sup", "code", "kbd", "samp", "var", "mark", "q", "cite", "time", "dfn",
         "ul", "ol", "li", "dl", "dt", "dd", "table", "caption", "colgroup", "col", "thead",
         "tbody", "tfoot", "tr", "th", "td", "img"}
_GLOBAL = {"id", "class", "title", "lang", "style", "role", "hidden", "aria-label",
           "aria-hidden", "aria-describedby"}
_OWN = {"a": {"href"}, "img": {"src", "alt", "width", "height"},
        "td": {"colspan", "rowspan", "headers"}, "th": {"colspan", "rowspan", "scope", "headers"},
        "col": {"span"}, "colgroup": {"span"}, "ol": {"start", "reversed", "type"},
        "li": {"value"}, "details": {"open"}, "time": {"datetime"},
        "meta": {"charset", "name", "content"}}
#: Why a tag is not on the list, where the answer helps (else "not allowed in a report").
_WHY_TAG = {"script": "a script (a report runs no code)",
            "link": "a <link> (put the style in <style>)",
            "base": "a <base> (it would move every link)",
            "iframe": "an embedded page or object", "object": "an embedded page or object",
            "embed": "an embedded page or object", "frame": "an embedded page or object",
            "svg": "an inline <svg> (embed a logo with embed(\"logo.svg\") in an <img>)",
            "video": "a <video> (nothing is fetched)", "audio": "an <audio> (nothing is fetched)",
            "form": "a form (a report sends nothing)"}
#: An image's source: crowdvib's figures and embed()'s logos, nothing else.
_IMAGE_URI = re.compile(r"data:image/(?:png|jpeg|gif|webp|svg\+xml);base64,[A-Za-z0-9+/=\s]*")
#: A link's target: a place in the report, or an address to write to; nothing to fetch or run.
_LINK = re.compile(r"#[^\s]*|mailto:[^\s:/]+@[^\s/]+", re.I)
#: CSS that fetches (url, image-set, image, cross-fade, src, @import, a binding) or runs code.
_CSS_FORBIDDEN = ("url(", "image-set(", "image(", "cross-fade(", "element(", "src(", "@import",
                  "expression(", "-moz-binding")
_CSS_ESCAPE = re.compile(r"\\(?:([0-9a-fA-F]{1,6})[ \t\r\n\f]?|\r\n|([\s\S]))")
_CSS_COMMENT = re.compile(r"/\*[\s\S]*?(?:\*/|$)")
_EXCERPT = 60


def checked_page(text, name):
    """``text`` (a template's rendered page) written out again from its parsed tokens, each
    allowed, with :data:`CSP_META` first in ``<head>``.

    Raises
    ------
    ParameterError
        Naming the template ``name``, the construct and the rule, at the first token that is
        not allowed.
    """
    parser = _Checker(name)
    parser.feed(text)
    parser.close()
    return "".join(parser.out)


def css_problem(css):
    """The forbidden construct in ``css`` (escapes and comments undone, any case), or None."""
    decoded = _CSS_ESCAPE.sub(_unescape, css)
    for variant in (css, decoded, _CSS_COMMENT.sub("", decoded)):
        folded = re.sub(r"\s+", "", variant.lower().replace("\x00", ""))
        for word in _CSS_FORBIDDEN:
            if word in folded:
                return word
    return None


def _unescape(found):
    digits, other = found.groups()
    if digits is not None:
        code = int(digits, 16)
        return chr(code) if 0 < code <= 0x10FFFF and not 0xD800 <= code <= 0xDFFF else "\ufffd"
    return other or ""          # an escaped newline continues the line


class _Checker(HTMLParser):
    """The page token by token: each allowed one written out in a canonical form."""

    def __init__(self, name):
        super().__init__(convert_charrefs=True)
        self.name, self.out, self.policy, self.style = name, [], False, None

    def refuse(self, what, rule):
        line = self.getpos()[0]
        raise ParameterError(f"report template {self.name}: its page (line {line}) holds "
                             f"{terminal_safe(what)}: {rule}; a report must open as one file, "
                             "without a network and without script")

    def _policy(self):
        # First in <head>: before anything but the doctype, <html> and <head> themselves.
        if not self.policy:
            self.out.append(CSP_META)
            self.policy = True

    # ------------------------------------------------------------------ tokens
    def handle_decl(self, decl):
        if decl.strip().lower() != "doctype html":
            self.refuse(_shown(f"<!{decl}>"), "the only declaration allowed is <!DOCTYPE html>")
        self.out.append("<!DOCTYPE html>")

    def unknown_decl(self, data):
        self.refuse(_shown(f"<![{data}]>"), "no CDATA or conditional sections")

    def handle_pi(self, data):
        self.refuse(_shown(f"<?{data}>"), "no processing instructions")

    def handle_comment(self, data):
        pass            # dropped: a comment shows nothing, and is no place for a browser's quirks

    def handle_starttag(self, tag, attrs):
        self._start(tag, attrs)
        if tag == "style":
            self.style = []

    def handle_startendtag(self, tag, attrs):
        # "<style/>" opens a style element in a browser (the slash counts only on void
        # elements) while this parser reads on as markup: written as the parser read it, an
        # empty element, so that both read the same.
        self._start(tag, attrs)
        if tag not in _VOID:
            self.out.append(f"</{tag}>")

    def _start(self, tag, attrs):
        if tag not in _TAGS:
            self.refuse(_WHY_TAG.get(tag, f"a <{tag}>"), "only the tags of a document's text, "
                        "tables and images are allowed")
        if tag not in ("html", "head"):
            self._policy()
        allowed = _GLOBAL | _OWN.get(tag, set())
        parts = [tag]
        for key, value in attrs:
            self._attribute(tag, key, value, allowed)
            parts.append(key if value is None else f'{key}="{escape(value)}"')
        self.out.append(f"<{' '.join(parts)}>")
        if tag == "head":
            self._policy()

    def _attribute(self, tag, key, value, allowed):
        shown = _shown(f'<{tag} {key}="{value}">' if value is not None else f"<{tag} {key}>")
        if key.startswith("on"):
            self.refuse(f"an event handler {shown}", "a report runs no code")
        if key not in allowed:
            self.refuse(f"the attribute {shown}",
                        "URL attributes other than href and an image's src, and http-equiv, are "
                        "not allowed" if key in ("srcset", "poster", "action", "formaction",
                                                 "xlink:href", "data", "http-equiv", "background",
                                                 "cite", "ping")
                        else f"attributes of <{tag}> are limited to {sorted(allowed)}")
        value = value or ""
        if key == "href" and not _LINK.fullmatch(value):
            self.refuse(f"the link {shown}", "a link must be #place in the report or "
                        "mailto:address (nothing is fetched or run)")
        if key == "src" and not _IMAGE_URI.fullmatch(value):
            self.refuse(f"a src other than data: {shown}", "an image must be a data:image URI "
                        "(embed a logo with embed(\"logo.png\"))")
        if key == "style":
            self._css(value, f"the style attribute {shown}")

    def _css(self, css, where):
        word = css_problem(css)
        if word is not None:
            self.refuse(f"{word}…) in {where}" if word.endswith("(") else f"{word} in {where}",
                        "CSS may fetch nothing (no url(…), image-set(…), @import, even as CSS "
                        "escapes) and run nothing")

    def handle_endtag(self, tag):
        if tag not in _TAGS:
            self.refuse(_WHY_TAG.get(tag, f"a </{tag}>"), "only the tags of a document's text, "
                        "tables and images are allowed")
        if tag == "style" and self.style is not None:
            self._style_end()
        if tag not in _VOID:
            self.out.append(f"</{tag}>")

    def _style_end(self):
        css, self.style = "".join(self.style), None
        if "<" in css:
            # Where a browser ends a style element ("</style x>") is not where every parser
            # does: no markup at all inside, so both agree.
            self.refuse(_shown(f"<style>{css}"), "a <style> holds CSS only, no '<'")
        self._css(css, "a <style>")
        self.out.append(css)

    def handle_data(self, data):
        if self.style is not None:
            self.style.append(data)
            return
        if data.strip():
            self._policy()
        self.out.append(str(escape(data)))

    def close(self):
        super().close()
        if self.style is not None:      # an unclosed <style>: checked as one that is closed
            self._style_end()
        self._policy()


def _shown(text):
    """A short excerpt of the template's markup for a message."""
    text = html.unescape(text) if "&" in text else text
    return repr(text[:_EXCERPT] + ("…" if len(text) > _EXCERPT else ""))
