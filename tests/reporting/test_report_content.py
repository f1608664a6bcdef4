"""What the reports say (issue 10): defaults marked as defaults, only the tables a command read,
the simulated response first, every output plotted and named, the analysis band in the legend,
a sensitivity verdict that names cases on a search bound."""

import json
import re
from pathlib import Path

import numpy as np

from crowdvib import load_case, running_rms
from crowdvib.cli import main
from crowdvib.cases import ESTIMATION_TABLES, SIMULATION_TABLES
from crowdvib.reporting.report import render_report

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _row(page, label):
    """The value cell (HTML) of the Inputs row labelled ``label``."""
    inputs = page[page.index('id="inputs"'):]
    found = re.search(rf"<tr><th>{re.escape(label)}</th><td>(.*?)</td></tr>", inputs)
    assert found, f"no input row {label!r}"
    return found.group(1)


def test_defaults_are_marked_and_derived_values_say_so(tmp_path):
    case_file = tmp_path / "case.toml"
    # No walking speed: derived from the density (Weidmann), as the case-file reference says.
    case_file.write_text('[structure]\ntype = "simply_supported_beam"\nspan = 50.0\nwidth = 3.0\n'
                         'frequency = 2.0\ndamping_ratio = 0.005\nmodal_mass = 5e4\n'
                         'outputs = { mid = 25.0 }\n[crowd]\ndensity = 0.5\n'
                         '[estimation]\nband = [0.0, 10.0]\n')
    case = load_case(case_file)
    page = render_report({"command": "estimate", "inputs": case.inputs(ESTIMATION_TABLES)})
    assert "default" not in _row(page, "crowd density [persons/m²]")
    assert "default" not in _row(page, "analysis band [Hz]")
    assert "derived" in _row(page, "walking speed [m/s]")
    assert "Weidmann" in _row(page, "walking speed [m/s]")
    # [hsi] was not given: the MSD of the inputs is the default one, and says so.
    assert "default" in _row(page, "frequency [Hz]")
    assert "default" in _row(page, "Welch window T [s]")
    assert "default" in _row(page, "low-pass cut-off [Hz]")     # filter.cutoff, renamed


def test_a_command_shows_only_the_tables_it_read():
    case = load_case(EXAMPLES / "paper_example.toml")
    simulated = render_report({"command": "simulate", "inputs": case.inputs(SIMULATION_TABLES)})
    estimated = render_report({"command": "estimate", "inputs": case.inputs(ESTIMATION_TABLES)})
    assert "<h3>Simulation</h3>" in simulated and "<h3>Estimation</h3>" not in simulated
    assert "<h3>Measurement</h3>" not in simulated
    assert "<h3>Estimation</h3>" in estimated and "<h3>Simulation</h3>" not in estimated
    # No automatic title-casing: the label is written once, as it reads.
    assert "<h3>HSI (MSD model)</h3>" in estimated


def test_running_rms_of_a_sine_is_amplitude_over_root_two():
    # Closed form: a sine of amplitude A over whole periods has RMS A/√2.
    rate, amplitude, frequency = 200.0, 0.8, 2.5
    t = np.arange(0, 10.0, 1 / rate)
    result = running_rms(amplitude * np.sin(2 * np.pi * frequency * t), rate, window=1.0)
    assert result.shape == (t.size - 199,)               # one value per full 1-s window
    assert np.allclose(result, amplitude / np.sqrt(2), rtol=1e-9)


def test_simulate_report_leads_with_the_response_of_every_output(tmp_path):
    out = tmp_path / "sim"
    # A 2 s crossing replay (default 30 s, here the whole record): nothing below reads it, and
    # its frames, replayed one by one, were a sixth of the command's time.
    assert main(["simulate", str(EXAMPLES / "eeklo_like.toml"), "--duration-s", "20",
                 "--replay-length", "2", "--out", str(out)]) == 0
    results = json.loads((out / "results.json").read_text())
    response = results["response"]
    assert response["output_names"] == ["main_span", "side_span"]
    # Every output has its own time history, named after it.
    assert results["figures"] == ["psd.png", "time_history_main_span.png",
                                  "time_history_side_span.png"]
    page = (out / "report.html").read_text(encoding="utf-8")
    summary = page[page.index('id="summary"'):page.index('id="estimate"')]
    worst = max(response["max_running_rms"])
    assert f"largest 1 s running RMS = {worst:.3g} m/s²" in summary
    for name, rms, peak in zip(response["output_names"], response["rms"], response["peak"]):
        assert name in summary and f"{rms:.3g}" in summary and f"{peak:.3g}" in summary
    # The running RMS never exceeds the peak and its largest value is at least the record's RMS
    # (a mean of the same squares over shorter windows).
    for rms, peak, largest in zip(response["rms"], response["peak"],
                                  response["max_running_rms"]):
        assert rms <= largest + 1e-12 and largest <= peak


def test_psd_figures_name_the_analysis_band():
    from crowdvib import Crowd, ModalModel, response_psd
    from crowdvib.reporting.plotting import plot_psd_comparison

    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3)
    psd = response_psd(bridge, Crowd.from_density(0.5), np.linspace(0, 10, 201),
                       crowd_model="smeared")
    ax = plot_psd_comparison({"model": psd}, analysis_band=(1.5, 8.0))
    assert "analysis band 1.5–8 Hz" in ax.get_legend_handles_labels()[1]
    assert [t.get_text() for t in ax.get_legend().get_texts()][0] == "analysis band 1.5–8 Hz"


def test_sensitivity_cases_on_a_search_bound_reach_the_verdict():
    cases = [{"name": "nominal", "kind": "nominal", "level": 0, "perturbations": [],
              "active_bounds": []},
             {"name": "frequencies+0.05", "label": "structural frequency +5 %",
              "kind": "individual", "level": 0, "perturbations": [["frequencies", 0.05]],
              "delta_frequency": 1.0, "delta_damping_ratio": 30.0,
              "active_bounds": ["damping_ratio:upper"]}]
    page = render_report({"command": "sensitivity",
                          "estimate": {"frequency": 3.0, "damping_ratio": 0.3},
                          "sensitivity": {"cases": cases, "nominal": {}}})
    summary = page[page.index('id="summary"'):page.index('id="estimate"')]
    assert "No warnings" not in summary
    assert "1 of 2 modelling-error case(s) ended on a search bound" in summary
    assert "structural frequency +5 %" in summary


def _text(page, section):
    part = page.split(f'<section id="{section}">')[1].split("</section>")[0]
    return re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", part))


def test_a_check_with_another_msd_does_not_list_hsi_and_a_field_estimate_no_empty_columns(
        tmp_path):
    # Issue 36 §3. (1) A check that used an estimate's MSD listed the case's [hsi] beside it;
    # (2) a structure name the file did not set (the file's name) was listed as "default";
    # (3) a field estimate showed empty "nominal ± bound / expected / error" columns.
    case_file = tmp_path / "bridge.toml"
    case_file.write_text('[structure]\ntype = "simply_supported_beam"\nspan = 50.0\nwidth = 3.0\n'
                         'frequency = 2.0\ndamping_ratio = 0.005\nmodal_mass = 5e4\n'
                         'outputs = { mid = 25.0 }\n[crowd]\ndensity = 0.5\n'
                         '[hsi]\nfrequency = 3.0\ndamping_ratio = 0.3\n'
                         '[estimation]\nband = [0.0, 10.0]\n')
    inputs = load_case(case_file).inputs(ESTIMATION_TABLES)
    assert inputs["not_set"].get("structure.name") == "default"
    msd = {"frequency": 3.1, "damping_ratio": 0.25, "mass_ratio": 0.95,
           "source": "the estimate in est"}
    page = render_report({"command": "check", "inputs": inputs, "msd": msd})
    assert "the MSD model of the check is the estimate in est" in _row(page, "not used")
    cards = _text(page, "inputs")
    assert "HSI (MSD model) not used" in cards and "damping ratio [-] 0.3 " not in cards
    assert "bridge" not in _text(page, "inputs").split("Structure")[1].split("Crowd")[0]
    # The same [hsi] used by the check itself is listed.
    page = render_report({"command": "check", "inputs": inputs, "msd": {**msd,
                                                                       "source": "[hsi]"}})
    assert "damping ratio [-] 0.3" in _text(page, "inputs")
    # (3) An estimate with neither a modelling-error study nor a truth: three columns fewer.
    page = render_report({"command": "estimate", "estimate": {
        "frequency": 3.1, "damping_ratio": 0.25, "mass_ratio": 0.95}})
    head = page.split('<section id="estimate">')[1].split("</tr>")[0]
    assert "nominal ± bound" not in head and "error" not in head and "expected" not in head
    assert "search bounds" in head
