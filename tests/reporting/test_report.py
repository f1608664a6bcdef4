"""report.html of every command's results directory, opened in a real headless browser (issue 6).

The browser is Debian's ``chromium`` (``.ci/run`` installs it). Without it these tests fail under
CI (the env var ``CI`` set) and are skipped on a developer's machine.

Each command's report must be one a consultant can send (issue 27 §4, "Must show"): run as a
user runs it (a subprocess, its output captured), on a case with a [report] table, a damper and
a doubtful input, the rendered report names no folder of the machine, holds every warning the
command printed, shows the case's [report] table, breaks no table cell inside a word, and a
design report shows the damper crowdvib designed.
"""

import base64
import html
import io
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from crowdvib import DataError
from crowdvib.cli import main
from crowdvib.cli.common import IN_DOUBT
from crowdvib.reporting.paths import without_machine_paths
from crowdvib.reporting.report import (REPORT_NAME, SECTIONS, provenance, render_report,
                             write_report)
from tests.conftest import copy_paper_case

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
PAPER_CASE = EXAMPLES / "paper_example.toml"

# Sets data attributes on <body> once every image has loaded (or failed to): how many images the
# page holds and how many did not decode; and the words of table cells the browser broke across
# lines (a letter or digit run whose line boxes lie on more than one line; code, such as a
# hash, may break anywhere). Injected into a copy (_with_probe); the report itself has no script.
_PROBE = """<script>
window.addEventListener("load", function () {
  var images = document.images, broken = 0;
  for (var i = 0; i < images.length; i++) {
    if (!images[i].complete || images[i].naturalWidth === 0) { broken++; }
  }
  document.body.setAttribute("data-images", String(images.length));
  document.body.setAttribute("data-broken-images", String(broken));
  var split = [], cells = document.querySelectorAll("th, td");
  for (var c = 0; c < cells.length; c++) {
    var walker = document.createTreeWalker(cells[c], NodeFilter.SHOW_TEXT), node;
    while ((node = walker.nextNode())) {
      if (node.parentElement.closest("code")) { continue; }
      var words = /[\\p{L}\\p{N}]+/gu, word;
      while ((word = words.exec(node.data))) {
        var range = document.createRange(), lines = {};
        range.setStart(node, word.index);
        range.setEnd(node, word.index + word[0].length);
        var boxes = range.getClientRects();
        for (var k = 0; k < boxes.length; k++) {
          if (boxes[k].width > 0) { lines[Math.round(boxes[k].top)] = true; }
        }
        if (Object.keys(lines).length > 1) { split.push(word[0]); }
      }
    }
  }
  document.body.setAttribute("data-split-words", split.join(" "));
});
</script>"""


# ------------------------------------------------------------------------------ browser
def _chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    message = ("chromium is not installed, so report.html cannot be checked in a real browser; "
               "install it with `apt-get install -y chromium` (.ci/run does this)")
    if os.environ.get("CI"):
        pytest.fail(message)
    pytest.skip(message)


def _browser(url, tmp_path, *options):
    command = [_chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
               "--disable-background-networking", "--disable-component-update",
               "--disable-sync", "--hide-scrollbars", "--mute-audio",
               f"--user-data-dir={tmp_path / 'chromium-profile'}", *options, url]
    done = subprocess.run(command, capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, f"chromium failed ({done.returncode}): {done.stderr[-2000:]}"
    return done.stdout


def with_script(text, script, where="</body>"):
    """The report's page with ``script`` (``<script>…</script>``) before ``where``, its
    Content-Security-Policy allowing that script too by its hash (as the policy allows
    crowdvib's own: none in a report without moving pictures, its one script in one with
    them; issue 38)."""
    import hashlib

    from crowdvib.reporting.animation import SCRIPT_HASH
    from crowdvib.reporting.safe_html import CSP, policy_with_scripts

    code = script[len("<script>"):-len("</script>")]
    digest = base64.b64encode(hashlib.sha256(code.encode("utf-8")).digest()).decode("ascii")
    policies = [p for p in (CSP, policy_with_scripts([SCRIPT_HASH])) if p in text]
    assert len(policies) == 1 and text.count(policies[0]) == 1
    own = [SCRIPT_HASH] if policies[0] != CSP else []
    return (text.replace(policies[0], policy_with_scripts([*own, f"sha256-{digest}"]))
            .replace(where, script + where, 1))


def _with_probe(text):
    """The report's page with the probe before </body>, allowed by its hash."""
    return with_script(text, _PROBE)


def _open_in_browser(report, tmp_path):
    """Rendered DOM (with the image probe), a screenshot and a printed PDF of ``report``."""
    probe = tmp_path / "probe.html"
    probe.write_text(_with_probe(report.read_text(encoding="utf-8")), encoding="utf-8")
    # The virtual-time budget lets the load event (after every image) fire before the dump; a
    # window 800 px wide squeezes the tables as a narrow screen or a printed page does.
    dom = _browser(probe.as_uri(), tmp_path, "--virtual-time-budget=10000", "--dump-dom",
                   "--window-size=800,2000")
    screenshot = tmp_path / "screenshot.png"
    _browser(report.as_uri(), tmp_path, f"--screenshot={screenshot}", "--window-size=1280,2000")
    pdf = tmp_path / "print.pdf"
    _browser(report.as_uri(), tmp_path, f"--print-to-pdf={pdf}", "--no-pdf-header-footer")
    return dom, screenshot, pdf


def _check_in_browser(report, tmp_path):
    from PIL import Image

    from tests.reporting.test_template_security import _policy_first

    # Issue 35 §1: each command's report carries the Content-Security-Policy first in <head>.
    assert _policy_first(report.read_text(encoding="utf-8"))
    dom, screenshot, pdf = _open_in_browser(report, tmp_path)
    images = int(re.search(r'data-images="(\d+)"', dom).group(1))
    broken = int(re.search(r'data-broken-images="(\d+)"', dom).group(1))
    assert images >= 1 and broken == 0, f"{broken} of {images} images did not decode"
    # Issue 27 §4: "estima|te" split over two lines in a table header.
    assert re.search(r'data-split-words="([^"]*)"', dom).group(1) == "", "words broken in cells"
    for section in SECTIONS:
        assert re.search(rf'<section id="{section}">\s*<h2>', dom), f"section {section} missing"
    pixels = np.asarray(Image.open(screenshot).convert("L"), dtype=float)
    assert pixels.shape == (2000, 1280)
    # Not blank: text, tables and plots darken a real share of the page and vary strongly.
    assert (pixels < 200).mean() > 0.02
    assert pixels.std() > 20.0
    assert _input_rows_without_units(dom) == []
    data = pdf.read_bytes()
    assert data.startswith(b"%PDF")
    assert len(re.findall(rb"/Type\s*/Page\b", data)) >= 2
    return dom


#: Input rows whose value is a name or a choice, not a quantity: no unit to show.
_NAMES = {"name", "path", "description", "seed", "source", "files", "output names",
          "channel names", "outputs", "formats", "format", "dtype", "record units",
          "convergence norm", "design codes", "hivoss", "setra", "en1990", "ukna",
          "comfort class", "height of the deck k3", "mode", "gamma figure",
          "defaults not verified against the guide"}


def _input_rows_without_units(dom):
    """(label, value) of every row of the Inputs section whose value holds a number but whose
    label has no [unit] (issue 10: every input with its unit). Nested tables are checked row by
    row; a row holding a table is only its container."""
    part = dom[dom.index('<section id="inputs">'):]
    part = part[:part.index("</section>")]
    missing = []
    for head, cell in re.findall(r"<tr><th>([^<]*)</th><td>((?:(?!<table).)*?)</td></tr>", part,
                                 re.S):
        name, text = html.unescape(head), html.unescape(re.sub(r"<[^>]+>", "", cell))
        if re.search(r"\d", text) and "[" not in name and name not in _NAMES:
            missing.append((name, text))
    return missing


def _decode_embedded_images(text):
    """Decode every data-URI image of the report in Python: PNGs with PIL, SVGs as XML."""
    from xml.etree import ElementTree

    from PIL import Image

    found = re.findall(r'src="data:(image/[a-z+]+);base64,([A-Za-z0-9+/=]+)"', text)
    sizes = []
    for mime, payload in found:
        data = base64.b64decode(payload, validate=True)
        if mime == "image/png":
            image = Image.open(io.BytesIO(data))
            image.load()
            sizes.append(image.size)
        else:
            assert mime == "image/svg+xml"
            assert ElementTree.fromstring(data).tag.endswith("svg")
            sizes.append((1, 1))
    return sizes


# ------------------------------------------------------------------------------ results dirs
@pytest.fixture(scope="module")
def demo_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo") / "out"
    assert main(["demo", "--spectral", "--out", str(out)]) == 0
    return out


def test_demo_writes_its_report_and_prints_the_path(tmp_path, capsys):
    out = tmp_path / "demo"
    assert main(["demo", "--spectral", "--seed", "5", "--out", str(out)]) == 0
    assert f"report: {out / REPORT_NAME}" in capsys.readouterr().out
    text = (out / REPORT_NAME).read_text(encoding="utf-8")
    assert "psd_fit.png" in text
    assert [p.name for p in out.iterdir() if p.name.startswith(".")] == []   # atomic: no leftovers


def test_demo_report_in_the_browser(demo_dir, tmp_path):
    dom = _check_in_browser(demo_dir / REPORT_NAME, tmp_path)
    results = json.loads((demo_dir / "results.json").read_text())
    found = results["estimate"]
    # The estimate table shows the demo's estimate against its truth, with the relative error.
    error = 100 * (found["frequency"] - 3.0) / 3.0
    assert f"{found['frequency']:.4g}" in dom and f"{error:+.1f} %" in dom
    assert "crowdvib demo report" in dom.lower() or "crowdvib demo report" in html.unescape(dom)
    assert str(results["seed"]) in dom
    assert "no case file (embedded example" in dom
    assert _decode_embedded_images(dom) and all(w > 500 for w, _ in _decode_embedded_images(dom))


#: The case's [report] table (issue 27 §4), with characters the report must escape.
REPORT_TABLE = {"client": "City of <Ghent> & Co", "project": "Footbridge comfort",
                "bridge": "Paper footbridge", "location": "Ghent, Belgium",
                "engineer": "A. N. Engineer", "measurement_date": "2024-05-01"}


@pytest.fixture(scope="module")
def report_case(tmp_path_factory):
    """The paper example (its least squares: the estimator is not the point) with a [report]
    table, design checks with a damper tuned to its mode, and a walking speed of 3.2 m/s: legal
    but doubtful (km/h?), so every command prints a PlausibilityWarning its report must hold."""
    case = copy_paper_case(tmp_path_factory.mktemp("case"))
    text = case.read_text(encoding="utf-8")
    assert "walking_speed = 1.30" in text
    text = text.replace("walking_speed = 1.30", "walking_speed = 3.2", 1)
    text += ('\n[design]\ncodes = ["hivoss", "en1990"]\nprediction = false\n'
             '[design.classes]\nhivoss = "TC3"\nen1990 = "TC3"\n'
             "[design.damper]\nmode = 1\nmass_ratio = 0.02\n"
             "[report]\n" + "".join(f"{key} = {json.dumps(value)}\n"
                                    for key, value in REPORT_TABLE.items()))
    case.write_text(text, encoding="utf-8")
    return case


class Run:
    """A command run as a user runs it: its results folder and what it printed."""

    def __init__(self, case, command, *options):
        self.case, self.out = case, case.parent / command
        done = subprocess.run([sys.executable, "-m", "crowdvib", command, *options,
                               "--out", str(self.out)], capture_output=True, text=True,
                              timeout=600, check=False, cwd=case.parent)
        self.status, self.printed = done.returncode, done.stdout + done.stderr
        assert self.status in (0, IN_DOUBT), self.printed[-3000:]
        self.results = json.loads((self.out / "results.json").read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def estimate_run(report_case):
    return Run(report_case, "estimate", str(report_case))


@pytest.fixture(scope="module")
def check_run(report_case):
    return Run(report_case, "check", str(report_case))


@pytest.fixture(scope="module")
def map_run(report_case):
    return Run(report_case, "map", str(report_case), "--frequencies", "2:4:5",
               "--damping-ratios", "0.2:0.4:3")


@pytest.fixture(scope="module")
def sensitivity_run(report_case):
    return Run(report_case, "sensitivity", str(report_case), "--no-joint",
               "--no-record-length")


@pytest.fixture(scope="module")
def simulate_run(report_case):
    return Run(report_case, "simulate", str(report_case), "--duration-s", "30")


def _rendered_text(dom):
    """The text a reader sees: no markup, style, script or image data; entities decoded."""
    body = re.sub(r"<(style|script)\b.*?</\1>", " ", dom, flags=re.S)
    return html.unescape(re.sub(r"<[^>]+>", " ", body))


#: An absolute path as text: "/" + a name + "/" + a name, not after a letter or bracket (so not
#: the m/s² of a unit or (m/s²)/N), or a Windows drive path.
_ABSOLUTE = re.compile(r"(?<![\w.)\]/])/[\w.\-]+/[\w.\-]+|\b[A-Za-z]:\\[\w.\-]+")


def _printed_warnings(run):
    """Every warning the command printed (a Python warning's line, "crowdvib …: warning: …" or
    the verdict's "- …Warning: …"), with its paths as the report shows them."""
    found = []
    for line in run.printed.splitlines():
        match = (re.search(r"\b(\w+Warning: .+)", line)
                 or re.search(r"warning: (.+)", line, re.IGNORECASE))
        if match:
            found.append(without_machine_paths(match.group(1), str(run.case.parent)))
    return list(dict.fromkeys(found))


def _plain(text):
    """Text compared without white space and underscores (the report typesets f_h1 as f<sub>h1
    </sub>, and wraps lines)."""
    return re.sub(r"[\s_]", "", text)


def _check_sendable(run, tmp_path):
    """The report of ``run`` in the browser (:func:`_check_in_browser`), and what issue 27's
    must-show asks of every report type; returns the DOM."""
    dom = _check_in_browser(run.out / REPORT_NAME, tmp_path)
    text = _rendered_text(dom)
    # No folder of the machine: not the case's, not the repository's, no absolute path at all.
    for folder in (run.case.parent, ROOT, Path.home()):
        assert str(folder) not in text
    assert _ABSOLUTE.findall(text) == []
    # The case's [report] table heads the report, escaped in the page.
    header = dom[dom.index("<header>"):dom.index("</header>")]
    for key, value in REPORT_TABLE.items():
        assert html.escape(value, quote=False) in header, key
    # Every warning the command printed is in the report (the walking speed's at least).
    printed = _printed_warnings(run)
    assert any("walking_speed = 3.2 m/s" in w for w in printed), run.printed[-3000:]
    missing = [w for w in printed if _plain(w) not in _plain(text)]
    assert missing == [], f"printed but not in the report: {missing}"
    return dom


def test_estimate_report_in_the_browser(estimate_run, tmp_path):
    assert main(["report", str(estimate_run.out)]) == 0
    report = estimate_run.out / REPORT_NAME
    dom = _check_sendable(estimate_run, tmp_path)
    results = estimate_run.results
    # Both figures the command wrote are embedded, in its order, and nothing else is drawn.
    assert re.findall(r'alt="([^"]+)"', dom) == results["figures"]
    # Provenance: the case file's SHA-256 as it is on disk.
    import hashlib

    digest = hashlib.sha256(estimate_run.case.read_bytes()).hexdigest()
    assert digest in dom
    assert "PSD convergence" in dom and "midspan" in dom
    assert len(_decode_embedded_images(report.read_text(encoding="utf-8"))) == 2


def test_simulate_report_in_the_browser(simulate_run, tmp_path):
    dom = _check_sendable(simulate_run, tmp_path)
    assert "These results hold no MSD estimate (command simulate)" in dom
    assert "psd.png" in dom


def test_map_report_in_the_browser(map_run, tmp_path):
    dom = _check_sendable(map_run, tmp_path)
    assert "objective_map" in dom


def test_sensitivity_report_in_the_browser(sensitivity_run, tmp_path):
    dom = _check_sendable(sensitivity_run, tmp_path)
    summary = sensitivity_run.results["sensitivity"]["summary"]
    bound = summary["frequency"]["bound"]
    assert f"± {bound:.2g}" in html.unescape(dom)


def test_check_report_in_the_browser(check_run, tmp_path):
    # The design-check report: its inputs carry units like every other report's (issue 10),
    # and the damper crowdvib designed is shown with its numbers and its FRF (issue 27 §4).
    dom = _check_sendable(check_run, tmp_path)
    text = " ".join(_rendered_text(dom).split())
    (damper,) = check_run.results["design"]["dampers"]
    row = (f"damper 1 {damper['mass']:.4g} {damper['frequency']:.4g} "
           f"{damper['damping_ratio']:.3g} {damper['position']:.4g}")
    assert row in text, "the designed damper's parameters are missing"
    assert "damper_frf.png (drawn from results.json)" in dom
    assert "without the tuned mass damper (dashed) and with it" in text


# ------------------------------------------------------------------------------ content
def _synthetic_results():
    """A results.json with every section's keys, including sensitivity and map data."""
    frequencies, damping = [1.0, 2.0, 3.0, 4.0], [0.1, 0.3, 0.5]
    cost = [[(f - 3.0) ** 2 + (x - 0.3) ** 2 + 0.01 for f in frequencies] for x in damping]
    cases = [{"name": "nominal", "kind": "nominal", "level": 0, "perturbations": []},
             {"name": "frequencies+0.01", "kind": "individual", "level": 0,
              "perturbations": [["frequencies", 0.01]], "delta_frequency": 1.5,
              "delta_damping_ratio": -4.0},
             {"name": "joint", "kind": "joint", "level": 0,
              "perturbations": [["frequencies", 0.01], ["modal_masses", 0.02]],
              "delta_frequency": 2.0, "delta_damping_ratio": 10.0},
             {"name": "modal_masses+0.02", "kind": "individual", "level": 0,
              "perturbations": [["modal_masses", 0.02]], "error": "EstimationError: <no fit>"}]
    return {
        "command": "sensitivity", "crowdvib_version": "0.1.0", "seed": 7,
        "case": "bridge <&> case.toml", "case_sha256": "ab" * 32, "created": "2024-05-01T10:00:00Z",
        "estimate": {"frequency": 3.0, "damping_ratio": 0.3, "mass_ratio": 0.95},
        "expected": {"frequency": 3.0, "damping_ratio": 0.25},
        "diagnostics": {"cost": 0.5, "cost_no_hsi": 2.0, "relative_cost": 0.25, "success": False,
                        "message": "max evaluations", "active_bounds": ["damping_ratio:upper"],
                        "bounds": {"frequency": [0.5, 8.0], "damping_ratio": [0.01, 0.3]},
                        "convergence": {"n_windows": [1, 2, 3], "duration": [60.0, 120.0, 180.0],
                                        "error": [[0.5, 0.3, 0.0]], "output_names": ["mid"],
                                        "window_length": 60.0, "band": [0.0, 10.0],
                                        "norm": "2"}},
        "objective_map": {"frequencies": frequencies, "damping_ratios": damping, "cost": cost,
                          "cost_no_hsi": 2.0, "mass_ratio": 0.95, "estimate": None},
        "sensitivity": {"nominal": {"frequency": 3.0, "damping_ratio": 0.3}, "cases": cases,
                        "summary": {"frequency": {"nominal": 3.0, "bound": 0.06,
                                                  "bound_percent": 2.0},
                                    "damping_ratio": {"nominal": 0.3, "bound": 0.03,
                                                      "bound_percent": 10.0}}},
        "record_length": [{"duration": 600.0, "n_windows": 19, "frequency": 2.9,
                           "damping_ratio": 0.35, "delta_frequency": -3.333,
                           "delta_damping_ratio": 16.67, "relative_cost": 0.01},
                          {"duration": 1200.0, "error": "EstimationError: too short"}],
        "warnings": ["BoundWarning: optimum on the upper bound of damping_ratio"],
    }


def test_every_diagnostic_becomes_a_warning_and_figures_are_drawn_from_the_data(tmp_path):
    (tmp_path / "results.json").write_text(json.dumps(_synthetic_results()))
    text = write_report(tmp_path).read_text(encoding="utf-8")
    summary = text.split('<section id="summary">')[1].split("</section>")[0]
    for expected in ("J/J<sub>noHSI</sub> = 0.25 is above 10%", "did not converge: max evaluations",
                     "optimum sits on a bound (damping_ratio:upper)",
                     "PSD of mid has not converged: the last window changed it by 30.0 %",
                     "1 modelling-error case(s) failed", "BoundWarning: optimum on the upper",
                     "1 record-length re-estimation(s) failed"):
        assert expected in summary, expected
    # Headline and table: nominal ± bound from the sensitivity summary.
    assert "f<sub>h1</sub> = 3 Hz; modelling errors ± 0.06 Hz" in summary
    assert "3 ± 0.06 (2 %)" in text and "0.3 ± 0.03 (10 %)" in text
    assert '<span class="badge warn">on upper bound</span>' in text
    assert "+20.0 %" in text                     # ξ estimate 0.3 against expected 0.25
    assert ("<tr><td>600</td><td>19</td><td>2.9</td><td>0.35</td><td>-3.33</td><td>16.7</td>"
            "<td>0.01</td></tr>") in text
    # No figure files: the convergence, map and error figures are drawn from results.json.
    names = re.findall(r'alt="([^"]+)"', text)
    assert names == [f"{n}.png (drawn from results.json)" for n in
                     ("psd_convergence", "objective_map", "estimation_errors")]
    assert all(w > 300 and h > 200 for w, h in _decode_embedded_images(text))
    # Values from the file are escaped, never markup.
    assert "bridge &lt;&amp;&gt; case.toml" in text and "<no fit>" not in text
    assert "ab" * 32 in text and "recorded by the run" in text
    assert "<script" not in text and "http://" not in text and "https://" not in text


def test_an_empty_results_file_still_renders_every_section():
    text = render_report({})
    for section in SECTIONS:
        assert f'<section id="{section}">' in text
    assert "These results hold no MSD estimate" in text
    assert "No diagnostics in these results." in text
    assert "No figures in this results directory." in text


def test_listed_but_missing_and_broken_figures_are_reported(tmp_path):
    # Only the figures results.json names are embedded (no directory glob, issue 9).
    (tmp_path / "results.json").write_text(json.dumps({"command": "estimate",
                                                       "figures": ["gone.png", "fake.png"]}))
    (tmp_path / "fake.png").write_bytes(b"not a png")
    text = write_report(tmp_path).read_text(encoding="utf-8")
    assert "figure gone.png is listed in results.json but missing." in text
    assert "figure fake.png is not a PNG file and is left out." in text
    assert "data:image" not in text


def test_provenance_recorded_at_run_time_wins_over_the_file_now(tmp_path):
    import hashlib

    case = tmp_path / "case.toml"
    case.write_text("name = 'x'\n")
    keys = provenance(case)
    assert keys["case_sha256"] == hashlib.sha256(b"name = 'x'\n").hexdigest()
    assert provenance()["case_sha256"] is None
    case.write_text("name = 'edited later'\n")
    text = render_report({"command": "estimate", "case": str(case), **keys}, tmp_path)
    assert f"<code>{keys['case_sha256']}</code>" in text and "recorded by the run" in text
    assert f"<tr><td>run date</td><td>{keys['created']}</td></tr>" in text


def test_bad_directories_are_data_errors(tmp_path):
    with pytest.raises(DataError, match="results directory .*missing does not exist"):
        write_report(tmp_path / "missing")
    with pytest.raises(DataError, match="results.json does not exist: run a crowdvib command"):
        write_report(tmp_path)
    (tmp_path / "results.json").write_text("{not json")
    with pytest.raises(DataError, match="results.json is not valid JSON"):
        write_report(tmp_path)
    assert main(["report", str(tmp_path)]) == 1


def test_inputs_carry_units():
    # Issue 10: every input a reader needs a unit for shows it (kg, m/s, Hz, persons/m² …),
    # in words rather than raw keys.
    from crowdvib import load_case
    from crowdvib.reporting.report import render_report

    case = load_case(Path(__file__).resolve().parents[2] / "examples" / "eeklo_like.toml")
    page = render_report({"command": "estimate", "inputs": case.inputs()})
    inputs = page[page.index('id="inputs"'):]
    for text in ("crowd density [persons/m²]", "walking speed [m/s]", "body mass [kg]",
                 "mean step frequency [Hz]", "natural frequencies [Hz]", "modal masses [kg]",
                 "Welch window T [s]", "analysis band [Hz]", "walkway width [m]"):
        assert text in inputs
    assert "walking_speed" not in inputs


def test_statistical_interval_and_modelling_bound_side_by_side_and_together():
    # Issue 12: the sensitivity study's nominal ± bound beside the statistical interval, and the
    # two combined by the stated rule (interval widened by the bound).
    from crowdvib.reporting.report import render_report

    results = {"command": "sensitivity",
               "estimate": {"frequency": 3.06, "damping_ratio": 0.27, "mass_ratio": 0.95,
                            "interval": {"frequency": [2.97, 3.16],
                                         "damping_ratio": [0.216, 0.323], "level": 0.95}},
               "sensitivity": {"summary": {"frequency": {"nominal": 3.06, "bound": 0.2,
                                                         "bound_percent": 6.5},
                                           "damping_ratio": {"nominal": 0.27, "bound": 0.05,
                                                             "bound_percent": 18.5}}},
               "combined": {"frequency": {"interval": [2.97, 3.16], "bound": 0.2,
                                          "combined": [2.77, 3.36], "level": 0.95},
                            "damping_ratio": {"interval": [0.216, 0.323], "bound": 0.05,
                                              "combined": [0.166, 0.373], "level": 0.95}}}
    page = render_report(results)
    section = page[page.index('id="estimate"'):page.index('id="diagnostics"')]
    assert "2.97–3.16" in section and "3.06 ± 0.2 (6.5 %)" in section
    assert "with the interval: 2.77–3.36" in section
    assert "with the interval: 0.166–0.373" in section
    assert "widened on each side by the bound" in section
