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
    # Not stated, the estimator's choices are the default estimator's, filled in once the
    # records are known (EstimationSpec.resolved; docs: Case files, [estimation]).
    assert keys["estimation.method"][1] is None and case.estimation.method == "likelihood"
    assert keys["crowd.density"][2] is True                       # required
    reference = write_reference(parser_sources(), {"window_length": ("", "s")},
                                tmp_path / "keys.rst")
    text = (tmp_path / "keys.rst").read_text(encoding="utf-8")
    assert "``window_length``" in text and "     - s" in text and len(reference) == len(keys)


def test_reference_keeps_the_two_structure_forms_apart():
    # Issue 27 §1: a beam's span is not required of a modal-file structure, nor modal_table of
    # a beam (casefile._structure reads each form's keys in its own branch of `type`).
    keys = _keys()
    assert keys["structure.span"][2] == 'type = "simply_supported_beam"'
    assert keys["structure.modal_mass"][2] == 'type = "simply_supported_beam"'
    assert keys["structure.modal_table"][2] == 'type = "modal_files"'
    assert keys["structure.width"][2] is True                     # both forms
    # the damper is either explicit or tuned to a mode (casedesign._design_damper)
    assert keys["design.damper.mass"][2] == "``mode`` is left out"
    assert keys["design.damper.mode"][2] is False


def test_reference_prints_counts_as_integers_with_units_and_unit_choices(tmp_path):
    # Issue 27 §1: counts the parser takes as int(...) print as integers, the damper's mass and
    # position have units, and measurement.units lists its values (records._UNIT_ALIASES).
    from crowdvib.quantities import QUANTITIES

    keys = _keys()
    assert keys["structure.n_modes"][:2] == ("integer", 1)
    assert keys["estimation.n_boot"][:2] == ("integer", 200)
    assert keys["measurement.filter.order"][:2] == ("integer", 4)
    write_reference(parser_sources(), QUANTITIES, tmp_path / "keys.rst")
    text = (tmp_path / "keys.rst").read_text(encoding="utf-8")
    assert "``200``" in text and "``200.0``" not in text
    rows = {block.split("\n")[0]: block for block in text.split("   * - ")}
    assert "     - kg\n" in rows["``damper.mass``"]
    assert "     - m\n" in rows["``damper.position``"]
    assert '"m/s2"' in rows["``units``"] and '"g"' in rows["``units``"]


def test_ambient_reference_lists_every_key_of_the_ambient_example(tmp_path):
    # Issue 27 §1: the ambient-test format of `crowdvib modes` is documented, generated from its
    # reader (crowdvib.io.ambient) like the case file's; the example uses only keys it lists.
    import crowdvib.io.ambient
    from casefile_keys import AMBIENT_SECTIONS

    source = Path(crowdvib.io.ambient.__file__).read_text(encoding="utf-8")
    keys = parser_keys(source, AMBIENT_SECTIONS)
    data = tomllib.loads((ROOT / "examples" / "ambient" / "paper_beam_ambient.toml")
                         .read_text(encoding="utf-8"))
    used = {f"case.{k}" for k, v in data.items() if not isinstance(v, dict)}
    for section, table in data.items():
        if isinstance(table, dict):
            used |= set(_flat(table, section))
    assert used - set(keys) == set()
    assert keys["identification.n_modes"][:2] == ("integer", None)        # ambient._count
    assert keys["identification.max_order"][:2] == ("integer", None)      # chosen (issue 27)
    assert keys["record.file"][2] is True and keys["modal_model.width"][2] is True
