"""A report template is data, never instructions (issue 35 §1): what it renders passes an
allow-list, its rendering has limits, and every report carries a strict Content-Security-Policy
first in <head> (crowdvib.reporting.template, crowdvib.reporting.safe_html)."""

import re
import time
from html.parser import HTMLParser

import pytest

from crowdvib import ParameterError, load_case
from crowdvib.cases import check_case
from crowdvib.reporting.report import render_report
from crowdvib.reporting.animation import SCRIPT_HASH
from crowdvib.reporting.safe_html import (CSP, CSP_META, checked_page, css_problem,
                                          policy_with_scripts)
# The case with a letterhead template and its logo (the fixture ``folder``), as there.
from tests.reporting.test_report_template import LETTERHEAD, folder  # noqa: F401

pytest.importorskip("jinja2")

HEAD = "<!DOCTYPE html><html><head><title>{{ title }}</title></head><body>"
TAIL = "{{ body }}</body></html>"


def _render(folder, template):
    (folder / "letterhead.html").write_text(template, encoding="utf-8")
    return render_report(check_case(load_case(folder / "case.toml")).to_dict())


# The ten templates of issue 35 §1 that passed the regular expressions, each reaching the network
# or running script when the report was opened; the message names the construct and the rule.
HOSTILE = [
    ('<img srcset="http://example.com/a.png 1x" alt="">', r"the attribute '<img srcset="),
    ('<svg><image href="http://example.com/a.png"/></svg>', r"an inline <svg>"),
    ('<video poster="http://example.com/a.png"></video>', r"a <video> \(nothing is fetched\)"),
    ('<meta http-equiv="refresh" content="0;url=http://example.com/">',
     r"the attribute '<meta http-equiv=\"refresh\">'.*http-equiv.* not allowed"),
    ('<img src="data:image/png;base64,AAAA" onerror="alert(1)">',
     r"an event handler '<img onerror=\"alert\(1\)\">': a report runs no code"),
    ('</body><body onload="alert(1)">', r"an event handler '<body onload="),
    ('<a href="javascript:alert(1)">home</a>', r"the link '<a href=\"javascript:alert\(1\)\">'"),
    ("{% if summary %}<script>alert(1)</script>{% endif %}", r"a script"),
    ('<div style="background: u\\72l(http://example.com/a.png)">x</div>',
     r"url\(…\) in the style attribute"),
    ("<style>main { background: image-set('http://example.com/a.png' 1x) }</style>",
     r"image-set\(…\) in a <style>"),
]


@pytest.mark.parametrize("markup, message", HOSTILE)
def test_the_ten_templates_that_passed_the_patterns_are_refused(folder, markup, message):
    with pytest.raises(ParameterError,
                       match=rf"report template letterhead.html: its page \(line \d+\) holds "
                             rf"{message}"):
        _render(folder, HEAD + markup + TAIL)


@pytest.mark.parametrize("tag, shown", [
    ("{% include 'other.html' %}", "{% include %}"),
    ("{% extends 'other.html' %}", "{% extends %}"),
    ("{% import 'other.html' as other %}", "{% import %}"),
    ("{% from 'other.html' import x %}", r"{% from … import %}"),
    ("{% autoescape false %}{{ report.client }}{% endautoescape %}", "{% autoescape %}"),
])
def test_a_template_brings_in_no_other_file_and_keeps_escaping(folder, tag, shown):
    # Once a foreign TypeError ("no loader for this environment specified").
    (folder / "other.html").write_text("<p>other</p>", encoding="utf-8")
    with pytest.raises(ParameterError, match=rf"report template letterhead.html \(line 1\): "
                                             rf"holds {shown}: a report template is one file"):
        _render(folder, HEAD + tag + TAIL)


@pytest.mark.parametrize("expression, message", [
    ("{{ 'x' * 10**9 }}", r"\* makes a value of 1 × 1000000000 characters"),
    ("{{ ['x'] * 10**9 }}", r"\* makes a value of 5 × 1000000000 characters"),
    # Short as lists, huge as text: a list of the report's body, a hundred thousand times.
    ("{{ [body] * 100000 }}", r"\* makes a value of \d+ × 100000 characters"),
    ("{% set ns = namespace(l=[body, body]) %}{% for i in range(30) %}"
     "{% set ns.l = ns.l + ns.l %}{% endfor %}", r"\+ makes a value of more than"),
    ("{{ ([body] * 3)|join }}{{ ((range(100)|list) * 1000)|join(body) }}",
     "join makes a string of more than"),
    ("{% for i in range(100000) %}{% for j in range(100000) %}{{ '' }}{% endfor %}{% endfor %}",
     "its loops take more than 100000 steps"),
    ("{% for i in range(10**9) %}{% endfor %}", "a call is given the number 1000000000"),
    ("{% for c in body %}{% for d in body %}{% endfor %}{% endfor %}",
     "its loops take more than 100000 steps"),
    ("{{ 10 ** 100000 }}", r"10 \*\* 100000 is a number of about 400000 bits"),
    ("{{ 'x'.ljust(10**9) }}", "a call is given the number 1000000000"),
    ("{{ '%0999999999d' % 1 }}", "% formats a string"),
    ("{% set ns = namespace(s='x' * 100000) %}{% for i in range(60) %}"
     "{% set ns.s = ns.s ~ ns.s %}{% endfor %}", "~ makes a string of more than"),
    ("{% for i in range(99999) %}{{ body }}{% endfor %}", "its page grows past"),
    ("{{ range(100000)|join('x' * 100000) }}", "join makes a string of more than"),
])
def test_huge_strings_numbers_and_loops_are_refused_at_once(folder, expression, message):
    started = time.perf_counter()
    with pytest.raises(ParameterError, match=f"report template letterhead.html: {message}.*"
                                             "may not compute that much"):
        _render(folder, HEAD + expression + TAIL)
    assert time.perf_counter() - started < 10.0          # refused, not computed


@pytest.mark.parametrize("expression, message", [
    ("{{ 'x'|center(80) }}", "No filter named 'center'"),
    ("{{ 'x'.format() }}", "access to attribute 'format' of 'str' object is unsafe"),
    ("{{ 1 / 0 }}", "ZeroDivisionError: division by zero"),
])
def test_what_a_template_may_not_call_is_a_crowdvib_error(folder, expression, message):
    with pytest.raises(ParameterError, match=f"report template letterhead.html.*{message}"):
        _render(folder, HEAD + expression + TAIL)


def _head(page):
    """The tags of a page's <head> in order, each as (tag, attributes)."""
    class Head(HTMLParser):
        def __init__(self):
            super().__init__()
            self.inside, self.tags = False, []

        def handle_starttag(self, tag, attrs):
            if tag == "head":
                self.inside = True
            elif tag == "body":
                self.inside = False
            elif self.inside:
                self.tags.append((tag, dict(attrs)))

        def handle_endtag(self, tag):
            if tag == "head":
                self.inside = False

    parser = Head()
    parser.feed(page)
    return parser.tags


def _policy_first(page):
    """Whether the policy is the first element of the page's <head>: of the one the page
    writes, or (without one) of the one a browser makes for the first element that is not
    <html>. The policy is :data:`CSP`, or where the page has moving pictures (issue 38) the same
    policy allowing crowdvib's own script alone, by its hash."""
    class First(HTMLParser):
        first = None

        def handle_starttag(self, tag, attrs):
            if self.first is None and tag not in ("html", "head"):
                self.first = (tag, dict(attrs))

    parser = First()
    parser.feed(page)
    return parser.first in (("meta", {"http-equiv": "Content-Security-Policy", "content": policy})
                            for policy in (CSP, policy_with_scripts([SCRIPT_HASH])))


def test_the_policy_is_strict():
    # Nothing fetched, images only inline, no script, no form target, no <base>.
    rules = dict(rule.strip().split(" ", 1) for rule in CSP.split(";"))
    assert rules == {"default-src": "'none'", "img-src": "data:", "style-src": "'unsafe-inline'",
                     "script-src": "'none'", "form-action": "'none'", "base-uri": "'none'"}
    # A report with moving pictures (issue 38): the same, but one script may run, crowdvib's
    # own, named by its hash (no 'unsafe-inline', no source to fetch from, no 'strict-dynamic').
    own = dict(rule.strip().split(" ", 1)
               for rule in policy_with_scripts([SCRIPT_HASH]).split(";"))
    assert own == {**rules, "script-src": f"'{SCRIPT_HASH}'"}
    assert re.fullmatch(r"sha256-[A-Za-z0-9+/]{43}=", SCRIPT_HASH)


@pytest.mark.parametrize("command", ["demo", "estimate", "simulate", "map", "sensitivity",
                                     "check", "modes", "season", "comfort", None])
def test_every_report_kind_has_the_policy_first_in_its_head(command):
    # The built-in page of each command's results (its sections vary, its head does not).
    page = render_report({} if command is None else {"command": command})
    assert _policy_first(page), _head(page)[:2]
    assert page.count("Content-Security-Policy") == 1


@pytest.mark.parametrize("template", [
    LETTERHEAD,
    "<html><title>t</title><body>{{ body }}</body></html>",           # no <head>
    "{{ body }}",                                                       # no <html> either
    "<!-- a comment first -->\n<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8>"
    "<style>{{ css }}</style></head><body>{{ body }}</body></html>",
])
def test_a_templated_report_has_the_policy_first_in_its_head(folder, template):
    # Where the template has a <head>, first in it; without one, before anything a browser
    # puts in the <head> it makes.
    page = _render(folder, template)
    assert _policy_first(page), page[:300]
    assert page.count("Content-Security-Policy") == 1
    assert page.index(CSP_META) < page.index("<section")


def test_the_allowed_page_is_written_anew_from_its_tokens():
    # Attribute values re-quoted and re-escaped, comments dropped, a <style/> (which a browser
    # opens, reading what follows as CSS) closed at once: what the browser reads is what was
    # checked.
    page = checked_page('<html><head><style/></head><body><div title=a&quot;b class=x><!-- c -->'
                        "<p>1 &lt; 2 &amp; <b>bold</b></p></div><br/></body></html>", "t.html")
    assert page == (f'<html><head>{CSP_META}<style></style></head><body><div title="a&#34;b" '
                    'class="x"><p>1 &lt; 2 &amp; <b>bold</b></p></div><br></body></html>')


@pytest.mark.parametrize("css, word", [
    ("a { background: url(x) }", "url("),
    ("a { background: U\\52 L(x) }", "url("),
    ("a { background: \\75 \\72 \\6c (x) }", "url("),
    ("a { background: u/**/rl(x) }", "url("),
    ("@\\69mport 'x.css';", "@import"),
    ("a { width: expression(alert(1)) }", "expression("),
    ("a { background: -webkit-image-set('x.png' 1x) }", "image-set("),
    ("a { color: red; font: 12px serif }", None),
])
def test_css_is_judged_after_its_escapes_and_comments_are_undone(css, word):
    assert css_problem(css) == word


@pytest.mark.parametrize("markup, message", [
    ("<style>a{}</style x><img src=x onerror=alert(1)></style>", r"a <style> holds CSS only"),
    ('<a href="https://example.com/">site</a>', "a link must be #place in the report or mailto"),
    ("<base href='https://example.com/'>", "a <base>"),
    ('<link rel="icon" href="data:,">', "a <link>"),
    ("<?xml version='1.0'?>", "no processing instructions"),
    ('<form action="https://example.com/"><button>go</button></form>', "a form"),
    ('<object data="https://example.com/x.swf"></object>', "an embedded page or object"),
    ('<img src=" javascript:alert(1)">', "a src other than data:"),
])
def test_other_ways_out_are_refused(markup, message):
    with pytest.raises(ParameterError, match=f"report template t.html: .*{message}"):
        checked_page(markup, "t.html")


def test_a_refusal_quotes_a_short_escaped_excerpt(folder):
    # A control character of the template reaches the message escaped, and no more than an
    # excerpt of the offending tag.
    long = "x" * 500
    with pytest.raises(ParameterError) as caught:
        _render(folder, HEAD + f'<img alt="" onerror="\x1b]0;owned\x07{long}">' + TAIL)
    message = str(caught.value)
    assert "\x1b" not in message and "\\x1b" in message and long not in message


# ------------------------------------------------------------------------------ in a browser
class _Watch:
    """A local HTTP server that records every request made to it."""

    def __init__(self):
        import http.server
        import threading

        requests = self.requests = []

        class Handler(http.server.BaseHTTPRequestHandler):
            def do_GET(self):               # noqa: N802 (http.server's name)
                requests.append(self.path)
                self.send_response(404)
                self.end_headers()

            do_POST = do_GET

            def log_message(self, *args):
                pass

        self.server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.base = f"http://127.0.0.1:{self.server.server_address[1]}"
        threading.Thread(target=self.server.serve_forever, daemon=True).start()

    def close(self):
        self.server.shutdown()
        self.server.server_close()


#: Hosts chromium itself calls in the background (updates, time, accounts), not the page.
_BROWSER_OWN = (".google.com", ".googleapis.com", ".gstatic.com")


def _open_watched(page, tmp_path, name):
    """The DOM after load, and the URL of every request the browser began for ``page`` opened
    from a file (its net log's URL requests; chromium's own background calls left out)."""
    import json

    from tests.reporting.test_report import _browser

    path = tmp_path / f"{name}.html"
    path.write_text(page, encoding="utf-8")
    log = tmp_path / f"{name}.netlog.json"
    dom = _browser(path.as_uri(), tmp_path, "--virtual-time-budget=5000", "--dump-dom",
                   f"--log-net-log={log}")
    data = json.loads(log.read_text(encoding="utf-8"))
    request = data["constants"]["logSourceType"]["URL_REQUEST"]
    urls = {e["params"]["url"] for e in data["events"]
            if e["source"]["type"] == request and "url" in e.get("params", {})}
    # (A blocked <iframe> still gets a speculative preconnect, no request: the allow-list
    # refuses <iframe>.)
    return dom, sorted(u for u in urls if not u.split("/")[2].split(":")[0].endswith(_BROWSER_OWN))


def test_a_report_opened_in_a_browser_requests_nothing_and_runs_nothing(folder, tmp_path):
    # The report crowdvib writes (a templated one: a letterhead and its logo) asks the network
    # for nothing. Then the policy alone, first in its <head>, is tried: a copy with every way
    # out of issue 35 §1 put in after it, as if the allow-list had missed them all, pointing at
    # a server of the test's own. Nothing reaches the server and no script runs. (A meta
    # refresh and a javascript: link are navigation, which a policy cannot stop: the
    # allow-list refuses them above.)
    page = _render(folder, LETTERHEAD)
    dom, requested = _open_watched(page, tmp_path, "report")
    assert requested == [] and "Example Consult Ltd" in dom

    watch = _Watch()
    try:
        base = watch.base
        ran = "document.body.setAttribute('data-ran', '{}')"
        hostile = f"""
<img srcset="{base}/srcset.png 1x" alt="">
<svg><image href="{base}/svg.png" width="10" height="10"/></svg>
<video poster="{base}/poster.png"></video>
<img src="{base}/src.png" onerror="{ran.format('onerror')}">
<div style="height:10px; background: u\\72l({base}/css-escape.png)">x</div>
<div style="height:10px; background-image: image-set('{base}/image-set.png' 1x)">x</div>
<style>@import url({base}/import.css); main {{ background: url({base}/url.png) }}
@font-face {{ font-family: f; src: url({base}/font.woff) }} p {{ font-family: f }}</style>
<link rel="stylesheet" href="{base}/link.css">
<script src="{base}/script.js"></script>
<script>{ran.format('script')}; fetch("{base}/fetch");</script>
<iframe src="{base}/frame.html"></iframe>
<object data="{base}/object"></object>
"""
        page = page.replace("<body>", f"<body onload=\"{ran.format('onload')}\">")
        page = page.replace("</body>", hostile + "</body>")
        assert page.index(CSP_META) < page.index("<img srcset")
        dom, requested = _open_watched(page, tmp_path, "hostile")
    finally:
        watch.close()
    assert watch.requests == []
    assert [url for url in requested if url.startswith(base)] == []
    assert re.search(r"<body[^>]*\sdata-ran=", dom) is None
    assert "<svg>" in dom               # the page was read to its end: the test saw it all


@pytest.mark.parametrize("expression", [
    # A macro calling itself twice: 2**40 calls, no loop to count.
    "{% macro m(d) %}{% if d < 40 %}{{ m(d + 1) }}{{ m(d + 1) }}{% endif %}{% endmacro %}"
    "{{ m(0) }}",
    # The whole report's text, stripped, in each of many loop steps.
    "{% for i in range(99999) %}{% set x = body|striptags|upper|striptags %}{% endfor %}",
])
def test_work_no_count_bounds_is_stopped_by_the_clock(folder, expression, monkeypatch):
    import crowdvib.reporting.template as template

    monkeypatch.setattr(template, "MAX_SECONDS", 1.0)
    started = time.perf_counter()
    with pytest.raises(ParameterError, match="report template letterhead.html: it renders for "
                                             "more than 1 s"):
        _render(folder, HEAD + expression + TAIL)
    assert time.perf_counter() - started < 5.0


def test_lipsum_is_not_given(folder):
    with pytest.raises(ParameterError, match="'lipsum' is undefined"):
        _render(folder, HEAD + "{{ lipsum(100000) }}" + TAIL)
