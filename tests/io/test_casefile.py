"""Case files and modal models from CSV files (issue 4)."""

from pathlib import Path

import numpy as np
import pytest

from crowdvib import Crowd, MSDModel, ModalModel, response_psd
from crowdvib.io.casefile import load_case, read_modal_model, write_modal_model
from crowdvib.errors import ParameterError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

BEAM_CASE = """
name = "beam"
[structure]
type = "simply_supported_beam"
span = 50.0
width = 3.0
frequency = 2.0
damping_ratio = 0.005
modal_mass = 50e3
outputs = {{ midspan = 25.0 }}
[crowd]
density = {density}
walking_speed = 1.30
step_frequency_mean = 1.89
body_mass = 70.0
{extra}
"""


def write_case(tmp_path, density=0.5, extra="", name="eeklo_like.toml"):
    path = tmp_path / name
    path.write_text(BEAM_CASE.format(density=density, extra=extra))
    return path


def test_beam_case_loads_with_defaults(tmp_path):
    case = load_case(write_case(tmp_path))
    assert case.structure.output_names == ("midspan",)
    assert case.crowd.step_frequency_std == 0.175     # AFGC default (docs: theory, Design-guide load models)
    assert case.msd == MSDModel(3.0, 0.30, 0.95)
    assert case.estimation.band == (0.0, 10.0)
    assert case.measurement.lowpass_cutoff == 10.0   # the paper's 10 Hz filter


def test_error_names_file_key_rule_and_value(tmp_path):
    # The issue's own example of a message.
    with pytest.raises(ParameterError, match=r"^eeklo_like.toml: crowd.density must be > 0, "
                                             r"got -0.5$"):
        load_case(write_case(tmp_path, density=-0.5))


@pytest.mark.parametrize("extra, message", [
    ("[hsi]\ndamping_ratio = 30", r"hsi.damping_ratio must be > 0 and < 2 \(fractions, not "
                                  r"percent\), got 30"),
    ("[hsi]\nmass_ratio = 95", r"hsi.mass_ratio must lie in \(0, 1\)"),
    ("[estimation]\nband = [8.0, 2.5]", r"estimation.band must have lower < upper"),
    ("[estimation]\nband = [2.5, 8.0]\noutputs = [\"nowhere\"]", r"output name must be one of"),
    ("[estimation]\nband = [2.5, 8.0]\nweights = [1.0]", r"estimation.weights must give one "
                                                         r"weight per entry"),
    ("[measurement]\nwindow_length = -25", r"measurement.window_length must be > 0, got -25"),
    ("[measurement]\nfilter = { cutoff = 10, order = 2.5 }", r"measurement.filter.order must "
                                                             r"be an integer"),
    ("[measurement]\ntime_frame = [-1, 10]", r"measurement.time_frame must start at t >= 0"),
    ("[measurement]\nunits = \"µg\"", r"measurement.units must be 'm/s2', 'g', 'mg' or 'mm/s2'"),
    ("[simulation]\nformats = [\"xls\"]", r"simulation.formats must list formats among"),
    ("[estimation]\nband = [2, 6]\n[estimation.bounds]\nfrequency = [0, 10]",
     r"estimation.bounds.frequency must have a lower bound > 0"),
    ("[crowd2]\ndensity = 1", r"unknown key\(s\) \['crowd2'\]"),
    ("[estimation]\nband = [0, 10]\nmethod = \"whittle\"", r"estimation.method must be one of"),
    ("[estimation]\nband = [0, 10]\nlevel = 95",
     r"estimation.level must lie in \(0, 1\) \(a fraction, not percent\), got 95"),
    ("[estimation]\nband = [0, 10]\n"
     "free_parameters = [\"frequency\", \"damping_ratio\", \"step_frequency_mean\"]",
     r"estimation.free_parameters must be .* optionally both \"step_frequency_mean\" and"),
])
def test_bad_values_point_at_the_key(tmp_path, extra, message):
    with pytest.raises(ParameterError, match=r"eeklo_like.toml: .*" + message):
        load_case(write_case(tmp_path, extra=extra))


def test_missing_section_and_file(tmp_path):
    path = tmp_path / "c.toml"
    path.write_text("[crowd]\ndensity = 0.5\n")
    with pytest.raises(ParameterError, match=r"c.toml: structure is required"):
        load_case(path)
    path.write_text("[structure]\nmodal_table = \"nope.csv\"\nmode_shapes = \"s.csv\"\n"
                    "width = 3.0\n[crowd]\ndensity = 0.5\n")
    with pytest.raises(ParameterError, match=r"c.toml: structure.modal_table names a file that "
                                             r"does not exist: 'nope.csv'"):
        load_case(path)
    path.write_text("not = [toml")
    with pytest.raises(ParameterError, match="not valid TOML"):
        load_case(path)


def _two_lane_bridge():
    x = np.linspace(0.0, 25.0, 51)
    lanes = np.array([0.0, 3.45, 6.9])
    sine = np.sin(np.pi * x / 25.0)
    shapes = np.stack([np.stack([sine, sine * (2 * y / 6.9 - 1)], axis=-1) for y in lanes])
    return ModalModel([3.3, 4.14], [0.0086, 0.0025], [4e4, 2e4], x, shapes, 6.9,
                      ("bending", "torsion"), [[1.0, 0.0], [1.0, 1.0]], lanes=lanes)


def test_mass_normalised_export_and_unity_table_give_the_same_physics(tmp_path):
    # docs: theory, Conventions: every formula is invariant to the mode scaling if m_j matches it.
    bridge = _two_lane_bridge()
    write_modal_model(bridge, tmp_path / "unity_modes.csv", tmp_path / "unity_shapes.csv",
                      tmp_path / "unity_points.csv")
    fe = bridge.mass_normalised()
    write_modal_model(fe, tmp_path / "fe_modes.csv", tmp_path / "fe_shapes.csv",
                      tmp_path / "fe_points.csv")
    unity = read_modal_model(tmp_path / "unity_modes.csv", tmp_path / "unity_shapes.csv",
                             width=6.9, output_points=tmp_path / "unity_points.csv")
    normalised = read_modal_model(tmp_path / "fe_modes.csv", tmp_path / "fe_shapes.csv",
                                  width=6.9, output_points=tmp_path / "fe_points.csv")
    np.testing.assert_allclose(normalised.modal_masses, 1.0)
    np.testing.assert_allclose(unity.lanes, [0.0, 3.45, 6.9])
    crowd = Crowd(1.0, 1.06, 1.68, 0.13, 72.0)
    frequency = np.arange(1, 601) / 60
    a = response_psd(unity, crowd, frequency, msd=MSDModel(), crowd_model="smeared")
    b = response_psd(normalised, crowd, frequency, msd=MSDModel(), crowd_model="smeared")
    np.testing.assert_allclose(b.psd, a.psd, rtol=1e-8)
    np.testing.assert_allclose(unity.modal_mass_ratios(1.0, 72.0),
                               normalised.modal_mass_ratios(1.0, 72.0), rtol=1e-8)


def test_outputs_by_position_interpolate_the_shapes(tmp_path):
    bridge = _two_lane_bridge()
    write_modal_model(bridge, tmp_path / "m.csv", tmp_path / "s.csv")
    model = read_modal_model(tmp_path / "m.csv", tmp_path / "s.csv", width=6.9,
                             outputs={"centre": 12.5, "edge": [12.5, 6.9]})
    np.testing.assert_allclose(model.output_shapes, [[1.0, 0.0], [1.0, 1.0]], atol=1e-12)
    with pytest.raises(ParameterError, match="give exactly one of outputs"):
        read_modal_model(tmp_path / "m.csv", tmp_path / "s.csv", width=6.9)
    with pytest.raises(ParameterError, match=r"outputs\['far'\] must lie on the walkway"):
        read_modal_model(tmp_path / "m.csv", tmp_path / "s.csv", width=6.9, outputs={"far": 40})


def test_modal_csv_errors(tmp_path):
    (tmp_path / "m.csv").write_text("frequency,damping_ratio\n2.0,0.005\n")
    (tmp_path / "s.csv").write_text("position,mode_1\n0,0\n50,0\n")
    with pytest.raises(ParameterError, match=r"m.csv: missing column\(s\) \['modal_mass'\]"):
        read_modal_model(tmp_path / "m.csv", tmp_path / "s.csv", width=3.0, outputs={"a": 1})
    (tmp_path / "m.csv").write_text("frequency,damping_ratio,modal_mass\n2.0,0.5,1e4\n")
    (tmp_path / "s.csv").write_text("position,mode_1,mode_2\n0,0,0\n50,0,0\n")
    with pytest.raises(ParameterError, match=r"s.csv: must have one column per mode"):
        read_modal_model(tmp_path / "m.csv", tmp_path / "s.csv", width=3.0, outputs={"a": 1})


@pytest.mark.parametrize("name", ["paper_example", "eeklo_like", "waalse_krook_like"])
def test_example_cases_load(name):
    case = load_case(EXAMPLES / f"{name}.toml")
    assert case.measurement.files and all(f.is_file() for f in case.measurement.files)
    assert {"frequency", "damping_ratio", "mass_ratio"} <= set(case.expected)
    assert case.inputs()["name"] == case.name


def test_eeklo_like_mass_ratios_follow_the_paper():
    # docs: theory, The paper's case studies (paper, Table 1, 0.50 persons/m², %) with the paper's 73.2 kg.
    case = load_case(EXAMPLES / "eeklo_like.toml")
    table = [0.7, 10.5, 2.7, 0.4, 11.2, 3.3, 2.4, 11.4, 2.4, 1.7, 13.0, 1.1, 2.2, 0.6]
    np.testing.assert_allclose(100 * case.structure.modal_mass_ratios(0.5, 73.2), table,
                               rtol=1e-6)
    np.testing.assert_allclose(case.structure.frequencies[[0, 1, 4, 7]], [1.69, 2.97, 5.68, 6.42])
    assert case.structure.length == pytest.approx(96.0)


def test_waalse_krook_like_follows_the_paper():
    # docs: theory, The paper's case studies: 25 m × 6.9 m, 3.30 Hz 0.86 %, 4.14 Hz 0.25 %, μ_m 5.8 % / 5.7 % at 1 p/m².
    case = load_case(EXAMPLES / "waalse_krook_like.toml")
    s = case.structure
    assert (s.length, s.width) == (25.0, 6.9)
    np.testing.assert_allclose(s.frequencies, [3.30, 4.14])
    np.testing.assert_allclose(s.damping_ratios, [0.0086, 0.0025])
    np.testing.assert_allclose(100 * s.modal_mass_ratios(1.0, 72.0), [5.8, 5.7], rtol=1e-6)
    assert s.lanes.size > 1


def test_load_measurement_frame_units_resample_and_channel_map(tmp_path):
    from crowdvib.io.casefile import load_measurement
    rate = 100.0
    t = np.arange(int(300 * rate)) / rate
    signal = 0.01 * np.sin(2 * np.pi * 1.9 * t) + 0.002   # [g], with an offset to detrend
    (tmp_path / "logger.csv").write_text(
        "acc_3\n" + "\n".join(f"{v:.9g}" for v in signal) + "\n")
    extra = ('[measurement]\nfiles = ["logger.csv"]\nsample_rate = 100.0\nunits = "g"\n'
             'channels = { midspan = "acc_3" }\ntime_frame = [60.0, 240.0]\nresample = 25.0\n')
    record = load_measurement(load_case(write_case(tmp_path, extra=extra)))
    assert record.channel_names == ("midspan",)
    assert record.sample_rate == 25.0 and record.duration == pytest.approx(180.0)
    assert record.start_time == pytest.approx(60.0)
    assert abs(record.data.mean()) < 1e-4     # offset 0.0196 m/s² removed (constant detrend)
    assert np.std(record.data) == pytest.approx(0.01 * 9.81 / np.sqrt(2), rel=0.01)  # g → m/s²


def test_load_measurement_needs_the_records(tmp_path):
    from crowdvib.io.casefile import load_measurement
    case = load_case(write_case(tmp_path, extra='[measurement]\nfiles = ["none.npz"]\n'))
    with pytest.raises(ParameterError, match=r"measurement.files\[0\] names a file that does "
                                             r"not exist"):
        load_measurement(case)


def test_estimation_method_and_interval_keys(tmp_path):
    # The estimator and its uncertainty are chosen in [estimation] (docs: case files).
    extra = '[estimation]\nband = [0, 10]\nmethod = "likelihood"\ninterval = "wald"\nlevel = 0.9'
    case = load_case(write_case(tmp_path, extra=extra))
    assert (case.estimation.method, case.estimation.interval) == ("likelihood", "wald")
    assert case.estimation.level == 0.9
    defaults = load_case(write_case(tmp_path, name="plain.toml")).estimation
    assert (defaults.method, defaults.interval, defaults.level) == ("likelihood", "profile",
                                                                    0.95)


def test_estimator_not_stated_is_the_default_and_least_squares_the_papers(tmp_path):
    # docs: theory, The default estimator — one table (crowdvib._estimators) for the API and
    # case files: the likelihood with the fluctuating crowd and the step frequencies fitted;
    # method = "least_squares" alone is the paper's (smeared crowd, crowd as given).
    steps = ("frequency", "damping_ratio", "step_frequency_mean", "step_frequency_std")
    plain = load_case(write_case(tmp_path, name="plain.toml")).estimation
    assert (plain.method, plain.crowd_model, plain.free_parameters) == (
        "likelihood", "fluctuating", steps)
    paper = load_case(write_case(tmp_path, name="paper.toml", extra=(
        '[estimation]\nband = [0, 10]\nmethod = "least_squares"'))).estimation
    assert (paper.method, paper.crowd_model, paper.free_parameters) == (
        "least_squares", "smeared", steps[:2])
    # A stated choice is kept: the likelihood at the crowd as given, with the smeared model.
    held = load_case(write_case(tmp_path, name="held.toml", extra=(
        '[estimation]\nband = [0, 10]\ncrowd_model = "smeared"\n'
        'free_parameters = ["frequency", "damping_ratio"]'))).estimation
    assert (held.method, held.crowd_model, held.free_parameters) == (
        "likelihood", "smeared", steps[:2])


def test_step_frequencies_can_be_fitted_with_the_msd(tmp_path):
    # docs: theory, Step frequencies fitted with the MSD — both crowd parameters or neither.
    case = load_case(write_case(tmp_path, extra=(
        "[estimation]\nband = [0, 10]\nmethod = \"likelihood\"\nfree_parameters = "
        "[\"frequency\", \"damping_ratio\", \"step_frequency_mean\", \"step_frequency_std\"]\n"
        "[estimation.bounds]\nstep_frequency_mean = [1.5, 2.5]")))
    assert "step_frequency_std" in case.estimation.free_parameters
    assert case.estimation.bounds == {"step_frequency_mean": (1.5, 2.5)}
