"""crowdvib's local worker pool (runner/_pool.py, issue 14): results, the death of a
worker, of the parent, errors inside tasks, cancelling and killing.

References: the same functions called in this process (results), the operating system's view of
the processes (psutil, exit codes), and the pool's documented rules (a task gets three tries).
"""

import concurrent.futures
import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from crowdvib.runner._pool import ProcessPool, WorkerDied

psutil = pytest.importorskip("psutil")


def _square(value):
    return value * value, os.getpid()


def _die(_):
    os._exit(3)


def _fail(value):
    raise ValueError(f"bad value {value}")


def _unpicklable(_):
    return lambda: None


def _exit(_):
    sys.exit(5)


def _sleep(seconds):
    time.sleep(seconds)
    return seconds


def _crash_once(marker):
    if not os.path.exists(marker):
        open(marker, "w").close()
        os._exit(1)
    return "second try"


@pytest.mark.parametrize("method", ["fork", "forkserver", "spawn"])
def test_results_equal_the_same_calls_in_this_process_on_two_workers(method):
    # Reference: _square called here; every worker is a process other than this one.
    if method not in __import__("multiprocessing").get_all_start_methods():
        pytest.skip(f"no {method} start method here")
    with ProcessPool(2, method=method) as pool:
        results = list(pool.map(_square, range(40)))
    assert [value for value, _ in results] == [_square(k)[0] for k in range(40)]
    pids = {pid for _, pid in results}
    assert os.getpid() not in pids and 1 <= len(pids) <= 2


def test_a_task_that_kills_its_worker_fails_after_three_tries_and_the_rest_go_on(tmp_path):
    # The pool's rule: a task gets three workers; each death is replaced by a new worker.
    with ProcessPool(2) as pool:
        doomed = pool.submit(_die, None)
        others = [pool.submit(_square, k) for k in range(10)]
        with pytest.raises(WorkerDied, match=r"died 3 time\(s\) \(last exit code 3\)"):
            doomed.result(timeout=60)
        assert [f.result(timeout=60)[0] for f in others] == [k * k for k in range(10)]
        # Workers replaced: the pool still has two live ones and runs new work.
        assert pool.submit(_square, 7).result(timeout=60)[0] == 49
        assert sum(p.is_alive() for p in pool._processes.values()) == 2


def test_a_task_whose_worker_died_once_runs_again_on_a_new_worker(tmp_path):
    marker = str(tmp_path / "crashed")
    with ProcessPool(1) as pool:
        first = pool._processes[0].pid
        assert pool.submit(_crash_once, marker).result(timeout=60) == "second try"
        assert pool._processes[0].pid != first
    assert os.path.exists(marker)


def test_errors_of_a_task_reach_the_caller_with_the_workers_traceback():
    with ProcessPool(1) as pool:
        with pytest.raises(ValueError, match="bad value 4") as raised:
            pool.submit(_fail, 4).result(timeout=60)
        assert "in _fail" in str(raised.value.__cause__)          # the worker's traceback
        with pytest.raises(RuntimeError, match="result could not be sent back"):
            pool.submit(_unpicklable, None).result(timeout=60)
        with pytest.raises(RuntimeError, match=r"ended its worker: SystemExit\(5\)"):
            pool.submit(_exit, None).result(timeout=60)
        # A call that cannot be sent (pickle's words differ: 3.11 "pickle", 3.13 "local object").
        with pytest.raises(Exception, match="pickle|local object"):
            pool.submit(lambda: None).result(timeout=60)
        assert pool.submit(_square, 3).result(timeout=60)[0] == 9   # the worker lives on


def test_shutdown_cancels_what_has_not_started_and_close_kill_stops_busy_workers():
    pool = ProcessPool(1)
    busy = pool.submit(_sleep, 60.0)
    waiting = [pool.submit(_sleep, 60.0) for _ in range(3)]
    while not busy.running():
        time.sleep(0.01)
    workers = [psutil.Process(p.pid) for p in pool._processes.values()]
    pool.close(kill=True)
    assert all(f.cancelled() for f in waiting)
    with pytest.raises(WorkerDied, match=r"the pool ended its worker \(close\(kill=True\)"):
        busy.result(timeout=10)
    assert not any(w.is_running() and w.status() != psutil.STATUS_ZOMBIE for w in workers)
    with pytest.raises(RuntimeError, match="closed"):
        pool.submit(_square, 1)


def test_workers_ended_by_the_pool_are_not_said_to_die_nor_leak_semaphores(tmp_path):
    # Issue 36 §3: after Ctrl-C (close(kill=True)) the console said "worker … died, its task
    # fails" for workers the pool itself ended, and Python's resource tracker "There appear to
    # be 2 leaked semaphore objects" (numba's thread-launch lock, made in each worker: a
    # SIGKILL skips its release). The workers are now asked to exit (SIGTERM) first.
    script = tmp_path / "ended.py"
    script.write_text(textwrap.dedent("""
        import time
        from crowdvib.runner._pool import ProcessPool

        def nap(seconds):
            time.sleep(seconds)

        if __name__ == "__main__":
            pool = ProcessPool(2)
            busy = [pool.submit(nap, 60.0) for _ in range(2)]
            while not all(f.running() for f in busy):
                time.sleep(0.05)
            started = time.monotonic()
            pool.close(kill=True)
            print(f"closed in {time.monotonic() - started:.2f} s")
    """))
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          timeout=180, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "died" not in done.stderr and "leaked" not in done.stderr, done.stderr
    # Within the grace period: a sleeping worker leaves at once (_pool._GRACE = 2 s).
    assert float(done.stdout.split()[2]) < 2.0


def test_workers_ignore_ctrl_c_and_die_with_their_parent_even_by_sigkill(tmp_path):
    # A parent holding two busy workers: SIGINT to the workers changes nothing; SIGKILL of the
    # parent leaves no worker behind (the lifeline pipe closes with it).
    script = tmp_path / "parent.py"
    # The main guard: workers import this script (forkserver, as under spawn).
    script.write_text(textwrap.dedent(f"""
        import sys, time
        sys.path.insert(0, {os.path.dirname(__file__)!r})
        from crowdvib.runner._pool import ProcessPool
        from test_pool import _sleep
        if __name__ == "__main__":
            pool = ProcessPool(2)
            futures = [pool.submit(_sleep, 120.0) for _ in range(2)]
            print(" ".join(str(p.pid) for p in pool._processes.values()), flush=True)
            time.sleep(120)
    """))
    parent = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
    try:
        workers = [psutil.Process(int(pid)) for pid in parent.stdout.readline().split()]
        assert len(workers) == 2
        for worker in workers:
            os.kill(worker.pid, signal.SIGINT)
        time.sleep(0.5)
        assert all(w.is_running() for w in workers)               # Ctrl-C is the parent's
        parent.kill()
        parent.wait()
        gone, alive = psutil.wait_procs(workers, timeout=10)
        assert alive == []
    finally:
        parent.kill()
        parent.wait()
        parent.stdout.close()       # else the garbage collector warns of it in a later test


def test_the_pool_is_a_concurrent_futures_executor():
    # run_tasks and the studies use the Executor interface (submit, as_completed, shutdown).
    with ProcessPool(2) as pool:
        futures = [pool.submit(_square, k) for k in range(6)]
        done = {f.result()[0] for f in concurrent.futures.as_completed(futures, timeout=60)}
    assert done == {k * k for k in range(6)}


@pytest.mark.parametrize("name, value", [("workers", 0), ("attempts", 0), ("workers", 1.5)])
def test_bad_sizes_are_refused_naming_the_parameter(name, value):
    from crowdvib.errors import ParameterError

    with pytest.raises(ParameterError, match=f"{name} must be an integer >= 1, got {value}"):
        ProcessPool(**{"workers": 1, name: value})
