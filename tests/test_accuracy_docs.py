"""docs/benchmarks.md quotes the boundary-element benchmark's quick run (benchmarks/bench_accuracy.py --quick) from
its committed JSON: the levels' table and the reference's pixel ladder, impact and summit-cutoff block are the
ones the bench's own formatters write from docs/figures/accuracy_quick.json, so the page cannot drift from the
numbers."""
from __future__ import annotations

import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

import bench_accuracy  # noqa: E402
import pytest  # noqa: E402

RESULT = json.loads((ROOT / "docs" / "figures" / "accuracy_quick.json").read_text())
PAGE = (ROOT / "docs" / "benchmarks.md").read_text()


def _between(text: str, tag: str) -> str:
    start, end = f"<!-- {tag} -->", f"<!-- /{tag} -->"
    assert text.count(start) == 1 and text.count(end) == 1, tag
    return text.split(start, 1)[1].split(end, 1)[0].strip()


def test_levels_table_is_the_jsons():
    assert _between(PAGE, "bench_accuracy:levels") == bench_accuracy.markdown(RESULT)


def test_bem_block_is_the_jsons():
    assert _between(PAGE, "bench_accuracy:bem") == bench_accuracy.markdown_bem(RESULT)


def test_the_json_holds_what_the_issue_asks_for():
    """bem_convergence (converged, or a not_converged reason with numbers) and, per level, impact_rel_error and
    seconds; the summit cutoff's origin kind."""
    conv = RESULT["bem_convergence"]
    assert len(conv["grids"]) >= 3
    assert conv["converged"] or ("upper bound" in conv["not_converged"] and conv["required_pixel_m"] > 0)
    assert all("impact_rel_error" in r and r["seconds"] >= 0 for r in RESULT["levels"])
    assert RESULT["summit_cutoff"]["kind"] == "bem"


def test_the_impact_is_a_roller_through_the_driver_that_turns_where_its_tables_turn():
    """The roller's impacts: each level's table turns where the body turns (within a thousandth of a step; the half
    grid, rerun once, a hundredth), the driver's energy audit closes, and the driver's rebound is the
    quasi-static energy balance through the same table (a rate-independent law: equal up to the driver's tolerance,
    gravity's work and what the turn's shift moves); the roller reaches many summits."""
    body = RESULT["impact"]
    assert body["shape"].startswith("short roller") and body["summits_reached_at_turn"] >= 5
    assert 0.0 < body["reach_band_x_over_L"][0] < body["reach_band_x_over_L"][1] < 1.0
    runs = [body["reference"]["impact"]] + [r["impact"] for r in RESULT["levels"] if "restitution" in r["impact"]]
    assert len(runs) == len(RESULT["levels"]) + 1
    for run in runs:
        assert abs(run["turn_shift_over_step"]) < (1e-2 if run is runs[1] else 1e-3)   # the half grid: one rerun
        assert run["energy_audit_max_relative_error"] < 1e-5
        # the balance is the table's own turn; the body's turn lies turn_shift_m away, which moves the energy the
        # retraction starts from by at most the peak force times that shift
        shift = abs(run["turn_shift_m"]) * run["peak_force_N"] / run["impact_energy_J"]
        assert run["restitution"] ** 2 == pytest.approx(run["energy_balance_restitution"] ** 2, abs=1e-6 + 2 * shift)
