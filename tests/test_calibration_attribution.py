"""Claim attribution (calibration.attribution): which calibrated value breaks a claim that holds with the base set."""
from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from calibration.attribution import ClaimWhy, Revert, attribute_claims, explain_claims, revert_table, reverts
from calibration.mdset import _get_nested, _set_nested, write_parameter_set
from nanoimpact import data


def _row(key, recipe, quantity, value, base, status="used", units="J/m^2"):
    return {"key": key, "recipe": recipe, "quantity": quantity, "value": value, "base_value": base,
            "status": status, "units": units}


ROWS = [_row("surfaces.work_of_adhesion", "adhesion_silica", "work_of_adhesion_free_energy", 0.2, 0.12),
        _row("surfaces.body.contact_angle", "contact_angle_silica", "contact_angle", 39.0, 20.0, units="deg"),
        _row("surfaces.substrate.contact_angle", "contact_angle_silica", "contact_angle", 39.0, 20.0, units="deg"),
        _row("surfaces.sam.contact_angle", "contact_angle_ots", "contact_angle", 110.0, 110.0, units="deg"),
        _row("menisci.surface_tension", "surface_tension_spce", "surface_tension", 0.01, 0.072, status="rejected"),
        _row("surfaces.interaction_range", "adhesion_silica", "interaction_range_z0", 2e-10, None, units="m")]


def test_reverts_group_by_run_quantity_and_skip_unused_or_unchanged_values():
    groups = reverts(ROWS, "cal")
    assert [(g.recipe, g.quantity) for g in groups] == [
        ("adhesion_silica", "work_of_adhesion_free_energy"), ("contact_angle_silica", "contact_angle"),
        ("adhesion_silica", "interaction_range_z0")]
    angles = groups[1]
    assert angles.keys == ("surfaces.body.contact_angle", "surfaces.substrate.contact_angle")
    assert angles.base == (20.0, 20.0) and angles.set_name == "cal--contact_angle_silica--contact_angle"
    assert len({g.set_name for g in groups}) == len(groups)


def test_a_revert_set_has_the_base_values_of_its_group_only():
    table = {"meta": {"description": "x", "calibration": {"surfaces.work_of_adhesion": {"value": 0.2},
                                                          "surfaces.interaction_range": {"value": 2e-10}}},
             "surfaces": {"work_of_adhesion": 0.2, "interaction_range": 2e-10, "body": {"contact_angle": 39.0}}}
    w, _, z0 = reverts(ROWS, "cal")
    t = revert_table(table, w)
    assert t["surfaces"]["work_of_adhesion"] == 0.12 and t["surfaces"]["interaction_range"] == 2e-10
    assert t["surfaces"]["body"]["contact_angle"] == 39.0
    assert "surfaces.work_of_adhesion" not in t["meta"]["calibration"]
    assert t["meta"]["reverted"]["surfaces.work_of_adhesion"] == {"calibrated": 0.2, "base": 0.12}
    assert table["surfaces"]["work_of_adhesion"] == 0.2                      # the calibrated table is untouched
    t = revert_table(table, z0)                                              # a key the base set lacks: removed
    assert "interaction_range" not in t["surfaces"]


def _claims(set_name, passes):
    return [{"name": n, "set": set_name, "pass": ok} for n, ok in passes.items()]


def test_each_failing_claim_is_explained_from_the_sets_that_ran():
    w, angles, z0 = reverts(ROWS, "cal")
    cal = _claims("cal", {"a": False, "b": False, "c": False, "d": True})
    base = _claims("paper", {"a": True, "b": True, "c": False, "d": True})
    by = {w.set_name: _claims(w.set_name, {"a": True, "b": False, "c": False}),
          angles.set_name: _claims(angles.set_name, {"a": False, "b": False, "c": False}),
          z0.set_name: _claims(z0.set_name, {"a": True, "b": False, "c": True})}
    why = {x.claim: x for x in explain_claims(cal, base, by, (w, angles, z0))}
    assert set(why) == {"a", "b", "c"}                                       # only the failing claims
    assert why["a"].cause == "single"
    assert why["a"].restored_by == (w.label, z0.label)
    assert "`surfaces.work_of_adhesion` 0.2 -> 0.12 J/m^2" in why["a"].text
    assert why["b"].cause == "several" and "3 tried" in why["b"].text
    assert why["c"].cause == "base fails too"                                # even though a revert passes it
    assert isinstance(why["a"], ClaimWhy) and why["a"].to_dict()["restored_by"] == [w.label, z0.label]


def test_without_revert_runs_a_failing_claim_says_so():
    cal = _claims("cal", {"a": False})
    base = _claims("paper", {"a": True})
    (why,) = explain_claims(cal, base, {}, reverts(ROWS, "cal"))
    assert why.cause == "not run"


@pytest.fixture
def figure4_only(monkeypatch):
    """The paper step cut to Fig 4's pressure-gap curves (two GW tables per set, ~1 s): its claims need no
    impact, so the attribution runs for real and fast."""
    from continuum.paper import run

    monkeypatch.setattr(run, "dry_cases", lambda: [])
    monkeypatch.setattr(run, "wet_cases", lambda: [])
    monkeypatch.setattr(run, "fig8_cases", lambda: [])


def test_the_value_that_breaks_a_claim_is_found_by_running_the_reverts(tmp_path, figure4_only):
    """A 'calibrated' set = the paper set with the silica work of adhesion cut to 0.3x and the OTS contact angle
    moved. Fig 4's claim that OTS's adhesive loop is below 0.3 of silica's then fails (the loop area scales
    with the work of adhesion: 0.042 / (0.3 x 0.12) > 1), and only putting W back restores it; the angle,
    which no dry case reads, restores nothing."""
    from continuum.paper.report import make_paper
    from nanoimpact.executors import executor

    base = tomllib.loads((data.shipped_root() / "params" / "paper.toml").read_text())
    w0 = _get_nested(base, "surfaces.work_of_adhesion")
    a0 = _get_nested(base, "surfaces.sam.contact_angle")
    table = dict(base)
    _set_nested(table, "surfaces.work_of_adhesion", 0.3 * w0)
    _set_nested(table, "surfaces.sam.contact_angle", a0 + 10.0)
    path = write_parameter_set(table, tmp_path / "cal.toml")
    rows = [_row("surfaces.work_of_adhesion", "adhesion_silica", "work_of_adhesion_free_energy", 0.3 * w0, w0),
            _row("surfaces.sam.contact_angle", "contact_angle_ots", "contact_angle", a0 + 10.0, a0, units="deg")]
    ex = executor("local", None, None)
    try:
        paper = make_paper(["paper", str(path)], tmp_path / "paper", executor=ex, progress=lambda m: None,
                           draw_figures=False)
        got = attribute_claims(table, rows, paper["checks"], "cal", "paper", tmp_path / "attribution", executor=ex)
    finally:
        ex.close()
    assert not list((tmp_path / "paper").glob("*.png"))                     # draw_figures=False drew nothing
    why = {c["claim"]: c for c in got["claims"]}
    claim = why["fig4_ots_loop_smaller_than_silica"]
    assert claim["cause"] == "single"
    assert claim["restored_by"] == ["adhesion_silica work_of_adhesion_free_energy"]
    assert got["ran"] and len(got["reverts"]) == 2
    for r in got["reverts"]:                                                 # every revert set is a loadable file
        assert (tmp_path / "attribution" / "sets" / f"{r['set']}.toml").is_file()


def test_no_revert_runs_when_every_failing_claim_fails_with_the_base_set_too(tmp_path):
    cal = _claims("cal", {"a": False, "b": True})
    base = _claims("paper", {"a": False, "b": True})
    got = attribute_claims({}, ROWS, cal + base, "cal", "paper", tmp_path / "attribution")
    assert not got["ran"] and not (tmp_path / "attribution").exists()
    assert got["claims"] == [{"claim": "a", "cause": "base fails too", "restored_by": [],
                              "text": "fails with the base set too: not caused by the calibrated values"}]
