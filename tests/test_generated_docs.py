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


def test_a_moved_benchmark_moves_the_md_engine_table(tmp_path):
    """The wet-ensemble table is the bench's own (`tests/continuum/test_wet_ensemble_docs.py`); this module's
    benchmark tables are checked here: a changed number in the json changes the block."""
    data = json.loads(doc_blocks.ENGINE_JSON.read_text())
    moved = tmp_path / "engine.json"
    moved.write_text(json.dumps(_scaled(data)))
    assert doc_blocks.md_engine(moved) != doc_blocks.md_engine()


def _scaled(node):
    """Every float in a json tree doubled (a stand-in for a rerun that measured something else)."""
    if isinstance(node, dict):
        return {k: _scaled(v) for k, v in node.items()}
    if isinstance(node, list):
        return [_scaled(v) for v in node]
    return node * 2 if isinstance(node, float) else node


def test_the_ensemble_threshold_in_code_is_the_committed_measurement():
    """`ENSEMBLE_BELOW_CONTACTS` is typed in `continuum.model.decisions`; docs/model.md says it is read from
    docs/figures/ensemble_threshold.json (benchmarks/bench_ensemble_threshold.py): a rerun that moves the measured
    threshold by more than its rounding, or a changed constant, fails here."""
    from continuum.model.decisions import ENSEMBLE_BELOW_CONTACTS, ENSEMBLE_TOLERANCE

    measured = json.loads((doc_blocks.ROOT / "docs" / "figures" / "ensemble_threshold.json").read_text())
    assert measured["constant_in_code"] == ENSEMBLE_BELOW_CONTACTS
    assert measured["tolerance_over_h0"] == ENSEMBLE_TOLERANCE
    assert round(measured["threshold_expected_contacts"]) == ENSEMBLE_BELOW_CONTACTS
    fit = measured["fit"]
    assert measured["threshold_expected_contacts"] == pytest.approx((fit["A"] / ENSEMBLE_TOLERANCE) ** 2, rel=1e-9)


def test_a_moved_md_benchmark_moves_its_table(tmp_path):
    """Negative controls for the MD benchmark tables: a moved engine ratio, a moved rank timing, a moved lateral stress
    (and with it the zero crossing) change the blocks."""
    engine = json.loads(doc_blocks.ENGINE_JSON.read_text())
    engine["ratio_loop"] *= 0.9
    (tmp_path / "engine.json").write_text(json.dumps(engine))
    assert doc_blocks.md_engine(tmp_path / "engine.json") != doc_blocks.md_engine()
    ranks = json.loads(doc_blocks.RANKS_JSON.read_text())
    ranks["rows"][-1]["dynamics_loop_s"] *= 1.1
    (tmp_path / "ranks.json").write_text(json.dumps(ranks))
    assert doc_blocks.md_ranks(tmp_path / "ranks.json") != doc_blocks.md_ranks()
    for path in doc_blocks.FIGURES.glob("md_lateral_stress_a*.json"):
        shutil.copy(path, tmp_path / path.name)
    before = doc_blocks.md_lateral_stress(tmp_path)
    assert before == doc_blocks.md_lateral_stress()
    moved = tmp_path / "md_lateral_stress_a7.0.json"
    data = json.loads(moved.read_text())
    data["sigma_bulk_Pa"] *= 2.0
    moved.write_text(json.dumps(data))
    after = doc_blocks.md_lateral_stress(tmp_path)
    assert after != before and after.split("a ≈ ")[1][:4] != before.split("a ≈ ")[1][:4]
