"""Threads of a study's workers and the --workers default (issue 14)."""

import os

import pytest

from crowdvib._resources import (
    BUDGET_VARIABLE,
    THREAD_VARIABLES,
    default_workers,
    physical_cores,
    thread_budget,
    thread_share,
)
from crowdvib.runner import run_tasks, study_executor


def _threads_in_worker(payload):
    import numba

    return {"numba": numba.get_num_threads(), "budget": thread_budget(),
            "environ": {name: os.environ.get(name)
                        for name in THREAD_VARIABLES + (BUDGET_VARIABLE, "NUMBA_NUM_THREADS")}}


def test_thread_share_divides_the_cores():
    # Reference: the rule cores // workers, at least one.
    assert [thread_share(w, cores=8) for w in (1, 2, 3, 8, 16)] == [8, 4, 2, 1, 1]


def test_default_workers_is_the_physical_core_count():
    # Reference: psutil's count of physical cores (the rule).
    psutil = pytest.importorskip("psutil")
    assert physical_cores() == (psutil.cpu_count(logical=False) or os.cpu_count())
    assert default_workers() == physical_cores()


def test_local_workers_run_numba_and_blas_with_their_share_of_the_cores():
    # Two workers on this machine: each gets physical_cores() // 2 threads (numba would
    # otherwise start one thread per CPU in every worker).
    share = thread_share(2)
    with study_executor(workers=2) as executor:
        result = run_tasks(_threads_in_worker, [("only", None)], executor=executor)["only"]
    assert result["numba"] == share
    for name in THREAD_VARIABLES:
        assert result["environ"][name] == os.environ.get(name, str(share))
    # crowdvib's own parallel code (simulate_many) reads the share from CROWDVIB_THREADS;
    # NUMBA_NUM_THREADS stays as this process had it (numba refuses a change once its threads
    # run, issue 24).
    assert result["budget"] == share and result["environ"][BUDGET_VARIABLE] == str(share)
    assert result["environ"]["NUMBA_NUM_THREADS"] == os.environ.get("NUMBA_NUM_THREADS")


def test_the_cli_states_the_default_in_its_help(capsys):
    # Reference: the rule (--workers defaults to the physical cores), said in --help.
    from crowdvib.cli.main import main

    try:
        main(["sensitivity", "--help"])
    except SystemExit:
        pass
    text = " ".join(capsys.readouterr().out.split())
    assert "the physical cores of the machine it runs on" in text
    # Issue 27 §1: the help is published in the docs, so it names no core count of its own.
    assert f"{physical_cores()} on this machine" not in text
