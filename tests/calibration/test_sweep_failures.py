"""A sweep point that fails is recorded with its one-line reason; the others run, the table and the plot are
written, and the record says to exit with EXIT_PARTIAL; on every executor, a real Dask scheduler included."""
from __future__ import annotations

import csv
import json
import logging
from pathlib import Path

from calibration.sweep import parse_vary, run_sweep
from conftest import require_backend
from nanoimpact.errors import EXIT_OK, EXIT_PARTIAL

ROOT = Path(__file__).resolve().parents[2]
SCENE = ROOT / "inputs" / "scenes" / "rough_silica.toml"
# summit_density 1e8 /m^2 passes the scene's checks but leaves 0.43 summits in the roller's footprint: the
# rough law refuses it when the point runs (a real failure, not a mock; raised in whichever worker runs it)
FAST = ["numerics.max_bounces=1", "numerics.fidelity=fast", "physics.half_space=off",
        "surfaces.roughness.mode=mean_field"]
VARY = ["surfaces.roughness.summit_density=1e9,1e8,2e9"] + FAST
REASON = "ValueError: rough contact: only 0.43 summits expected in the footprint"


def _check(record, out: Path):
    assert record["exit_code"] == EXIT_PARTIAL
    assert [f["overrides"]["surfaces.roughness.summit_density"] for f in record["failed"]] == [1e8]
    assert record["failed"][0]["error"].startswith(REASON)
    rows = list(csv.DictReader(open(out / "sweep.csv")))
    assert [r["status"] for r in rows][1] == "failed" and rows[1]["error"].startswith(REASON)
    assert rows[1]["n_bounces"] == "" and rows[1]["input_hash"]
    assert [r["status"] for r in rows[::2]] == ["max_bounces"] * 2 and all(not r["error"] for r in rows[::2])
    assert all(float(r["first_rebound_height_m"]) > 0 for r in rows[::2])
    saved = json.loads((out / "failures.json").read_text())
    assert saved["failed"] == record["failed"] and saved["points"] == 3
    assert (out / "sweep.png").stat().st_size > 0
    assert len(list((out / "points").glob("*/result.json"))) == 2          # no result for the failed point


def test_a_failed_point_is_recorded_the_others_run_and_a_rerun_retries_only_it(tmp_path):
    out = tmp_path / "sw"
    lines = []
    record = run_sweep(SCENE, parse_vary(VARY), out, progress=lines.append)
    _check(record, out)
    assert (record["computed"], record["reused"]) == (3, 0)
    assert any("FAILED: " + REASON in line for line in lines)
    again = run_sweep(SCENE, parse_vary(VARY), out, progress=lambda m: None)
    assert (again["computed"], again["reused"]) == (1, 2) and again["exit_code"] == EXIT_PARTIAL
    # the failed value left out: nothing fails, nothing reruns, and the stale failures.json goes
    good = run_sweep(SCENE, parse_vary(["surfaces.roughness.summit_density=1e9,2e9"] + FAST), out,
                     progress=lambda m: None)
    assert (good["computed"], good["exit_code"], good["failed"]) == (0, EXIT_OK, [])
    assert not (out / "failures.json").exists()


def test_on_a_process_pool(tmp_path):
    record = run_sweep(SCENE, parse_vary(VARY), tmp_path / "sw", executor_name="processes", workers=2,
                       progress=lambda m: None)
    _check(record, tmp_path / "sw")


def test_on_a_real_dask_scheduler(tmp_path, caplog):
    """A cluster started apart from the sweep, reached by its address (as `--scheduler` does): the failing
    point's exception travels back from the worker and is recorded; the sweep does not go down."""
    require_backend("distributed", "dask.distributed")
    import distributed
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=":0") as cl:
        with caplog.at_level(logging.INFO, logger="nanoimpact.executors"):
            record = run_sweep(SCENE, parse_vary(VARY), tmp_path / "sw", executor_name="dask",
                               scheduler=cl.scheduler_address, progress=lambda m: None)
    _check(record, tmp_path / "sw")
    said = [r.getMessage() for r in caplog.records if r.name == "nanoimpact.executors"]
    assert any(m.startswith(f"dask: the cluster at {cl.scheduler_address}; dashboard ") for m in said), said
