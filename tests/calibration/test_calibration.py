"""MD results -> parameter set, Latin hypercube, executors, sweeps and the smoke pipeline."""
from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from calibration.mdset import MAPPING, build_parameter_set, recipes_needed, write_parameter_set
from calibration.pipeline import CalibrationError, load_calibration
from calibration.sampling import latin_hypercube
from calibration.sweep import parse_vary, run_sweep
from calibration.validation import VALIDATION
from continuum.scene import SceneError, resolve_scene
from nanoimpact.executors import executor

ROOT = Path(__file__).resolve().parents[2]

#: the bare-silica adhesion recipe the calibration reads (the mapping's choice, so these tests follow it)
SILICA = next(s.recipe for s in MAPPING if s.key == "surfaces.work_of_adhesion")
#: the pull-off the silica validation reads (calibration.validation.VALIDATION)
PULL_SI = next(pull for pull, adh in VALIDATION if adh == SILICA)
#: the OTS-OTS adhesion recipe the calibration reads (W, z0 and the layer modulus), and its validation pull-off
OTS = next(s.recipe for s in MAPPING if s.key == "surfaces.sam.work_of_adhesion")
PULL_OTS = next(pull for pull, adh in VALIDATION if adh == OTS)


def _result(recipe, quantities, run_hash=None):
    return {"recipe": recipe, "fidelity": "quick", "run_hash": run_hash or f"{recipe:0<64}"[:64],
            "quantities": {k: {"value": v, "stderr": e, "units": u} for k, (v, e, u) in quantities.items()}}


def _results(**changes):
    res = {
        SILICA: _result(SILICA, {"work_of_adhesion": (0.21, 0.02, "J/m^2"),
                                                       "work_of_adhesion_free_energy": (0.18, 0.03, "J/m^2")}),
        OTS: _result(OTS, {"work_of_adhesion": (0.045, 0.004, "J/m^2"),
                                                 "work_of_adhesion_free_energy": (0.04, None, "J/m^2"),
                                                 "sam_layer_tangent_modulus": (5.6e9, 0.6e9, "Pa"),
                                                 "sam_layer_thickness_per_layer": (2.2e-9, 0.01e-9, "m")}),
        "contact_angle_silica": _result("contact_angle_silica", {"contact_angle": (31.0, 3.0, "deg")}),
        "contact_angle_ots": _result("contact_angle_ots", {"contact_angle": (108.0, 4.0, "deg")}),
        "surface_tension_spce": _result("surface_tension_spce", {"surface_tension": (0.0615, 0.002, "N/m")}),
        "pulloff_silica": _result("pulloff_silica", {"interaction_range_z0": (0.35e-9, 0.05e-9, "m")}),
        PULL_SI: _result(PULL_SI, {"interaction_range_z0": (0.35e-9, 0.05e-9, "m")}),
        "pulloff_ots": _result("pulloff_ots", {"interaction_range_z0": (0.42e-9, 0.06e-9, "m")}),
        PULL_OTS: _result(PULL_OTS, {"interaction_range_z0": (0.42e-9, 0.06e-9, "m")}),
    }
    res.update(changes)
    return res


def test_md_values_land_on_their_scene_keys_with_stderr_and_run_hash(tmp_path):
    results = _results()
    results[SILICA]["quantities"]["work_of_adhesion_free_energy"]["discretisation_error"] = 0.04
    table, rows = build_parameter_set(results, "paper", "cal")
    s = table["surfaces"]
    assert s["work_of_adhesion"] == 0.18                       # the free energy (Dupre work), not dE/A = 0.21
    assert s["sam"]["work_of_adhesion"] == 0.04
    assert s["body"]["contact_angle"] == s["substrate"]["contact_angle"] == 31.0
    assert s["sam"]["contact_angle"] == 108.0 and s["sam"]["interaction_range"] == 0.42e-9
    assert s["interaction_range"] == 0.35e-9 and table["menisci"]["surface_tension"] == 0.0615
    cal = table["meta"]["calibration"]
    w = cal["surfaces.work_of_adhesion"]
    assert w["quantity"] == "work_of_adhesion_free_energy"
    assert w["stderr"] == pytest.approx(0.05) and w["stderr_statistical"] == 0.03   # hypot(0.03, grid 0.04)
    assert w["discretisation_error"] == 0.04 and w["energy_estimate"]["value"] == 0.21
    origin = table["meta"]["origin"]
    assert (origin["surfaces.work_of_adhesion"]["kind"] == "md"
            and "free energy" in origin["surfaces.work_of_adhesion"]["note"])
    assert origin["surfaces.work_of_adhesion"]["run_hash"] == results[SILICA]["run_hash"]
    assert cal["menisci.surface_tension"]["run_hash"] == _results()["surface_tension_spce"]["run_hash"]
    assert s["roughness"]["summit_radius"] == 0.2e-6            # from the base set, with its origin
    assert origin["surfaces.roughness.summit_radius"]["kind"] == "chosen"
    assert "systematic_hysteresis" not in w                      # one-way windows: no out-and-back systematic
    # the base's chosen summit modulus, adhesion law and additive wet adhesion give way to the materials' E*, the
    # Tabor parameter and the wet work of adhesion
    assert "summit_modulus" not in s["roughness"] and "physics" not in table
    assert set(table["meta"]["replaced"]) == {"surfaces.roughness.summit_modulus", "physics.adhesion_law",
                                              "menisci.solid_adhesion"}
    assert "solid_adhesion" not in table.get("menisci", {})
    # W_SL comes only from thermodynamic integration (wsl_*), which these results lack: those rows say so
    assert all(r["status"] == "used" for r in rows if not r["key"].endswith("work_of_adhesion_sl"))
    assert {r["status"] for r in rows if r["key"].endswith("work_of_adhesion_sl")} == {"missing"}
    path = write_parameter_set(table, tmp_path / "cal.toml", header="test set")
    assert tomllib.loads(path.read_text())["meta"]["calibration"]["surfaces.sam.contact_angle"]["value"] == 108.0
    scene = resolve_scene(ROOT / "inputs" / "scenes" / "wet_silica.toml", params=str(path)).scene
    assert math.degrees(scene.surfaces.body.contact_angle) == pytest.approx(31.0, rel=1e-12, abs=0)
    assert scene.surfaces.interaction_range == 0.35e-9 and scene.menisci.surface_tension == 0.0615


def test_without_a_free_energy_the_energy_difference_is_used_and_named():
    res = _results(**{SILICA: _result(SILICA, {"work_of_adhesion": (0.21, 0.02, "J/m^2")})})
    table, _ = build_parameter_set(res, "paper", "cal")
    assert table["surfaces"]["work_of_adhesion"] == 0.21
    assert table["meta"]["calibration"]["surfaces.work_of_adhesion"]["quantity"] == "work_of_adhesion"
    assert "not a free energy" in table["meta"]["origin"]["surfaces.work_of_adhesion"]["note"]


def test_an_out_and_back_work_of_adhesion_carries_half_its_hysteresis_as_a_systematic():
    """W_F = mean of the outward 0.052 and the return 0.040 chains: 0.046, stat. 0.002, grid 0.003, half the
    hysteresis 0.006 as a systematic; the set's stderr holds all three (hypot = 0.007), so the uncertainty bands
    sample the range the reversible work can lie in, and the entry records both directions."""
    res = _results()
    res[OTS]["quantities"]["work_of_adhesion_free_energy"] = {
        "value": 0.046, "stderr": 0.002, "units": "J/m^2", "discretisation_error": 0.003,
        "systematic_hysteresis": 0.006, "value_out": 0.052, "stderr_out": 0.0025, "value_back": 0.040,
        "stderr_back": 0.003}
    table, _ = build_parameter_set(res, "paper", "cal")
    w = table["meta"]["calibration"]["surfaces.sam.work_of_adhesion"]
    assert table["surfaces"]["sam"]["work_of_adhesion"] == 0.046
    assert w["stderr"] == pytest.approx(0.007, rel=1e-12) and w["stderr_statistical"] == 0.002
    assert w["systematic_hysteresis"] == 0.006
    assert w["out_and_back"] == {"value_out": 0.052, "stderr_out": 0.0025, "value_back": 0.040, "stderr_back": 0.003}
    # the pull-off validation weighs the difference with the same W_F error the set carries
    from calibration.validation import pulloff_validation
    res[PULL_OTS]["quantities"]["work_of_adhesion_eff_dmt"] = {"value": 0.060, "stderr": 0.024, "units": "J/m^2"}
    v = pulloff_validation(res)[PULL_OTS]
    assert v["W_F_stderr"] == pytest.approx(0.007, rel=1e-12)
    assert v["difference_in_stderr"] == pytest.approx(0.014 / 0.025, rel=1e-12)      # hypot(0.024, 0.007) = 0.025


def test_unusable_md_values_keep_the_base_value_and_say_so():
    bad = _results(contact_angle_ots=_result("contact_angle_ots", {"contact_angle": (180.0, 0.0, "deg")}),
                   **{SILICA: _result(SILICA, {"work_of_adhesion": (-0.3, 0.5, "J/m^2")})})
    for pull in {"pulloff_ots", PULL_OTS}:                 # z0's fallback and the validation pull (one or two)
        del bad[pull]
    table, rows = build_parameter_set(bad, "paper", "cal")
    base = tomllib.loads((ROOT / "inputs" / "params" / "paper.toml").read_text())
    assert table["surfaces"]["sam"]["contact_angle"] == base["surfaces"]["sam"]["contact_angle"]
    assert table["surfaces"]["work_of_adhesion"] == base["surfaces"]["work_of_adhesion"]
    rej = table["meta"]["rejected"]
    assert "no droplet contact" in rej["surfaces.sam.contact_angle"]["why"]
    assert "outside the scene schema" in rej["surfaces.work_of_adhesion"]["why"]
    status = {r["key"]: r["status"] for r in rows}
    assert status["surfaces.sam.interaction_range"] == "missing"
    assert "surfaces.sam.interaction_range" not in table["surfaces"]["sam"]


def test_a_wetting_droplet_enters_as_the_uniform_interval_below_its_bound():
    """status 'wets' (the MD contact_angle is a 0 mark) with an upper bound of 12 deg: theta ~ U[0, 12],
    mean 6 deg and stderr 12/sqrt(12) = 3.4641 deg, named as the bound's quantity."""
    wet = _result("contact_angle_silica", {"contact_angle": (0.0, None, "deg"),
                                           "contact_angle_upper_bound": (12.0, None, "deg")})
    wet["quantities"]["contact_angle"]["status"] = "wets"
    table, rows = build_parameter_set(_results(contact_angle_silica=wet), "paper", "cal")
    assert table["surfaces"]["body"]["contact_angle"] == table["surfaces"]["substrate"]["contact_angle"] == 6.0
    cal = table["meta"]["calibration"]["surfaces.body.contact_angle"]
    assert cal["quantity"] == "contact_angle_upper_bound"
    assert cal["stderr"] == pytest.approx(12.0 / math.sqrt(12.0), rel=1e-12)
    assert "wets" in cal["note"] and "[0, 12]" in cal["note"]
    assert {r["key"]: r["status"] for r in rows}["surfaces.body.contact_angle"] == "used"
    # without a bound the 0 mark is refused as before
    del wet["quantities"]["contact_angle_upper_bound"]
    table, _ = build_parameter_set(_results(contact_angle_silica=wet), "paper", "cal")
    assert "surfaces.body.contact_angle" in table["meta"]["rejected"]


def test_a_drifting_or_non_circular_droplet_is_flagged_on_its_calibrated_angle():
    """The MD result's drift flag and its shape check (details.shape_check.circular) travel with the angle into the
    set's meta, so a reader of calibrated.toml sees that the stderr does not hold the whole error."""
    ca = _result("contact_angle_ots", {"contact_angle": (125.0, 0.3, "deg")})
    ca["quantities"]["contact_angle_drift"] = {"value": 27.0, "stderr": 18.0, "units": "deg/ns", "drifting": False}
    ca["details"] = {"shape_check": {"circular": False, "spread_deg": 5.4}}
    table, _ = build_parameter_set(_results(contact_angle_ots=ca), "paper", "cal")
    cal = table["meta"]["calibration"]["surfaces.sam.contact_angle"]
    assert table["surfaces"]["sam"]["contact_angle"] == 125.0
    assert cal["not_circular"] is True and "drifting" not in cal and "5.4 deg" in cal["note"]
    ca["quantities"]["contact_angle_drift"]["drifting"] = True
    ca["details"]["shape_check"]["circular"] = True
    cal = build_parameter_set(_results(contact_angle_ots=ca), "paper", "cal")[0]["meta"]["calibration"][
        "surfaces.sam.contact_angle"]
    assert cal["drifting"] is True and "not_circular" not in cal and "drift" in cal["note"]
    cal = build_parameter_set(_results(), "paper", "cal")[0]["meta"]["calibration"]["surfaces.sam.contact_angle"]
    # no flag: the note is only the fallback's (the droplet stands in for W_SL by TI on OTS)
    assert cal["note"].startswith("fallback: no W_SL") and "drifting" not in cal and "not_circular" not in cal


def test_angles_and_gamma_of_different_water_models_are_not_combined():
    res = _results()
    for r, model in (("contact_angle_silica", "tip4p2005"), ("contact_angle_ots", "tip4p2005"),
                     ("surface_tension_spce", "spce")):
        res[r]["settings"] = {"water_model": model}
    table, rows = build_parameter_set(res, "paper", "cal")
    base = tomllib.loads((ROOT / "inputs" / "params" / "paper.toml").read_text())
    rej = table["meta"]["rejected"]
    for key in ("surfaces.body.contact_angle", "surfaces.sam.contact_angle", "menisci.surface_tension"):
        assert "water models differ" in rej[key]["why"] and "tip4p2005" in rej[key]["why"], key
    assert table["surfaces"]["sam"]["contact_angle"] == base["surfaces"]["sam"]["contact_angle"]
    assert table["surfaces"]["work_of_adhesion"] == 0.18          # not water-derived: still used
    res["surface_tension_spce"]["settings"] = {"water_model": "tip4p2005"}     # one model: all used
    table, rows = build_parameter_set(res, "paper", "cal")
    assert "rejected" not in table["meta"]
    assert all(r["status"] == "used" for r in rows if not r["key"].endswith("work_of_adhesion_sl"))


def test_a_report_is_typed_and_writes_its_json_and_markdown(tmp_path):
    from calibration.pipeline import CalibrationRecipe, Uncertainty
    from calibration.report import CalibrationReport, ValueRow

    table, rows = build_parameter_set(_results(), "paper", "cal")
    write_parameter_set(table, tmp_path / "cal.toml")
    recipe = CalibrationRecipe(name="cal", base="paper", path="recipe.toml", compare_sets=[],
                               uncertainty=Uncertainty(scene="s", ranges={}, overrides={}))
    band = {"median": 0.5, "p05": 0.4, "p95": 0.6, "n": 4}
    report = CalibrationReport(
        name="cal", set_path=tmp_path / "cal.toml", out=tmp_path / "out",
        calibration=recipe,
        rows=tuple(ValueRow.from_dict(r) for r in rows), md_sources={SILICA: {"source": "committed"}},
        bands={"first_rebound_over_h0": band, "rebound_count": band, "escape_velocity_m_per_s": band,
               "covers": ["x"], "samples": 4, "failed_samples": 0, "seed": 0, "scene": "s", "max_bounces": 3},
        paper_checks=({"set": "cal", "name": "claim_a", "pass": True, "threshold": "t", "values": {}},
                      {"set": "cal", "name": "claim_b", "pass": False, "threshold": "t2", "values": {"v": 1}},
                      {"set": "paper", "name": "claim_a", "pass": True, "threshold": "t", "values": {}}),
        timings={"md_s": 1.0, "paper_s": 2.0, "uncertainty_s": 3.0, "total_s": 6.0},
        machine={"cores": 2, "platform": "p", "python": "3.11"}, md_compute_total_s=10.0,
        claim_attribution={"claims": [{"claim": "claim_b", "cause": "single", "restored_by": ["r"],
                                       "text": "holds again when only W is put back"}]},
        validation={"pulloff_ots": {"F_over_2piR": 0.05, "F_over_2piR_stderr": 0.01, "W_F": 0.04, "W_F_stderr": None,
                                    "ratio": 1.25, "difference_in_stderr": 1.0, "adhesion_recipe": "adhesion_ots",
                                    "residual_drag_N": None}})
    # 13 mapped keys: 10 used (the SAM thickness among them); the three W_SL keys need wsl_* results, absent here
    assert len(report.used) == 10
    assert sorted(r.key for r in report.not_used) == ["surfaces.body.work_of_adhesion_sl",
                                                      "surfaces.sam.work_of_adhesion_sl",
                                                      "surfaces.substrate.work_of_adhesion_sl"]
    assert [c["name"] for c in report.claims()] == ["claim_a", "claim_b"]
    md = report.write()
    text = md.read_text()
    assert "1 of 2 claims hold" in text and "`claim_b`: needs t2" in text
    # what the set still chooses comes first, each with its reason; the replaced base choices after it
    assert text.index("## Still chosen") < text.index("## MD values")
    reason = table["meta"]["origin"]["surfaces.roughness.summit_radius"]["reason"]
    assert f"- `surfaces.roughness.summit_radius`: {reason}" in text
    assert "- `surfaces.roughness.summit_modulus`: the base's 10000000000.0" in text
    assert '`claim_b`: needs t2; got {"v": 1}. **Why:** holds again when only W is put back.' in text
    assert f"| `surfaces.work_of_adhesion` | {SILICA} | work_of_adhesion_free_energy | 0.18 J/m^2 | 0.03 | " \
           "none quoted | - |" in text
    # the fixture's silica angle, 31 +- 3 deg: (31 - 20) / 3 = 3.7 stderr above the literature's 0-20 deg and beyond
    # the 0-30 deg acceptance window; OTS 108 deg inside Wasserman's 105-112 deg; z0 = 0.35 nm only inside the window
    assert "| 31 deg | 3 | 0-20 deg (accepted 0-30) | 3.7 sigma above |" in text
    assert "| 108 deg | 4 | 105-112 deg (accepted 105-120) | inside |" in text
    assert "**Against the literature**" in text and "2 of 10 used values inside the literature range;" in text
    assert "outside it but inside the acceptance window: `surfaces.interaction_range` (1.0 sigma above" in text
    assert "**outside the acceptance window**: `surfaces.body.contact_angle` (3.7 sigma above" in text
    assert "Wasserman et al., Langmuir 5 (1989) 1074" in text
    assert (tmp_path / "out" / "md_vs_literature.png").stat().st_size > 0
    saved = json.loads((tmp_path / "out" / "calibration.json").read_text())
    assert saved["rows"][0] == rows[0] | {k: None for k in ValueRow.__dataclass_fields__ if k not in rows[0]}
    assert saved["versions"]["numpy"] == np.__version__
    assert saved["claim_attribution"]["claims"][0]["cause"] == "single"
    assert "**Pull-off validation" in text and "| pulloff_ots (vs adhesion_ots) |" in text
    assert saved["validation"]["pulloff_ots"]["ratio"] == 1.25
    assert saved["calibration"]["uncertainty"]["samples"] == 16            # the declared default
    assert "Calibration `cal` (base `paper`)" in text and "Recipe `recipe.toml`" in text
    assert not list((tmp_path / "out").glob("*.tmp*"))                   # atomic: nothing half-written left


def test_recipes_needed_are_the_nine_mapped_ones_and_fallbacks_run_only_when_needed():
    from calibration.mdset import fallbacks_needed, recipes_first
    assert recipes_needed() == [SILICA, OTS, "wsl_silica", "wsl_ots", "surface_tension_spce",
                                "contact_angle_silica", "contact_angle_ots", "pulloff_silica", "pulloff_ots"]
    # every calibration runs the preferred recipes and the validation pull-offs; the droplets only as fallbacks
    assert recipes_first() == [SILICA, OTS, "wsl_silica", "wsl_ots", "surface_tension_spce", PULL_SI, PULL_OTS]
    ti = _ti(0.0, None, "wets", w=0.15, bound=0.0)
    both = {"wsl_silica": ti, "wsl_ots": ti, **{k: v for k, v in _results().items() if k in recipes_first()}}
    both[SILICA] = _result(SILICA, {"work_of_adhesion_free_energy": (0.18, 0.03, "J/m^2"),
                                    "interaction_range_z0": (0.2e-9, 0.05e-9, "m")})     # its own z0: no pull-off
    both[OTS] = _result(OTS, {"work_of_adhesion_free_energy": (0.04, 0.005, "J/m^2"),
                              "interaction_range_z0": (0.4e-9, 0.05e-9, "m"),
                              "sam_layer_tangent_modulus": (5.6e9, 0.6e9, "Pa"),
                              "sam_layer_thickness_per_layer": (2.2e-9, 0.01e-9, "m")})
    assert fallbacks_needed(both) == []
    # without its own z0 the OTS flat slab sends the calibration to z0's fallback, the one-position pull-off
    no_z0 = {**both, OTS: _results()[OTS]}
    assert fallbacks_needed(no_z0) == ["pulloff_ots"]
    no_angle = {**both, "wsl_ots": _result("wsl_ots", {"work_of_adhesion_sl": (0.04, 0.003, "J/m^2")})}
    assert fallbacks_needed(no_angle) == ["contact_angle_ots"]
    assert fallbacks_needed({**no_angle, "contact_angle_ots": _results()["contact_angle_ots"]}) == []


def _ti(theta, theta_err, status="measured", w=0.09, bound=None):
    r = _result("wsl_silica", {"contact_angle": (theta, theta_err, "deg"), "work_of_adhesion_sl": (w, 0.003, "J/m^2")})
    r["workflow"] = "wsl_ti"
    r["quantities"]["contact_angle"]["status"] = status
    if bound is not None:
        r["quantities"]["contact_angle_upper_bound"] = {"value": bound, "stderr": None, "units": "deg"}
    return r


def test_silica_angles_come_from_the_ti_and_fall_back_to_the_droplet_with_a_note():
    """W_SL by TI (wsl_silica) sets both silica angles; without it the droplet's angle is used, and the set says
    that a pinned droplet measures its start."""
    table, rows = build_parameter_set(_results(wsl_silica=_ti(24.0, 2.0)), "paper", "cal")
    assert table["surfaces"]["body"]["contact_angle"] == table["surfaces"]["substrate"]["contact_angle"] == 24.0
    e = table["meta"]["calibration"]["surfaces.body.contact_angle"]
    assert e["recipe"] == "wsl_silica" and e["work_of_adhesion_sl"]["value"] == 0.09 and "note" not in e
    table, _ = build_parameter_set(_results(), "paper", "cal")              # no TI result: the droplet
    e = table["meta"]["calibration"]["surfaces.body.contact_angle"]
    assert e["recipe"] == "contact_angle_silica" and e["value"] == 31.0 and "pinned contact line" in e["note"]


def test_the_ots_angle_comes_from_the_ti_and_falls_back_to_the_droplet_with_a_note():
    ti = _ti(112.0, 1.5, w=0.04)
    ti["recipe"] = "wsl_ots"
    table, _ = build_parameter_set(_results(wsl_ots=ti), "paper", "cal")
    e = table["meta"]["calibration"]["surfaces.sam.contact_angle"]
    assert table["surfaces"]["sam"]["contact_angle"] == 112.0 and e["recipe"] == "wsl_ots" and "note" not in e
    table, _ = build_parameter_set(_results(), "paper", "cal")              # no TI result: the droplet
    e = table["meta"]["calibration"]["surfaces.sam.contact_angle"]
    assert e["recipe"] == "contact_angle_ots" and e["value"] == 108.0 and "+-4 deg for the droplet size" in e["note"]


def test_a_ti_that_wets_enters_as_zero_or_as_its_bound_never_as_a_film_mark():
    # W_SL - 2 stderr still >= 2 gamma: theta = 0 is Young-Dupre's answer, used (a droplet's 0 would be rejected)
    table, rows = build_parameter_set(_results(wsl_silica=_ti(0.0, None, "wets", w=0.15, bound=0.0)), "paper", "cal")
    assert table["surfaces"]["body"]["contact_angle"] == 0.0
    assert "wets completely" in table["meta"]["calibration"]["surfaces.body.contact_angle"]["note"]
    # within 2 stderr of 2 gamma: uniform on [0, bound]
    table, _ = build_parameter_set(_results(wsl_silica=_ti(0.0, None, "wets", w=0.13, bound=18.0)), "paper", "cal")
    e = table["meta"]["calibration"]["surfaces.body.contact_angle"]
    assert e["value"] == 9.0 and e["stderr"] == pytest.approx(18.0 / math.sqrt(12.0))
    assert "thermodynamic integration reaches 2 gamma_lv" in e["note"]
    # a droplet's 0 (film mark) is still rejected
    wet = _result("contact_angle_silica", {"contact_angle": (0.0, None, "deg")})
    wet["quantities"]["contact_angle"]["status"] = "wets"
    _, rows = build_parameter_set(_results(contact_angle_silica=wet), "paper", "cal")
    assert {r["key"]: r["status"] for r in rows}["surfaces.body.contact_angle"] == "rejected"


def test_the_md_plan_says_before_anything_runs_where_each_result_will_come_from(tmp_path):
    """Committed at the current hash, finished in the md cache, unfinished in the cache (resumes), or not there
    (runs): decided from hashes and files alone."""
    from calibration.pipeline import current_hash, md_plan

    results, cache = tmp_path / "results", tmp_path / "cache"
    (results / "adhesion_ots-smoke").mkdir(parents=True)
    (results / "adhesion_ots-smoke" / "result.json").write_text(
        json.dumps({"run_hash": current_hash("adhesion_ots", "smoke")}))
    (results / "adhesion_silica-smoke").mkdir(parents=True)                        # a stale committed result
    (results / "adhesion_silica-smoke" / "result.json").write_text(json.dumps({"run_hash": "0" * 64}))
    done = cache / f"adhesion_silica-smoke-{current_hash('adhesion_silica', 'smoke')[:16]}"
    done.mkdir(parents=True)
    (done / "result.json").write_text("{}")
    partial = cache / f"pulloff_ots-smoke-{current_hash('pulloff_ots', 'smoke')[:16]}"
    (partial / "legs").mkdir(parents=True)
    plan = md_plan(["adhesion_ots", "adhesion_silica", "pulloff_ots", "pulloff_silica"], "smoke", str(cache), results)
    assert plan == {"adhesion_ots": "committed", "adhesion_silica": "md cache", "pulloff_ots": "resumes",
                    "pulloff_silica": "runs"}


def test_latin_hypercube_hits_every_stratum_once_per_dimension():
    u = latin_hypercube(50, 4, np.random.default_rng(3))
    assert u.shape == (50, 4) and np.all((u >= 0) & (u < 1))
    for j in range(4):
        assert sorted(np.floor(u[:, j] * 50).astype(int)) == list(range(50))


def _square(x):
    return x * x


@pytest.mark.parametrize("name", ["local", "processes"])
def test_executors_return_every_result_at_its_index(name):
    ex = executor(name, workers=2)
    try:
        got = dict(ex.map(_square, [3, 1, 4, 1, 5]))
    finally:
        ex.close()
    assert got == {0: 9, 1: 1, 2: 16, 3: 1, 4: 25}


def test_bad_executor_and_calibration_recipe_are_refused(tmp_path):
    with pytest.raises(ValueError, match="one of local, processes, dask"):
        executor("slurm")
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\nbase = "paper"\n[uncertainty]\nsamples = 1\n')
    with pytest.raises(CalibrationError, match="uncertainty.samples = 1"):
        load_calibration(bad)


def test_sweep_validates_first_then_resumes_without_rerunning(tmp_path):
    scene = ROOT / "inputs" / "scenes" / "rough_silica.toml"
    with pytest.raises(SceneError, match="surfaces.roughness.sigma"):
        run_sweep(scene, parse_vary(["surfaces.roughness.sigma=6e-9,-1"]), tmp_path / "bad", progress=lambda m: None)
    assert not (tmp_path / "bad").exists()
    vary = parse_vary(["surfaces.roughness.sigma=6e-9,10e-9", "numerics.max_bounces=2"])
    first = run_sweep(scene, vary, tmp_path / "sw", progress=lambda m: None)
    again = run_sweep(scene, vary, tmp_path / "sw", progress=lambda m: None)
    assert (first["computed"], first["reused"]) == (2, 0) and (again["computed"], again["reused"]) == (0, 2)
    assert [r["first_rebound_height_m"] for r in first["rows"]] == [r["first_rebound_height_m"] for r in again["rows"]]
    text = (tmp_path / "sw" / "sweep.csv").read_text().splitlines()
    assert text[0].startswith("surfaces.roughness.sigma,numerics.max_bounces,status") and len(text) == 3
    assert (tmp_path / "sw" / "sweep.png").stat().st_size > 0


#: the recipe whose smoke MD runs on a Dask worker in the pipeline test: the cheapest smoke run
#: (docs/figures/md_cost.json); the others come from the session's shared smoke runs, AS_COMMITTED as a committed
#: result, the rest from the md cache
RUN_ON_WORKER = "surface_tension_spce"
AS_COMMITTED = "wsl_silica"


@pytest.mark.md
@pytest.mark.filterwarnings("ignore:No artists with labels found:UserWarning")     # Fig 8b without its wet cases
def test_smoke_pipeline_on_two_dask_workers(md_smoke, tmp_path, monkeypatch):
    """The whole pipeline on executor 'dask' with two workers: the MD jobs, the paper's cases, the claim
    attribution and the uncertainty samples are Dask tasks. Each MD source is exercised once: the cheapest recipe's
    LAMMPS runs on a worker ('ran'), one session smoke run is handed over as a committed result ('committed',
    through results_dir), and the other five are the smoke runs other md tests made this session (md_smoke), copied
    into this test's md cache and found there by their hash ('md cache'): smoke MD proves plumbing, so running it
    again here would prove nothing more. The paper's case lists are cut to the three impacts its figures read, one
    bounce each at the fast preset, and one sweep (as test_executors cuts them; the cases themselves are
    test_paper's), the sampled claims to one discrete-summit seed and, in each set's sample bundle, three impacts
    per drop and two sigmas for the escape velocity, and the smoke recipe's uncertainty to two samples at the fast
    preset."""
    import shutil
    from dataclasses import replace

    from calibration import CalibrationReport, calibrate
    from calibration.mdset import recipes_first
    from continuum.paper import run, samples

    cache, committed = tmp_path / "md", tmp_path / "committed"
    cache.mkdir()
    shared = [r for r in recipes_first() if r != RUN_ON_WORKER]
    for name in shared:
        run_dir = md_smoke(name).outcome.run_dir
        if name == AS_COMMITTED:
            (committed / f"{name}-smoke").mkdir(parents=True)
            shutil.copy(run_dir / "result.json", committed / f"{name}-smoke" / "result.json")
        else:
            shutil.copytree(run_dir, cache / run_dir.name)
    # the cases the figures read (hertz, rough silica, rough OTS), one bounce each at the fast preset (the runs take
    # it as an argument, so it reaches the Dask workers); one sweep; no wet case; one discrete-summit seed
    fast = {"numerics.max_bounces": 1, "numerics.fidelity": "fast"}
    cheap = [replace(c, overrides={**c.overrides, **fast}) for c in run.dry_cases()
             if c.name in ("hertz", "rough_silica", "rough_ots")]
    monkeypatch.setattr(run, "dry_cases", lambda: cheap)
    monkeypatch.setattr(run, "wet_cases", lambda: [])
    monkeypatch.setattr(run, "fig8_cases", lambda: cheap[:1])
    monkeypatch.setattr(samples, "DEFAULT_SEEDS", 1)
    # each set's sample bundle (the attribution runs seven sets) cut to 3 impacts per drop and the escape velocity
    # over two sigmas: here and, through a setup callback, on every Dask worker (a worker imports its own modules)
    from calibration import pipeline

    def small_bundles(dask_worker=None):
        from continuum.paper import samples as on_worker
        on_worker.SAMPLE_MAX_BOUNCES, on_worker.FIG8_SIGMAS_NM = 3, (3.0, 6.0)

    def executor(*args, **kwargs):
        ex = make_executor(*args, **kwargs)
        ex.client.register_worker_callbacks(small_bundles)
        return ex

    make_executor = pipeline.executor
    monkeypatch.setattr(pipeline, "executor", executor)
    monkeypatch.setattr(samples, "SAMPLE_MAX_BOUNCES", 3)
    monkeypatch.setattr(samples, "FIG8_SIGMAS_NM", (3.0, 6.0))
    recipe = tmp_path / "smoke.toml"
    text = (ROOT / "inputs" / "calibration" / "smoke.toml").read_text()
    overrides = 'overrides = { "physics.half_space" = "auto" }'
    assert "\nsamples = 4\n" in text and overrides in text
    recipe.write_text(text.replace("\nsamples = 4\n", "\nsamples = 2\n").replace(
        overrides, overrides[:-2] + ', "numerics.fidelity" = "fast" }'))

    out = tmp_path / "cal"
    report = calibrate(recipe, out, md_fidelity="smoke", executor_name="dask", workers=2,
                       params_out=tmp_path / "calibrated_smoke.toml", md_cache=str(cache), results_dir=committed,
                       progress=lambda m: None)
    assert isinstance(report, CalibrationReport) and report.name == "calibrated_smoke"
    sources = {r: v["source"] for r, v in report.md_sources.items()}
    assert sources == {**{r: "md cache" for r in shared}, RUN_ON_WORKER: "ran", AS_COMMITTED: "committed"}
    assert (out / "report.md").stat().st_size > 0 and (out / "uncertainty.png").stat().st_size > 0
    assert (out / "paper" / "checks.json").is_file()
    assert sorted(p.name for p in (out / "paper" / "cases").iterdir()) == ["hertz", "rough_ots", "rough_silica"]
    # the 7 recipes every calibration runs (the droplets are fallbacks: the smoke TIs give angles), 13 keys
    assert len(report.md_sources) == 7 and len(report.rows) == 13
    assert {c["set"] for c in report.paper_checks} == {"paper", "calibrated_smoke"}    # compare_sets = []
    assert report.claims() and all(c["set"] == "calibrated_smoke" for c in report.claims())
    # the new set's claims are judged on the mean field over the recipe's own Latin-hypercube rows; the discrete
    # seeds are reported beside them (single_surfaces), never in the verdict
    checks = {c["set"]: c for c in report.paper_checks if c["name"] == "fig5a_ots_outbounces_silica"}
    assert checks["calibrated_smoke"]["sampled"]["uncertainty"] == 2 and checks["paper"]["sampled"]["uncertainty"] == 0
    assert checks["calibrated_smoke"]["single_surfaces"]["n"] == checks["paper"]["single_surfaces"]["n"] > 0
    assert len(report.used) + len(report.not_used) == 13
    # every claim that fails with the new set is explained (the attribution's revert runs are on Dask too)
    failing = {c["name"] for c in report.claims() if not c["pass"]}
    assert {w["claim"] for w in report.claim_attribution["claims"]} == failing and "attribution_s" in report.timings
    scene = resolve_scene(ROOT / "inputs" / "scenes" / "rough_silica.toml",
                          params=str(tmp_path / "calibrated_smoke.toml"))
    # the calibrated set drops the paper's chosen compliant summits: the summits take the materials' E*
    assert scene.scene.surfaces.roughness.summit_modulus is None
    saved = json.loads((out / "calibration.json").read_text())
    assert saved["bands"]["samples"] == 2 and saved == json.loads(json.dumps(report.to_dict(), default=str))
    assert saved["versions"]["nanoimpact"] and saved["rows"][0]["key"] == report.rows[0].key
    # the set points to its Latin-hypercube rows, written beside it, so `nanoimpact paper --params` judges the set's
    # claims over them by default
    written = tomllib.loads((tmp_path / "calibrated_smoke.toml").read_text())
    assert written["meta"]["uncertainty_rows"] == "calibrated_smoke.uncertainty.csv"
    rows = samples.set_uncertainty_rows([str(tmp_path / "calibrated_smoke.toml")])["calibrated_smoke"]
    assert len(rows) == 2 and all(set(r) == set(saved["bands"]["covers"]) for r in rows)


def test_uncertainty_samples_stay_inside_each_keys_allowed_range():
    """A calibrated value with a large stderr (z0 = 0.21 +- 0.14 nm) is sampled from its normal truncated to the
    key's allowed range: no sample is refused by the scene, and where the bounds are far the samples are the plain
    normal's quantiles."""
    from scipy.stats import norm

    from calibration.sampling import latin_hypercube, sample_inputs, sampling_bounds, truncation

    cal = {"surfaces.interaction_range": {"value": 0.21e-9, "stderr": 0.14e-9},
           "surfaces.work_of_adhesion": {"value": 0.196, "stderr": 0.039}}
    n, seed = 64, 5
    keys, samples = sample_inputs(cal, {}, n, seed)
    lo, hi = sampling_bounds("surfaces.interaction_range")
    assert lo == pytest.approx(5e-11)
    z0 = np.array([s["surfaces.interaction_range"] for s in samples])
    assert z0.min() >= lo and z0.max() <= hi
    # the plain normal would have put some of the 64 strata below the bound (P = 12.7 %)
    u = latin_hypercube(n, len(keys), np.random.default_rng(seed))
    plain = 0.21e-9 + 0.14e-9 * norm.ppf(u[:, 0])
    assert (plain < lo).sum() >= 4
    # far from its bounds (0 is 5 sigma away: 3e-7 of the normal cut) the work of adhesion is the plain normal, to
    # that cut's shift of the quantiles (3e-6 relative in the tail strata)
    w = np.array([s["surfaces.work_of_adhesion"] for s in samples])
    np.testing.assert_allclose(w, 0.196 + 0.039 * norm.ppf(u[:, 1]), rtol=1e-4)
    t = truncation(cal)
    assert set(t) == {"surfaces.interaction_range"}
    assert t["surfaces.interaction_range"]["outside"] == pytest.approx(norm.cdf((5e-11 - 0.21e-9) / 0.14e-9), rel=1e-6)


def test_a_value_is_placed_against_its_published_range_in_its_own_stderr():
    from calibration.targets import TARGETS, Target, target_of, verdict

    t = Target("k", 1.0, 2.0, "m", "src")
    assert verdict(1.5, 0.1, t).inside and verdict(1.5, 0.1, t).distance_sigma == 0.0
    above = verdict(2.3, 0.2, t)
    assert not above.inside and above.distance_sigma == pytest.approx(1.5) and above.inside_2sigma
    assert above.text == "1.5 sigma above"
    below = verdict(0.5, 0.1, t)
    assert below.distance_sigma == pytest.approx(-5.0) and not below.inside_2sigma and below.text == "5.0 sigma below"
    assert verdict(2.5, None, t).text == "above (no stderr)" and not verdict(2.5, 0.0, t).inside_2sigma
    # every target names a scene key the continuum declares, in that key's SI unit, low < high, with a source
    from continuum.schema import FIELD_BY_PATH
    for tgt in TARGETS:
        f = FIELD_BY_PATH[tgt.key]
        lo, hi = tgt.window
        assert tgt.unit == f.unit and tgt.low <= tgt.high and f.low <= lo <= tgt.low and tgt.high <= hi <= f.high
        assert tgt.source and (tgt.accept_reason or (lo, hi) == (tgt.low, tgt.high))
    # a value inside the acceptance window but outside the literature range is accepted, never "inside"
    w = Target("k", 1.0, 2.0, "m", "src", 0.5, 3.0, "a choice")
    assert verdict(2.5, 0.1, w).accepted and not verdict(2.5, 0.1, w).inside and not verdict(3.5, 0.1, w).accepted
    assert target_of("surfaces.work_of_adhesion") is None        # no published Dupre work for this IFF surface


def test_the_report_shows_the_pulloff_validation_against_the_flat_slab_work(tmp_path):
    """F / (2 pi R) of each pull-off beside W_F of the same pair (DMT at MD scale): ratio, combined stderrs, and a
    sentence when the two differ by more than 2 of them. 0.09 +- 0.004 against 0.18 +- 0.03: ratio 0.50,
    -0.09 / hypot(0.004, 0.03) = -3.0 sigma; OTS 0.05 +- 0.01 against 0.04 (no stderr): +1.0 sigma."""
    from calibration.report import _validation_lines
    from calibration.validation import pulloff_validation

    res = _results()
    res[PULL_SI]["quantities"]["work_of_adhesion_eff_dmt"] = {"value": 0.09, "stderr": 0.004,
                                                                       "units": "J/m^2"}
    res[PULL_OTS]["quantities"]["work_of_adhesion_eff_dmt"] = {"value": 0.05, "stderr": 0.01, "units": "J/m^2"}
    res[PULL_SI]["quantities"]["residual_drag_force"] = {"value": 1.5e-12, "units": "N"}
    v = pulloff_validation(res)
    assert v[PULL_SI]["ratio"] == pytest.approx(0.5, rel=1e-12)
    assert v[PULL_SI]["difference_in_stderr"] == pytest.approx(-0.09 / math.hypot(0.004, 0.03), rel=1e-12)
    text = "\n".join(_validation_lines(v))
    assert f"| {PULL_SI} (vs {SILICA}) | 0.09 +- 0.004 | 0.18 +- 0.03 | 0.50 | -3.0 sigma | +0.002 |" in text
    assert f"| {PULL_OTS} (vs {OTS}) | 0.05 +- 0.01 | 0.04 +- - | 1.25 | +1.0 sigma | - |" in text
    assert f"Beyond 2 combined stderrs: {PULL_SI}." in text
    assert _validation_lines({}) == []
    table, _ = build_parameter_set(res, "paper", "cal")
    assert table["meta"]["validation"] == v                 # the set records what the report shows


def _ots_with_windows(separation_A, force, stderr, thickness_A=24.0, area_A2=530.0, tilt=None):
    """An OTS adhesion result that predates the small-strain layer modulus: its windows, system record and (with
    ``tilt``) an anneal's mean-tilt series only."""
    res = _result(OTS, {"work_of_adhesion_free_energy": (0.05, 0.005, "J/m^2")}, run_hash="b" * 64)
    sam = {"builder": "ots_sam", "thickness_A": thickness_A}
    res["system"] = {"area_A2": area_A2, "lower": sam, "upper": sam}
    res["details"] = {"pmf_windows": {"separation_A": list(separation_A), "mean_force_kcal_mol_A": list(force),
                                      "stderr_kcal_mol_A": list(stderr), "tail_force_kcal_mol_A": [0.0] * len(force)}}
    if tilt is not None:
        res["details"]["anneal"] = {"mean_tilt_deg": list(tilt)}
    return res


def test_the_sam_layer_modulus_is_derived_from_committed_windows_and_converted_to_youngs_modulus():
    """A result without the small-strain modulus but with its windows: a linear compression branch of 20 kcal/mol/A
    per A over two 24 A SAMs (no anneal: the builder's thickness) on 530 A^2 is M = 20 x 48 / 530 kcal/mol/A^3, its
    tangent the same; the set takes Young's modulus E = M (1 + nu)(1 - 2 nu) / (1 - nu) with the base set's layer
    Poisson ratio, origin md with the run hash and a note that it was derived from the committed windows; the SAM
    thickness is the per-layer 24 A the modulus used; E's stderr holds the unmeasured nu's spread (the poisson
    record says NOT MEASURED). Three repulsive windows: not used (a quadratic's tangent unchecked), base value
    kept."""
    d = [-4.0, -3.0, -2.0, -1.0, 0.5, 2.0]
    f = [80.0, 60.0, 40.0, 20.0, -5.0, -1.0]
    table, rows = build_parameter_set(_results(**{OTS: _ots_with_windows(d, f, [1.0] * 6)}), "paper", "cal")
    nu = table["surfaces"]["sam"].get("layer_poisson_ratio", 0.3)
    m = 20.0 * 48.0 / 530.0 * 4184.0 / 6.02214076e23 / 1e-30
    e = table["surfaces"]["sam"]["layer_modulus"]
    assert e == pytest.approx(m * (1 + nu) * (1 - 2 * nu) / (1 - nu), rel=1e-6)
    origin = table["meta"]["origin"]["surfaces.sam.layer_modulus"]
    assert origin["kind"] == "md" and origin["run_hash"] == "b" * 64 and "committed windows" in origin["note"]
    cal = table["meta"]["calibration"]["surfaces.sam.layer_modulus"]
    assert cal["confined_modulus"]["value"] == pytest.approx(m, rel=1e-6) and cal["confined_modulus"]["windows"] == 4
    assert "derived from the run's committed windows" in cal["note"]
    assert cal["poisson_ratio"]["measured"] is False and "NOT MEASURED" in cal["poisson_ratio"]["note"]
    assert cal["stderr"] >= 0.25 * e                                     # the nu spread alone is ~26 %
    assert table["surfaces"]["sam"]["thickness"] == pytest.approx(24.0e-10, rel=1e-12)
    assert cal["thickness_used"]["matches_within_5_percent"] is True
    few = _ots_with_windows(d[1:], f[1:], [1.0] * 5)
    table2, rows2 = build_parameter_set(_results(**{OTS: few}), "paper", "cal")
    row = next(r for r in rows2 if r["key"] == "surfaces.sam.layer_modulus")
    assert row["status"] == "rejected" and "sam_layer_tangent_modulus" in row["why"]
    assert table2["surfaces"]["sam"]["layer_modulus"] == row["base_value"]
    assert table2["meta"]["rejected"]["surfaces.sam.layer_modulus"]["kept"] == "base set value"


def test_pulloff_validation_carries_tabor_mu_of_the_current_results():
    """mu = (R W^2 / (E*^2 z0^3))^(1/3) from the pull-off's radius and the flat slab's W_F and z0, with E* of silica
    on silica: R = 1.5 nm, W = 0.196 J/m^2, z0 = 0.2075 nm give mu = 0.167 at E* = 37.0 GPa."""
    from calibration.validation import pulloff_validation
    from md.analysis.pulloff import SILICA_E_STAR_PA

    res = _results()
    res[PULL_SI]["settings"] = {"asperity_radius_A": 15.0}
    res[PULL_SI]["quantities"]["work_of_adhesion_eff_dmt"] = {"value": 0.096, "stderr": 0.004}
    res[SILICA]["quantities"]["work_of_adhesion_free_energy"]["value"] = 0.196
    res[SILICA]["quantities"]["interaction_range_z0"] = {"value": 0.2075e-9, "stderr": 0.1e-9}
    v = pulloff_validation(res)[PULL_SI]
    mu = (1.5e-9 * 0.196 ** 2 / (SILICA_E_STAR_PA ** 2 * 0.2075e-9 ** 3)) ** (1 / 3)
    assert v["tabor_mu"] == pytest.approx(mu, rel=1e-12) and v["maugis_lambda"] == pytest.approx(1.157 * mu, rel=1e-3)
