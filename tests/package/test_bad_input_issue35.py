"""Issue 35 §2 and §3: an answer in seconds when the input is wrong, and the last silent and
foreign cases.

§2: a unit mistake took the default estimator 7 to more than 25 minutes before it said anything;
now the measured level is checked against what the model reaches with any MSD within the bounds
BEFORE the fit, and a gross mismatch is a DataError naming the likely cause and the value it
would then be (override: ``check_level=False``). The CPU times are measured by
benchmarks/bench_bad_input_speed.py (house rule: no timing in tests). §3: each input that was
read silently wrong, or refused with a foreign exception, now gets a crowdvib error naming the
parameter, the rule and the value, or a warning where the value is legal but suspect.
"""

import json

import numpy as np
import pytest

from crowdvib import (BoundWarning, DataError, ModalModel, MSDModel, ParameterError,
                      PlausibilityWarning, estimate_hsi, psd_convergence, read_record,
                      response_psd, welch_psd)
from crowdvib.cases.results import load_results
from crowdvib.cli import main
from crowdvib.design import TunedMassDamper
from crowdvib.errors import DataWarning
from crowdvib.identification import Estimator
from crowdvib.io import load_case
from crowdvib.io.crowdtable import read_crowd_table
from crowdvib.io.csvtables import read_csv_table
from crowdvib.models.loading import STANDARD_GRAVITY
from crowdvib.models.profile import CrowdProfile
from crowdvib.studies import modelling_error_study, objective_map
from crowdvib.studies.season import season_study
from tests.conftest import copy_paper_case
from tests.io.test_bad_input_files import BEAM
# One simulated hour of the paper example as a Welch estimate, and a PSD read k times too large.
from tests.package.test_plausibility import _scaled as scaled, measured  # noqa: F401

pytestmark = pytest.mark.badinput

SIGNAL = np.random.default_rng(35).normal(size=(1, 6000))   # 60 s at 100 Hz


def beam(**changes):
    """The paper's bridge with one value changed (its PlausibilityWarning expected)."""
    values = dict(span=50.0, width=3.0, frequency=2.0, damping_ratio=0.005, modal_mass=50e3)
    with pytest.warns(PlausibilityWarning):
        return ModalModel.simply_supported_beam(**dict(values, **changes))


# ---------------------------------------------------------------- §2: a fast answer, diagnosed
# (label, the measured PSD's factor, error, message: the likely cause and the value it would be)
LEVELS = [
    ("PSD x 9.81²: m/s² declared as g", STANDARD_GRAVITY**2, DataError,
     r"measured/model from 'midspan': 3\d\.?\d* to .*a record in m/s² declared as g\? \(read so, "
     r"measured/model would be 0\.3\d* to 1\.\d*\)"),
    ("PSD / 9.81²: g read as m/s²", STANDARD_GRAVITY**-2, DataError,
     r"a record in g read as m/s²\? \(read so, measured/model would be 0\.3\d* to"),
    ("PSD x 1e6: mm/s² read as m/s²", 1e6, DataError,
     r"3\.\d*e\+05 to .*a record in mm/s² read as m/s²\? \(read so, measured/model would be 0\.3"),
]


@pytest.mark.parametrize("label, factor, error, pattern", LEVELS, ids=[c[0] for c in LEVELS])
def test_a_wrong_level_is_refused_before_the_fit(measured, paper_bridge, paper_crowd, label,
                                                 factor, error, pattern):
    with pytest.raises(error, match=pattern) as caught:
        estimate_hsi(scaled(measured, factor), paper_bridge, paper_crowd, band=(0.0, 10.0))
    assert "check_level=False" in str(caught.value)          # the override is named


def test_structure_frequency_in_rad_s_is_refused_naming_it(measured, paper_crowd):
    bridge = beam(frequency=4 * np.pi)
    with pytest.raises(DataError, match=r"measured PSD level must be one the model reaches.*"
                       r"frequencies\[0\] = 12\.5664 Hz .*rad/s instead of Hz\? "
                       r"\(12\.5664 rad/s is 2 Hz\)"):
        estimate_hsi(measured, bridge, paper_crowd, band=(0.0, 10.0))


@pytest.mark.parametrize("damping", [0.5, 0.6])
def test_structure_damping_far_outside_plausible_is_refused(measured, paper_crowd, damping):
    # The hard tier of the plausible ranges: ξ > 0.2 (60 % is no bridge); 0.5 meant as 0.5 %.
    bridge = beam(damping_ratio=damping)
    with pytest.raises(ParameterError, match=rf"structure: damping_ratios\[0\] = {damping:g} "
                       r"is above 0\.1.*percent instead of fraction\? .*far above any "
                       r"plausible value \(> 0\.2\).*check_level=False"):
        estimate_hsi(measured, bridge, paper_crowd, band=(0.0, 10.0))


def test_the_joint_estimate_checks_every_record(measured, paper_bridge, paper_crowd):
    with pytest.raises(DataError, match=r"record in m/s² declared as g"):
        from crowdvib import estimate_hsi_joint
        estimate_hsi_joint([measured, scaled(measured, STANDARD_GRAVITY**2)], paper_bridge,
                           [paper_crowd, paper_crowd], band=(0.0, 10.0))


@pytest.mark.filterwarnings("ignore::crowdvib.errors.BoundWarning")
def test_check_level_false_fits_anyway_and_warns_after(measured, paper_bridge, paper_crowd):
    # The override: the fit runs, and the diagnosis after it still names the mix-up.
    with pytest.warns(PlausibilityWarning, match="record in m/s² declared as g"):
        estimate_hsi(scaled(measured, STANDARD_GRAVITY**2), paper_bridge, paper_crowd,
                     band=(0.0, 10.0), method="least_squares", interval=None,
                     check_level=False)


def test_check_level_must_be_a_boolean(measured, paper_bridge, paper_crowd):
    with pytest.raises(ParameterError, match=r"check_level must be True or False, got 'no'"):
        estimate_hsi(measured, paper_bridge, paper_crowd, band=(0.0, 10.0), check_level="no")


def test_the_case_file_key_check_level_is_read(tmp_path):
    path = copy_paper_case(tmp_path)
    path.write_text(path.read_text().replace("[estimation]\n",
                                             "[estimation]\ncheck_level = false\n", 1))
    assert load_case(path).estimation.check_level is False


def test_a_fit_ending_on_a_bound_gets_no_profile_interval(measured, paper_bridge, paper_crowd):
    # The truth is 3 Hz; a search bound at 2.5 Hz holds the estimate there. Its profile would run
    # along the bound: NaN ends and a BoundWarning saying why (the other parameter keeps its).
    with pytest.warns(BoundWarning) as caught:
        fit = estimate_hsi(measured, paper_bridge, paper_crowd, band=(0.0, 10.0),
                           method="least_squares", bounds={"frequency": (0.5, 2.5)})
    assert fit.active_bounds == ("frequency:upper",)
    assert np.isnan(fit.intervals["frequency"]).all()
    assert np.isfinite(fit.intervals["damping_ratio"]).all()
    assert "frequency:upper" in fit.interval_on_bound
    assert "no interval: the estimate sits on a search bound" in fit.summary().splitlines()[0]
    assert any("no 95% interval for frequency:upper (NaN ends): the estimate sits on that "
               "search bound" in str(w.message) for w in caught)
    back = type(fit).from_dict(json.loads(json.dumps(fit.to_dict()).replace("NaN", "null")))
    assert np.isnan(back.intervals["frequency"]).all()


def _wide_csv(tmp_path, columns=100_000):
    path = tmp_path / "wide.csv"
    path.write_text(",".join(f"c{i}" for i in range(columns)) + "\n"
                    + "\n".join(",".join(["0.01"] * columns) for _ in range(3)) + "\n")
    return path


def test_a_csv_of_100000_columns_is_refused_as_transposed(tmp_path):
    with pytest.raises(DataError, match=r"must hold at most 1000 channels .*got 100000 channels "
                       r"of 3 sample\(s\) each: is the file transposed"):
        read_record(_wide_csv(tmp_path), sample_rate=100.0)


def test_init_refuses_a_transposed_csv_instead_of_drafting_placeholders(tmp_path, capsys):
    path = _wide_csv(tmp_path)
    assert main(["init", str(path)]) != 0
    assert "is the file transposed" in capsys.readouterr().err
    assert not list(tmp_path.glob("*.toml"))


# ------------------------------------------------------------------------- §3: silent cases
def test_msd_given_an_array_for_a_scalar_is_refused():
    with pytest.raises(ParameterError, match=r"frequency must be one number, got list of shape "
                       r"\(2,\)"):
        MSDModel([3.0, 4.0], 0.3, 0.95)


def test_a_half_kilogram_damper_warns():
    with pytest.warns(PlausibilityWarning, match=r"mass = 0\.5 kg is below 10 kg, unusual for a "
                      r"footbridge's tuned mass damper: tonnes instead of kg\? \(0\.5 t is "
                      r"500 kg\)"):
        TunedMassDamper(0.5, 1.9, 0.08, 25.0)


def test_a_csv_cell_of_1e308_is_refused(tmp_path):
    path = tmp_path / "huge.csv"
    path.write_text("time,a\n" + "\n".join(f"{i / 100},{1e308 if i == 5 else 0.01}"
                                           for i in range(100)))
    with pytest.raises(DataError, match=r"channel 'a': samples must be below 1e\+100 in "
                       r"magnitude, got 1e\+308 at sample index 5"):
        read_record(path)


def _record(tmp_path, values, name="r.csv"):
    path = tmp_path / name
    path.write_text("time,a\n" + "\n".join(f"{i / 100},{float(v)!r}"
                                           for i, v in enumerate(values)))
    return path


def test_one_column_read_as_two_channels_is_refused(tmp_path):
    path = _record(tmp_path, [0.01, -0.01] * 50)
    with pytest.raises(DataError, match=r"channels must each be read once, got channel 'a' for "
                       r"both 'x' and 'y'"):
        read_record(path, channels={"x": "a", "y": "a"})


def test_a_modal_table_with_a_duplicated_column_is_refused(tmp_path):
    path = tmp_path / "modes.csv"
    path.write_text("frequency,damping_ratio,frequency\n2.0,0.005,2.1\n")
    with pytest.raises(DataError, match=r"column names must be unique, got 'frequency' as "
                       r"columns 1 and 3"):
        read_csv_table(path)


def test_n_modes_of_2_5_is_refused(tmp_path):
    path = tmp_path / "beam.toml"
    path.write_text(BEAM.replace("modal_mass = 50e3\n", "modal_mass = 50e3\nn_modes = 2.5\n"))
    with pytest.raises(ParameterError, match=r"beam.toml: structure.n_modes must be a positive "
                       r"integer, got 2.5"):
        load_case(path)


def test_units_g_on_a_record_with_the_gravity_offset_in_m_s2_is_refused(tmp_path):
    rng = np.random.default_rng(3)
    path = _record(tmp_path, STANDARD_GRAVITY + 0.05 * rng.normal(size=200))
    with pytest.raises(DataError, match=r"channel 'a': units 'g' must not hold a mean of 9\.81 "
                       r"g .*gravity offset in m/s²; declare units 'm/s2'"):
        read_record(path, units="g")


def test_units_g_on_a_record_of_m_s2_level_warns(tmp_path):
    rng = np.random.default_rng(4)
    path = _record(tmp_path, 3.0 * rng.normal(size=200))
    with pytest.warns(PlausibilityWarning, match=r"RMS \d\.\d+ g is above 1 g, unusual for a "
                      r"footbridge .*m/s² declared as g\?"):
        read_record(path, units="g")


def test_a_counts_table_wholly_after_the_record_is_doubted():
    profile = CrowdProfile.from_counts([700.0, 800.0], [10.0, 20.0], 150.0)
    notes = profile.implausibilities(600.0)
    assert len(notes) == 1 and "start at 700 s, after the 600 s record ends" in notes[0]


def _skip(payload):           # never called: every row is skipped
    raise AssertionError


def test_a_season_whose_densities_are_all_zero_warns(paper_bridge):
    windows = [(f"night{i}", None, {"density": 0.0,
                                    "skipped": "no crowd on the deck: nothing to estimate"})
               for i in range(3)]
    with pytest.warns(DataWarning, match=r"no row of the season was estimated: all 3 row\(s\) "
                      r"were skipped \(no crowd on the deck"):
        season_study(windows, _skip, paper_bridge, estimator=Estimator(band=(0.0, 10.0)))


def test_crowd_tables_read_semicolons_and_decimal_commas(tmp_path):
    path = tmp_path / "crowd.csv"
    path.write_text("record;count;step_frequency_mean;time\n"
                    "day1.npz;42;1,85;2026-05-04T08:00\n")
    row = read_crowd_table(path).rows[0]
    assert (row.record, row.count, row.step_frequency_mean) == ("day1.npz", 42.0, 1.85)


def test_counts_tables_read_semicolons_and_decimal_commas(tmp_path):
    path = tmp_path / "counts.csv"
    path.write_text("time;count\n0;12\n300,5;30\n")
    header, rows = read_csv_table(path)
    assert header == ["time", "count"] and rows == [["0", "12"], ["300.5", "30"]]


# ------------------------------------------------------------------------ §3: foreign errors
@pytest.fixture
def model_psd(paper_bridge, paper_crowd, paper_msd, welch_grid):
    return response_psd(paper_bridge, paper_crowd, welch_grid, msd=paper_msd,
                        welch_window_length=60.0)


#: The default estimator over 0–10 Hz, as the studies take it.
BAND = Estimator(band=(0, 10))
FOREIGN = [
    ("estimate_hsi: outputs an int", lambda b, c, p: estimate_hsi(p, b, c, band=(0, 10),
                                                                  outputs=3),
     r"outputs must be a sequence of str, got int 3"),
    ("estimate_hsi: bounds a list", lambda b, c, p: estimate_hsi(p, b, c, band=(0, 10),
                                                                 bounds=[(1, 2)]),
     r"bounds must be a dict of parameter → \(lower, upper\) or None, got list"),
    ("estimate_hsi: bounds a string", lambda b, c, p: estimate_hsi(p, b, c, band=(0, 10),
                                                                   bounds="abc"),
     r"bounds must be a dict .* got str 'abc'"),
    ("estimate_hsi: damping bound above 2",
     lambda b, c, p: estimate_hsi(p, b, c, band=(0, 10), bounds={"damping_ratio": (0.01, 3.0)}),
     r"bounds\['damping_ratio'\] must stay below 2, the MSD's own limit .*got \(0\.01, 3\.0\)"),
    ("welch_psd: output_names an int",
     lambda b, c, p: welch_psd(SIGNAL, 100.0, window_length=10.0, output_names=5),
     r"output_names must be a sequence of str, got int 5"),
    ("welch_psd: output_names of ints",
     lambda b, c, p: welch_psd(SIGNAL, 100.0, window_length=10.0, output_names=[5]),
     r"output_names must hold names \(str\), got int 5"),
    ("welch_psd: overlap a string",
     lambda b, c, p: welch_psd(SIGNAL, 100.0, window_length=10.0, overlap="half"),
     r"overlap must be numeric, got 'half'"),
    ("welch_psd: overlap None",
     lambda b, c, p: welch_psd(SIGNAL, 100.0, window_length=10.0, overlap=None),
     r"overlap must be numeric, got None"),
    ("welch_psd: overlap a list",
     lambda b, c, p: welch_psd(SIGNAL, 100.0, window_length=10.0, overlap=[0.5]),
     r"overlap must be one number, got list"),
    ("welch_psd: lowpass a cut-off",
     lambda b, c, p: welch_psd(SIGNAL, 100.0, window_length=10.0, lowpass=10.0),
     r"lowpass must be a LowPassFilter or None, got float"),
    ("psd_convergence: overlap a string",
     lambda b, c, p: psd_convergence(SIGNAL, 100.0, window_length=10.0, overlap="x"),
     r"overlap must be numeric, got 'x'"),
    ("psd_convergence: lowpass a cut-off",
     lambda b, c, p: psd_convergence(SIGNAL, 100.0, window_length=10.0, lowpass=5.0),
     r"lowpass must be a LowPassFilter or None, got float"),
    ("psd_convergence: output_names an int",
     lambda b, c, p: psd_convergence(SIGNAL, 100.0, window_length=10.0, output_names=1),
     r"output_names must be a sequence of str, got int 1"),
    ("response_psd: outputs an int",
     lambda b, c, p: response_psd(b, c, p.frequency, outputs=3),
     r"outputs must be a sequence of str, got int 3"),
    ("response_psd: lowpass a cut-off",
     lambda b, c, p: response_psd(b, c, p.frequency, lowpass=10.0),
     r"lowpass must be a LowPassFilter or None, got float"),
    ("modelling_error_study: the estimator's options as a dict",
     lambda b, c, p: modelling_error_study(p, b, c, estimator={"band": (0, 10)}),
     r"estimator must be a crowdvib.identification.Estimator .* got dict"),
    ("modelling_error_study: levels a list",
     lambda b, c, p: modelling_error_study(p, b, c, estimator=BAND, levels=[0.1]),
     r"levels must be a dict of parameter → error fractions or None, got list"),
    ("modelling_error_study: levels a string",
     lambda b, c, p: modelling_error_study(p, b, c, estimator=BAND, levels="paper"),
     r"levels must be a dict .* got str 'paper'"),
    ("modelling_error_study: store an int",
     lambda b, c, p: modelling_error_study(p, b, c, estimator=BAND.replace(method="least_squares"),
                                           store=3),
     r"store must be a folder \(str or path\), a TaskStore or None, got int 3"),
    ("objective_map: estimate a string",
     lambda b, c, p: objective_map(p, b, c, frequencies=[2, 3], damping_ratios=[0.2, 0.3],
                                   estimator=BAND, estimate="x"),
     r"estimate must be an MSDModel, an HSIEstimate or None, got str"),
    ("objective_map: outputs an int",
     lambda b, c, p: objective_map(p, b, c, frequencies=[2, 3], damping_ratios=[0.2, 0.3],
                                   estimator=BAND.replace(outputs=3)),
     r"outputs must be a sequence of str, got int 3"),
]


@pytest.mark.parametrize("label, call, pattern", FOREIGN, ids=[c[0] for c in FOREIGN])
def test_wrong_types_get_a_crowdvib_error(paper_bridge, paper_crowd, model_psd, label, call,
                                          pattern):
    with pytest.raises(ParameterError, match=pattern):
        call(paper_bridge, paper_crowd, model_psd)


def test_load_results_of_deeply_nested_json_is_refused(tmp_path):
    path = tmp_path / "results.json"
    path.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(DataError, match=r"is not a crowdvib results.json: its JSON is nested "
                       r"deeper than Python's recursion limit"):
        load_results(path)


def test_modes_from_a_results_json_that_is_a_list_is_refused(tmp_path, capsys):
    case = copy_paper_case(tmp_path / "case")
    modes = tmp_path / "modes"
    modes.mkdir()
    (modes / "results.json").write_text("[1, 2, 3]")
    assert main(["sensitivity", str(case), "--modes-from", str(modes), "--out",
                 str(tmp_path / "out")]) != 0
    err = capsys.readouterr().err
    assert "is not the results.json of `crowdvib modes`" in err
    assert "bug in crowdvib" not in err
