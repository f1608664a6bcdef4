"""Text from someone else's file reaches the terminal escaped (issue 35 §1): control sequences
(``ESC ] 0 ; … BEL`` retitles the window, ``ESC [ 2 J`` clears it) and bidi overrides (U+202E)
of a case file or a table are written as escapes, and of a foreign file only a short excerpt is
quoted (crowdvib.errors.terminal_safe, excerpt)."""

import pytest

from crowdvib.errors import excerpt, terminal_safe
from crowdvib.cli import main
from tests.reporting.test_report_header import BEAM

#: What a hostile file holds, as TOML escapes: retitle, clear, turn the line around.
HOSTILE_TOML = r"\u001b]0;PWNED\u0007\u001b[2J\u202eevil"
HOSTILE = "\x1b]0;PWNED\x07\x1b[2J\u202eevil"
RAW = ("\x1b", "\x07", "\u202e", "\x9b", "\r")


@pytest.mark.parametrize("text, shown", [
    (HOSTILE, r"\x1b]0;PWNED\x07\x1b[2J\u202eevil"),
    ("a\x9b31mb", r"a\x9b31mb"),                              # C1 CSI
    ("over\rwrite", r"over\rwrite"),
    ("\u2066isolate\u2069 \u200fmark", r"\u2066isolate\u2069 \u200fmark"),
    ("line 1\n\tline 2: 2.5 m/s², μ_h1 = 0.9, café", "line 1\n\tline 2: 2.5 m/s², μ_h1 = 0.9, café"),
])
def test_terminal_safe_escapes_controls_and_keeps_text(text, shown):
    assert terminal_safe(text) == shown


def test_an_excerpt_is_short_escaped_and_one_line():
    text = "root:x:0:0:root:/root:/bin/bash\n" + "\x1b[2J" * 100
    shown = excerpt(text, 40)
    assert shown.startswith("'root:x:0:0:root:/root:/bin/bash\\n") and shown.endswith("…'")
    assert len(shown) < 70 and not any(c in shown for c in RAW + ("\n",))


def _clean(output):
    return not any(c in output for c in RAW)


def test_a_case_files_name_and_keys_reach_the_terminal_escaped(tmp_path, capsys):
    case = tmp_path / "case.toml"
    case.write_text(f'name = "{HOSTILE_TOML}"\n' + BEAM.split("\n", 1)[1], encoding="utf-8")
    assert main(["check", str(case), "--out", str(tmp_path / "out")]) in (0, 3, 4)
    out, err = capsys.readouterr()
    assert _clean(out) and _clean(err)
    assert r"crowdvib check: \x1b]0;PWNED\x07\x1b[2J\u202eevil, codes hivoss" in out
    # An unknown key and a missing file named by the case file, in the error line.
    case.write_text(BEAM + f'"{HOSTILE_TOML}" = 1\n', encoding="utf-8")
    assert main(["check", str(case), "--out", str(tmp_path / "out2")]) == 1
    err = capsys.readouterr().err
    assert _clean(err) and r"unknown key(s) ['design.\x1b]0;PWNED\x07" in err


def test_a_missing_record_named_with_controls_is_named_escaped(tmp_path, capsys):
    from tests.conftest import copy_paper_case

    case = copy_paper_case(tmp_path)
    text = case.read_text(encoding="utf-8")
    case.write_text(text.replace('files = ["paper_example_record.npz"]',
                                 f'files = ["{HOSTILE_TOML}.npz"]'), encoding="utf-8")
    assert main(["estimate", str(case), "--out", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert _clean(err) and "names a file that does not exist: " in err
    assert r"/\x1b]0;PWNED\x07\x1b[2J\u202eevil.npz" in err


def test_a_foreign_file_as_crowd_table_is_quoted_as_a_short_excerpt(tmp_path, capsys):
    # `crowdvib season CASE /etc/passwd` printed the file's first line whole.
    from tests.conftest import copy_paper_case

    case = copy_paper_case(tmp_path)
    secret = tmp_path / "passwd"
    line = "root:x:0:0:" + HOSTILE + ":" + "s3cr3t" * 40
    secret.write_text(line + "\nsecond:line\n", encoding="utf-8")
    assert main(["season", str(case), str(secret), "--out", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert _clean(err) and "passwd: is not a crowd table" in err
    assert "root:x:0:0:\\x1b]0;PWNED" in err and "s3cr3t" * 3 not in err
    assert "second:line" not in err
    # A header with some known columns: the unknown ones, each shortened, escaped.
    secret.write_text(f"record,count,{HOSTILE}{'y' * 200}\nr1,3,x\n", encoding="utf-8")
    assert main(["season", str(case), str(secret), "--out", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert _clean(err) and "unknown column(s) ['\\x1b]0;" in err and "y" * 60 not in err
