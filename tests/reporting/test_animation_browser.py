"""The moving pictures of every report kind that has them, in headless Chromium (issue 38, "Must
show"): the frames advance when played, the slider moves the phase (or the time), no console
error, no request leaves the page; a script that is not crowdvib's does not run.

Each report comes from its command run as a user runs it (``simulate``, ``demo``, ``estimate``,
``check``, ``modes``). A probe (allowed by its hash, as :func:`tests.reporting.test_report.
with_script` adds it) runs before crowdvib's script: it presses Play, waits a second of the
browser's virtual time, pauses, moves the slider, and writes what it saw into ``<body>``.
"""

import html
import json
import math
import re
import subprocess
import sys

import pytest

from crowdvib.reporting.report import REPORT_NAME
from tests.reporting.test_report import (EXAMPLES, Run, _chromium, report_case,  # noqa: F401
                                         with_script)

_PROBE = """<script>
(function () {
  var errors = [];
  window.addEventListener("error", function (e) { errors.push("error " + e.message); });
  document.addEventListener("securitypolicyviolation", function (e) {
    errors.push("policy " + e.violatedDirective + " " + e.blockedURI);
  });
  function moving(box) {
    var parts = [], nodes = box.querySelectorAll(
      "path[data-cv-line], path[data-cv-deck], line[data-cv-cursor], g[data-cv-walkers] circle");
    for (var i = 0; i < nodes.length; i++) {
      parts.push(nodes[i].getAttribute("d") || nodes[i].getAttribute("x1") ||
                 (nodes[i].getAttribute("cx") + "," + nodes[i].getAttribute("cy")));
    }
    return parts.join(";");
  }
  window.addEventListener("load", function () {
    var boxes = document.querySelectorAll(".cv-anim"), seen = [];
    for (var i = 0; i < boxes.length; i++) {
      seen.push({kind: boxes[i].getAttribute("data-cv-kind"),
                 ready: boxes[i].getAttribute("data-cv-ready"),
                 step0: boxes[i].getAttribute("data-cv-step"), picture0: moving(boxes[i])});
      boxes[i].querySelector("button.cv-play").click();
    }
    setTimeout(function () {
      for (var i = 0; i < boxes.length; i++) {
        var box = boxes[i], s = seen[i], slider = box.querySelector("input.cv-slider");
        s.played = box.getAttribute("data-cv-step");
        s.picture1 = moving(box);
        box.querySelector("button.cv-play").click();
        s.paused = box.getAttribute("data-cv-playing");
        s.max = slider.max;
        slider.value = String(Math.floor(Number(slider.max) / 3));
        slider.dispatchEvent(new Event("input"));
        s.slid = box.getAttribute("data-cv-step");
        s.phase = box.getAttribute("data-cv-phase");
        s.time = box.getAttribute("data-cv-time");
        s.picture2 = moving(box);
      }
      document.body.setAttribute("data-probe", JSON.stringify({boxes: seen, errors: errors}));
    }, 1000);
  });
})();
</script>"""

#: Hosts chromium itself calls in the background, not the page.
_BROWSER_OWN = (".google.com", ".googleapis.com", ".gstatic.com")


def _open(page, tmp_path, name):
    """The DOM after the probe, the console lines and the URL of every request the page made
    (chromium's net log; its own background calls left out)."""
    path = tmp_path / f"{name}.html"
    path.write_text(page, encoding="utf-8")
    log = tmp_path / f"{name}.netlog.json"
    command = [_chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
               "--disable-background-networking", "--disable-component-update",
               "--disable-sync", "--mute-audio", f"--user-data-dir={tmp_path / 'profile'}",
               "--enable-logging=stderr", "--v=0", "--virtual-time-budget=8000",
               f"--log-net-log={log}", "--dump-dom", path.as_uri()]
    done = subprocess.run(command, capture_output=True, text=True, timeout=180, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    console = [line for line in done.stderr.splitlines() if ":CONSOLE" in line]
    data = json.loads(log.read_text(encoding="utf-8"))
    request = data["constants"]["logSourceType"]["URL_REQUEST"]
    urls = {e["params"]["url"] for e in data["events"]
            if e["source"]["type"] == request and "url" in e.get("params", {})}
    urls = sorted(u for u in urls
                  if not u.split("/")[2].split(":")[0].endswith(_BROWSER_OWN))
    return done.stdout, console, urls


def _probed(report, tmp_path):
    page = with_script(report.read_text(encoding="utf-8"), _PROBE, where="<main>")
    dom, console, urls = _open(page, tmp_path, "probed")
    probe = json.loads(html.unescape(re.search(r'data-probe="([^"]*)"', dom).group(1)))
    return probe, console, urls


def _check_moving(report, tmp_path, kinds):
    """The pictures of ``report`` move as issue 38 asks; their kinds in page order."""
    probe, console, urls = _probed(report, tmp_path)
    assert console == [] and probe["errors"] == [], (console, probe["errors"])
    assert urls == [], urls                   # the page alone: nothing fetched, not even a file
    assert [box["kind"] for box in probe["boxes"]] == kinds
    for box in probe["boxes"]:
        assert box["ready"] == "yes" and box["step0"] == "0"
        # Played for a second of virtual time: the modes at 32 steps a second, the replay at
        # its 20 frames a second (setInterval; a loaded machine may lose a few).
        assert int(box["played"]) >= 10, box
        assert box["picture1"] != box["picture0"]
        assert box["paused"] == "no"
        third = int(box["max"]) // 3
        assert box["slid"] == str(third) and box["picture2"] not in (box["picture0"],
                                                                      box["picture1"])
        if box["kind"] == "modes":
            # The phase of step k of 48: 360 k / 48 degrees (animation.py's _PHASE_STEPS),
            # rounded half up as JavaScript's Math.round does.
            assert int(box["phase"]) == math.floor(360 * third / (int(box["max"]) + 1) + 0.5)
        else:
            assert float(box["time"]) > 0
    return probe


@pytest.fixture(scope="module")
def simulated(report_case):  # noqa: F811
    return Run(report_case, "simulate", str(report_case), "--duration-s", "40")


@pytest.fixture(scope="module")
def estimated(report_case):  # noqa: F811
    return Run(report_case, "estimate", str(report_case))


def test_simulate_report_plays_its_mode_shapes_and_its_crossing(simulated, tmp_path):
    run = simulated
    probe = _check_moving(run.out / REPORT_NAME, tmp_path, ["modes", "replay"])
    replay = run.results["replay"]
    # The slider's step is a frame: t = t0 + k / frame rate (the replay's own clock).
    box = probe["boxes"][1]
    assert float(box["time"]) == pytest.approx(replay["t0"] + int(box["slid"])
                                               / replay["frame_rate"], abs=0.006)
    assert int(box["max"]) + 1 == len(replay["q"])
    _check_walkers_lifted(run.out / REPORT_NAME, box)


def _check_walkers_lifted(report, box):
    """The script's walker dots at the slider's frame: where the page's data put them, with
    HSI lifted by the MSD motion decoded in Python (replay_view.msd_motion, from the same
    codes: reference for the script's own decoding), to the 0.1 px the script writes."""
    import numpy as np

    from crowdvib.reporting.replay_view import msd_motion

    page = report.read_text(encoding="utf-8")
    blocks = re.findall(r'<script type="application/json" class="cv-data">(.*?)</script>', page,
                        flags=re.S)
    data = [d for d in map(json.loads, blocks) if d["kind"] == "replay"][0]
    w = {k: np.asarray(v) for k, v in data["walkers"].items()}
    step = int(box["slid"])
    t = data["t0"] + step / data["rate"]
    deck = data["y0"] + np.asarray(data["shapes"]).T @ np.asarray(data["q"][step])
    px = data["ax"] + data["bx"] * (w["x_start"] + w["velocity"] * (t - w["arrival"]))
    lift = data["msd"]["px"] / data["msd"]["unit"] * msd_motion(
        data["msd"], w["t_on"].size, len(data["q"]))[:, step]
    expected = np.interp(px, data["x"], deck) - data["lift"] - lift
    dots = np.array([part.split(",") for part in box["picture2"].split(";") if "," in part],
                    dtype=float)
    on = (w["t_on"] <= t) & (t < w["t_off"])
    assert dots.shape == (w["t_on"].size, 2) and on.sum() >= 5
    np.testing.assert_allclose(dots[on], np.c_[px, expected][on], atol=0.051)
    assert np.any(lift[on] != 0)          # lifted: a step is 8/30 px, the tolerance 0.05 px


def test_demo_report_plays_its_mode_shapes_and_its_crossing(tmp_path):
    out = tmp_path / "demo"
    done = subprocess.run([sys.executable, "-m", "crowdvib", "demo", "--duration-s", "300",
                           "--out", str(out)], capture_output=True, text=True, timeout=600,
                          check=False)
    assert done.returncode in (0, 3), done.stdout[-2000:] + done.stderr[-2000:]
    _check_moving(out / REPORT_NAME, tmp_path, ["modes", "replay"])


def test_estimate_report_plays_its_mode_shapes(estimated, tmp_path):
    _check_moving(estimated.out / REPORT_NAME, tmp_path, ["modes"])


def test_check_report_plays_its_mode_shapes(report_case, tmp_path):  # noqa: F811
    run = Run(report_case, "check", str(report_case))
    _check_moving(run.out / REPORT_NAME, tmp_path, ["modes"])


def test_modes_report_plays_the_models_and_the_identified_shapes(tmp_path):
    out = tmp_path / "modes"
    ambient = EXAMPLES / "ambient" / "paper_beam_ambient.toml"
    done = subprocess.run([sys.executable, "-m", "crowdvib", "modes", str(ambient), "--out",
                           str(out)], capture_output=True, text=True, timeout=600, check=False)
    assert done.returncode in (0, 3), done.stdout[-2000:] + done.stderr[-2000:]
    _check_moving(out / REPORT_NAME, tmp_path, ["modes", "modes"])


def test_only_crowdvibs_script_runs(estimated, tmp_path):
    # A script the allow-list would have missed (put in after it, with an inline handler and
    # one the policy's hash does not name): blocked, while crowdvib's own runs.
    text = (estimated.out / REPORT_NAME).read_text(encoding="utf-8")
    hostile = ("<script>document.body.setAttribute('data-ran', 'script')</script>"
               "<img src=\"data:image/png;base64,AAAA\" "
               "onerror=\"document.body.setAttribute('data-ran', 'handler')\">")
    dom, console, urls = _open(text.replace("<main>", "<main>" + hostile, 1), tmp_path,
                               "hostile")
    assert re.search(r"<body[^>]*\sdata-ran=", dom) is None
    assert 'data-cv-ready="yes"' in dom                       # crowdvib's script ran
    assert len(console) == 2 and all("Content Security Policy" in line for line in console)
    assert urls == []


def test_without_script_the_report_shows_a_still(simulated, tmp_path):
    # Script off (the page's policy back to script-src 'none', which blocks crowdvib's script as
    # a browser with script off does not run it; --dump-dom needs script of its own): no
    # controls (the script makes them), the still of each picture: the deck, and the walkers
    # of the replay at the instant the caption names, in elevation and in plan.
    from crowdvib.reporting.animation import SCRIPT_HASH
    from crowdvib.reporting.safe_html import CSP, policy_with_scripts

    text = (simulated.out / REPORT_NAME).read_text(encoding="utf-8")
    dom, console, urls = _open(text.replace(policy_with_scripts([SCRIPT_HASH]), CSP), tmp_path,
                               "still")
    assert len(console) == 1 and "Content Security Policy" in console[0] and urls == []
    assert '<div class="cv-controls">' not in dom and 'data-cv-ready="yes"' not in dom
    still = re.search(r'<g class="cv-still">(.*?)</g>', dom, flags=re.S).group(1)
    caption = re.search(r"The still shows t = ([\d.]+) s", dom).group(1)
    replay = simulated.results["replay"]
    walkers = {k: [float(v) for v in values] for k, values in replay["walkers"].items()}
    on = sum(a <= float(caption) < b for a, b in zip(walkers["t_on"], walkers["t_off"]))
    assert on >= 10 and still.count("<circle") == 2 * on
    assert re.search(r'<path data-cv-deck="" d="M[\d.]+ [\d.]+L', dom)
    assert dom.count('<path data-cv-line="0 0" d="M') == 1
