"""Moving pictures in the report (issue 38) without a browser: what results.json keeps, the
pictures drawn from it, and the policy that lets crowdvib's own script run and nothing else."""

import base64
import hashlib
import json
import re
from importlib import resources

import numpy as np
import pytest

from crowdvib import ModalModel, ParameterError
from crowdvib.reporting.animation import (SCRIPT, SCRIPT_HASH, mode_shape_table,
                                          report_animations)
from crowdvib.reporting.frames import MAX_STATIONS
from crowdvib.reporting.report import render_report
from crowdvib.reporting.safe_html import CSP, CSP_META

_POLICY = re.compile(r'<meta http-equiv="Content-Security-Policy" content="([^"]*)">')


def _results(**extra):
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3, n_modes=2)
    return {"command": "estimate", "mode_shapes": mode_shape_table(bridge), **extra}


def _replay_results(names=("midspan",)):
    from crowdvib.models.examples import paper_example
    from crowdvib.reporting.replay_view import replay_table
    from crowdvib.response.time_domain.replay import crossing_replay

    case = paper_example()
    replay = crossing_replay(case.structure, case.crowd, 60.0, msd=case.msd, rng=3,
                             start=10.0, length=30.0)
    table = replay_table(replay, case.structure)
    table["output_names"] = list(names)
    return {"command": "simulate", "replay": table,
            "mode_shapes": mode_shape_table(case.structure)}, replay, case


@pytest.fixture(scope="module")
def replayed():
    return _replay_results()


def test_the_shipped_script_is_the_one_the_policy_names():
    # The policy's hash is SHA-256 of the package's animation.js as the page holds it (CSP
    # Level 2, "hash-source": base64 of the digest of the script element's text).
    text = resources.files("crowdvib.reporting").joinpath("animation.js").read_text("utf-8")
    digest = base64.b64encode(hashlib.sha256(text.encode("utf-8")).digest()).decode("ascii")
    assert SCRIPT == text and SCRIPT_HASH == f"sha256-{digest}"
    page = render_report(_results())
    policy = _POLICY.search(page).group(1)
    # Every directive as issue 35 set it, but script-src: crowdvib's one script by its hash.
    assert policy == CSP.replace("script-src 'none'", f"script-src '{SCRIPT_HASH}'")
    assert page.index(_POLICY.search(page).group(0)) < page.index("<meta charset")
    scripts = re.findall(r"<script([^>]*)>(.*?)</script>", page, flags=re.S)
    assert [body for attributes, body in scripts if "application/json" not in attributes] \
        == [SCRIPT]


def test_a_report_without_a_modal_model_allows_no_script():
    page = render_report({"command": "map"})
    assert CSP_META in page and "<script" not in page


def test_the_table_of_contents_links_the_animations_where_they_are_drawn():
    # The section follows the figures on the page (report.py); the contents list it there, and
    # only where a picture is drawn (a table that does not draw leaves no dead link).
    page = render_report(_results())
    contents = page[page.index('<nav class="toc">'):page.index("</nav>")]
    assert '<a href="#figures">Figures</a><a href="#animations">Animations</a>' in contents
    assert '<section id="animations">' in page
    assert "#animations" not in render_report({"command": "map"})
    broken = _results()
    broken["mode_shapes"] = {**broken["mode_shapes"], "frequencies": [1.0, 2.0, 3.0]}
    assert "#animations" not in render_report(broken)


def test_mode_shape_table_keeps_exact_values_at_its_stations():
    # An FE-like model of 1001 stations: at most MAX_STATIONS kept, both ends, each kept value
    # the model's own at that station (reference: ModalModel.mode_shapes), to 5 significant digits.
    x = np.linspace(0.0, 50.0, 1001)
    shapes = np.stack([np.sin(np.pi * x / 50), np.sin(2 * np.pi * x / 50)], axis=-1)
    bridge = ModalModel([2.0, 8.0], [0.005, 0.01], [5e4, 5e4], x, shapes, 3.0, ("mid",),
                        [[1.0, 0.0]])
    table = mode_shape_table(bridge)
    kept = np.asarray(table["positions"])
    assert kept.size <= MAX_STATIONS and kept[0] == 0.0 and kept[-1] == 50.0
    index = np.searchsorted(x, kept)
    np.testing.assert_allclose(np.asarray(table["shapes"])[0], shapes[index], rtol=5e-5,
                               atol=1e-9)
    assert table["frequencies"] == [2.0, 8.0] and table["damping_ratios"] == [0.005, 0.01]


def test_each_mode_is_labelled_empty_and_occupied():
    # The occupied structure's f and ξ (reference: effective_modal_properties, docs: theory,
    # The smeared crowd and the occupied bridge) beside the empty ones: the paper example's
    # crowd of MSDs lowers f_1 and adds damping to the empty 0.5 %.
    from crowdvib.models.examples import paper_example
    from crowdvib.response.frequency_domain.spectral import effective_modal_properties

    case = paper_example()
    table = mode_shape_table(case.structure, case.crowd, case.msd)
    found = effective_modal_properties(case.structure, case.crowd, case.msd)
    assert table["occupied"]["frequencies"] == pytest.approx(found.frequencies, rel=1e-12)
    assert table["occupied"]["frequencies"][0] < 2.0
    assert table["occupied"]["damping_ratios"][0] > 0.005
    page = render_report({"command": "simulate", "mode_shapes": table})
    assert (f"mode 1: 2 Hz, ξ = 0.5 %; occupied {found.frequencies[0]:.4g} Hz, "
            f"ξ = {100 * found.damping_ratios[0]:.3g} %") in page
    assert "occupied" not in mode_shape_table(case.structure, case.crowd, None)


def test_the_still_draws_each_mode_at_phase_zero():
    # The still's line of mode j is y0 − φ_j/max|φ_j|·(height/2 − 6) (animation.py's panel):
    # a half sine for mode 1 (reference: sin(πx/L) of the simply supported beam), a full one for
    # mode 2; the caption holds f and ξ.
    page = render_report(_results())
    lines = re.findall(r'<path data-cv-line="(\d) 0" d="([^"]*)"', page)
    assert [j for j, _ in lines] == ["0", "1"]
    for j, d in lines:
        points = np.array(re.findall(r"[ML]([-\d.]+) ([-\d.]+)", d), dtype=float)
        x = (points[:, 0] - points[0, 0]) / (points[-1, 0] - points[0, 0]) * 50.0
        drawn = points[0, 1] - points[:, 1]
        expected = np.sin((int(j) + 1) * np.pi * x / 50.0) * (92.0 / 2 - 6)
        np.testing.assert_allclose(drawn, expected, atol=0.16)
    assert "mode 1: 2 Hz, ξ = 0.5 %" in page and "mode 2: 8 Hz" in page


def test_the_replay_data_agree_with_the_replay(replayed):
    # What the page's script draws at frame k: the walkers at x_k + v_k (t − t_k) (to the mm
    # the table keeps) and the deflection Σ φ_j z_j (reference: the Replay, from the record).
    results, replay, case = replayed
    table = results["replay"]
    walkers = {k: np.asarray(v) for k, v in table["walkers"].items()}
    shapes, q = np.asarray(table["shapes"]), np.asarray(table["q"])
    for k in (0, 37, replay.n_frames - 1):
        t = table["t0"] + k / table["frame_rate"]
        assert t == pytest.approx(replay.time[k])
        on = (walkers["t_on"] <= t) & (t < walkers["t_off"])
        x = walkers["x_start"][on] + walkers["velocity"][on] * (t - walkers["arrival"][on])
        np.testing.assert_allclose(np.sort(x), np.sort(replay.positions(t)[1]), atol=0.01)
        positions = np.asarray(table["positions"])
        expected = case.structure.shapes_at(positions) @ replay.modal_displacement[:, k]
        np.testing.assert_allclose(shapes.T @ q[k], expected,
                                   atol=1e-3 * table["largest_deflection"])


def _replay_picture(page):
    """The replay's figure, its data block and its still's walkers."""
    picture = re.search(r'<figure class="cv-anim" data-cv-kind="replay".*?</figure>', page,
                        flags=re.S).group(0)
    data = json.loads(re.search(r'<script type="application/json" class="cv-data">(.*?)'
                                r"</script>", picture, flags=re.S).group(1))
    return picture, data


def test_the_replay_page_stays_light(replayed):
    results = replayed[0]
    picture = _replay_picture(render_report(results))[0]
    # 30 s at 20 frames a second of one mode, some 130 walkers, the trace's envelope (1.3 kB a
    # second without HSI) and the MSD motion of the ~70 walkers on the deck at one byte a
    # frame (1.4 kB a second): under 3 kB a second of replay, the script (6.5 kB) once a page
    # (issue 38: the page stays light).
    assert len(picture.encode("utf-8")) / 30.0 < 3000


def test_the_pages_msd_motion_is_the_replays(replayed):
    # Decoded as the script does (code index − zero, times unit), each walker's MSD motion in
    # the page's data at frame k equals u − φᵀz of the Replay (reference: Replay.
    # msd_displacement, checked against paper Eq. 2 in tests/response/test_replay.py) to half
    # a quantisation step, the step the largest motion / 30; no walker off the deck has one.
    results, replay, _ = replayed
    data = _replay_picture(render_report(results))[1]
    msd = data["msd"]
    largest = np.nanmax(np.abs(replay.msd_displacement))
    assert msd["unit"] == pytest.approx(largest / 30, rel=1e-12)
    assert len(msd["codes"]) == replay.arrival.size
    for k in (0, 37, 300, replay.n_frames - 1):
        expected = replay.msd_displacement[:, k]
        found = np.full(expected.shape, np.nan)
        for i, (first, code) in enumerate(zip(msd["first"], msd["codes"])):
            if 0 <= k - first < len(code):
                found[i] = msd["unit"] * (msd["alphabet"].index(code[k - first]) - msd["zero"])
        np.testing.assert_array_equal(np.isfinite(found), np.isfinite(expected))
        assert np.sum(np.isfinite(found)) >= 30
        np.testing.assert_allclose(found[np.isfinite(found)], expected[np.isfinite(expected)],
                                   rtol=0, atol=msd["unit"] / 2 * (1 + 1e-9))


def test_the_still_lifts_each_walker_by_its_msds_motion(replayed):
    # The still's dot of walker i at the frame the caption names: the deck under it (the
    # page's own deflection there) less the lift (4 + 8 px) less 8 px × r_i / max|r| (r the
    # Replay's u − φᵀz; REPLAY_GEOMETRY), to the quantisation step and the 0.1 px written.
    results, replay, _ = replayed
    picture, data = _replay_picture(render_report(results))
    t = float(re.search(r"The still shows t = ([\d.]+) s", picture).group(1))
    k = int(round((t - data["t0"]) * data["rate"]))
    deck = data["y0"] + np.asarray(data["shapes"]).T @ np.asarray(data["q"][k])
    w = {name: np.asarray(v) for name, v in data["walkers"].items()}
    on = np.flatnonzero((w["t_on"] <= t) & (t < w["t_off"]))      # as the page puts them
    px = data["ax"] + data["bx"] * (w["x_start"][on] + w["velocity"][on] * (t - w["arrival"][on]))
    r = replay.msd_displacement[on, k]
    pixels = 8.0 / np.nanmax(np.abs(replay.msd_displacement))
    expected = np.interp(px, data["x"], deck) - 12.0 - pixels * r
    still = re.search(r'<g class="cv-still">(.*?)</g>', picture, flags=re.S).group(1)
    dots = np.array(re.findall(r'<circle r="2.5" cx="([\d.]+)" cy="([\d.]+)"', still),
                    dtype=float)
    assert dots.shape == (on.size, 2) and on.size >= 30
    order = np.argsort(px)
    drawn = dots[np.argsort(dots[:, 0])]
    np.testing.assert_allclose(drawn[:, 0], px[order], atol=0.06)
    np.testing.assert_allclose(drawn[:, 1], expected[order],
                               atol=pixels * data["msd"]["unit"] / 2 + 0.06)
    assert "lifted by their MSD's motion relative to the deck" in picture
    assert "bobbing" not in picture


def test_without_hsi_no_msd_motion_is_written():
    # Moving forces (no msd): the Replay has no MSD motion, results.json's table and the page's
    # data none either, and the caption says the walkers bob at their step frequency.
    from crowdvib.models.examples import paper_example
    from crowdvib.reporting.replay_view import replay_table
    from crowdvib.response.time_domain.replay import crossing_replay

    case = paper_example()
    replay = crossing_replay(case.structure, case.crowd, 20.0, rng=3, start=5.0, length=5.0)
    assert not replay.hsi and replay.msd_displacement is None
    table = replay_table(replay, case.structure)
    assert "msd" not in table and table["hsi"] is False
    picture, data = _replay_picture(render_report({"command": "simulate", "replay": table}))
    assert "msd" not in data and data["lift"] == 4.0
    assert "bobbing at their step frequency" in picture and "MSD" not in picture


@pytest.mark.parametrize("broken", [{"first": [10**6]}, {"codes": ["!"]}, {"unit": -1.0},
                                    {"alphabet": "ab"}, {"codes": []}])
def test_a_replay_whose_msd_motion_does_not_decode_is_left_out(replayed, broken):
    # A received results.json's msd: codes beyond the frames, a character not crowdvib's, a
    # unit not positive, another alphabet, fewer codes than walkers: no picture.
    results = dict(replayed[0])
    del results["mode_shapes"]
    msd = dict(results["replay"]["msd"])
    for key, value in broken.items():
        msd[key] = value * len(msd[key]) if isinstance(value, list) and value else value
    results["replay"] = {**results["replay"], "msd": msd}
    assert report_animations(results).pictures == []


def test_a_received_results_file_cannot_end_the_data_block_or_add_script(replayed):
    # An output name written to close the data block and open a script: escaped in the JSON
    # (\\u003c), so the page holds crowdvib's script and its data blocks, nothing else.
    hostile = '</script><script>document.title="ran"</script><!--'
    results = _replay_results(names=(hostile,))[0]
    page = render_report(results)
    assert 'document.title="ran"</script>' not in page
    opened = re.findall(r"<script([^>]*)>", page)
    assert sorted(opened) == sorted([""] + [' type="application/json" class="cv-data"'] * 2)
    data = re.findall(r'<script type="application/json" class="cv-data">(.*?)</script>', page,
                      flags=re.S)
    assert json.loads(data[1])["kind"] == "replay"


@pytest.mark.parametrize("broken", [{"shapes": "x"}, {"positions": [0.0]},
                                    {"frequencies": [1.0, 2.0, 3.0]},
                                    {"shapes": [[[float("nan")]]]}])
def test_a_mode_shape_table_that_does_not_draw_is_left_out(broken):
    results = _results()
    results["mode_shapes"] = {**results["mode_shapes"], **broken}
    assert report_animations(results).pictures == []
    assert "<script" not in render_report(results)


def test_a_replay_table_that_does_not_draw_is_left_out(replayed):
    results = dict(replayed[0])
    del results["mode_shapes"]
    results["replay"] = {**results["replay"], "q": [[1.0, 2.0]]}     # two modes of one
    assert report_animations(results).pictures == []


def test_a_template_cannot_forge_the_placeholder_or_bring_a_script(tmp_path):
    # The placeholder's token is drawn for each page: a template writing a slot of its own
    # gets it back as text, not pictures; a template with a <script> is refused (issue 35).
    template = tmp_path / "page.html"
    template.write_text('<!DOCTYPE html><html><head><title>{{ title }}</title></head><body>'
                        '<div class="cv-slot">00000000000000000000000000000000</div>'
                        "{{ body }}</body></html>", encoding="utf-8")
    page = render_report(_results(), template=template)
    assert page.count('<figure class="cv-anim"') == 1
    assert '<div class="cv-slot">00000000000000000000000000000000</div>' in page
    assert _POLICY.search(page).group(1).count("sha256-") == 1
    template.write_text("<html><body>{{ body }}<script>alert(1)</script></body></html>",
                        encoding="utf-8")
    with pytest.raises(ParameterError, match="a script"):
        render_report(_results(), template=template)
