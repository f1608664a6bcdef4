"""`crowdvib init RECORD` end to end (issue 27 §2): a CSV as an engineer's logger writes it (a
header row, a ``Time [s]`` column, values in g with the gravity offset, no stated sample rate)
→ findings on the console and a case-file draft → only its placeholders replaced by the paper
example's values (docs: theory, The paper's numerical example) → ``crowdvib estimate`` runs.
"""

import json
import re

import numpy as np
import pytest

from crowdvib import ModalModel, load_case, response_psd
from crowdvib.cli import main
from crowdvib.errors import ParameterError
from crowdvib.io.draft import PLACEHOLDER, inspect_record
from crowdvib.models.examples import paper_example
from crowdvib.models.loading import STANDARD_GRAVITY
from crowdvib.signals.synthesis import gaussian_record, record_frequencies

# Ten minutes at 25 Hz (the paper record's rate): fast, and 19 Welch windows of 60 s.
RATE, DURATION = 25.0, 600.0
#: The paper example's values for every placeholder of the draft (examples/paper_example.toml).
PAPER = {"span": "50.0", "width": "3.0", "frequency": "2.0", "damping_ratio": "0.005",
         "modal_mass": "50e3", '"midspan"': "25.0", "density": "0.5", "band": "[0.0, 10.0]"}


@pytest.fixture(scope="module")
def logger_csv(tmp_path_factory):
    """The paper example's midspan response (model PSD, Gaussian), in g plus the 1 g offset of
    a vertical accelerometer, written as a logger does: time stamps, no stated rate."""
    folder = tmp_path_factory.mktemp("init")
    example = paper_example()
    bridge = ModalModel.simply_supported_beam(50.0, 3.0, 2.0, 0.005, 50e3,
                                              outputs={"midspan": 25.0})
    psd = response_psd(bridge, example.crowd, record_frequencies(DURATION, RATE),
                       msd=example.msd, crowd_model="smeared").psd
    in_g = gaussian_record(psd, RATE, rng=7)[0] / STANDARD_GRAVITY + 1.0
    path = folder / "bridge.csv"
    np.savetxt(path, np.c_[np.arange(in_g.size) / RATE, in_g], delimiter=",", fmt="%.6f",
               header="Time [s],midspan", comments="")
    return path


def _fill(text, values):
    """The draft with each placeholder of ``values``' keys replaced, nothing else edited."""
    for key, value in values.items():
        text, count = re.subn(rf'(?m)^({re.escape(key)} = )"{PLACEHOLDER}[^"\n]*"',
                              lambda m: m.group(1) + value, text)
        assert count == 1, key
    return text


@pytest.fixture(scope="module")
def drafted(logger_csv):
    """(draft path, stdout) of `crowdvib init` on the logger's CSV."""
    import contextlib
    import io

    output = io.StringIO()
    with contextlib.redirect_stdout(output):
        assert main(["init", str(logger_csv)]) == 0
    return logger_csv.with_suffix(".toml"), output.getvalue()


def test_init_finds_time_column_rate_length_and_g(logger_csv, drafted):
    # Issue 27 §2: the columns, the time column, the rate from the time stamps, the length and
    # the units guess from the gravity offset (mean 1 → g).
    found = inspect_record(logger_csv)
    assert found.channel_names == ("midspan",) and found.time_column == "Time [s]"
    assert found.rate_source == "time stamps"
    assert found.sample_rate == pytest.approx(RATE, rel=1e-9)
    assert found.n_samples == RATE * DURATION and found.duration == pytest.approx(DURATION)
    assert found.units == "g" and "gravity offset" in found.units_reason
    (channel,) = found.channels
    assert channel.mean == pytest.approx(1.0, abs=0.01)        # the 1 g offset
    # RMS of the model response in g (the paper example's midspan: ~0.3 m/s²)
    assert 0.01 < channel.rms < 0.1
    path, printed = drafted
    assert path.is_file()
    assert "column 'Time [s]'; sample rate 25 Hz from the time stamps" in printed
    assert "15000 samples, 600 s" in printed and "units        g:" in printed
    assert f"crowdvib estimate {path}" in printed


def test_init_never_overwrites(logger_csv, drafted, capsys):
    # Issue 27 §2 "Never overwrites": a second run refuses in one line naming the file (exit 1,
    # as every command's refusals), and the draft stays byte for byte.
    path, _ = drafted
    before = path.read_bytes()
    assert main(["init", str(logger_csv)]) == 1
    assert main(["init", str(logger_csv), "-o", str(logger_csv)]) == 1     # nor the record
    errors = capsys.readouterr().err.strip().splitlines()
    assert errors == [f"crowdvib init: error: {path} exists: crowdvib init never overwrites a "
                      "file; choose another name with -o or remove it",
                      f"crowdvib init: error: {logger_csv} exists: crowdvib init never "
                      "overwrites a file; choose another name with -o or remove it"]
    assert path.read_bytes() == before


def test_every_placeholder_is_refused_naming_its_key(drafted):
    # The draft keeps the file honest: load_case refuses it while any placeholder is left, and
    # names the key (here each one left alone in turn).
    text = drafted[0].read_text(encoding="utf-8")
    assert text.count(f'= "{PLACEHOLDER}') == len(PAPER)
    named = {"span": "structure.span", "width": "structure.width",
             "frequency": "structure.frequency", "damping_ratio": "structure.damping_ratio",
             "modal_mass": "structure.modal_mass", '"midspan"': "structure.outputs['midspan']",
             "density": "crowd.density", "band": "estimation.band"}
    for key in PAPER:
        others = {k: v for k, v in PAPER.items() if k != key}
        case = drafted[0].parent / f"left_{key.strip(chr(34))}.toml"
        case.write_text(_fill(text, others), encoding="utf-8")
        with pytest.raises(ParameterError, match=re.escape(named[key]) + ".*REPLACE"):
            load_case(case)


def test_filled_draft_loads_and_estimates(drafted, tmp_path):
    # Issue 27 "Must show": init → estimate without editing anything but the placeholders.
    # The estimator is stated (least squares: fixed and fast while the defaults change).
    path, _ = drafted
    text = _fill(path.read_text(encoding="utf-8"), PAPER)
    text = text.replace("[estimation]\n", '[estimation]\nmethod = "least_squares"\n')
    case_path = path.parent / "filled.toml"
    case_path.write_text(text, encoding="utf-8")
    case = load_case(case_path)
    assert case.measurement.units == "g" and case.measurement.files == (path.parent / "bridge.csv",)
    assert case.structure.output_names == ("midspan",) and case.crowd.density == 0.5
    assert main(["estimate", str(case_path), "--out", str(tmp_path / "est")]) == 0
    assert (tmp_path / "est" / "report.html").is_file()
    estimate = json.loads((tmp_path / "est" / "results.json").read_text())["estimate"]
    # The record was made with the paper's MSD, f_h1 = 3.0 Hz, ξ_h1 = 0.30; ten minutes of it
    # give f_h1 within 10 % (the g read as g: no factor 9.81 anywhere).
    assert estimate["frequency"] == pytest.approx(3.0, rel=0.10)
    assert 0.1 < estimate["damping_ratio"] < 0.6


def test_european_csv_without_time_stamps(tmp_path, capsys):
    # A CSV with ";" separators and decimal commas and no time column (issue 27 §2): read, the
    # rate given with --sample-rate is written to the draft, and the level guesses m/s²
    # (RMS 0.5 lies only in the m/s² range 0.01–2 of footbridge accelerations).
    rng = np.random.default_rng(3)
    rows = "\n".join(f"{a:.5f};{b:.5f}".replace(".", ",")
                     for a, b in 0.5 * rng.normal(size=(2000, 2)))
    record = tmp_path / "brug.txt"
    record.write_text("Kanal 1;Kanal 2\n" + rows + "\n", encoding="utf-8")
    assert main(["init", str(record), "--sample-rate", "50", "-o",
                 str(tmp_path / "case.toml")]) == 0
    printed = capsys.readouterr().out
    assert "sample rate 50 Hz given (--sample-rate)" in printed and "m/s2" in printed
    text = (tmp_path / "case.toml").read_text(encoding="utf-8")
    assert "sample_rate = 50.0" in text and 'units = "m/s2"' in text
    filled = _fill(text, {**{k: v for k, v in PAPER.items() if k != '"midspan"'},
                          '"Kanal_1"': "20.0", '"Kanal_2"': "30.0"})
    (tmp_path / "filled.toml").write_text(filled, encoding="utf-8")
    case = load_case(tmp_path / "filled.toml")
    assert case.measurement.sample_rate == 50.0
    # The drafted output names (blanks made "_", issue 36 §2), each mapped to its column.
    assert case.structure.output_names == ("Kanal_1", "Kanal_2")
    assert case.measurement.channels == {"Kanal_1": "Kanal 1", "Kanal_2": "Kanal 2"}


def _written(path, content):
    path.write_bytes(content)
    return path


@pytest.mark.parametrize("make, message", [
    (lambda folder: folder / "gone.csv", "gone.csv: record file not found"),
    (lambda folder: folder, "is a directory, expected a record file"),
    (lambda folder: _written(folder / "junk.csv", b"\xff\xfe\x00\x81" * 40),
     "junk.csv: cannot be read as a CSV file: not UTF-8 text"),
], ids=["missing", "directory", "not_a_record"])
def test_bad_record_is_one_line(tmp_path, capsys, make, message):
    # Bad input (common rules): one line on stderr naming the file, exit 1, nothing written.
    record = make(tmp_path)
    assert main(["init", str(record), "-o", str(tmp_path / "case.toml")]) == 1
    errors = capsys.readouterr().err.strip().splitlines()
    assert len(errors) == 1 and errors[0].startswith("crowdvib init: error: ")
    assert message in errors[0]
    assert not (tmp_path / "case.toml").exists()


def test_named_time_column_must_exist(logger_csv, tmp_path, capsys):
    # --time-column names a column the record lacks: refused with the columns listed, also
    # where a given rate would let read_record take the file for one without time stamps.
    for rate in ([], ["--sample-rate", "25"]):
        assert main(["init", str(logger_csv), "--time-column", "Zeit", *rate, "-o",
                     str(tmp_path / "c.toml")]) == 1
    first, second = capsys.readouterr().err.strip().splitlines()
    assert "none of its columns ['Time [s]', 'midspan'] is a time column" in first
    assert second.endswith("bridge.csv: has no time column 'Zeit'; its columns are "
                          "['Time [s]', 'midspan']")
    assert not (tmp_path / "c.toml").exists()


def test_the_drafts_report_table_uncommented_is_the_reports_header(drafted):
    # The draft names the [report] keys (issue 27 §4), commented out: uncommented and filled,
    # they are the case's report header, the date a TOML date kept as ISO text.
    path, _ = drafted
    text = _fill(path.read_text(encoding="utf-8"), PAPER)
    assert "# [report]\n" in text
    filled = {"client": "City of Ghent", "project": "Footbridge monitoring",
              "bridge": "Eeklo", "location": "Eeklo, Belgium", "engineer": "A. Engineer"}
    text = text.replace("# [report]\n", "[report]\n")
    for key, value in filled.items():
        text = text.replace(f'# {key} = "..."', f'{key} = "{value}"')
    text = text.replace("# measurement_date = 2024-05-01", "measurement_date = 2024-05-01")
    case_path = path.parent / "reported.toml"
    case_path.write_text(text, encoding="utf-8")
    assert load_case(case_path).report == {**filled, "measurement_date": "2024-05-01"}
