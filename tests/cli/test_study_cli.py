"""`crowdvib map` and `crowdvib sensitivity` on the example cases (issue 5)."""

import json
from pathlib import Path

import pytest

from crowdvib.cli import main
from tests.conftest import copy_paper_case

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.slow
def test_map_of_eeklo_like_has_its_minimum_at_the_estimate(tmp_path):
    out = tmp_path / "map"
    # 0.1 Hz × 0.05 steps over the region of paper Fig. 10 around the optimum.
    assert main(["map", str(EXAMPLES / "eeklo_like.toml"), "--out", str(out),
                 "--frequencies", "2.0:4.0:21", "--damping-ratios", "0.15:0.8:14"]) == 0
    results = json.loads((out / "results.json").read_text())
    grid = results["objective_map"]["grid_optimum"]
    estimate = results["estimate"]
    assert abs(grid["frequency"] - estimate["frequency"]) <= 0.1 + 1e-9
    assert abs(grid["damping_ratio"] - estimate["damping_ratio"]) <= 0.05 + 1e-9
    # Paper (Figs. 4 and 10): J is much more sensitive to f_h1 than to ξ_h1; here per relative
    # change of each parameter, at the minimum.
    assert results["curvature_ratio"] > 5
    assert (out / "objective_map.png").stat().st_size > 10_000


def test_sensitivity_runs_resumes_and_refuses_to_overwrite(tmp_path, capsys):
    out = tmp_path / "study"
    case = str(copy_paper_case(tmp_path / "case"))    # the paper's estimator: the fast one
    arguments = ["sensitivity", case, "--out", str(out), "--no-joint", "--no-record-length"]
    assert main(arguments) == 0
    first = json.loads((out / "results.json").read_text())
    assert len(first["sensitivity"]["cases"]) == 1 + 5 * 2 * 2      # nominal + 5 inputs × 2 levels × ±
    summary = first["sensitivity"]["summary"]
    assert summary["frequency"]["nominal"] == pytest.approx(first["estimate"]["frequency"])
    assert "nominal ± largest single-error change" in capsys.readouterr().out   # --no-joint
    # An existing study is not overwritten; --resume finds every task done and recomputes none.
    assert main(arguments) == 1
    stamps = {p: p.stat().st_mtime_ns for p in (out / "tasks").glob("*.json")}
    assert main(arguments + ["--resume"]) == 0
    assert "resuming: 21 finished task(s)" in capsys.readouterr().out
    assert {p: p.stat().st_mtime_ns for p in (out / "tasks").glob("*.json")} == stamps
    again = json.loads((out / "results.json").read_text())
    assert again["sensitivity"] == first["sensitivity"]


def test_sensitivity_with_bad_worker_count(tmp_path, capsys):
    # A usage error (issue 10: exit 2), refused before the output directory is made.
    assert main(["sensitivity", str(EXAMPLES / "paper_example.toml"), "--out",
                 str(tmp_path / "s"), "--workers", "0", "--no-record-length"]) == 2
    assert "argument --workers: must be >= 1, got 0" in capsys.readouterr().err
    assert not (tmp_path / "s").exists()


def test_sensitivity_on_a_dask_scheduler_equals_local_run(tmp_path):
    # `--scheduler ADDRESS` runs the study on a real dask.distributed cluster (two worker
    # processes on loopback); same tasks, same numbers as the in-process run.
    distributed = pytest.importorskip("distributed")
    case = str(copy_paper_case(tmp_path / "case"))    # the paper's estimator: the fast one
    common = ["--no-joint", "--no-record-length"]
    assert main(["sensitivity", case, "--out", str(tmp_path / "local"), *common]) == 0
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None,
                                  scheduler_kwargs={"dashboard_address": "127.0.0.1:0"}) as cluster:
        assert main(["sensitivity", case, "--out", str(tmp_path / "dask"), "--scheduler",
                     cluster.scheduler_address, *common]) == 0
    local = json.loads((tmp_path / "local" / "results.json").read_text())
    remote = json.loads((tmp_path / "dask" / "results.json").read_text())
    assert remote["sensitivity"] == local["sensitivity"]
