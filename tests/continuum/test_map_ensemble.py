"""Ensembles of a height map: members drawn from the map's distributions (never copies of it), the two tail models,
the cutoff band, the stick probability's Wilson interval and censored members, and the 'auto' member count.

The small case: the paper roller shortened to 50 um (its strip holds a few hundred summits, about as many as the
5 um synthetic map, so the tail the impact samples lies within the map's data) on a rigid substrate, dropped 1 um:
about 60 % of the members stick at the first impact, so the stick probability is sensitive to the summits."""
import math

import numpy as np
import pytest
from scipy import stats as sps

from continuum.dynamics.ensemble_run import auto_members, member_law, member_plan, run_ensemble
from continuum.model.regime import first_impact_speed
from continuum.output.proportions import wilson_interval
from continuum.rough.cutoff_band import band_crosses, band_entry, band_warning, tail_warning
from continuum.rough.ensemble import MemberOutcome, first_impact_record, within_run_record
from continuum.rough.tail import fit_empirical_gpd, gpd_pwm
from continuum.scene import SceneError, resolve_scene

SMALL = {"body.length": 50e-6, "release_height": 1e-6, "physics.half_space": "off"}
MEMBERS = 48


def _stuck_first(ens):
    return sum(o.stuck_at_first_impact for o in ens.outcomes)


def test_wilson_interval_has_its_closed_form_at_none_and_all():
    """k = 0: the upper end is z^2 / (n + z^2) (0/64 -> 5.7 %, not the Wald '0 +- 0'); k = n mirrors it; and the
    interval holds the fraction."""
    z = 1.959964
    assert wilson_interval(0, 64) == pytest.approx((0.0, z * z / (64 + z * z)), abs=1e-12)
    assert wilson_interval(64, 64) == pytest.approx((64 / (64 + z * z), 1.0), abs=1e-12)
    lo, hi = wilson_interval(3, 256)
    assert lo < 3 / 256 < hi


def test_members_built_from_a_gaussian_map_agree_with_members_drawn_from_its_statistics_as_numbers():
    """On the Gaussian synthetic map, members drawn from the map's own summit heights with a fitted generalised
    Pareto tail and members drawn from sigma_s, eta, beta typed in as numbers (a Gaussian) give stick probabilities
    each inside the other's Wilson 95 % interval. The comparison can fail: the same numbers with sigma doubled
    (a different surface) give an interval disjoint from the map's."""
    mapped = resolve_scene("rough_synthetic", overrides={**SMALL, "surfaces.roughness.tail_model": "empirical_gpd"})
    s = mapped.surface
    numbers = {"surfaces.roughness.sigma": s["summit_height_std"], "surfaces.roughness.summit_density":
               s["summit_density"], "surfaces.roughness.summit_radius": s["summit_radius"]}

    def given(**scale):
        over = {**SMALL, **{k: v * scale.get(k.rsplit(".", 1)[1], 1.0) for k, v in numbers.items()}}
        return resolve_scene("rough_silica", params="paper", overrides=over).scene

    from_map = run_ensemble(mapped, members=MEMBERS, seed=2, first_impact=True)
    assert from_map.source == {"source": "map_statistics", "tail_model": "empirical_gpd"}
    from_numbers = run_ensemble(given(), members=MEMBERS, seed=3, first_impact=True)
    assert from_numbers.source["source"] == "statistics"
    k_map, k_num = _stuck_first(from_map), _stuck_first(from_numbers)
    i_map, i_num = wilson_interval(k_map, MEMBERS), wilson_interval(k_num, MEMBERS)
    assert 0 < k_map < MEMBERS and 0 < k_num < MEMBERS            # the case resolves sticking: not all or none
    assert i_num[0] <= k_map / MEMBERS <= i_num[1] and i_map[0] <= k_num / MEMBERS <= i_map[1]
    other = run_ensemble(given(sigma=2.0), members=MEMBERS, seed=3, first_impact=True)
    i_other = wilson_interval(_stuck_first(other), MEMBERS)
    assert i_other[1] < i_map[0] or i_map[1] < i_other[0]


def test_a_member_draws_the_whole_strip_and_copies_no_summit():
    """A member of a map scene holds a Poisson number of summits for the strip's area (eta 2 x_f l, within 5
    standard deviations), each at its own position (no two at one x, as tiled copies were), its heights in the tail
    drawn from the fitted GPD and so not the map's own values."""
    resolved = resolve_scene("rough_synthetic", overrides={**SMALL, "surfaces.roughness.tail_model": "empirical_gpd"})
    from continuum.dynamics.map_ensembles import map_tail
    model, _ = map_tail(resolved)
    scene = resolved.scene
    plan = member_plan(scene, first_impact_speed(scene), model)
    law = member_law(scene, 7, plan)[1]
    rough = scene.surfaces.roughness
    mean = rough.summit_density * 2.0 * plan.footprint_half_width * scene.body.length
    assert abs(law.summits_in_strip - mean) < 5.0 * math.sqrt(mean)
    assert np.unique(law.sx).size == law.sx.size
    tall = law.sz[law.sz > model.threshold]
    assert tall.size > 0 and not np.any(np.isin(tall, model.body))


def test_the_pwm_tail_fit_recovers_known_shapes_and_the_model_samples_its_own_quantiles():
    """Probability-weighted moments (Hosking & Wallis 1987) on 20 000 GPD draws: xi within 0.05 (their asymptotic
    standard error is ~0.01 here) and the scale within 5 %. A model fitted to Gaussian heights reaches the threshold
    with its declared probability and its draws' 99.9 % quantile is the model's own (binomial tolerance)."""
    rng = np.random.default_rng(4)
    for xi in (-0.3, 0.0, 0.25):
        got_xi, got_scale = gpd_pwm(sps.genpareto.rvs(xi, scale=2.0, size=20000, random_state=rng))
        assert got_xi == pytest.approx(xi, abs=0.05) and got_scale == pytest.approx(2.0, rel=0.05)
    model = fit_empirical_gpd(rng.normal(0.0, 1.0, 400))
    assert model.p_exceed == pytest.approx(0.2)
    z = model.sample(rng, 200000)
    above = np.mean(z > model.threshold)
    assert abs(above - model.p_exceed) < 5.0 * math.sqrt(model.p_exceed * (1 - model.p_exceed) / z.size)
    q = model.quantile(0.999)
    assert abs(np.mean(z > q) - 1e-3) < 5.0 * math.sqrt(1e-3 / z.size)


def _outcome(status, rebounds=()):
    return MemberOutcome(seed=0, status=status, rebound_heights=tuple(rebounds), release_height=1e-7,
                         max_contacts=1, wall_s=0.0)


def test_censored_members_are_reported_apart_from_those_that_stuck_or_rebounded_clear():
    """Two stuck (one at the first impact), three cut by max_bounces, one at rest: the within-run count is 2 of 6,
    its bounds run to (2 + 3)/6 if every censored member would have stuck; at the first impact one stuck and the
    rest rebounded clear."""
    outs = [_outcome("stuck"), _outcome("stuck", (5e-8,)), *[_outcome("max_bounces", (9e-8, 8e-8))] * 3,
            _outcome("rest", (1e-9,))]
    within, first = within_run_record(outs), first_impact_record(outs)
    assert (within["count"], within["members"], within["censored"]) == (2, 6, 3)
    assert within["censored_by"] == {"max_bounces": 3, "max_time": 0} and within["not_stuck"]["rest"] == 1
    assert within["bounds"] == {"no_censored_member_sticks": 2 / 6, "every_censored_member_sticks": 5 / 6}
    assert within["interval"] == list(wilson_interval(2, 6))
    assert (first["count"], first["rebounded"], first["censored"]) == (1, 5, 0)


def test_auto_members_stop_at_the_target_or_the_cap_and_say_why():
    stop = auto_members(0.05, cap=100, batch=32)
    assert not stop([_outcome("rest", (1e-9,))] * 32)[0]                   # 0/32: half-width 0.054
    assert stop([_outcome("rest", (1e-9,))] * 40)[0]                       # 0/40: half-width 0.044
    done, why = stop([_outcome("stuck")] * 50 + [_outcome("rest", (1e-9,))] * 50)
    assert done and "member cap 100" in why
    ens = run_ensemble(resolve_scene("rough_silica", params="paper", overrides={
        **SMALL, "surfaces.roughness.target_half_width": 0.01, "surfaces.roughness.max_members": 40}).scene,
        members="auto", seed=1, first_impact=True)
    assert ens.members == 40 and ens.members_rule["rule"] == "auto" and "member cap 40" in ens.members_rule["stopped"]


def test_a_map_run_records_both_tail_models_and_the_cutoff_band_at_the_maps_own_statistics(tmp_path):
    """rough_synthetic as an ensemble: result.json -> ensemble.tail_models has both models; surface.cutoff_band
    has the cutoffs 1/2, 1 and 2 x the run's, each with the beta and eta the map gives there
    (summit_statistics, computed here independently of the run) and a stick probability with its interval."""
    from continuum import run_scene
    from continuum.rough.surface_map import height_map
    from continuum.rough.topography import summit_statistics

    r = run_scene("rough_synthetic", overrides={**SMALL, "surfaces.roughness.mode": "ensemble",
                                                "surfaces.roughness.members": 6, "numerics.max_bounces": 2})
    tails = r.record["ensemble"]["tail_models"]
    assert set(tails) == {"gaussian", "empirical_gpd"}
    assert tails["empirical_gpd"]["fit"]["fitted"] and tails["empirical_gpd"]["members"] == 6
    band = r.record["surface"]["cutoff_band"]
    cutoff = r.record["surface"]["cutoff"]
    assert [e["factor"] for e in band] == [0.5, 1.0, 2.0]
    hmap, _ = height_map(resolve_scene("rough_synthetic").values, None)
    for e in band:
        assert e["cutoff"] == pytest.approx(e["factor"] * cutoff)
        st = summit_statistics(hmap, e["cutoff"], "direct")
        assert e["summit_radius"] == pytest.approx(st.summit_radius, rel=1e-12)
        assert e["summit_density"] == pytest.approx(st.summit_density, rel=1e-12)
        p = e["stick_probability"]
        assert p["members"] == 6 and p["interval"] == list(wilson_interval(p["count"], 6))
    out = r.write(tmp_path / "run")
    assert (out / "ensemble.png").is_file()
    from continuum.cli import ensemble_summary
    from continuum.output import plots
    assert len(plots.ensemble_spread(r.record["ensemble"], band=band).figure.axes) == 2
    assert "cutoff" in ensemble_summary(r.record["ensemble"], r.record["surface"])


def test_a_band_that_crosses_from_sticking_to_rebounding_warns_naming_the_scene():
    def entry(cutoff, k, n=40):
        return band_entry(1.0, cutoff, {"summit_radius": 1e-7, "summit_density": 1e13, "summit_height_std": 5e-9},
                          {"members": n, "stick_probability_first_impact": {
                              "count": k, "members": n, "value": k / n, "interval": list(wilson_interval(k, n)),
                              "censored": 0}, "first_rebound_m": {"p50": 0.0}})
    crossing = [entry(1e-8, 2), entry(2e-8, 30)]
    assert band_crosses(crossing) and "scene rough_x" in band_warning("rough_x", crossing)
    assert band_warning("rough_x", [entry(1e-8, 25), entry(2e-8, 38)]) is None
    agree = {m: {"stick_probability_first_impact": {"value": 0.1, "interval": [0.03, 0.2]}} for m in ("a", "b")}
    assert tail_warning("rough_x", agree) is None
    agree["b"]["stick_probability_first_impact"] = {"value": 0.9, "interval": [0.8, 0.97]}
    assert "scene rough_x" in tail_warning("rough_x", agree)


def test_the_empirical_tail_needs_a_map():
    with pytest.raises(SceneError) as err:
        run_ensemble(resolve_scene("rough_silica", params="paper", overrides={
            **SMALL, "surfaces.roughness.tail_model": "empirical_gpd"}), members=2)
    assert err.value.key == "surfaces.roughness.tail_model" and "\n" not in str(err.value)


def test_the_shipped_topography_scene_runs_the_calibrated_set_with_the_law_the_tabor_parameter_picks():
    from continuum.model.decisions import adhesion_decision
    from continuum.model.regime import regime_of

    r = resolve_scene("rough_topography")
    assert r.params_file is not None and r.params_file.endswith("calibrated.toml")
    scene = r.scene
    assert scene.physics.adhesion_law == "auto" and scene.surfaces.roughness.members == "auto"
    d = adhesion_decision(scene, regime_of(scene, first_impact_speed(scene)))
    assert d.record()["decided_by"] == "tabor_parameter"
    assert resolve_scene("rough_ots").scene.surfaces.roughness.mode == "auto"


def test_a_mean_field_run_on_a_map_reports_the_band_of_its_first_impact(tmp_path):
    """Under the mean field the band is the mean-field law's first impact at each cutoff: at the run's own cutoff it
    is the run's own first bounce; the others run on the map's statistics there, and the figure is drawn."""
    from continuum import run_scene

    r = run_scene("rough_synthetic", overrides={**SMALL, "surfaces.roughness.mode": "mean_field",
                                                "numerics.max_bounces": 1})
    band = r.record["surface"]["cutoff_band"]
    assert "ensemble" not in r.record and [e["factor"] for e in band] == [0.5, 1.0, 2.0]
    own = band[1]
    h0 = r.record["scene"]["si"]["release_height"]
    first = r.record["bounces"][0]["rebound_height"] or 0.0
    assert own["model"] == "mean_field" and own["first_rebound_median"] == pytest.approx(first / h0, rel=1e-9)
    assert own["stick_probability"]["value"] == float(r.record["stuck"] and first == 0.0)
    assert band[2]["summit_density"] < own["summit_density"]     # (the map holds no wavelength below 1x: 1/2x = 1x)
    assert (r.write(tmp_path / "run") / "cutoff_band.png").is_file()


def test_a_members_first_impact_does_not_depend_on_the_bounces_that_follow():
    """The tail models' and the band's ensembles run to the first rebound only and take the scene's own ensemble's
    first impacts for its own entries: a member's first impact (stuck or not, first rebound) is the same whether
    its run stops there or goes on."""
    scene = resolve_scene("rough_silica", params="paper", overrides={**SMALL, "numerics.max_bounces": 4}).scene
    full = run_ensemble(scene, members=6, seed=5)
    first = run_ensemble(scene, members=6, seed=5, first_impact=True)
    assert [o.stuck_at_first_impact for o in full.outcomes] == [o.stuck_at_first_impact for o in first.outcomes]
    assert [o.first_rebound for o in full.outcomes] == [o.first_rebound for o in first.outcomes]
    assert any(o.rebounds > 1 for o in full.outcomes) and all(o.rebounds <= 1 for o in first.outcomes)
