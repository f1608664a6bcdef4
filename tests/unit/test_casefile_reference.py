"""The case-file key reference in the docs is generated from the parser (issue 10): it lists every
key the example case files use, with the defaults the parser applies."""

import sys
import tomllib
from pathlib import Path

from crowdvib import load_case

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "docs" / "_ext"))
from casefile_keys import parser_keys, parser_sources, write_reference  # noqa: E402


def _keys():
    keys = {}
    for source in parser_sources():
        keys.update(parser_keys(Path(source).read_text(encoding="utf-8")))
    return keys


def _flat(table, prefix):
    for key, value in table.items():
        name = f"{prefix}.{key}"
        # Tables of names (outputs, channels) are values, not sections of keys.
        if isinstance(value, dict) and key not in ("outputs", "channels"):
            yield from _flat(value, name)
        else:
            yield name


def test_reference_lists_every_key_the_examples_use():
    keys = _keys()
    for case in sorted((ROOT / "examples").glob("*.toml")):
        data = tomllib.loads(case.read_text(encoding="utf-8"))
        used = {f"case.{k}" for k, v in data.items() if not isinstance(v, dict)}
        for section, table in data.items():
            if isinstance(table, dict) and section != "expected":
                used |= set(_flat(table, section))
        assert used - set(keys) == set(), case.name


def test_reference_defaults_are_the_parsers(tmp_path):
    # The defaults the table prints are those load_case applies (a minimal beam case).
    keys = _keys()
    path = tmp_path / "beam.toml"
    path.write_text('[structure]\ntype = "simply_supported_beam"\nspan = 50.0\nwidth = 3.0\n'
                    'frequency = 2.0\ndamping_ratio = 0.005\nmodal_mass = 5e4\n'
                    'outputs = { midspan = 25.0 }\n[crowd]\ndensity = 0.5\n')
    case = load_case(path)
    assert keys["measurement.window_length"][1] == case.measurement.window_length == 60.0
    assert keys["crowd.step_frequency_std"][1] == case.crowd.step_frequency_std == 0.175
    assert keys["hsi.mass_ratio"][1] == case.msd.mass_ratio == 0.95
    assert keys["estimation.method"][1] == case.estimation.method
    assert keys["crowd.density"][2] is True                       # required
    reference = write_reference(parser_sources(), {"window_length": ("", "s")},
                                tmp_path / "keys.rst")
    text = (tmp_path / "keys.rst").read_text(encoding="utf-8")
    assert "``window_length``" in text and "     - s" in text and len(reference) == len(keys)
