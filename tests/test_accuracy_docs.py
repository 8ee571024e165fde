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
