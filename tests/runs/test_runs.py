"""The commands as calls (issue 26 §1): each command of the command line is one call of
:mod:`crowdvib.runs`, so a Python user gets the command's folder, lines and verdict."""

from pathlib import Path

from crowdvib.cases import load_results
from crowdvib.cli import main
from crowdvib.runs import run_check

CASE = Path(__file__).resolve().parents[2] / "examples" / "check_paper.toml"
#: What differs between two runs of the same case: when, how long, and the figures' pixels.
VOLATILE = ("created", "elapsed_s")


def _stable(results):
    data = results.to_dict()
    return {key: value for key, value in data.items() if key not in VOLATILE}


def test_run_check_from_python_is_the_command(tmp_path, capsys):
    lines = []
    found = run_check(CASE, tmp_path / "python", say=lines.append)
    # 4: the bridge fails design codes (an answer, docs: Command line, Exit status)
    assert main(["check", str(CASE), "--out", str(tmp_path / "cli")]) == 4
    printed = capsys.readouterr().out.splitlines()
    # The same results.json (but for the time stamps), read back as the same object, and the
    # same verdict: the paper example fails every code without HSI and passes none with it
    # but the UK NA (examples/check_paper.toml; docs: theory, Design checks).
    assert _stable(found) == _stable(load_results(tmp_path / "cli"))
    assert found.verdict() == load_results(tmp_path / "cli").verdict()
    # Each code by its name in words (design.code_label), as a client reads it.
    assert {f.text.split(" TC3")[0].split(" II")[0] for f in found.verdict()
            if f.severity == "fail"} == {"HiVoSS", "Sétra", "EN 1990"}
    # The same lines, the folder's name and the run time aside; the verdict line is the CLI's.
    assert [line for line in lines if not line.startswith("  wrote")] == [
        line for line in printed[:len(lines)] if not line.startswith("  wrote")]
    # The bridge fails codes: the checks' answer comes first (issue 36 §3).
    assert printed[len(lines)].startswith("  verdict: the bridge fails ")


def test_a_leaked_file_of_other_code_is_not_a_warning_of_the_run():
    import gc
    import warnings

    from crowdvib.errors import ResolutionWarning
    from crowdvib.runs.lines import caught_warnings, warning_texts

    # CI once found "ResourceWarning: unclosed file" in a design check's results: the garbage
    # collector raises it for a file some earlier code left open, whenever it runs. Python
    # ignores it by default; a run's record of warnings must too, and keep its own warnings.
    with caught_warnings() as caught:
        open(__file__).close()
        leaked = open(__file__)       # noqa: SIM115 - left open on purpose
        del leaked
        gc.collect()
        warnings.warn("a doubtful resolution", ResolutionWarning, stacklevel=1)
        warnings.warn("a doubtful resolution", ResolutionWarning, stacklevel=1)
    assert warning_texts(caught) == ["ResolutionWarning: a doubtful resolution"] * 2
