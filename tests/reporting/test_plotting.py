"""Figures (paper Figs. 2-6, 9-12, 15, 17-20): the returned artists, labels with units, markers."""

from dataclasses import dataclass

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from crowdvib import ParameterError, ResponsePSD, Simulation, frf, response_psd  # noqa: E402
from crowdvib.reporting import plotting  # noqa: E402
from crowdvib.studies import ObjectiveMap, ParametricResult, SensitivityResult  # noqa: E402
from crowdvib.signals import PSDConvergence  # noqa: E402


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _legend_texts(ax):
    return [t.get_text() for t in ax.get_legend().get_texts()]


# ------------------------------------------------------------------------------ Fig. 2
def test_load_psd_has_one_line_per_mode_and_peaks_near_the_mean_step_frequency(
        paper_bridge, paper_crowd, welch_grid):
    ax = plotting.plot_load_psd(welch_grid, paper_crowd, structure=paper_bridge)
    (line,) = ax.get_lines()
    assert ax.get_xlabel() == "Frequency [Hz]"
    assert ax.get_ylabel().endswith("[N²/Hz]")
    x, y = line.get_data()
    # Paper Fig. 2: the first harmonic of N(1.89, 0.175) Hz, slightly shifted up because the DLF
    # grows with the step frequency.
    assert 1.85 <= x[np.argmax(y)] <= 2.0
    assert _legend_texts(ax) == ["mode 1 (2 Hz)"]


def test_load_spectrum_without_structure_is_per_unit_influence(paper_crowd, welch_grid):
    ax = plotting.plot_load_psd(welch_grid, paper_crowd)
    assert len(ax.get_lines()) == 1
    assert ax.get_ylabel() == "Load PSD s [N²/Hz]"


# ------------------------------------------------------------------------------ Fig. 3
def test_hsi_effect_shows_both_peaks_in_the_enlargement(paper_bridge, paper_crowd, paper_msd,
                                                        welch_grid):
    without = response_psd(paper_bridge, paper_crowd, welch_grid, welch_window_length=60.0,
                           crowd_model="smeared")
    with_hsi = response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd,
                            welch_window_length=60.0, crowd_model="smeared")
    handles = plotting.plot_hsi_effect(without, with_hsi)
    full, detail = handles.axes
    assert len(full.get_lines()) == 2 and len(detail.get_lines()) == 2
    # Paper Fig. 3: peak at 2 Hz without HSI, 1.93 Hz with HSI.
    assert _legend_texts(full) == ["without HSI (peak 2.00 Hz)", "with HSI (peak 1.93 Hz)"]
    lower, upper = detail.get_xlim()
    assert lower < 1.93 and upper > 2.0 and upper - lower < 1.0
    assert detail.get_yscale() == "linear" and full.get_yscale() == "log"
    for ax in handles.axes:
        assert ax.get_xlabel() == "Frequency [Hz]"
        assert ax.get_ylabel() == "Acceleration PSD [(m/s²)²/Hz]"


# ------------------------------------------------------------------------------ Figs. 9, 18
def test_frf_empty_dashed_and_occupied_solid(paper_bridge, paper_crowd, paper_msd):
    frequency = np.linspace(0.5, 6.0, 2201)
    ax = plotting.plot_frf(frf(paper_bridge, frequency),
                           frf(paper_bridge, frequency, crowd=paper_crowd, msd=paper_msd))
    empty, occupied = ax.get_lines()
    assert empty.get_linestyle() == "--" and occupied.get_linestyle() == "-"
    assert _legend_texts(ax) == ["empty (peak 2.00 Hz)", "with HSI (peak 1.93 Hz)"]
    assert ax.get_ylabel() == "|H| [(m/s²)/N]"
    # The crowd damps the peak: the occupied FRF is lower at resonance.
    assert occupied.get_ydata().max() < 0.6 * empty.get_ydata().max()


# ------------------------------------------------------------------------------ Figs. 12, 17, 20
def test_psd_comparison_draws_every_curve(paper_bridge, paper_crowd, paper_msd, welch_grid):
    fitted = response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd,
                          crowd_model="smeared")
    no_hsi = response_psd(paper_bridge, paper_crowd, welch_grid, crowd_model="smeared")
    ax = plotting.plot_psd_comparison({"measured": fitted, "fitted": fitted, "no HSI": no_hsi},
                                      band=(1.0, 3.0))
    assert [line.get_label() for line in ax.get_lines()] == ["measured", "fitted", "no HSI"]
    assert ax.get_lines()[0].get_xdata().min() >= 1.0
    assert ax.get_ylabel() == "Acceleration PSD [(m/s²)²/Hz]"


def test_psd_comparison_leaves_out_the_0_hz_bin(paper_bridge, paper_crowd, welch_grid):
    # Issue 27 §4: a measured record's 0 Hz bin (its offset, e.g. gravity on an accelerometer)
    # set the axis of the estimate's figures and hid the resonance eight decades below it.
    model = response_psd(paper_bridge, paper_crowd, welch_grid, crowd_model="smeared")
    spiked = model.psd.copy()
    spiked[:, 0] = 1e6 * spiked.max()
    measured = ResponsePSD(frequency=model.frequency, psd=spiked,
                           output_names=model.output_names)
    ax = plotting.plot_psd_comparison({"measured": measured}, band=(0.0, 10.0))
    assert ax.get_lines()[0].get_xdata().min() == welch_grid[1]
    # The axis top is the resonance's (×3 headroom), not the spike's.
    assert ax.get_ylim()[1] == pytest.approx(3 * model.psd[0, 1:].max())


# ------------------------------------------------------------------------------ Figs. 4, 10
def _bowl_map(estimate=None):
    frequencies = np.linspace(1.0, 6.0, 11)
    damping_ratios = np.linspace(0.1, 0.8, 8)
    cost = ((frequencies[np.newaxis] - 3.0) ** 2 + (damping_ratios[:, np.newaxis] - 0.3) ** 2
            + 1e-3)
    return ObjectiveMap(frequencies, damping_ratios, cost, cost_no_hsi=10.0, mass_ratio=0.95,
                        estimate=estimate)


def test_objective_map_marks_the_grid_optimum(paper_msd):
    ax = plotting.plot_objective_map(_bowl_map())
    (optimum,) = [line for line in ax.get_lines() if line.get_gid() == "optimum"]
    assert optimum.get_marker() == "o"
    assert optimum.get_xdata()[0] == pytest.approx(3.0)
    assert optimum.get_ydata()[0] == pytest.approx(0.3)
    assert ax.get_xlabel() == "MSD natural frequency $f_{h1}$ [Hz]"
    assert ax.get_ylabel() == "MSD damping ratio $\\xi_{h1}$ [-]"
    colorbar_ax = ax.figure.axes[-1]
    assert colorbar_ax.get_ylabel() == "$J/J_{noHSI}$ [-]"


def test_objective_map_marks_the_estimate_and_the_uncertainty_bounds(paper_msd):
    from crowdvib import MSDModel

    estimate = MSDModel(3.1, 0.32, 0.95)
    summary = {"frequency": {"nominal": 3.1, "bound": 0.2, "bound_percent": 6.45},
               "damping_ratio": {"nominal": 0.32, "bound": 0.05, "bound_percent": 15.6}}
    ax = plotting.plot_objective_map(_bowl_map(estimate), uncertainty=summary,
                                     search_bounds={"frequency": (1.5, 5.0),
                                                    "damping_ratio": (0.05, 0.7)})
    (optimum,) = [line for line in ax.get_lines() if line.get_gid() == "optimum"]
    assert (optimum.get_xdata()[0], optimum.get_ydata()[0]) == (3.1, 0.32)
    bounds = [line for line in ax.get_lines() if line.get_gid() == "uncertainty"]
    assert len(bounds) == 4 and all(line.get_linestyle() == "--" for line in bounds)
    vertical = sorted(line.get_xdata()[0] for line in bounds[:2])
    horizontal = sorted(line.get_ydata()[0] for line in bounds[2:])
    assert vertical == pytest.approx([2.9, 3.3]) and horizontal == pytest.approx([0.27, 0.37])
    (box,) = [p for p in ax.patches if p.get_gid() == "search_bounds"]
    assert box.get_width() == pytest.approx(3.5) and box.get_height() == pytest.approx(0.65)


# ------------------------------------------------------------------------------ Fig. 15
def test_psd_convergence_one_line_per_output_and_the_reference_level():
    convergence = PSDConvergence(n_windows=np.arange(1, 5), duration=60.0 * np.arange(1, 5),
                                 error=np.array([[0.5, 0.2, 0.05, 0.0], [0.4, 0.1, 0.02, 0.0]]),
                                 output_names=("mode1", "mode2"), window_length=60.0,
                                 band=(0.0, 10.0), norm="2")
    ax = plotting.plot_psd_convergence(convergence)
    lines = ax.get_lines()
    assert [line.get_label() for line in lines] == ["mode1", "mode2", "10%"]
    # The last point (0 by construction) is left out; errors are shown in percent.
    assert list(lines[0].get_ydata()) == pytest.approx([50.0, 20.0, 5.0])
    assert ax.get_xlabel() == "Record length k·T [s]" and ax.get_ylabel().endswith("[%]")
    assert ax.get_ylim()[0] == 0.0


# ------------------------------------------------------------------------------ Figs. 11, 19
def _sensitivity():
    cases = [{"name": "nominal", "kind": "nominal", "level": 0, "perturbations": []}]
    for level, scale in ((0, 1.0), (1, 3.0)):
        for sign in (+1, -1):
            cases.append({"name": f"frequencies{sign}", "kind": "individual", "level": level,
                          "perturbations": [["frequencies", sign * 0.01 * (level + 1)]],
                          "delta_frequency": sign * scale, "delta_damping_ratio": -2 * scale})
        cases.append({"name": f"joint{level}", "kind": "joint", "level": level,
                      "perturbations": [["frequencies", 0.01], ["modal_masses", 0.02]],
                      "delta_frequency": 4 * scale, "delta_damping_ratio": 5 * scale})
    cases.append({"name": "broken", "kind": "individual", "level": 0,
                  "perturbations": [["modal_masses", 0.02]], "error": "EstimationError: no"})
    return SensitivityResult(nominal={"frequency": 3.0, "damping_ratio": 0.3}, cases=tuple(cases))


def test_estimation_errors_bars_span_zero_to_the_extremes_per_group_and_level():
    handles = plotting.plot_estimation_errors(_sensitivity())
    frequency_ax, damping_ax = handles.axes
    assert frequency_ax.get_ylabel() == "$\\Delta f_{h1}$ [%]"
    assert damping_ax.get_ylabel() == "$\\Delta \\xi_{h1}$ [%]"
    # The individual groups name their error levels, lower / higher.
    assert [t.get_text() for t in frequency_ax.get_xticklabels()] == [
        "$\\varepsilon_f$\n1 / 2 %", "joint"]
    assert frequency_ax.get_ylim() == pytest.approx((-3.9, 12.9))  # 6 % room for the marks
    bars = frequency_ax.patches
    assert len(bars) == 4                                   # 2 groups × 2 levels
    spans = [(bar.get_y(), bar.get_y() + bar.get_height()) for bar in bars]
    # np.testing rather than pytest.approx: newer pytest refuses nested sequences in approx.
    np.testing.assert_allclose(spans, [(-1.0, 1.0), (-3.0, 3.0), (0.0, 4.0), (0.0, 12.0)],
                               rtol=1e-6, atol=1e-12)
    damping_spans = [(b.get_y(), b.get_y() + b.get_height()) for b in damping_ax.patches]
    assert damping_spans[1] == pytest.approx((-6.0, 0.0))
    assert "1 case(s) failed" in handles.figure.get_suptitle()


def test_estimation_errors_reads_the_json_form_too():
    as_dict = _sensitivity().to_dict()
    handles = plotting.plot_estimation_errors(as_dict)
    assert len(handles.axes[0].patches) == 4


# ------------------------------------------------------------------------------ Figs. 5, 6
def _parametric():
    rows = []
    for f1 in (1.0, 2.0, 3.0):
        for damping in (0.005, 0.02):
            for mass_ratio in (0.05, 0.10):
                for level, epsilon in ((0, 0.01), (1, 0.02)):
                    active = ["damping_ratio:upper"] if (f1 == 3.0 and level == 1) else []
                    rows.append({"structure_frequency": f1, "structure_damping": damping,
                                 "structure_mass_ratio": mass_ratio, "parameter": "frequencies",
                                 "epsilon": epsilon, "level": level,
                                 "frequency_ratio": 1.0 + epsilon * f1,
                                 "damping_ratio_ratio": 1.0 - epsilon * f1,
                                 "active_bounds": active})
    rows.append({"structure_frequency": 1.0, "structure_damping": 0.005,
                 "structure_mass_ratio": 0.05, "parameter": "frequencies", "epsilon": 0.01,
                 "level": 0, "error": "EstimationError: failed"})
    return ParametricResult(rows=tuple(rows), truth={"frequency": 3.0})


def test_parametric_ratios_one_panel_per_quantity_and_mass_ratio_with_active_bounds_filled():
    handles = plotting.plot_parametric_ratios(_parametric())
    assert len(handles.axes) == 4                   # (f ratio, ξ ratio) × 2 mass ratios
    top_left = handles.axes[0]
    assert top_left.get_ylabel() == "$\\hat f_{h1}/f_{h1}$ [-]"
    assert handles.axes[2].get_xlabel() == "Footbridge frequency $f_1$ [Hz]"
    series = [line for line in top_left.get_lines() if line.get_gid() is None
              and line.get_linestyle() == "-" and len(line.get_xdata()) == 3]
    assert len(series) == 4                         # 2 structural damping ratios × 2 levels
    ratios = {tuple(np.round(line.get_ydata(), 6)) for line in series}
    assert (1.01, 1.02, 1.03) in ratios and (1.02, 1.04, 1.06) in ratios
    active = [line for line in top_left.get_lines() if line.get_gid() == "active_bounds"]
    assert len(active) == 2                         # one filled circle per structural damping
    for line in active:
        assert line.get_marker() == "o" and line.get_markerfacecolor() != "none"
        assert list(line.get_xdata()) == [3.0]
    open_circles = [line for line in series if line.get_marker() == "o"]
    assert open_circles and all(line.get_markerfacecolor() == "none" for line in open_circles)


def test_parametric_ratios_refuses_the_wrong_number_of_axes():
    _, axes = plt.subplots(1, 3)
    with pytest.raises(ParameterError, match="axes must hold 4 panels, got 3"):
        plotting.plot_parametric_ratios(_parametric(), axes=axes)


# ------------------------------------------------------------------------------ time history
@dataclass(frozen=True)
class _Record:
    """The documented fields of :class:`crowdvib.Simulation` and nothing else."""

    time: np.ndarray
    acceleration: np.ndarray
    output_names: tuple
    n_on_deck: np.ndarray
    sample_rate: float


def test_time_history_running_rms_of_a_sine_and_people_on_deck():
    sample_rate, amplitude = 100.0, 0.4
    time = np.arange(1000) / sample_rate
    acceleration = np.vstack([amplitude * np.sin(2 * np.pi * 2.0 * time), np.zeros_like(time)])
    n_on_deck = np.minimum(np.arange(1000) // 100, 6)
    record = _Record(time, acceleration, ("midspan", "quarter"), n_on_deck, sample_rate)
    handles = plotting.plot_time_history(record)
    top, bottom = handles.axes
    signal, rms = top.get_lines()
    assert np.array_equal(signal.get_ydata(), acceleration[0])
    values = rms.get_ydata()
    assert np.isnan(values[:99]).all()              # the first window is not full yet
    # A whole number of periods of a sine: RMS = A/√2 exactly.
    assert values[99:] == pytest.approx(amplitude / np.sqrt(2), rel=1e-9)
    assert "max 0.283 m/s²" in rms.get_label()
    (people,) = bottom.get_lines()
    assert people.get_ydata().max() == 6
    assert top.get_ylabel() == "Acceleration [m/s²]"
    assert bottom.get_ylabel() == "People on deck [-]" and bottom.get_xlabel() == "Time [s]"


def test_time_history_of_a_real_simulation_result_and_an_unknown_output():
    time = np.arange(200) / 50.0
    simulation = Simulation(time=time, acceleration=np.ones((1, 200)), output_names=("midspan",),
                            n_on_deck=np.full(200, 3), sample_rate=50.0, seed=1, duration=4.0)
    handles = plotting.plot_time_history(simulation, window=2.0)
    assert handles.axes[0].get_lines()[1].get_ydata()[99:] == pytest.approx(1.0)
    with pytest.raises(ParameterError, match="output must be one of \\['midspan'\\], got 'x'"):
        plotting.plot_time_history(simulation, output="x")


# ------------------------------------------------------------------------------ files
def test_save_and_encode_close_the_figure(tmp_path):
    psd = ResponsePSD(np.linspace(0.1, 5.0, 50), np.ones((1, 50)), ("midspan",))
    path = plotting.save_figure(plotting.plot_psd_comparison({"flat": psd}), tmp_path / "a.svg")
    assert path.read_text(encoding="utf-8").lstrip().startswith("<?xml")
    png = plotting.figure_bytes(plotting.plot_psd_comparison({"flat": psd}), "png")
    assert png.startswith(b"\x89PNG\r\n\x1a\n")
    svg = plotting.figure_bytes(plotting.plot_psd_comparison({"flat": psd}), "svg")
    assert b"<svg" in svg
    assert plt.get_fignums() == []


def test_season_trends_of_failed_rows_draw_without_a_legend_warning():
    # Issue 36 §3: a season whose one row failed printed matplotlib's "No artists with labels
    # found to put in legend". Nothing estimated: no legend, no warning, the row counted.
    import warnings

    rows = [{"name": "record 1", "status": "error", "density": 0.5, "time": None}]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        handles = plotting.plot_season_trends(rows)
    assert handles.axes[0].get_legend() is None
    assert "(1 row(s) not estimated are not shown)" in handles.figure._suptitle.get_text()
    plt.close(handles.figure)


def test_mode_accelerations_of_one_mode_on_whole_numbers_with_the_limit_inside():
    # Issue 36 §3: one mode was drawn on a continuous axis 0.96–1.04 with the UK NA limit on
    # the lower edge. The mode axis has the whole mode numbers; both the limit and the peaks
    # lie inside the axes, which start at 0 (the paper bridge, docs: theory, Design checks).
    from crowdvib import ModalModel
    from crowdvib.design import design_check
    from crowdvib.reporting.design_plots import plot_mode_accelerations

    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3,
                                              outputs={"midspan": 25.0})
    checks = {"ukna": design_check(bridge, "ukna", traffic_class="C")}
    handles = plot_mode_accelerations(checks)
    ax = handles.axes[0]
    assert list(ax.get_xticks()) == [1] and ax.get_xlim() == (0.5, 1.5)
    low, high = ax.get_ylim()
    peak = float(np.max(checks["ukna"].peak_accelerations))
    assert low == 0.0 and high == pytest.approx(1.15 * max(checks["ukna"].limit, peak))
    plt.close(handles.figure)
