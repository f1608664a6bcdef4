"""The command line's exit status, --quiet and --verbose (issue 27 §2; docs: Command line,
Exit status)."""

import json
from pathlib import Path

import pytest

from crowdvib.cli import main
from crowdvib.cli.common import FAILS_DESIGN, IN_DOUBT, set_quiet

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
        assert ("4 finished and written, not in doubt, and the bridge fails a design check (an "
                "answer, not a doubt)") in text


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


def _passing_prediction_off(tmp_path):
    """examples/check_paper.toml without the stochastic prediction (fast): without a damper the
    bridge fails Sétra II, HiVoSS TC3 and EN 1990 TC3 with HSI (docs: how-to 2), no doubt."""
    text = (EXAMPLES / "check_paper.toml").read_text(encoding="utf-8")
    case = tmp_path / "fails.toml"
    case.write_text(text.replace("[design]\n", "[design]\nprediction = false\n", 1),
                    encoding="utf-8")
    return case


def test_a_failed_design_check_is_an_answer_not_a_doubt(tmp_path, capsys):
    # Issue 36 §3: a code the bridge fails was shown under "Check before use", yellow, and exited
    # 0 even with --strict. It is the checks' answer: its own words, exit status 4 (docs:
    # Command line, Exit status), --strict or not, and a red box of its own in the report.
    case = _passing_prediction_off(tmp_path)
    for n, options in enumerate(([], ["--strict"], ["-q"])):
        out = tmp_path / f"fails{n}"
        assert main(["check", str(case), "--out", str(out), *options]) == FAILS_DESIGN == 4
        printed, err = capsys.readouterr()
        failing = [r for r in json.loads((out / "results.json").read_text())["design"]["verdict"]
                   if r["model"] == "HSI" and r["passes"] is False]
        assert len(failing) >= 3
        assert (f"  verdict: the bridge fails {len(failing)} design check(s) (the checks' "
                "answer; details in report.html):") in printed
        assert ("  verdict: the result itself is not in doubt: no warnings (details in "
                "report.html)") in printed
        assert "check before use" not in printed and err == ""
    page = (out / "report.html").read_text(encoding="utf-8")
    summary = page.split('<section id="summary">')[1].split("</section>")[0]
    assert f"The bridge fails {len(failing)} design check(s)" in summary
    assert '<div class="callout fail">' in summary and 'class="callout warn"' not in summary
    assert "The result itself is not in doubt: no warnings" in summary


def test_a_doubtful_result_is_check_before_use_each_warning_once(tmp_path, capsys):
    # The result in doubt (a walking speed of 3.2 m/s: km/h?): other words, exit status 3, and
    # with -q the warning is printed once (on stderr, as raised), the verdict counting it.
    case = _doubtful_check_case(tmp_path)
    assert main(["check", str(case), "--out", str(tmp_path / "d"), "-q"]) == IN_DOUBT == 3
    printed, err = capsys.readouterr()
    assert "  verdict: check before use: the result itself is in doubt (" in printed
    assert "    - and the 1 warning(s) printed above" in printed
    both = printed + err
    assert both.count("walking_speed = 3.2 m/s") == 1
    assert err.startswith("crowdvib check: warning: ")
    summary = (tmp_path / "d" / "report.html").read_text(encoding="utf-8").split(
        '<section id="summary">')[1].split("</section>")[0]
    assert "Check before use: the result itself is in doubt" in summary


def test_verdict_colours_only_on_a_terminal(monkeypatch):
    # Red fails, yellow doubts, green none (ANSI SGR 31/33/32) on a terminal; plain text in a
    # pipe or a file, and with NO_COLOR set (no-color.org).
    from crowdvib.cli.common import _paint

    class Terminal:
        def isatty(self):
            return True

    monkeypatch.delenv("NO_COLOR", raising=False)
    assert _paint("x", "fail", Terminal()) == "\x1b[31mx\x1b[0m"
    assert _paint("x", "doubt", Terminal()) == "\x1b[33mx\x1b[0m"
    assert _paint("x", "ok", Terminal()) == "\x1b[32mx\x1b[0m"
    assert _paint("x", "fail", object()) == "x"
    monkeypatch.setenv("NO_COLOR", "1")
    assert _paint("x", "fail", Terminal()) == "x"


def test_every_commands_help_ends_with_examples_that_parse(capsys):
    # Issue 36 §3: --help had no examples. Each command shows one or two, and each is a valid
    # command line of this parser (the words after "crowdvib", a "#" comment dropped).
    import shlex

    from crowdvib.cli.main import _COMMANDS, EXAMPLES, build_parser

    assert set(EXAMPLES) == set(_COMMANDS)
    for name in _COMMANDS:
        assert main([name, "--help"]) == 0
        text = capsys.readouterr().out
        assert 1 <= len(EXAMPLES[name]) <= 2
        for line in EXAMPLES[name]:
            assert f"\n  {line}\n" in text
            argv = shlex.split(line.split("#")[0])
            assert argv[:2] == ["crowdvib", name]
            assert build_parser().parse_args(argv[1:]).command == name
