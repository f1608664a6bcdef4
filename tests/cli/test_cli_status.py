"""The command line's exit status, --quiet and --verbose (issue 27 §2; docs: Command line,
Exit status)."""

import pytest

from crowdvib.cli import main
from crowdvib.cli.common import set_quiet


@pytest.fixture(autouse=True)
def loud_again():
    yield
    set_quiet(False)        # --quiet is process-wide: leave the next test its output


def test_quiet_prints_the_verdict_alone(tmp_path, capsys):
    # The spectral demo finishes without a doubt: exit 0, and with -q its one verdict line is
    # all that reaches stdout (docs: Command line, Exit status).
    assert main(["demo", "--spectral", "-q", "--out", str(tmp_path / "q")]) == 0
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
