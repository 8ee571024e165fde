"""The docs' blocks that quote committed results (`calibration.doc_blocks`) are what those results give now."""
from __future__ import annotations

import json
import shutil

import pytest

from calibration import doc_blocks


def test_every_generated_block_is_current():
    stale = [page for page, (now, new) in doc_blocks.rendered().items() if now != new]
    assert not stale, f"regenerate with: python -m calibration.doc_blocks ({stale})"


def test_a_moved_result_moves_the_block(tmp_path):
    """Negative control: a committed pull-off that moves, or a moved SEI prediction, must change the block."""
    results = tmp_path / "results"
    for recipe in doc_blocks.PULLOFF_RUNS:
        shutil.copytree(doc_blocks.RESULTS_DIR / f"{recipe}-quick", results / f"{recipe}-quick")
    before = doc_blocks.pulloff_sei(doc_blocks.SEI_JSON, results)
    assert before == doc_blocks.pulloff_sei()
    path = results / "pulloff_ots-quick" / "result.json"
    data = json.loads(path.read_text())
    data["quantities"]["pull_off_force"]["value"] *= 1.05
    path.write_text(json.dumps(data))
    assert doc_blocks.pulloff_sei(doc_blocks.SEI_JSON, results) != before
    sei = json.loads(doc_blocks.SEI_JSON.read_text())
    sei["ots"]["tabor_flat_slab"]["mu"] *= 1.5
    moved = tmp_path / "sei.json"
    moved.write_text(json.dumps(sei))
    assert doc_blocks.pulloff_sei(moved, doc_blocks.RESULTS_DIR) != doc_blocks.pulloff_sei()


def test_a_missing_or_doubled_marker_is_an_error():
    with pytest.raises(ValueError, match="md-pulloff-sei"):
        doc_blocks.render("no marker here", {"md-pulloff-sei": "x"})
    twice = "<!-- generated: b -->\n<!-- /generated -->\n" * 2
    with pytest.raises(ValueError, match="exactly once"):
        doc_blocks.render(twice, {"b": "x"})


def test_a_moved_benchmark_moves_the_wet_ensemble_table(tmp_path):
    data = json.loads(doc_blocks.WET_ENSEMBLE_JSON.read_text())
    data["rows"][-1]["cpu_ratio_to_dry"] *= 2
    moved = tmp_path / "wet.json"
    moved.write_text(json.dumps(data))
    assert doc_blocks.wet_ensemble(moved) != doc_blocks.wet_ensemble()
    assert doc_blocks._sci(1.0942e-4) == "1.1e-4"
