"""The bad-input catalogue (the tests marked badinput) counted by outcome, now and on an older source tree.

Each test marked badinput is one hostile input and the answer crowdvib owes it: a crowdvib
error naming parameter, rule and value, a warning naming the likely mistake, or (for inputs that
other programs write, such as a CSV with decimal commas) a correct reading. This script runs the
catalogue and counts the cases by what the test demanded (seen at run time: which of
``pytest.raises`` and ``pytest.warns`` the test used; the CLI cases demand an exit code with a
message). With ``--against SRC`` it runs the same tests against another crowdvib source tree
(for example a worktree of an older commit: ``git worktree add /tmp/old 49020a3`` then
``--against /tmp/old/src``) and counts how that tree answered each case:

* ``as demanded``: the test passes there too;
* ``silent``: no error and no warning where one was due (``DID NOT RAISE``/``WARN``, exit 0);
* ``poor message``: a crowdvib error whose message lacks what the test demands;
* ``foreign``: an exception that is not crowdvib's (its class is listed);
* ``no answer``: no answer within ``--cpu-limit`` seconds of CPU (a unit mistake that the
  estimator fitted for minutes before it said anything: issue 35 §2 asks for an answer in
  seconds); the test is stopped there;
* ``not comparable``: the test needs a name the older tree does not have.

Issue 35 (tests/package/test_bad_input_issue35.py) added the last silent and foreign cases of
§3 and the unit mistakes of §2; ``--only issue35`` counts those alone.

Usage: ``python accuracy/bad_input_catalogue.py [--against SRC] [--only TEXT] [--cpu-limit S]``.
Prints tables; asserts nothing.
"""

import argparse
import collections
import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ElementTree
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: A pytest plugin (written to a temporary module) that records, per test, whether it called
#: pytest.raises or pytest.warns.
_PLUGIN = '''
import json, os, signal, pytest
_kinds, _current = {}, [None]
_LIMIT = float(os.environ.get("CATALOGUE_CPU_LIMIT", "0"))
class NoAnswerWithinLimit(Exception):
    pass
def _stop(signum, frame):
    raise NoAnswerWithinLimit(f"no answer within {_LIMIT:g} s of CPU")
_raises, _warns = pytest.raises, pytest.warns
def _recording(kind, original):
    def wrapper(*args, **kwargs):
        if _current[0] is not None:
            _kinds.setdefault(_current[0], set()).add(kind)
        return original(*args, **kwargs)
    return wrapper
pytest.raises, pytest.warns = _recording("raises", _raises), _recording("warns", _warns)
@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_call(item):
    _current[0] = item.nodeid
    if _LIMIT > 0:          # CPU time of this process (ITIMER_PROF), per test
        signal.signal(signal.SIGPROF, _stop)
        signal.setitimer(signal.ITIMER_PROF, _LIMIT)
    try:
        yield
    finally:
        if _LIMIT > 0:
            signal.setitimer(signal.ITIMER_PROF, 0)
        _current[0] = None
def pytest_sessionfinish(session):
    with open(os.environ["CATALOGUE_KINDS"], "w") as f:
        json.dump({k: sorted(v) for k, v in _kinds.items()}, f)
'''


def run(source=None, only=None, cpu_limit=0.0):
    """{nodeid: (outcome, message)} and {nodeid: kinds} of the tests marked badinput on ``source``
    (those whose node id holds ``only``, if given), each stopped after ``cpu_limit`` s of CPU."""
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "catalogue_plugin.py").write_text(_PLUGIN)
        env = dict(os.environ, CATALOGUE_KINDS=str(tmp / "kinds.json"),
                   CATALOGUE_CPU_LIMIT=str(cpu_limit))
        path = [str(tmp)] + ([str(Path(source).resolve())] if source else [])
        env["PYTHONPATH"] = os.pathsep.join(path + [env.get("PYTHONPATH", "")])
        selection = ["-k", only] if only else []
        subprocess.run([sys.executable, "-m", "pytest", "tests", "-m", "badinput", "-q", *selection,
                        "-p", "catalogue_plugin", "-p", "no:cacheprovider",
                        f"--junitxml={tmp / 'junit.xml'}"],
                       cwd=ROOT, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       preexec_fn=_limit_memory)
        outcomes = {}
        for case in ElementTree.parse(tmp / "junit.xml").iter("testcase"):
            nodeid = f"{case.get('classname')}::{case.get('name')}"
            problem = next((child for child in case if child.tag in ("failure", "error")), None)
            if problem is None:
                outcomes[nodeid] = ("passed", "")
            else:
                outcomes[nodeid] = (problem.tag, (problem.get("message") or "")
                                    + "\n" + (problem.text or ""))
        kinds_file = tmp / "kinds.json"
        import json

        kinds = json.loads(kinds_file.read_text()) if kinds_file.exists() else {}
        kinds = {_junit_id(k): v for k, v in kinds.items()}
    return outcomes, kinds


def _limit_memory():
    """8 GiB of address space for the catalogue's run: an old tree that allocates without
    bound (a simulation of 1e9 s) then fails with MemoryError, counted as foreign, instead of
    being killed by the system with the whole run."""
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (8 << 30, 8 << 30))


def _junit_id(nodeid):
    """tests/badinput/test_x.py::name[p] → tests.badinput.test_x::name[p] (junit's classname)."""
    module, _, name = nodeid.partition("::")
    return module.removesuffix(".py").replace("/", ".") + "::" + name


def demanded(nodeid, kinds):
    if "test_cli" in nodeid:
        return "crowdvib error (CLI exit code and message)"
    used = set(kinds.get(nodeid, ()))
    if "raises" in used:
        return "crowdvib error"
    if "warns" in used:
        return "warning"
    return "read or computed correctly"


def classify(outcome, message):
    if outcome == "passed":
        return "as demanded"
    if re.search(r"ImportError while importing|cannot import name|No module named 'crowdvib\.",
                 message):
        return "not comparable (newer API)"
    if "NoAnswerWithinLimit" in message:
        return "no answer in the CPU limit"
    if re.search(r"DID NOT RAISE|DID NOT WARN|did not emit|assert 0 == [12]", message):
        return "silent"
    if "Regex pattern did not match" in message or "does not match" in message:
        return "poor message"
    foreign = re.search(r"^E\s+(\w+(?:Error|Exception|Warning))\b", message, re.M)
    if foreign and not re.match(r"(Parameter|Data|Estimation|Output|Crowdvib)", foreign.group(1)):
        return f"foreign ({foreign.group(1)})"
    if re.search(r"Traceback", message):
        return "traceback"
    return "other failure"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", help="another crowdvib source tree (its src folder)")
    parser.add_argument("--list", action="store_true",
                        help="with --against: each case and how that tree answered it")
    parser.add_argument("--only", help="only the cases whose test id holds this text (pytest -k), "
                        "e.g. issue35")
    parser.add_argument("--cpu-limit", type=float, default=120.0,
                        help="CPU seconds a case may take before it counts as no answer "
                             "(default 120; 0: no limit)")
    args = parser.parse_args()
    # this tree's catalogue on this tree's source
    now, kinds = run(ROOT / "src", args.only, args.cpu_limit)
    print(f"tests marked badinput: {len(now)} cases")
    table = collections.Counter((demanded(n, kinds), classify(*now[n])) for n in now)
    print(f"\n{'demanded':46s}{'now':>22s}{'cases':>7s}")
    for (want, got), count in sorted(table.items()):
        print(f"{want:46s}{got:>22s}{count:7d}")
    if args.against:
        before, _ = run(args.against, args.only, args.cpu_limit)
        table = collections.Counter(classify(*before.get(n, ("error", "missing"))) for n in now)
        print(f"\non {args.against}:")
        for got, count in table.most_common():
            print(f"  {got:40s}{count:5d}")
        if args.list:
            for nodeid in now:
                outcome, message = before.get(nodeid, ("error", "missing"))
                print(f"{classify(outcome, message):32s} {nodeid}  "
                      f"{' '.join(message.split())[:160]}")


if __name__ == "__main__":
    main()
