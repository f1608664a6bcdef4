"""crowdvib.io.draft: the units guess and the case-file draft of `crowdvib init` (issue 27 §2)."""

import tomllib
from pathlib import Path

import pytest

from crowdvib.errors import ParameterError
from crowdvib.io.draft import (PLACEHOLDER, ChannelSummary, RecordSummary, draft_case,
                               guess_units, new_case_path)
from crowdvib.io.headers import output_name
from crowdvib.models.loading import STANDARD_GRAVITY


@pytest.mark.parametrize("mean, rms, units", [
    (1.0, 0.03, "g"),                           # vertical sensor, gravity offset 1 g
    (-0.98, 0.03, "g"),                         # mounted upside down
    (0.9, 0.03, "g"),                           # tilted by ~25°: cos 25° = 0.906
    (STANDARD_GRAVITY, 0.3, "m/s2"),            # offset g = 9.81 m/s²
    (-9.7, 0.3, "m/s2"),
    (0.0, 0.005, "g"),                          # 0.005 m/s² would be below the m/s² range
    (0.0, 0.5, "m/s2"),                         # 0.5 g would be beyond the g range
    (0.0, 0.05, None),                          # in both ranges: unsure
    (0.0, 50.0, None),                          # in the mg and the mm/s² ranges: unsure
    (0.0, 5.0, "mg"),                           # only in the mg range 1–200 (issue 36 §2)
    (0.0, 500.0, "mm/s2"),                      # only in the mm/s² range 10–2000
    (0.0, 5000.0, None),                        # in no range
    (1000.0, 30.0, "mg"),                       # offset 1 g = 1000 mg (issue 36 §2's file)
    (-9810.0, 300.0, "mm/s2"),                  # offset 9810 mm/s², upside down
    (0.0, 1e-4, None),
    (1.0, 0.6, "m/s2"),                         # no 1 g offset under 0.6 g of motion: the level
])
def test_guess_units(mean, rms, units):
    # Issue 27 §2 and the brief's levels: gravity offset ±15 % (1 g, 9.81 m/s², 1000 mg, 9810
    # mm/s²), else RMS in 0.01–2 m/s², 0.001–0.2 g, 1–200 mg, 10–2000 mm/s²; a level fitting
    # two ranges, or none, is unsure.
    assert guess_units(mean, rms)[0] == units


def test_guess_units_says_why():
    assert guess_units(0.0, 50.0)[1] == ("RMS 50 fits each of the usual footbridge levels "
                                         "1–200 mg, 10–2000 mm/s2")
    assert guess_units(-1.0, 0.01)[1] == "mean -1.000 is the gravity offset -1 g"


def _summary(names, **changes):
    fields = dict(path=Path("/data/site/rec.dat"), format="csv",
                  channels=tuple(ChannelSummary(n, 0.0, 0.5, "m/s2", "level", output_name(n))
                                 for n in names),
                  time_column=None, sample_rate=40.0, rate_source="given", duration=900.0,
                  n_samples=36000, units="m/s2", units_reason="level")
    fields.update(changes)
    return RecordSummary(**fields)


def test_draft_is_toml_that_gives_back_every_name():
    # Channel names from a file may hold quotes, backslashes, non-ASCII letters and DEL: the
    # draft quotes them so that TOML gives each back exactly (as outputs and as channels).
    # Each output is named by the draft (issue 36 §2: the header without unit and the words
    # "acceleration" and axis), mapped to the channel as the file names it.
    names = ['a "q"', "b\\c", "Brücke Mitte", "x\x7fy", "[z]"]
    outputs = ["q", "b_c", "Brücke_Mitte", "x_y", "z"]
    text = draft_case(_summary(names), "/data/cases/rec.toml")
    table = tomllib.loads(text)
    assert list(table["structure"]["outputs"]) == outputs
    assert table["measurement"]["channels"] == dict(zip(outputs, names))
    # What was found is filled in: path relative to the case's folder, the suffix .dat tells
    # no format, the file has no time stamps (the given rate is written), the units.
    assert table["measurement"]["files"] == ["../site/rec.dat"]
    assert table["measurement"]["format"] == "csv"
    assert table["measurement"]["sample_rate"] == 40.0
    assert table["measurement"]["units"] == "m/s2"
    assert table["name"] == "rec"
    # The placeholders: every one a string starting with REPLACE where a number belongs.
    holes = [table["structure"][k] for k in ("span", "width", "frequency", "damping_ratio",
                                             "modal_mass")]
    holes += list(table["structure"]["outputs"].values())
    holes += [table["crowd"]["density"], table["estimation"]["band"]]
    assert all(hole.startswith(PLACEHOLDER) for hole in holes)
    assert text.count(f'= "{PLACEHOLDER}') == len(holes)
    # The band's hint stays below the Nyquist frequency (20 Hz here): 0.8 × … capped at 10 Hz.
    assert "e.g. [0.0, 10.0]; upper below the Nyquist frequency 20 Hz" in text


def test_draft_of_an_unsure_record_has_a_units_placeholder():
    # Unsure units are not guessed into the file: a placeholder load_case refuses.
    text = draft_case(_summary(["a"], units=None, units_reason="RMS 0.05 fits each …",
                               time_column="t", rate_source="time stamps"), "rec.toml")
    table = tomllib.loads(text)["measurement"]
    assert table["units"].startswith(PLACEHOLDER)
    assert table["time_column"] == "t" and "sample_rate" not in table


def test_new_case_path_defaults_beside_the_record_and_refuses_existing(tmp_path):
    record = tmp_path / "bridge.csv"
    assert new_case_path(record) == tmp_path / "bridge.toml"
    (tmp_path / "bridge.toml").write_text("x")
    with pytest.raises(ParameterError, match="bridge.toml exists: crowdvib init never overwrites"):
        new_case_path(record)
    assert new_case_path(record, tmp_path / "other.toml") == tmp_path / "other.toml"
