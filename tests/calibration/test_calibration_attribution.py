"""Claim attribution (calibration.attribution): which calibrated value breaks a claim that holds with the base set."""
from __future__ import annotations

import tomllib

import pytest

from calibration.attribution import ClaimWhy, attribute_claims, explain_claims, revert_table, reverts
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


# ------------------------------------------------------------------------------ acceptance
def _named(set_name, states):
    return [{"name": n, "set": set_name, "pass": ok, "holds_fraction": 1.0 if ok else 0.25, "samples": 4}
            for n, ok in states.items()]


ESC = "fig8b_ots_lower_escape_velocity"


def test_a_failure_restored_by_one_measured_value_is_accepted_only_in_the_physical_direction():
    """OTS's escape velocity below silica's needs silica stickier: a measured W_silica below the base (0.2 ->
    0.12 read backwards) that breaks it is physical; the same claim restored by putting back a W_silica measured
    *above* the base would mean a stickier silica broke it, which physics does not predict."""
    from calibration.attribution import acceptance

    lower = [_row("surfaces.work_of_adhesion", "adhesion_silica", "work_of_adhesion_free_energy", 0.08, 0.12)]
    higher = [_row("surfaces.work_of_adhesion", "adhesion_silica", "work_of_adhesion_free_energy", 0.2, 0.12)]
    for rows, accepted in ((lower, True), (higher, False)):
        groups = reverts(rows, "cal")
        why = explain_claims(_named("cal", {ESC: False}), _named("paper", {ESC: True}),
                             {groups[0].set_name: _named(groups[0].set_name, {ESC: True})}, groups)
        (a,) = acceptance(_named("cal", {ESC: False}), why, groups)
        assert a["accepted"] is accepted and a["holds_fraction"] == 0.25 and a["samples"] == 4
        assert "surfaces.work_of_adhesion" in a["why"] and ("opposite" in a["why"]) is (not accepted)


def test_failures_through_several_values_the_base_set_or_the_samples_are_not_accepted():
    from calibration.attribution import acceptance

    groups = reverts(ROWS, "cal")
    cal = _named("cal", {"a": False, "b": False, "c": False})
    cal[2]["nominal_state"] = "pass"                               # holds on its own runs, not over its samples
    why = explain_claims(cal, _named("paper", {"a": True, "b": False, "c": True}),
                         {g.set_name: _named(g.set_name, {"a": False, "b": False, "c": False}) for g in groups}, groups)
    causes = {w.claim: w.cause for w in why}
    assert causes == {"a": "several", "b": "base fails too", "c": "samples"}
    # a base set that holds on its own runs and fails only over its seeds still counts as holding
    base = _named("paper", {"a": True, "b": False, "c": True})
    base[1].update(state="fail", nominal_state="pass")
    assert explain_claims(cal, base, {}, groups)[1].cause == "not run"
    acc = {a["claim"]: a for a in acceptance(cal, why, groups)}
    assert not any(a["accepted"] for a in acc.values())
    assert "no single measured value" in acc["a"]["why"] and "base set too" in acc["b"]["why"]


def test_the_report_says_per_claim_whether_it_is_accepted_with_its_sample_fraction_and_figure_4s_choices():
    from calibration.report import _acceptance_text

    a = {"claim": "fig4_ots_loop_smaller_than_silica", "accepted": False, "holds_fraction": 0.0, "samples": 17,
         "cause": "several", "why": "no single measured value put back restores it"}
    probe = {"loop_ratio": 6.36, "set_summit_radius_m": 2e-7,
             "stiff_layer": {"layer_modulus_Pa": 1.69e11, "set_layer_modulus_Pa": 1e9, "loop_ratio": 2e-4},
             "summit_radius_scan": {"radius_m": [5e-8, 5e-7, 8e-7, 2e-6], "loop_ratio": [108, 1.07, 0.58, 0.26]},
             "crossing_m": [5e-7, 8e-7],
             "origins": {"surfaces.sam.layer_modulus": "md", "surfaces.roughness.summit_radius": "chosen"}}
    text = _acceptance_text(a, probe)
    assert text.startswith("**Acceptance:** not accepted (holds on 0.00 of 17 samples)")
    assert "0.0002 with the SAM layer as stiff as its substrate" in text and "between 0.5 and 0.8 um" in text
    assert "decided by the compliant layer (md) and the summit radius (chosen)" in text
    holds = _acceptance_text(a, dict(probe, loop_ratio=0.1))
    assert "decided by" not in holds and "the loop of OTS is the smaller" in holds


def test_a_compliant_sam_layer_raises_the_ots_loop():
    """Fig 4's probe, physics: a softer coated summit (lower E*) has a larger adhesive hysteresis (JKR: ~ E*^(-2/3),
    Maugis 2000), so the declared 1 GPa layer gives OTS a larger loop than a layer as stiff as its substrate, and a
    larger summit radius raises bare silica's Tabor parameter and loop, lowering the ratio."""
    from continuum.paper.loop_probe import loop_area, loop_ratio

    soft = loop_area("rough_ots.toml", "calibrated", {})
    stiff = loop_area("rough_ots.toml", "calibrated", {"surfaces.sam.layer_modulus": 1.69e11})
    assert soft > 10 * stiff
    small, large = ({"surfaces.roughness.summit_radius": r} for r in (0.1e-6, 1e-6))
    assert loop_ratio("calibrated", large, large) < loop_ratio("calibrated", small, small)


def test_a_claim_failing_over_its_rows_is_accepted_when_a_measured_inputs_spread_carries_it_the_physical_way():
    """Fig 4's loop over six Latin-hypercube rows: the margin falls as silica's measured range z0 rises (a longer
    range lowers the summits' Tabor parameter and silica's loop), rank correlation -1: accepted; the same margins
    rising with z0 would be the opposite of physics: not accepted. A user range (sigma) is never named."""
    from calibration.attribution import acceptance

    name = "fig4_ots_loop_smaller_than_silica"
    z0 = [0.1e-9, 0.15e-9, 0.2e-9, 0.25e-9, 0.3e-9, 0.4e-9]
    rows = [{"surfaces.interaction_range": z, "surfaces.roughness.sigma": 6e-9 + 1e-10 * (i % 2)}
            for i, z in enumerate(z0)]
    for sign, accepted in ((-1, True), (+1, False)):
        c = {"name": name, "pass": False, "state": "fail", "nominal_state": "pass", "holds_fraction": 0.5,
             "samples": 7, "reason": "holds on 3 of 7",
             "sample_margins": [{"label": f"uncertainty {i + 1}", "margin": sign * (z - 0.25e-9) * 1e10,
                                 "state": "pass" if sign * (z - 0.25e-9) > 0 else "fail"} for i, z in enumerate(z0)]}
        why = explain_claims([c], _named("paper", {name: True}), {}, ())
        (a,) = acceptance([c], why, (), rows, ["surfaces.interaction_range", "surfaces.work_of_adhesion"])
        assert a["cause"] == "samples" and a["accepted"] is accepted, a
        assert "`surfaces.interaction_range`" in a["why"] and f"{sign:+.2f}" in a["why"]
    (none,) = acceptance([c], why, (), None, ["surfaces.interaction_range"])
    assert none["accepted"] is False and "spread over its samples" in none["why"]
