"""Report templates: a consultancy's letterhead around the report's blocks, escaped and
self-contained (issue 27 §4, "consider report templates"; crowdvib.reporting.template)."""

import base64

import pytest

from crowdvib import DataError, ParameterError, load_case
from crowdvib.cases import check_case
from crowdvib.reporting.report import render_report
from tests.reporting.test_report_header import BEAM

pytest.importorskip("jinja2")   # jinja2 is needed only when a template is used

CASE = BEAM + """[report]
client = "City of <Ghent> & Co"
template = "letterhead.html"
"""
LETTERHEAD = """<!DOCTYPE html><html><head><title>{{ title }}</title><style>{{ css }}
.letter { border-bottom: 3px solid #c00; }</style></head><body><main>
<div class="letter"><img src="{{ embed('logo.png') }}" alt="logo"> Example Consult Ltd
for {{ report.client }}{% if report.project %}, {{ report.project }}{% endif %}</div>
{{ summary }}{{ figures }}{{ provenance }}</main></body></html>"""
#: The smallest PNG (one transparent pixel).
PNG = base64.b64decode("iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAQAAAC1HAwCAAAAC0lEQVR42mNkYAAAAAYAAjCB0C8A"
                       "AAAASUVORK5CYII=")


@pytest.fixture
def folder(tmp_path):
    (tmp_path / "case.toml").write_text(CASE, encoding="utf-8")
    (tmp_path / "letterhead.html").write_text(LETTERHEAD, encoding="utf-8")
    (tmp_path / "logo.png").write_bytes(PNG)
    return tmp_path


def _page(folder):
    return render_report(check_case(load_case(folder / "case.toml")).to_dict())


def test_case_template_lays_out_the_report_escaped_and_self_contained(folder):
    page = _page(folder)
    # The letterhead with the client escaped once, the logo embedded, the blocks as markup.
    assert "Example Consult Ltd\nfor City of &lt;Ghent&gt; &amp; Co</div>" in page
    assert f'src="data:image/png;base64,{base64.b64encode(PNG).decode()}"' in page
    assert '<section id="summary"><h2>Summary</h2>' in page
    assert '<section id="provenance">' in page and '<section id="inputs">' not in page
    assert ".letter { border-bottom" in page and "table.letterhead" in page   # both styles


def test_a_template_not_found_where_the_report_is_written_gives_the_built_in_page(folder):
    results = check_case(load_case(folder / "case.toml")).to_dict()
    (folder / "letterhead.html").unlink()
    page = render_report(results)
    assert "Example Consult" not in page and '<section id="inputs">' in page
    assert "the report template letterhead.html of the case is not found here" in page


@pytest.mark.parametrize("line, message", [
    ('<link rel="stylesheet" href="https://example.com/x.css">', "holds a <link>"),
    ('<img src="https://example.com/logo.png">', "holds a src other than data:"),
    ("<script>alert(1)</script>", "holds a script"),
    ("<style>body { background: url(https://example.com/a.png) }</style>",
     r"holds url\(…\) in a <style>: CSS may fetch nothing"),
    ("{{ summry }}", "'summry' is undefined"),
    ("{{ embed('../case.toml') }}", r"embed\('../case.toml'\) must name a png/jpg/jpeg/gif/svg "
                                    "file beside the template"),
    ("{% if %}", r" \(line 1\): Expected an expression"),
])
def test_templates_that_reach_outside_or_are_wrong_are_refused_by_name(folder, line, message):
    # docs: crowdvib.reporting.template: the page must open as one file, without a network.
    (folder / "letterhead.html").write_text(line + "{{ body }}", encoding="utf-8")
    with pytest.raises(ParameterError, match=f"report template letterhead.html.*{message}"):
        _page(folder)


def test_a_missing_template_file_is_refused_when_the_case_is_read(folder):
    (folder / "letterhead.html").unlink()
    with pytest.raises(DataError, match="report.template names a file that does not exist"):
        load_case(folder / "case.toml")


def test_templated_report_opens_in_the_browser_with_its_logo(folder, tmp_path):
    # The letterhead's logo decodes in a real browser (tests/reporting/test_report.py's probe),
    # and no cell is broken inside a word under the template's style either.
    from tests.reporting.test_report import _browser, _with_probe

    probe = tmp_path / "probe.html"
    probe.write_text(_with_probe(_page(folder)), encoding="utf-8")
    dom = _browser(probe.as_uri(), tmp_path, "--virtual-time-budget=10000", "--dump-dom",
                   "--window-size=800,2000")
    assert 'data-images="1"' in dom and 'data-broken-images="0"' in dom
    assert 'data-split-words=""' in dom
