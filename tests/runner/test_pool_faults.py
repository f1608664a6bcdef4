"""Study workers that start from a fresh install and never hang (issue 24 §2).

* numba's ``NUMBA_NUM_THREADS`` is no longer changed in a worker whose numba is loaded: numba
  reads it again before every compilation and raised "Cannot set NUMBA_NUM_THREADS to a
  different value once the threads have been launched" (numba.core.config), so from a cold
  numba cache every task of a study failed (both tests of that fail on 49020a3);
* workers come from a fork server, not from a fork of this threaded process (Python >= 3.12
  warns of deadlocks there);
* a stopped or stuck worker is killed after max(timeout_floor, timeout_factor × slowest finished
  task) and its task runs again, then fails naming it; a dead dask scheduler ends the study
  with one SchedulerLost.

References: the pool's documented rules (_pool.py), the same calls in this process, and the
bounds stated in each test.
"""

import logging
import math
import os
import re
import signal
import subprocess
import sys
import textwrap
import time
import warnings

import pytest

from crowdvib.errors import ParameterError, PlausibilityWarning
from crowdvib.runner import run_tasks, study_executor
from crowdvib.runner._pool import ProcessPool, WorkerDied

psutil = pytest.importorskip("psutil")


def _square(value):
    return value * value


def _sleep(seconds):
    time.sleep(seconds)
    return seconds


def _stop_or_square(payload):
    """A task of run_tasks: "stop" freezes its worker (as SIGSTOP from outside would)."""
    if payload == "stop":
        os.kill(os.getpid(), signal.SIGSTOP)
    return {"square": payload * payload}


def _compile_in_worker(value):
    """Compile a new numba function here (no cache can hold it) and report numba's threads."""
    import numba

    return numba.njit(lambda a: a + 1)(value), numba.get_num_threads()


def _die(_):
    os._exit(3)


# ------------------------------------------------------------------------------ hung workers
def test_a_stopped_worker_is_killed_and_its_task_runs_elsewhere_within_a_bound(caplog):
    # Bound: the other worker finishes 0.05 s tasks, so the limit is max(2 s, 10 × ~0.1 s) = 2 s,
    # looked at every second: the stopped worker's task runs again after at most 3 s; the study
    # of 20 tasks ends within 15 s (it took days before: nothing noticed the stopped worker).
    with ProcessPool(2, timeout_floor=2.0) as pool:
        stopped = pool._processes[0]
        os.kill(stopped.pid, signal.SIGSTOP)
        began = time.monotonic()
        futures = [pool.submit(_sleep, 0.05) for _ in range(20)]
        results = [future.result(timeout=60) for future in futures]
        elapsed = time.monotonic() - began
        assert pool._processes[0].pid != stopped.pid and pool._processes[0].is_alive()
    assert results == [0.05] * 20
    assert elapsed < 15.0
    assert stopped.exitcode == -signal.SIGKILL
    assert any("hung, killed after" in r.message and "runs again (attempt 2 of 3)" in r.message
               for r in caplog.records)


def test_a_task_that_always_hangs_fails_naming_it_after_three_tries(caplog):
    # The pool's rule: three tries, each ended at the limit (fixed here: timeout_factor 0 →
    # timeout_floor 1 s); the bound: 3 × (1 s + a worker's start) ≈ 4 s, < 15 s on a busy
    # machine. run_tasks names the task in its log and in its result; the other tasks are done.
    tasks = [("stuck", "stop")] + [(f"fine-{k}", k) for k in range(6)]
    with ProcessPool(2, timeout_floor=1.0, timeout_factor=0) as pool:
        began = time.monotonic()
        with caplog.at_level(logging.WARNING):
            results = run_tasks(_stop_or_square, tasks, executor=pool)
        elapsed = time.monotonic() - began
    assert elapsed < 15.0
    assert {name: results[name] for name in results if name != "stuck"} == {
        f"fine-{k}": {"square": k * k} for k in range(6)}
    error = results["stuck"]["error"]
    assert "WorkerDied" in error and "died 3 time(s)" in error
    assert re.search(r"killed after \d+\.\d s without an answer, past the time limit 1 s =",
                     error)
    assert any(r.message.startswith("task stuck failed on its worker: WorkerDied")
               for r in caplog.records)


def test_no_limit_until_a_task_has_finished_unless_the_factor_is_zero():
    # The documented rule: max(floor, factor × slowest); nothing measured yet → no limit.
    pool = ProcessPool(1, timeout_floor=30.0, timeout_factor=3.0)
    try:
        assert pool._limit() is None
        assert pool.submit(_sleep, 0.2).result(timeout=60) == 0.2
        assert 0.2 <= pool._slowest < 10.0 and pool._limit() == 30.0     # 3 × slowest < 30 s
        pool._slowest = 40.0
        assert pool._limit() == 120.0
        pool._factor = 0.0
        assert pool._limit() == 30.0
    finally:
        pool.close()


@pytest.mark.parametrize("keyword, value, message", [
    ("timeout_floor", 0, "timeout_floor must be a number of seconds > 0 (inf: no limit), got 0"),
    ("timeout_floor", -60.0, "timeout_floor must be a number of seconds > 0"),
    ("timeout_floor", math.nan, "timeout_floor must be a number of seconds > 0"),
    ("timeout_floor", "60", "timeout_floor must be a number of seconds > 0 (inf: no limit), "
                            "got '60'"),
    ("timeout_floor", True, "timeout_floor must be a number of seconds > 0"),
    ("timeout_factor", -1, "timeout_factor must be a finite number >= 0, got -1"),
    ("timeout_factor", math.inf, "timeout_factor must be a finite number >= 0, got inf"),
    ("timeout_factor", None, "timeout_factor must be a finite number >= 0, got None"),
])
def test_bad_time_limits_are_refused_naming_the_keyword(keyword, value, message):
    # Reference: the rules in ProcessPool's docstring; study_executor passes them on.
    with pytest.raises(ParameterError, match=message.replace("(", r"\(").replace(")", r"\)")):
        ProcessPool(1, **{keyword: value})
    with pytest.raises(ParameterError, match=keyword):
        with study_executor(workers=2, **{keyword: value}):
            pass


@pytest.mark.parametrize("keyword, value, message", [
    ("timeout_floor", 60000.0, r"timeout_floor = 60000 s is 16.7 h: milliseconds given for "
                               r"seconds\? \(it would then be 60 s\)"),
    ("timeout_factor", 0.1, r"timeout_factor = 0.1 kills a task .* a fraction given for a "
                            r"multiple\? \(0.1 → 10\)"),
])
def test_doubtful_time_limits_are_warned_with_the_likely_mix_up(keyword, value, message):
    with pytest.warns(PlausibilityWarning, match=message):
        ProcessPool(1, **{keyword: value}).close()


# ------------------------------------------------------------------------------ numba's threads
@pytest.mark.parametrize("method", ["fork", "forkserver"])
def test_a_worker_compiles_numba_code_after_this_process_launched_numbas_threads(method):
    # Reference: numba.core.config.reload_config raised in the worker on 49020a3 (the worker
    # had changed NUMBA_NUM_THREADS, then compiled). The worker gets its share of the cores.
    import numba

    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)        # launches this process's pool
    from crowdvib._resources import thread_share

    with ProcessPool(2, method=method) as pool:
        value, threads = pool.submit(_compile_in_worker, 41).result(timeout=120)
    assert (value, threads) == (42, thread_share(2))


@pytest.mark.slow
def test_monte_carlo_of_a_two_mode_bridge_on_two_workers_from_a_cold_numba_cache(tmp_path):
    # The case in small: a fresh NUMBA_CACHE_DIR, so the workers compile the multi-mode
    # kernels themselves; on 49020a3 every batch failed with numba's RuntimeError. Reference:
    # the records' own seeds and finite, positive RMS (the same rows as in this process are
    # checked by test_monte_carlo.py on a warm cache). About 50 s (compilation) on 2 cores.
    script = tmp_path / "cold.py"
    script.write_text(textwrap.dedent("""
        import math
        from crowdvib import Crowd, ModalModel, MSDModel
        from crowdvib.studies import monte_carlo
        from crowdvib.runner import study_executor

        if __name__ == "__main__":
            bridge = ModalModel.simply_supported_beam(
                span=50.0, width=3.0, frequency=[2.0, 7.5], damping_ratio=0.005,
                modal_mass=50e3, n_modes=2)
            crowd = Crowd(density=0.3, walking_speed=1.30, step_frequency_mean=1.89,
                          step_frequency_std=0.175, body_mass=70.0)
            msd = MSDModel(frequency=3.0, damping_ratio=0.30, mass_ratio=0.95)
            with study_executor(workers=2) as executor:
                rows = monte_carlo(bridge, crowd, 4.0, seeds=[1, 2], batch_size=1,
                                   executor=executor, msd=msd, sample_rate=50.0, warm_up=1.0)
            assert [row["seed"] for row in rows] == [1, 2], rows
            assert all(math.isfinite(v) and v > 0 for row in rows for v in row["rms"]), rows
            print("ok")
    """))
    environment = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    environment.pop("NUMBA_NUM_THREADS", None)               # unset: the usual case
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         env=environment, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stdout.strip() == "ok"
    assert "NUMBA_NUM_THREADS" not in run.stderr


# ------------------------------------------------------------------------------ start method
def test_a_dead_workers_replacement_is_not_forked_from_this_threaded_process():
    # Python >= 3.12 warns "This process ... is multi-threaded, use of fork() may lead to
    # deadlocks in the child" (os.fork); the pool's threads replace dead workers, so a fork
    # there is the case. Reference: the same pool on method="fork" warns on those Pythons.
    def forks_warned(method):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            with ProcessPool(2, method=method) as pool:
                with pytest.raises(WorkerDied):
                    pool.submit(_die, None).result(timeout=60)
                assert pool.submit(_square, 5).result(timeout=60) == 25
        return [w for w in caught if "fork()" in str(w.message)]

    assert forks_warned(None) == []
    if sys.version_info >= (3, 12):
        assert forks_warned("fork") != []


# ------------------------------------------------------------------------------ dask scheduler
def _nap(seconds):
    """A task of run_tasks on the dask cluster (imported there from this file's folder)."""
    time.sleep(seconds)
    return {"slept": seconds}


@pytest.fixture
def cluster(tmp_path):
    """A dask scheduler (in the process returned) with one worker process, on loopback."""
    pytest.importorskip("distributed")
    script = tmp_path / "cluster.py"
    script.write_text(textwrap.dedent("""
        import time
        from distributed import LocalCluster

        import crowdvib.studies  # the scheduler unpickles tasks: 3 s at the first, once

        if __name__ == "__main__":
            cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                   host="127.0.0.1", scheduler_port=0, dashboard_address=None)
            print(cluster.scheduler_address, flush=True)
            time.sleep(600)
    """))
    here = os.path.dirname(__file__)
    environment = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [here] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])}
    process = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True,
                               env=environment, start_new_session=True)
    try:
        process.address = process.stdout.readline().strip()
        assert process.address.startswith("tcp://127.0.0.1:"), process.address
        yield process
    finally:
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        process.wait(timeout=30)
        process.stdout.close()      # else the garbage collector warns of it in a later test


def _study_losing_its_scheduler(address, store, lose):
    """run_tasks of 40 naps of 0.2 s on ``address``, calling ``lose()`` after 3 are done;
    returns the error it ended with and the seconds from ``lose()`` to the end."""
    from crowdvib.runner.engine import SchedulerLost

    lost = []

    def progress(done, total):
        if done >= 3 and not lost:
            lose()
            lost.append(time.monotonic())

    with pytest.raises(SchedulerLost) as raised:
        with study_executor(scheduler=address) as executor:
            run_tasks(_nap, [(f"nap-{k}", 0.2) for k in range(40)], executor=executor,
                      store=store, progress=progress)
    return raised.value, time.monotonic() - lost[0]


@pytest.mark.slow
def test_a_killed_dask_scheduler_ends_the_study_with_one_crowdvib_error_within_a_bound(
        cluster, tmp_path, caplog):
    # The issue: the study waited minutes without a word, then Ctrl-C printed tracebacks. Now
    # dask's cancellation of every task on losing the connection becomes one SchedulerLost,
    # raised within 15 s of the kill (the client's close takes up to 2 s); the finished tasks
    # stay stored; no task is reported failed one by one and dask logs no traceback.
    from crowdvib.runner import TaskStore

    with caplog.at_level(logging.WARNING):
        error, elapsed = _study_losing_its_scheduler(
            cluster.address, tmp_path / "store", lambda: os.kill(cluster.pid, signal.SIGKILL))
    assert elapsed < 15.0
    assert f"the dask scheduler at {cluster.address} was lost" in str(error)
    assert "(its connection closed)" in str(error) and "run the study again (resume)" in str(error)
    assert isinstance(error, ConnectionError)                    # and a CrowdvibError
    assert len(TaskStore(tmp_path / "store").keys()) >= 3
    assert [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING] == []


@pytest.mark.slow
def test_a_frozen_dask_scheduler_is_noticed_by_its_missed_ping(cluster, tmp_path, monkeypatch):
    # A stopped scheduler keeps its connection open and says nothing; the ping (every 0.5 s
    # here, 2 s to answer) notices it: SchedulerLost within 2 + 0.5 + 2 (close) s, bound 10 s.
    from crowdvib.runner import engine

    monkeypatch.setattr(engine, "_PING_EVERY", 0.5)
    monkeypatch.setattr(engine, "_PING_TIMEOUT", 2.0)
    try:
        error, elapsed = _study_losing_its_scheduler(
            cluster.address, tmp_path / "store", lambda: os.kill(cluster.pid, signal.SIGSTOP))
    finally:
        os.kill(cluster.pid, signal.SIGCONT)
    assert elapsed < 10.0
    assert "no answer to a ping within 2 s" in str(error)
