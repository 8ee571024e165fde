"""`auto` model selection: each omission is safe (forcing the model back on moves every rebound by
less than 0.5 % of the release height), each choice is recorded with the number that decided it."""
from __future__ import annotations

from pathlib import Path

import pytest

from continuum.dynamics.impact import first_impact_speed, run_impact
from continuum.model import TABOR_DMT, TABOR_JKR, adhesion_decision, regime_of, regimes, select_law
from continuum.scene import resolve_scene

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "inputs" / "scenes"
SAFE = 5e-3        # the bound: every rebound within 0.5 % of the release height


def _rebounds(result):
    return [b["rebound_height"] for b in result["bounces"] if b["rebound_height"] is not None]


def _assert_same_rebounds(left, right, h0):
    a, b = _rebounds(left), _rebounds(right)
    assert len(a) == len(b) and left["status"] == right["status"]
    for x, y in zip(a, b):
        assert abs(x - y) < SAFE * h0


def test_half_space_left_out_under_the_paper_roller_is_safe():
    auto = run_impact(resolve_scene(SCENES / "rough_silica.toml",
                                       overrides={"physics.half_space": "auto", "numerics.max_bounces": 6,
                                                  "surfaces.roughness.mode": "mean_field"})).to_dict()
    rec = auto["models"]["half_space"]
    assert rec["used"] is False and rec["decided_by"] == "deflection_over_sigma"
    assert rec["deflection_over_sigma"] < 1e-3
    forced = run_impact(resolve_scene(SCENES / "rough_silica.toml",
                                         overrides={"physics.half_space": "on", "numerics.max_bounces": 6,
                                                    "surfaces.roughness.mode": "mean_field"})).to_dict()
    _assert_same_rebounds(auto, forced, 100e-9)


def test_half_space_kept_where_it_deflects_a_fraction_of_sigma():
    r = resolve_scene(SCENES / "rough_halfspace_heavy.toml", overrides={"physics.half_space": "auto"})
    _, models = select_law(r.scene, first_impact_speed(r))
    rec = models["half_space"]
    assert rec["used"] is True and rec["deflection_over_sigma"] > 1e-2


def test_menisci_left_out_when_no_contact_lasts_t_a_is_safe():
    auto = run_impact(resolve_scene(SCENES / "wet_silica.toml", overrides={"physics.half_space": "off"})).to_dict()
    rec = auto["models"]["menisci"]
    assert rec["used"] is False and rec["longest_contact_s"] < rec["condensation_time_s"]
    forced = run_impact(resolve_scene(SCENES / "wet_silica.toml",
                                         overrides={"physics.half_space": "off", "physics.menisci": "on"})).to_dict()
    _assert_same_rebounds(auto, forced, 100e-9)


@pytest.mark.parametrize("z0, law", [(0.05e-9, "jkr"), (0.3e-9, "maugis_dugdale"), (8e-9, "dmt")])
def test_summit_law_follows_the_tabor_parameter(z0, law):
    r = resolve_scene(SCENES / "rough_silica.toml", overrides={"physics.adhesion_law": "auto",
                                                               "surfaces.interaction_range": z0})
    decision = adhesion_decision(r.scene, regime_of(r.scene))
    chosen, rec = decision.law, decision.record()
    mu = regimes.tabor_parameter(0.2e-6, 0.12, 10e9, z0)       # the `paper` summits, written out
    assert rec["tabor_parameter"] == pytest.approx(mu, rel=1e-12, abs=0)
    expected = "jkr" if mu > TABOR_JKR else "dmt" if mu < TABOR_DMT else "maugis_dugdale"
    assert chosen == law == expected


def test_every_choice_is_recorded_with_what_decided_it():
    result = run_impact(resolve_scene(SCENES / "wet_ots.toml", overrides={"numerics.max_bounces": 2})).to_dict()
    models = result["models"]
    for key in ("adhesion", "half_space", "menisci"):
        assert {"decided_by", "why"} <= set(models[key]), key
    assert models["menisci"]["decided_by"] == "contact_angles"
    assert models["adhesion"]["decided_by"] == "scene"        # the paper's JKR, forced in the scene
    assert models["sam"]["used"] is True


def test_adhesion_left_out_for_stiff_weakly_adhesive_summits_is_safe():
    # the mean field: the decision is the scene's whatever the mode ('auto' adds a 64-member ensemble to each run)
    stiff = {"surfaces.roughness.summit_modulus": 150e9, "surfaces.work_of_adhesion": 0.01,
             "physics.half_space": "off", "numerics.max_bounces": 20, "surfaces.roughness.mode": "mean_field"}
    auto = run_impact(resolve_scene(SCENES / "rough_silica.toml",
                                       overrides={**stiff, "physics.adhesion_law": "auto"})).to_dict()
    rec = auto["models"]["adhesion"]
    assert rec["used"] is False and rec["decided_by"] == "estimated_loss_fraction"
    assert rec["tabor_parameter"] < TABOR_DMT and rec["estimated_pull_fraction"] < 1e-2
    forced = run_impact(resolve_scene(SCENES / "rough_silica.toml",
                                       overrides={**stiff, "physics.adhesion_law": "dmt"})).to_dict()
    assert forced["models"]["adhesion"]["used"] is True
    _assert_same_rebounds(auto, forced, 100e-9)


def test_the_dry_run_settles_a_pending_meniscus_decision_at_t_a():
    """Bridges cannot form before t_a: a dry run whose contacts all end sooner is the wet run; a contact of
    exactly t_a or longer calls for the wet run; a contact that never ends (stuck) does not count."""
    from continuum.model import dry_run_verdict
    from continuum.scene import resolve_scene

    scene = resolve_scene("wet_silica", params="paper", overrides={"menisci.condensation_time": 2e-5}).scene
    short = dry_run_verdict(regime_of(scene), [1e-5, 1.99e-5, None], "stuck")
    assert not short.rerun and short.longest_contact_s == 1.99e-5 and short.dry_run_bounces == 3
    assert short.record()["used"] is False and "'stuck'" in short.record()["final_contact"]
    assert "< t_a" in short.record()["why"]
    at = dry_run_verdict(regime_of(scene), [2e-5], "escaped")
    assert at.rerun and at.final_contact is None
    assert at.record()["dry_run_bounces"] == 1 and "used" not in at.record()    # the wet run's record says used
    assert dry_run_verdict(regime_of(scene), [], "escaped").longest_contact_s == 0.0


def test_discrete_summits_run_the_law_the_map_picks():
    """Where Johnson & Greenwood's map says Maugis-Dugdale, discrete summits run Maugis-Dugdale too (tabulated
    branches, continuum.rough.branch_laws), as the mean field does."""
    from continuum.model import select_law
    from continuum.scene import resolve_scene

    scene = resolve_scene("rough_silica", params="paper", overrides={
        "surfaces.roughness.mode": "discrete", "surfaces.interaction_range": 3e-9,
        "physics.adhesion_law": "auto"}).scene
    law, models = select_law(scene, 1e-3)
    assert models["adhesion"]["tabor_parameter"] < 5.0
    assert models["adhesion"]["law"] == "maugis_dugdale" and "map_suggests" not in models["adhesion"]
    assert law.name == "rough_roller_discrete_maugis_dugdale"
