"""Ensembles of discrete summit realisations (continuum.rough.ensemble, continuum.dynamics.ensemble_run) and the
'auto' rule.

The paper's roller on rough silica (`paper` set, rigid substrate): about 3 summits carry the first impact, each
loop a sizeable part of the impact energy, so realisations differ by whole loops."""
import dataclasses
import json
import math

import numpy as np
import pytest

from continuum import EnsembleResult, run_scene
from continuum.dynamics.ensemble_run import member_law, member_plan, run_ensemble, run_member
from continuum.model.decisions import ENSEMBLE_BELOW_CONTACTS, realisation_decision
from continuum.model.regime import first_impact_speed, regime_of
from continuum.rough.ensemble import MemberOutcome, member_seeds
from continuum.scene import SceneError, resolve_scene

RIGID = {"physics.half_space": "off"}


def _scene(**overrides):
    return resolve_scene("rough_silica", params="paper", overrides={**RIGID, **overrides}).scene


def test_member_seeds_are_reproducible_distinct_and_in_the_scene_range():
    a, b = member_seeds(7, 64), member_seeds(7, 64)
    assert a == b and len(set(a)) == 64
    assert all(0 <= s < 2**63 for s in a)
    assert member_seeds(7, 8) == a[:8]              # growing an ensemble keeps its first members
    assert set(member_seeds(8, 64)).isdisjoint(a)


def test_an_ensemble_is_reproducible_and_its_members_differ():
    scene = _scene(**{"numerics.max_bounces": 3})
    one, two = run_ensemble(scene, members=12, seed=5), run_ensemble(scene, members=12, seed=5)
    assert one.seeds == two.seeds == member_seeds(5, 12)
    assert [o.rebound_heights for o in one.outcomes] == [o.rebound_heights for o in two.outcomes]
    assert len({round(float(h), 12) for h in one.first_rebounds()}) > 1


def test_stick_probabilities_are_the_members_fractions():
    scene = _scene(**{"numerics.max_bounces": 100})
    ens = run_ensemble(scene, members=16, seed=3)
    stuck = [o.status == "stuck" for o in ens.outcomes]
    first = [o.status == "stuck" and not o.rebound_heights for o in ens.outcomes]
    assert ens.stick_probability == sum(stuck) / 16
    assert ens.stick_probability_first_impact == sum(first) / 16
    assert 0.0 <= ens.stick_probability_first_impact <= ens.stick_probability <= 1.0
    rec = ens.to_record()
    within = rec["stick_probability"]["within_run"]
    assert within["count"] == sum(stuck) and within["members"] == 16
    lo, hi = within["interval"]
    assert lo <= within["value"] <= hi and 0.0 <= lo < hi <= 1.0
    censored = sum(o.status in ("max_bounces", "max_time") for o in ens.outcomes)
    assert within["censored"] == censored
    assert within["bounds"]["every_censored_member_sticks"] == (sum(stuck) + censored) / 16
    assert rec["rebounds"]["p50"] == pytest.approx(np.percentile([o.rebounds for o in ens.outcomes], 50))


@pytest.mark.parametrize("law", ["jkr", "maugis_dugdale"])
def test_the_compiled_discrete_contact_is_the_python_stepper(law):
    """A member's contacts run in the compiled kernel (rigid substrate); the Python stepper integrates the same
    law with the law's own history rule, summit by summit. Rebound heights agree to the integration's accuracy:
    these runs close their energy books to ~1e-6 (JKR) and ~1e-5 (tabulated branches, whose force has a kink at
    every table node) of the impact energy, and a rebound height is that energy over m g."""
    import continuum.dynamics.ensemble_run as er
    from continuum.dynamics.driver import DriverSettings

    scene = _scene(**{"numerics.max_bounces": 4, "physics.adhesion_law": law})
    plan = member_plan(scene, first_impact_speed(scene))
    assert (plan.summit_law is None) == (law == "jkr")
    h0 = scene.release_height
    for seed in member_seeds(11, 4):
        compiled = run_member(scene, seed, plan)
        original = er.DriverSettings
        er.DriverSettings = lambda **kw: DriverSettings(**kw, compiled=False)
        try:
            python = run_member(scene, seed, plan)
        finally:
            er.DriverSettings = original
        assert compiled.status == python.status and compiled.rebounds == python.rebounds
        assert np.allclose(compiled.rebound_heights, python.rebound_heights, rtol=0, atol=2e-5 * h0)


def _departure(height: float, members: int):
    """(relative departure of the mean field's first-impact loss from the ensemble mean, its standard error, the
    members' relative spread, expected contacts) for the paper's roller dropped from `height`."""
    overrides = {**RIGID, "physics.adhesion_law": "jkr", "numerics.max_bounces": 1, "release_height": height}
    mf = run_scene("rough_silica", params="paper", overrides=overrides)
    scene = _scene(**overrides)
    h0 = scene.release_height
    loss_mf = 1.0 - mf.bounces[0].rebound_height / h0
    loss = 1.0 - run_ensemble(scene, members=members, seed=2).first_rebounds() / h0
    rel_se = loss.std(ddof=1) / math.sqrt(members) / loss.mean()
    return loss_mf / loss.mean() - 1.0, rel_se, loss.std() / loss.mean(), mf.record["models"]["regimes"][
        "expected_contacts"]


def test_the_ensemble_mean_approaches_the_mean_field_with_many_summits():
    """Few summits (drop 100 nm, ~3 expected contacts): the mean field's first-impact loss misses the ensemble
    mean by 15-35 % (seed to seed), outside 2 standard errors of 64 members. Many (drop 30 um, ~150): a
    realisation's loss is its count of summits reached times one loop, its scatter falls like 1/sqrt(N_c), and the
    mean field lies within 20 % of the ensemble mean: 3 standard errors of 8 members (~7 % each, the spread below
    0.3) plus the finite-N bias of the datum measured in docs/figures/ensemble_threshold.json (~6 % there)."""
    rel, se, spread, n_c = _departure(1e-7, 64)
    assert n_c < 5 and abs(rel) > 0.15 and abs(rel) > 2 * se and spread > 0.5
    rel, se, spread, n_c = _departure(3e-5, 8)
    assert n_c > 100 and spread < 0.3
    assert abs(rel) < 0.2


def test_auto_runs_an_ensemble_below_the_threshold_and_the_mean_field_above():
    few = _scene(**{"surfaces.roughness.mode": "auto"})
    d = realisation_decision(few, regime_of(few, first_impact_speed(few)))
    assert d.expected_contacts < ENSEMBLE_BELOW_CONTACTS and d.mode == "ensemble"
    assert d.record()["ensemble_below_contacts"] == ENSEMBLE_BELOW_CONTACTS
    # a heavier, deeper impact on a finer surface: many summits
    many = _scene(**{"surfaces.roughness.mode": "auto", "surfaces.roughness.sigma": 1e-9,
                     "surfaces.roughness.summit_modulus": 1e8})
    d = realisation_decision(many, regime_of(many, first_impact_speed(many)))
    assert d.expected_contacts >= ENSEMBLE_BELOW_CONTACTS and d.mode == "mean_field"
    # forced modes are the scene's
    forced = _scene(**{"surfaces.roughness.mode": "mean_field"})
    assert realisation_decision(forced, regime_of(forced, first_impact_speed(forced))).decided_by == "scene"


def test_auto_runs_an_ensemble_where_menisci_may_form():
    """Few summits in humid air: the members carry bridges (continuum.laws.discrete_bridges), so 'auto' no longer
    falls back to the mean field there."""
    wet = resolve_scene("wet_silica", params="paper", overrides={"surfaces.roughness.mode": "auto"}).scene
    d = realisation_decision(wet, regime_of(wet, first_impact_speed(wet)))
    assert d.mode == "ensemble" and d.decided_by == "expected_contacts"


@pytest.mark.parametrize("key, value, words", [
    ("surfaces.roughness.mode", "ensembles", "one of"),
    ("surfaces.roughness.members", 1, ">= 2"),
    ("surfaces.roughness.members", 2.5, "int"),
    ("surfaces.roughness.seed", -1, ">= 0"),
    ("surfaces.roughness.members", "many", "or 'auto'"),
    ("surfaces.roughness.target_half_width", 0.0, "> 0"),
    ("surfaces.roughness.max_members", 1, ">= 2"),
    ("surfaces.roughness.tail_model", "pareto", "one of"),
])
def test_bad_ensemble_keys_are_one_line_errors(key, value, words):
    with pytest.raises(SceneError) as err:
        _scene(**{key: value})
    assert err.value.key == key and "\n" not in str(err.value) and words in str(err.value)


def test_an_ensemble_of_maugis_dugdale_summits_runs_them():
    r = run_scene("rough_silica", params="paper", overrides={**RIGID, "surfaces.roughness.mode": "ensemble",
                                                             "surfaces.roughness.members": 3,
                                                             "physics.adhesion_law": "maugis_dugdale",
                                                             "numerics.max_bounces": 2})
    assert r.models["adhesion"].numbers["law"] == "maugis_dugdale"
    assert r.ensemble.members == 3 and r.record["models"]["contact_law"]["mode"] == "mean_field"


def test_result_json_carries_the_ensemble_and_the_front_door_types_it(tmp_path):
    r = run_scene("rough_silica", params="paper", overrides={**RIGID, "surfaces.roughness.mode": "ensemble",
                                                             "surfaces.roughness.members": 6,
                                                             "numerics.max_bounces": 4})
    assert isinstance(r.ensemble, EnsembleResult) and dataclasses.is_dataclass(r.ensemble)
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.ensemble.master_seed = 3
    rec = r.record["ensemble"]
    assert rec["members"] == 6 and rec["seeds"] == list(member_seeds(0, 6))
    assert set(rec["stick_probability"]) >= {"first_impact", "within_run"}
    assert rec["percentiles"] == [5, 25, 50, 75, 95]
    assert rec["escape_velocity"]["requested"] is False
    assert r.record["models"]["realisation"]["mode"] == "ensemble"
    assert r.ensemble.stick_probability == rec["stick_probability"]["within_run"]["value"]
    out = r.write(tmp_path / "run")
    assert (out / "ensemble.png").is_file()
    assert json.loads((out / "result.json").read_text())["ensemble"]["members"] == 6
    assert all(isinstance(o, MemberOutcome) for o in r.ensemble.outcomes)


def test_the_shipped_scene_at_auto_runs_an_ensemble_of_rigid_members_with_the_calibrated_set():
    """rough_silica as shipped (mode and half-space 'auto'): under the paper roller the half-space deflection is
    orders below 1e-3 sigma and a few summits carry the impact, so the calibrated set runs an ensemble."""
    r = run_scene("rough_silica", params="calibrated", overrides={"surfaces.roughness.members": 3,
                                                                  "numerics.max_bounces": 2})
    models = r.record["models"]
    assert models["half_space"]["used"] is False and models["half_space"]["deflection_over_sigma"] < 1e-3
    assert models["realisation"]["mode"] == "ensemble"
    assert models["realisation"]["expected_contacts"] < ENSEMBLE_BELOW_CONTACTS
    p = r.record["ensemble"]["stick_probability"]
    assert 0.0 <= p["first_impact"]["value"] <= p["within_run"]["value"] <= 1.0
    assert r.record["ensemble"]["source"] == "statistics"


def _member_law(scene, seed):
    return member_law(scene, seed, member_plan(scene, first_impact_speed(scene)))[1]


def test_tabulated_first_approach_forces_are_the_summit_sums_at_each_depth():
    """The depth search's batch of forces (one interpolation over all depths) is each depth's own summit sum."""
    scene = _scene(**{"physics.adhesion_law": "maugis_dugdale"})
    law = _member_law(scene, 11)
    depths = np.linspace(0.0, 4.0 * scene.surfaces.roughness.sigma, 257)
    one_by_one = np.array([law.approach_force(-d) for d in depths])
    assert np.count_nonzero(one_by_one) > 100
    assert np.allclose(law.approach_forces(depths), one_by_one, rtol=1e-12, atol=1e-12 * np.max(np.abs(one_by_one)))


@pytest.mark.parametrize("law", ["jkr", "maugis_dugdale"])
def test_samples_inside_steps_do_not_change_a_members_rebounds(law):
    """Members keep no time series (samples_per_step = 0): the samples are read off each step's dense output
    and do not steer the steps, so the rebounds are those of a fully sampled run, to the last bit."""
    from continuum.dynamics.driver import DriverSettings, simulate

    scene = _scene(**{"physics.adhesion_law": law, "numerics.max_bounces": 6})
    runs = []
    for per_step in (3, 0):
        run = simulate(_member_law(scene, 5), scene.body.mass, scene.environment.gravity,
                       release_height=scene.release_height,
                       settings=DriverSettings(rtol=scene.numerics.rtol, max_bounces=6, samples_per_step=per_step))
        runs.append([b.rebound_height for b in run.bounces])
    assert len(runs[0]) >= 2 and runs[0] == runs[1]


@pytest.mark.parametrize("law", ["jkr", "maugis_dugdale"])
def test_members_on_a_process_pool_are_bit_for_bit_the_serial_members(law):
    """A member's outcome depends on its seed only: run on two forked workers (which inherit the parent's compiled
    kernel and summit law) it is the serial run's, every rebound height to the last bit."""
    scene = _scene(**{"numerics.max_bounces": 5, "physics.adhesion_law": law})
    serial = run_ensemble(scene, members=5, seed=9, executor="local")
    pooled = run_ensemble(scene, members=5, seed=9, executor="processes", workers=2)
    assert pooled.executor.startswith("processes")
    assert pooled.seeds == serial.seeds
    for a, b in zip(serial.outcomes, pooled.outcomes):
        assert (a.seed, a.status, a.rebound_heights, a.max_contacts, a.energy_error) == \
            (b.seed, b.status, b.rebound_heights, b.max_contacts, b.energy_error)


def test_escape_velocities_are_asked_for_by_the_scene_and_their_percentiles_bracket_the_members():
    """Each member's escape velocity is bisected to the asked relative width: its lower end sticks and its upper
    end rebounds when the member's summits are drawn again (virgin), and the ensemble's percentiles are ordered
    and lie between the members' smallest and largest values.

    Closed form: at its escape speed a member whose tallest summit stands alone is caught by that summit only,
    and leaves iff its kinetic energy pays the summit's Fuller-Tabor loop U and the lift m g delta_c to the
    release point (the datum is the tallest summit's top): v_1 = sqrt(2 (U + m g delta_c) / m). Every member
    needs at least that (more summits lose more loops), and a member with a lone tallest summit needs exactly
    that (seed 3 has some)."""
    from continuum.dynamics.escape import single_impact
    from continuum.reference import jkr

    scene = _scene(**{"numerics.max_bounces": 2, "surfaces.roughness.escape_velocities": True})
    ens = run_ensemble(scene, members=6, seed=3, escape_rel_tol=0.01)
    rec = ens.to_record()["escape_velocity"]
    assert rec["requested"] is True and rec["rel_tol"] == 0.01 and rec["members_with_value"] == 6
    plan, rough, m = member_plan(scene, first_impact_speed(scene)), scene.surfaces.roughness, scene.body.mass
    loop = jkr.loop_area(rough.summit_radius, plan.work_of_adhesion, plan.summit_e_star, detachment="displacement")
    delta_c = jkr.critical_approach(rough.summit_radius, plan.work_of_adhesion, plan.summit_e_star)
    v_1 = math.sqrt(2.0 * (loop + m * scene.environment.gravity * delta_c) / m)
    lower = np.array([o.escape["lower"] for o in ens.outcomes])
    upper = np.array([o.escape["upper"] for o in ens.outcomes])
    assert np.all(upper >= v_1) and np.any((lower <= v_1) & (v_1 <= upper))
    values = ens.escape_velocities()
    q = [rec["m_per_s"][f"p{p}"] for p in (5, 25, 50, 75, 95)]
    assert all(a <= b for a, b in zip(q, q[1:]))
    assert values.min() <= q[0] and q[-1] <= values.max()
    assert rec["m_per_s"]["min"] == values.min() and rec["m_per_s"]["max"] == values.max()
    for o in ens.outcomes[:2]:
        lo, hi = o.escape["lower"], o.escape["upper"]
        assert lo < o.escape["escape_velocity"] < hi and hi / lo - 1.0 <= 0.01
        law = _member_law(scene, o.seed)
        assert single_impact(law, scene.body.mass, scene.environment.gravity, lo, scene.numerics.rtol).stuck
        assert not single_impact(law, scene.body.mass, scene.environment.gravity, hi, scene.numerics.rtol).stuck
    back = EnsembleResult.from_record(ens.to_record(), scene.release_height)
    assert back.escape_rel_tol == 0.01 and np.array_equal(back.escape_velocities(), values)


def test_without_the_scene_key_the_ensemble_says_no_escape_velocities_were_asked_for():
    ens = run_ensemble(_scene(**{"numerics.max_bounces": 1}), members=2, seed=2)
    rec = ens.to_record()["escape_velocity"]
    assert rec["requested"] is False and "surfaces.roughness.escape_velocities" in rec["why"]
    assert all(o.escape is None for o in ens.outcomes) and np.isnan(ens.escape_velocities()).all()


def test_the_ensemble_figure_and_summary_show_the_escape_velocity_spread():
    from continuum.cli import ensemble_summary
    from continuum.output import plots

    scene = _scene(**{"numerics.max_bounces": 1})
    with_escape = run_ensemble(scene, members=3, seed=2, escape=True, escape_rel_tol=0.1).to_record()
    without = run_ensemble(scene, members=2, seed=2).to_record()
    assert len(plots.ensemble_spread(with_escape).figure.axes) == 2
    assert len(plots.ensemble_spread(without).figure.axes) == 1
    assert "escape velocity median" in ensemble_summary(with_escape)
    assert "escape velocity" not in ensemble_summary(without)
