"""The command line's exit status, --quiet and --verbose (issue 27 §2; docs: Command line,
Exit status)."""

import json
from pathlib import Path

import pytest

from crowdvib.cli import main
from crowdvib.cli.common import IN_DOUBT, set_quiet

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture(autouse=True)
def loud_again():
    yield
    set_quiet(False)        # --quiet is process-wide: leave the next test its output


def test_quiet_prints_the_verdict_alone(tmp_path, capsys):
    # The spectral demo finishes without a doubt: exit 0, and with -q its one verdict line is
    # all that reaches stdout (docs: Command line, Exit status); --strict changes nothing then.
    assert main(["demo", "--spectral", "-q", "--strict", "--out", str(tmp_path / "q")]) == 0
    printed = capsys.readouterr().out
    assert printed.splitlines() == ["  verdict: no warnings (details in report.html)"]
    assert (tmp_path / "q" / "results.json").is_file()


def test_verbose_shows_the_estimators_log_records(tmp_path, capsys):
    # -v before the command: the optimiser's starts (logger crowdvib.identification.estimation,
    # one record per start and fit) reach stderr.
    assert main(["-v", "demo", "--spectral", "--out", str(tmp_path / "v")]) == 0
    err = capsys.readouterr().err
    assert err.count("crowdvib.identification.estimation: start") >= 4


def test_every_command_states_the_exit_statuses(capsys):
    from crowdvib.cli.main import _COMMANDS

    for name in _COMMANDS:
        assert main([name, "--help"]) == 0
        text = " ".join(capsys.readouterr().out.split())
        assert "exit status: 0 finished; 1 error; 2 usage error; 3 finished and written" in text
        assert "doubts the result (check before use; 1 with --strict)" in text


def _doubtful_check_case(tmp_path):
    """The paper's design check with a walking speed of 3.2 m/s: legal, but a PlausibilityWarning
    (km/h?) that the verdict counts as a doubt; no stochastic prediction (the exit status is
    the point)."""
    text = (EXAMPLES / "check_paper.toml").read_text(encoding="utf-8")
    assert "walking_speed = 1.30" in text and "[design]\n" in text
    case = tmp_path / "doubtful.toml"
    case.write_text(text.replace("walking_speed = 1.30", "walking_speed = 3.2", 1)
                    .replace("[design]\n", "[design]\nprediction = false\n", 1),
                    encoding="utf-8")
    return case


def test_strict_makes_a_result_in_doubt_a_failure(tmp_path, capsys):
    # Issue 27 §2 (docs: Command line, Exit status): "finished, but in doubt" is 3; with --strict
    # (before or after the command) it is 1, with one line saying why, and the results are
    # written all the same.
    case = _doubtful_check_case(tmp_path)
    assert main(["check", str(case), "--out", str(tmp_path / "plain")]) == IN_DOUBT
    capsys.readouterr()
    for n, argv in enumerate((["--strict", "check", str(case)], ["check", str(case), "--strict"])):
        out = tmp_path / f"strict{n}"
        assert main([*argv, "--out", str(out)]) == 1
        err = capsys.readouterr().err
        assert err.splitlines()[-1] == (f"crowdvib check: error: --strict: the verdict doubts the "
                                        f"result (see above; written to {out})")
        warnings = json.loads((out / "results.json").read_text(encoding="utf-8"))["warnings"]
        assert any("walking_speed = 3.2 m/s" in text for text in warnings)
        assert (out / "report.html").is_file()
