"""Monte Carlo in batches on the study engine (issue 14)."""

import concurrent.futures
import multiprocessing

import numpy as np
import pytest

from crowdvib import simulate
from crowdvib.errors import ParameterError
from crowdvib.runner import TaskStore
from crowdvib.studies import monte_carlo, record_statistics
from crowdvib.models.examples import paper_example

OPTIONS = {"sample_rate": 50.0, "warm_up": 1.0}

#: concurrent.futures' own pool, as a user would pass it, but from a fork server: its
#: default (fork) copies this threaded process, which Python 3.12+ warns may deadlock.
_CONTEXT = multiprocessing.get_context("forkserver")


def peak_only(record):
    return {"seed": record.seed, "peak": float(np.abs(record.acceleration).max())}


def test_batches_give_the_summaries_of_one_at_a_time_records(tmp_path):
    # Reference: record_statistics of simulate(rng=seed), one seed at a time in this thread.
    case = paper_example()
    seeds = [4, 8, 15, 16, 23]
    rows = monte_carlo(case.structure, case.crowd, 8.0, seeds=seeds, msd=case.msd,
                       batch_size=2, store=tmp_path / "store", **OPTIONS)
    alone = [record_statistics(simulate(case.structure, case.crowd, 8.0, msd=case.msd, rng=s,
                                        **OPTIONS)) for s in seeds]
    assert rows == [{**row, "rms": list(row["rms"]), "peak": list(row["peak"])} for row in alone]
    assert len(TaskStore(tmp_path / "store").keys()) == 3          # batches of 2, 2, 1


def test_a_finished_study_resumes_without_simulating(tmp_path):
    # Reference: run_tasks' contract: stored results are read back, nothing pending runs, so
    # progress is called once with everything done.
    case = paper_example()
    first = monte_carlo(case.structure, case.crowd, 5.0, seeds=range(4), summary=peak_only,
                        batch_size=3, store=tmp_path, **OPTIONS)
    calls = []
    again = monte_carlo(case.structure, case.crowd, 5.0, seeds=range(4), summary=peak_only,
                        batch_size=3, store=tmp_path, progress=lambda d, t: calls.append((d, t)),
                        **OPTIONS)
    assert again == first and calls == [(2, 2)]


def test_a_process_pool_gives_the_same_rows():
    # Reference: the same study in this process (a record depends on its seed alone).
    case = paper_example()
    with concurrent.futures.ProcessPoolExecutor(2, mp_context=_CONTEXT) as pool:
        pooled = monte_carlo(case.structure, case.crowd, 5.0, seeds=[1, 2, 3], summary=peak_only,
                             batch_size=1, executor=pool, **OPTIONS)
    here = monte_carlo(case.structure, case.crowd, 5.0, seeds=[1, 2, 3], summary=peak_only,
                       batch_size=1, **OPTIONS)
    assert pooled == here and [row["seed"] for row in here] == [1, 2, 3]


@pytest.mark.parametrize("kwargs, message", [
    ({"summary": lambda record: {}}, "summary must be a module-level function"),
    ({"batch_size": 0}, "batch_size must be an integer >= 1, got 0"),
    ({"seeds": []}, "seeds must hold at least one seed"),
])
def test_bad_input_names_the_parameter(kwargs, message):
    case = paper_example()
    arguments = {"seeds": [1], **kwargs}
    with pytest.raises(ParameterError, match=message):
        monte_carlo(case.structure, case.crowd, 5.0, **arguments)
