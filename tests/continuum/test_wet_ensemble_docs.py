"""docs/benchmarks.md quotes the humid-ensemble benchmark (benchmarks/bench_wet_ensemble.py) from its committed
JSON: the table is the one the bench's own formatter writes from docs/figures/bench_wet_ensemble.json."""
from __future__ import annotations

import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks"))

import bench_wet_ensemble  # noqa: E402

RESULT = json.loads((ROOT / "docs" / "figures" / "bench_wet_ensemble.json").read_text())
PAGE = (ROOT / "docs" / "benchmarks.md").read_text()


def test_the_table_is_the_jsons():
    start, end = "<!-- bench_wet_ensemble:table -->", "<!-- /bench_wet_ensemble:table -->"
    assert PAGE.count(start) == 1 and PAGE.count(end) == 1
    assert PAGE.split(start, 1)[1].split(end, 1)[0].strip() == bench_wet_ensemble.markdown(RESULT)


def test_the_json_holds_the_ratio_the_issue_asks_for():
    """Every humid case against the elastic dry ensemble of the same run, and how its contacts ran."""
    cases = {r["case"]: r for r in RESULT["rows"]}
    assert {"dry_elastic", "humid_short_t_a", "humid_short_t_a_elastic"} <= set(cases)
    assert cases["dry_elastic"]["cpu_ratio_to_elastic_dry"] == 1.0
    assert RESULT["max_cpu_ratio_with_menisci_to_elastic_dry"] == max(
        r["cpu_ratio_to_elastic_dry"] for r in RESULT["rows"] if r["case"].startswith("humid"))
    assert all({"compiled", "handed_over", "python"} <= set(r["contacts"]) for r in RESULT["rows"])
