"""The repository stands on its own (issue 10): no tracked file refers to a path outside it."""

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
# Design notes and data of the team live beside the repository, never in it: a user who clones
# crowdvib must find every reference inside (the theory chapter replaces them).
OUTSIDE = re.compile(r"\.\./shared|physics\.md|architecture\.md|style-anchors|paper\.txt|/work/")


def _tracked_files():
    try:
        listing = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True,
                                 check=True).stdout.split("\n")
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout: the tracked files are unknown")
    return [ROOT / name for name in listing if name]


def test_no_tracked_file_mentions_a_path_outside_the_repository():
    offenders = []
    for path in _tracked_files():
        if path.suffix in {".npz", ".png", ".mat", ".uff"} or not path.is_file():
            continue
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue
        for number, line in enumerate(text.splitlines(), 1):
            if OUTSIDE.search(line) and path.name != "test_repository.py":
                offenders.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()[:80]}")
    assert offenders == []
