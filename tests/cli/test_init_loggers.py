"""`crowdvib init` on logger exports as they come (issue 36 §2): a unit in the column header
(``[mg]``, ``[g]``), metadata lines above the header row, a dropout. Each draft, its placeholders
filled with the paper example's values, is read by ``load_measurement`` into the m/s² the file
holds (g = 9.81 m/s², docs: theory, Conventions), and names its output ``midspan``.
"""

import re
import tomllib

import numpy as np
import pytest

from crowdvib import load_case
from crowdvib.cli import main
from crowdvib.errors import DataError, DataWarning
from crowdvib.io import load_measurement, read_record
from crowdvib.io.draft import PLACEHOLDER
from crowdvib.io.headers import find_header, header_unit, output_name
from crowdvib.models.loading import STANDARD_GRAVITY

RATE, N = 50.0, 3000          # 60 s at 50 Hz: above the band's 10 Hz, one Welch window
#: The paper example's values for the draft's placeholders (examples/paper_example.toml).
PAPER = {"span": "50.0", "width": "3.0", "frequency": "2.0", "damping_ratio": "0.005",
         "modal_mass": "50e3", '"midspan"': "25.0", "density": "0.5", "band": "[0.0, 10.0]"}
#: A catman-like preamble: four lines of metadata above the header (";" and decimal commas).
PREAMBLE = ("Datei: brug_2026-11-28.csv\nDatum: 28.11.2026 10:00:00\n"
            "Gerät: MR3000; S/N 1234\nAbtastrate: 50 Hz\n")


def _signal(seed=5):
    """Midspan acceleration [m/s²]: RMS 0.1 m/s² of noise (the level only matters here)."""
    return 0.1 * np.random.default_rng(seed).normal(size=N)


def _write(path, header, column, *, sep=",", preamble="", blank=()):
    """A logger CSV: time [s] and one column of values as written, a cell of each ``blank``
    index left empty (a dropout)."""
    lines = [preamble + f"Time [s]{sep}{header}"]
    for i, value in enumerate(column):
        cell = "" if i in blank else f"{value:.6f}"
        row = f"{i / RATE:.2f}{sep}{cell}"
        lines.append(row.replace(".", ",") if sep == ";" else row)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _init(record, capsys, *options):
    """(exit status, stdout, stderr, the draft as TOML, its text) of `crowdvib init`."""
    case = record.with_suffix(".toml")
    status = main(["init", str(record), *options])
    out, err = capsys.readouterr()
    text = case.read_text(encoding="utf-8")
    return status, out, err, tomllib.loads(text), text


def _filled(record, text):
    """The draft with its placeholders replaced by the paper's values, loaded."""
    for key, value in PAPER.items():
        text, count = re.subn(rf'(?m)^({re.escape(key)} = )"{PLACEHOLDER}[^"\n]*"',
                              lambda m: m.group(1) + value, text)
        assert count == 1, key
    path = record.with_name(record.stem + "_filled.toml")
    path.write_text(text, encoding="utf-8")
    return load_case(path)


def test_mg_header_with_the_gravity_offset(tmp_path, capsys):
    # Issue 36 §2: "[mg]" with the 1 g offset (mean 1000) was told "× 0.001 to m/s²", 9.81×
    # wrong. The header's unit is read: mg, and the samples read as g/1000.
    signal = _signal()
    record = _write(tmp_path / "mg.csv", "Acc Z midspan [mg]",
                    1000.0 + signal / STANDARD_GRAVITY * 1000.0)
    status, out, err, draft, text = _init(record, capsys)
    assert status == 0 and err == ""
    assert draft["measurement"]["units"] == "mg"
    assert "its header states 'mg'" in out and "0.001" not in out
    assert draft["measurement"]["channels"] == {"midspan": "Acc Z midspan [mg]"}
    assert list(draft["structure"]["outputs"]) == ["midspan"]
    assert f"crowdvib estimate {record.with_suffix('.toml')} --out mg-estimate" in out
    measured = load_measurement(_filled(record, text))
    assert measured.channel_names == ("midspan",)
    # 1 mg = 9.81e-3 m/s²: the offset removed (detrend "constant"), the signal in m/s² back
    # to the 6 decimals of a mg cell (1e-6 mg = 1e-8 m/s²).
    np.testing.assert_allclose(measured.data[0], signal - signal.mean(), atol=1e-7)


def test_four_line_preamble_is_skipped_and_said(tmp_path, capsys):
    # Issue 36 §2: metadata lines above the header were refused as "mixes decimal commas and
    # points". The header is found (line 5), the four lines are said and skipped.
    signal = _signal(6)
    record = _write(tmp_path / "catman.csv", "Acc Z midspan [g]",
                    1.0 + signal / STANDARD_GRAVITY, sep=";", preamble=PREAMBLE)
    status, out, err, draft, text = _init(record, capsys)
    assert status == 0 and err == ""
    assert "header       line 5; skipped the 4 line(s) of metadata above it (Datei: " in out
    assert draft["measurement"]["header_row"] == 5
    assert "#   Gerät: MR3000; S/N 1234\n" in text
    assert draft["measurement"]["units"] == "g"
    assert draft["measurement"]["channels"] == {"midspan": "Acc Z midspan [g]"}
    measured = load_measurement(_filled(record, text))
    # g = 9.81 m/s²; cells of 6 decimals in g: 1e-6 g ≈ 1e-5 m/s².
    np.testing.assert_allclose(measured.data[0], signal - signal.mean(), atol=1e-5)
    # Read without header_row, the same header is found; skip_rows = 4 says the same.
    found = read_record(record)
    assert found.channel_names == ("Acc Z midspan [g]",) and found.n_samples == N
    case = _filled(record, text.replace("header_row = 5", "skip_rows = 4"))
    assert case.measurement.header_row == 5


def test_g_header_file(tmp_path, capsys):
    # A g file as most loggers write it: the unit in the header agrees with the 1 g offset.
    signal = _signal(7)
    record = _write(tmp_path / "g.csv", "Acc Z midspan (g)", 1.0 + signal / STANDARD_GRAVITY)
    status, out, err, draft, text = _init(record, capsys)
    assert status == 0 and err == ""
    assert draft["measurement"]["units"] == "g"
    assert draft["measurement"]["channels"] == {"midspan": "Acc Z midspan (g)"}
    assert "'Acc Z midspan (g)' → output 'midspan'" in out
    measured = load_measurement(_filled(record, text))
    np.testing.assert_allclose(measured.data[0], signal - signal.mean(), atol=1e-5)


def test_header_unit_against_the_samples_is_a_doubt(tmp_path, capsys):
    # The header says g, the samples hold the 1 g offset in mg: the header's unit is drafted
    # (it is what the file states) and the disagreement is a doubt: printed with -q, exit 3,
    # and 1 with --strict (issue 36 §2: "a doubt in the draft is a doubt").
    signal = _signal()
    record = _write(tmp_path / "odd.csv", "a [g]", 1000.0 + signal - signal.mean())
    status, out, err, draft, _ = _init(record, capsys, "-q")
    assert status == 3 and out == ""
    assert draft["measurement"]["units"] == "g"
    assert err.splitlines() == ["crowdvib init: warning: channel 'a [g]': its header states 'g' "
                                "but its samples look like 'mg' (mean 1000.000 is the gravity "
                                "offset 1000 mg): check the logger's unit setting"]
    record.with_suffix(".toml").unlink()
    status = main(["init", str(record), "--strict"])
    assert status == 1
    assert "error: --strict: the verdict doubts the result" in capsys.readouterr().err


def test_unsure_units_fail_strict(tmp_path, capsys):
    # RMS 0.05 lies in the g and the m/s² ranges (docs: the draft's levels): unsure → a units
    # placeholder and a doubt, exit 1 with --strict.
    record = tmp_path / "amb.csv"
    record.write_text("time,a\n" + "".join(f"{i / RATE:.2f},{v:.6f}\n"
                                           for i, v in enumerate(0.5 * _signal())))
    status, out, err, draft, _ = _init(record, capsys, "-q", "--strict")
    assert status == 1 and out == ""
    assert draft["measurement"]["units"].startswith(PLACEHOLDER)
    assert re.search(r"crowdvib init: warning: units unsure: channel 'a': RMS 0\.0\d+ fits each "
                     "of the usual footbridge levels 0.001–0.2 g, 0.01–2 m/s2", err)


@pytest.mark.parametrize("gaps", ["bridge", "cut"])
def test_dropout_is_bridged_or_cut_and_stated(tmp_path, capsys, gaps):
    # Issue 36 §2: an empty cell was refused. init finds it and drafts gaps = "bridge" (3
    # samples = 0.06 s, under max_gap 0.1 s); the record is bridged by a straight line, or cut
    # to the longest stretch without it, and its notes (results.json's "record") say so.
    signal = _signal(8)
    record = _write(tmp_path / "drop.csv", "midspan [m/s²]", signal, blank=(2000, 2001, 2002))
    status, out, err, draft, text = _init(record, capsys)
    assert status == 0 and err == ""
    assert draft["measurement"]["gaps"] == "bridge" and draft["measurement"]["units"] == "m/s2"
    assert ("dropouts     1 dropout(s) (empty cells), the longest 3 sample(s) (0.06 s), the "
            "first at sample index 2000 (t = 40 s)") in out
    case = _filled(record, text.replace('gaps = "bridge"', f'gaps = "{gaps}"'))
    measured = load_measurement(case)
    (note,) = measured.notes
    assert measured.metadata()["notes"] == [note]
    if gaps == "bridge":
        # Linear between samples 1999 and 2003 (then the mean removed).
        expected = signal.copy()
        expected[2000:2003] = np.interp([2000, 2001, 2002], [1999, 2003], signal[[1999, 2003]])
        np.testing.assert_allclose(measured.data[0], expected - expected.mean(), atol=1e-5)
        assert note.startswith("bridged the dropouts by linear interpolation: 1 dropout(s)")
    else:
        # The longest stretch without it: samples 0–1999, t = 0–40 s.
        assert measured.n_samples == 2000 and measured.start_time == 0.0
        assert "kept the longest stretch without one, t = 0–40 s (40 s of 60 s)" in note
    # Without gaps the dropout is refused, naming the key that decides it.
    with pytest.raises(DataError, match=r"NaN sample at sample index 2000 \(t = 40 s\) \(a "
                                        r"dropout.*measurement.gaps = \"cut\""):
        load_measurement(_filled(record, text.replace('gaps = "bridge"', "")))


def test_bridge_refuses_a_long_dropout(tmp_path):
    # max_gap 0.1 s: a 0.2 s dropout (10 samples at 50 Hz) is not made up by a straight line.
    record = _write(tmp_path / "long.csv", "a [m/s2]", _signal(), blank=range(100, 110))
    with pytest.raises(DataError, match=r"interpolates dropouts up to measurement.max_gap = "
                                        r"0.1 s, got 1 dropout\(s\) \(empty cells\), the longest "
                                        r"10 sample\(s\) \(0.2 s\)"):
        from crowdvib.io.gaps import mend_gaps

        mend_gaps(read_record(record), "bridge", 0.1)


def test_given_units_against_the_header_warn(tmp_path):
    # units given as m/s² for a column whose header says mg: read as told, and warned.
    record = _write(tmp_path / "w.csv", "a [mg]", 1000.0 + _signal())
    with pytest.warns(DataWarning, match=r"read in 'm/s2' as given, but the header of "
                                         r"column\(s\) 'a \[mg\]' states 'mg'"):
        read_record(record, units="m/s2")


@pytest.mark.parametrize("header, bare, unit, output", [
    ("Acc Z midspan [g]", "Acc Z midspan", "g", "midspan"),
    ("Acc Z midspan [mg]", "Acc Z midspan", "mg", "midspan"),
    ("a_quarter [m/s²]", "a_quarter", "m/s2", "a_quarter"),
    ("S3 (m/s^2)", "S3", "m/s2", "S3"),
    ("Beschleunigung Feldmitte [mm/s²]", "Beschleunigung Feldmitte", "mm/s2", "Feldmitte"),
    ("Strain [µm/m]", "Strain [µm/m]", None, "Strain_µm_m"),
    ("Acc Z", "Acc Z", None, "Acc_Z"),
])
def test_header_units_and_output_names(header, bare, unit, output):
    # The usual header units of issue 36 §2 ([g], [mg], [m/s²], [m/s^2], [mm/s²], (g)); a unit
    # crowdvib does not read is left in the name; the output name drops unit, "acceleration"
    # and axis words, and keeps the whole header when nothing else is left.
    assert header_unit(header) == (bare, unit)
    assert output_name(header) == output


def test_find_header_keeps_a_plain_file_and_refuses_a_dropout_row_as_header():
    # A file whose first line is its header: unchanged. A row of numbers with an empty cell is
    # no header (a dropout in the first rows must not move the header down).
    plain = ["time,a\n", "0,1\n", "0.1,2\n", "0.2,3\n"]
    assert find_header(plain) == (0, [])
    dropout = ["time,a\n", "0,\n", "0.1,2\n", "0.2,3\n", "0.3,4\n"]
    assert find_header(dropout) == (0, [])
