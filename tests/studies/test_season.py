"""A season of monitoring (issue 28 §2): a small season of short records with a crowd table,
each record estimated with its interval, the table, and the joint estimate covering the truth,
in this process, on the local pool and on a local dask cluster.

The records are stationary Gaussian records of the smeared crowd's expected PSD
(``write_synthetic_season``), which the paper's least squares assumes: an estimate's interval
then covers the truth at its level, and so does the joint one (docs: theory, Joint estimation).
"""

import warnings

import numpy as np
import pytest

from crowdvib import MSDModel, load_case
from crowdvib.cases import season_case
from crowdvib.errors import DataError, PlausibilityWarning
from crowdvib.models.examples import paper_example
from crowdvib.runner import TaskStore, study_executor
from crowdvib.studies.season import TABLE_COLUMNS, write_synthetic_season
from tests.conftest import copy_paper_case

#: The paper's numerical example (docs: theory, The paper's numerical example): its bridge,
#: crowd, MSD and estimator (tests.conftest.copy_paper_case); the season's records are 600 s at
#: 25 Hz, at eight densities.
TRUTH = MSDModel(3.0, 0.30, 0.95)
DENSITIES = np.linspace(0.2, 1.0, 8)
AREA = 50.0 * 3.0


@pytest.fixture(scope="module")
def season(tmp_path_factory):
    """The records, a crowd table (counts for half the rows, a night record with no one on the
    deck, times) and the case."""
    folder = tmp_path_factory.mktemp("season")
    paper = paper_example()
    write_synthetic_season(folder, paper.structure, paper.crowd, TRUTH,
                           densities=[*DENSITIES, 0.3],
                           duration=600.0, sample_rate=25.0, rng=28)
    lines = ["record,count,density,time"]
    for number, density in enumerate(DENSITIES, start=1):
        crowd_cells = f"{float(density * AREA)!r}," if number % 2 else f",{float(density)!r}"
        lines.append(f"record_{number:03d}.npz,{crowd_cells},2026-05-0{number}T12:00")
    lines.append("record_009.npz,0,,2026-05-09T03:00")       # night: no one on the deck
    (folder / "crowd.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
    copy_paper_case(folder, "season.toml")       # the paper's bridge and least squares
    return folder


def _run(folder, **options):
    return season_case(load_case(folder / "season.toml"), folder / "crowd.csv", records=folder,
                       **options)


@pytest.fixture(scope="module")
def alone(season):
    """The season run in this process, its tasks stored in the season's folder."""
    return _run(season, store=TaskStore(season / "tasks"))


def test_a_season_gives_one_row_per_record_with_intervals_and_a_joint_estimate(alone):
    found = alone
    table = found.season.to_dataframe()
    assert list(table.columns) == list(TABLE_COLUMNS) and len(table) == 9
    # Counts become densities on the 150 m² deck; the night record is kept, not estimated.
    assert table["density"].iloc[:8].to_numpy() == pytest.approx(DENSITIES, rel=1e-12)
    assert table["status"].iloc[8] == "skipped" and np.isnan(table["frequency"].iloc[8])
    estimated = table.iloc[:8]
    assert set(estimated["status"]) <= {"ok", "doubt"}
    for name in ("frequency", "damping_ratio"):
        assert (estimated[f"{name}_low"] < estimated[name]).all()
        assert (estimated[name] < estimated[f"{name}_high"]).all()
    # The joint estimate (docs: theory, Joint estimation): its 95 % interval covers the truth
    # and is narrower than any one record's.
    joint = found.season.joint
    for name in ("frequency", "damping_ratio"):
        low, high = joint.interval(name, 0.95)
        assert low <= getattr(TRUTH, name) <= high
        assert high - low < (estimated[f"{name}_high"] - estimated[f"{name}_low"]).min()
    # Per record the intervals cover the truth at their level: 8 records, at least 6 (the
    # chance of fewer is below 1 % at 95 % coverage).
    coverage = found.season.coverage(TRUTH.to_dict())
    assert coverage["frequency"] >= 6 / 8 and coverage["damping_ratio"] >= 6 / 8
    # results.json of kind "season", read back by load_results, with the same table.
    results = found.results()
    assert results.kind == "season" and results.to_dataframe().shape == (9, len(TABLE_COLUMNS))
    assert results.estimate["frequency"] == joint.msd.frequency
    assert results.interval("damping_ratio")[:2] == pytest.approx(joint.interval("damping_ratio"))


def test_a_season_on_the_local_pool_and_resumed_gives_the_same_table(season, alone, tmp_path):
    # Tasks are pinned to one BLAS thread (runner.tasks): the same bits in this process and on
    # two local workers; resumed, a season recomputes nothing and says it is done.
    with study_executor(2) as executor:
        pooled = _run(season, executor=executor, store=tmp_path / "tasks").season.table()
    assert pooled == alone.season.table()
    store = TaskStore(season / "tasks")
    stamps = {p: p.stat().st_mtime_ns for p in store.directory.glob("*.json")}
    calls = []
    again = _run(season, store=store, progress=lambda done, total: calls.append((done, total)))
    assert again.season.table() == alone.season.table() and calls == [(8, 8)]
    assert {p: p.stat().st_mtime_ns for p in store.directory.glob("*.json")} == stamps


def test_a_season_on_a_dask_cluster_in_batches_gives_the_same_table(season, alone):
    # A local two-process dask cluster, as CI runs it where dask is installed; three records per
    # dask task (the batching of issue 28 §2), each still stored and reported on its own.
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster:
        with study_executor(scheduler=cluster.scheduler_address) as executor:
            remote = _run(season, executor=executor, batch_size=3).season.table()
            # Asked, the cluster cuts 320 tasks into 16 batches per worker thread: 10 each.
            assert executor.batch_size(320) == 10
    assert remote == alone.season.table()


def test_a_crowd_table_naming_a_record_that_is_not_there_is_refused(season, tmp_path):
    table = tmp_path / "crowd.csv"
    table.write_text("record,density\nrecord_001.npz,0.5\nrecord_042.npz,0.5\n")
    with pytest.raises(DataError, match=r"crowd.csv: row 2, column 'record': 'record_042.npz' "
                                        r"is not among the season's 10 record\(s\)"):
        season_case(load_case(season / "season.toml"), table, records=season)


def test_a_count_in_the_density_column_is_named_with_the_density_it_would_be(season, tmp_path):
    # 45 persons/m² is no crowd that walks (Weidmann's jam density is 5.4): 45 persons on the
    # 150 m² deck are 0.3 persons/m² (docs: theory, Plausible ranges).
    table = tmp_path / "crowd.csv"
    table.write_text("record,density\nrecord_001.npz,45\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(DataError, match="crowd.csv: row 1: density must be < the jam "
                                            "density 5.4 persons/m², got 45"):
            season_case(load_case(season / "season.toml"), table, records=season)
    notes = [str(w.message) for w in caught if w.category is PlausibilityWarning]
    assert any("crowd.csv: row 1, density = 45 persons/m²" in note and "a count of persons? "
               "(45 persons on the 150 m² deck are 0.3 persons/m²)" in note for note in notes)


def test_a_record_of_another_length_than_the_table_says_is_an_error_in_its_row(season, tmp_path):
    table = tmp_path / "crowd.csv"
    table.write_text("record,density,duration\nrecord_001.npz,0.2,3600\n"
                     "record_002.npz,0.3,600\n")
    found = season_case(load_case(season / "season.toml"), table, records=season, joint=False)
    rows = found.season.table()
    assert rows[0]["status"] == "error" and "the record is 600 s long, the crowd table's " \
        "duration is 3600 s" in rows[0]["warnings"]
    assert rows[1]["status"] in ("ok", "doubt")
    # The verdict doubts a season with a failed row (cases.verdict), naming it.
    doubts = [f.text for f in found.verdict() if f.severity == "doubt"]
    assert doubts == ["1 of 2 row(s) of the season failed, e.g. record_001.npz: DataError: "
                      "record_001.npz: the record is 600 s long, the crowd table's duration is "
                      "3600 s: its count belongs to another stretch of time"]


def test_rows_of_thin_crowds_can_be_left_out_of_the_joint_estimate(season, alone):
    # The rows from the store (nothing estimated again); the joint estimate holds only the four
    # records of 0.6 persons/m² and more, and its interval still covers the truth.
    found = _run(season, store=TaskStore(season / "tasks"), joint_min_density=0.6).season
    used = [row["density"] for row in found.table() if row["in_joint"]]
    assert used == pytest.approx(DENSITIES[DENSITIES >= 0.6]) and len(used) == 4
    assert all(row["in_joint"] for row in alone.season.table()[:8])
    for name in ("frequency", "damping_ratio"):
        low, high = found.joint.interval(name, 0.95)
        assert low <= getattr(TRUTH, name) <= high
        assert found.joint.value(name) != alone.season.joint.value(name)


def test_a_results_folder_among_the_records_is_not_read_as_records(season, tmp_path):
    # An --out placed inside the records folder: its season.csv (a CSV, a record suffix) was
    # listed as a record on the next run. A folder with crowdvib's manifest holds outputs.
    from crowdvib.cases.season import season_records

    folder = tmp_path / "records"
    folder.mkdir()
    (folder / "record_001.npz").write_bytes((season / "record_001.npz").read_bytes())
    (folder / "out").mkdir()
    (folder / "out" / "crowdvib-manifest.json").write_text("{}", encoding="utf-8")
    (folder / "out" / "season.csv").write_text("record\n", encoding="utf-8")
    (folder / "other").mkdir()
    (folder / "other" / "record_002.csv").write_text("t,a\n", encoding="utf-8")
    found = season_records(load_case(season / "season.toml"), folder)
    assert sorted(found) == ["other/record_002.csv", "record_001.npz", "record_002.csv"]


@pytest.mark.slow
def test_the_default_estimator_joins_time_domain_records_into_one_covering_estimate(
        tmp_path):
    # Records simulated in the time domain (walkers arriving at random: the crowd fluctuates),
    # estimated by crowdvib's default estimator (the likelihood with the fluctuating crowd and
    # the step frequencies fitted per record), joined by the same likelihood, each record's crowd
    # held as its fit left it (docs: theory, A season of records). The joint 95 % interval holds
    # the truth and is narrower than any record's.
    from tests.conftest import EXAMPLES

    paper = paper_example()
    densities = np.linspace(0.3, 1.0, 6)
    write_synthetic_season(tmp_path, paper.structure, paper.crowd, TRUTH, densities=densities,
                           duration=600.0, sample_rate=25.0, simulate=True, rng=5)
    (tmp_path / "season.toml").write_text(
        (EXAMPLES / "paper_example.toml").read_text(encoding="utf-8"), encoding="utf-8")
    case = load_case(tmp_path / "season.toml")
    assert case.estimation.method == "likelihood"
    with study_executor(2) as executor, warnings.catch_warnings():
        warnings.simplefilter("ignore", PlausibilityWarning)
        found = season_case(case, tmp_path / "crowd.csv", records=tmp_path, executor=executor)
    joint, rows = found.season.joint, found.season.table()
    assert joint.method == "likelihood" and joint.crowd_model == "fluctuating"
    for name in ("frequency", "damping_ratio"):
        low, high = joint.interval(name, 0.95)
        assert low <= getattr(TRUTH, name) <= high
        assert high - low < min(row[f"{name}_high"] - row[f"{name}_low"] for row in rows)
