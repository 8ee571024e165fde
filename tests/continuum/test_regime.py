"""A scene's regime is derived once per run and passed on (`continuum.model.regime.Regime`), and its numbers are the
closed forms they stand for: E* (Johnson's 1/E* = sum (1 - nu^2)/E), Tabor's mu, Fuller-Tabor's theta, the GW
plasticity index, the Kelvin radius; `run_impact` returns the typed `ImpactResult` whose record is result.json."""
from __future__ import annotations

import json
import math
import pickle
import sys

import pytest

from continuum.dynamics.impact import first_impact_speed, run_impact
from continuum.model import regime as regime_module
from continuum.model import select_law
from continuum.output.impact_result import ImpactResult
from continuum.output.results import dumps
from continuum.scene import resolve_scene

#: The derivations a run makes from the scene: each belongs in `regime_of`, once per run.
DERIVATIONS = ("regime_of", "substrate_e_star", "coated_summits", "summit_e_star", "impact_estimate",
               "condensation_time", "kelvin_radius_cutoff", "solid_liquid_works", "meniscus_record",
               "meniscus_parameters")
R_GAS = 8.314462618            # J/(mol K), CODATA 2018 (exact)


@pytest.fixture
def counted(monkeypatch):
    """Count every call of a derivation, wherever a continuum module holds the function (a module that imported
    the name directly is patched too, so a step that derives again from the scene is seen)."""
    counts = {name: 0 for name in DERIVATIONS}
    for name in DERIVATIONS:
        original = getattr(regime_module, name)

        def wrapped(*args, _name=name, _original=original, **kwargs):
            counts[_name] += 1
            return _original(*args, **kwargs)
        for mod_name, module in list(sys.modules.items()):
            if (mod_name == "continuum" or mod_name.startswith("continuum.")) and \
                    getattr(module, name, None) is original:
                monkeypatch.setattr(module, name, wrapped)
    return counts


@pytest.mark.parametrize("scene, overrides, rough", [
    ("hertz_roller", {"numerics.max_bounces": 2}, False),
    # a wet smooth sphere, menisci 'auto': a dry run, its verdict, and the wet rerun share one regime
    ("afm_tip_humidity", {"physics.menisci": "auto", "menisci.condensation_time": 1e-12}, False),
    ("rough_silica", {"surfaces.roughness.mode": "mean_field", "physics.half_space": "off",
                      "numerics.max_bounces": 1, "numerics.fidelity": "fast"}, True),
    # an ensemble: its members' plan takes the run's regime (`member_plan`), the mean-field run beside it too
    ("rough_silica", {"surfaces.roughness.mode": "ensemble", "surfaces.roughness.members": 2,
                      "physics.half_space": "off", "numerics.max_bounces": 1, "numerics.fidelity": "fast"}, True),
])
def test_run_impact_derives_the_regime_once(counted, scene, overrides, rough):
    run = run_impact(resolve_scene(scene, overrides=overrides, override_label="test"), condensation_sweep=False)
    assert counted["regime_of"] == 1
    once = {name: 1 for name in DERIVATIONS if name not in ("summit_e_star", "meniscus_parameters")}
    once["impact_estimate"] = 1 if rough else 0
    once["meniscus_record"] = 1 if scene == "afm_tip_humidity" else 0
    # summit_e_star and meniscus_parameters are readers' shortcuts outside a run: a run calls neither
    assert counted == {**once, "summit_e_star": 0, "meniscus_parameters": 0}
    assert run.regime is not None and run.regime.speed == pytest.approx(first_impact_speed(
        resolve_scene(scene, overrides=overrides, override_label="test")), rel=0, abs=0)
    if scene == "afm_tip_humidity":
        assert run.models["menisci"].used is True       # the dry run's contact outlasted t_a: the wet rerun ran


def test_the_count_sees_a_step_that_derives_again(counted):
    """Negative control: two laws built without the run's regime derive it twice."""
    resolved = resolve_scene("hertz_roller", overrides={"numerics.max_bounces": 2}, override_label="test")
    v = first_impact_speed(resolved)
    select_law(resolved.scene, v)
    select_law(resolved.scene, v)
    assert counted["regime_of"] == 2
    regime = regime_module.regime_of(resolved.scene, v)
    select_law(resolved.scene, v, regime=regime)
    assert counted["regime_of"] == 3               # the one call above; the law built on it derived nothing


def test_a_regime_of_another_speed_is_refused():
    scene = resolve_scene("hertz_roller").scene
    with pytest.raises(ValueError, match="derived at"):
        select_law(scene, 1.0, regime=regime_module.regime_of(scene, 2.0))


def _johnson_e_star(scene) -> float:
    b, s = scene.surfaces.body, scene.surfaces.substrate
    return 1.0 / ((1.0 - b.poisson_ratio**2) / b.youngs_modulus + (1.0 - s.poisson_ratio**2) / s.youngs_modulus)


def test_a_smooth_spheres_regime_is_its_closed_forms():
    """jkr_sphere (silica on silica, R = 5 um, w = 0.1 J/m^2): E* by Johnson's sum, mu = (R w^2/(E*^2 z0^3))^(1/3)."""
    scene = resolve_scene("jkr_sphere").scene
    r = regime_module.regime_of(scene, 0.15)
    e = _johnson_e_star(scene)
    w, z0, big_r = scene.surfaces.work_of_adhesion, scene.surfaces.interaction_range, scene.body.radius
    assert not r.rough and r.radius == big_r and r.speed == 0.15 and r.estimate is None
    assert r.e_star == pytest.approx(e, rel=1e-12, abs=0)        # a few flops: round-off only
    assert r.work_of_adhesion == w and r.interaction_range == z0
    assert r.tabor_parameter == pytest.approx((big_r * w**2 / (e**2 * z0**3)) ** (1 / 3), rel=1e-12, abs=0)
    assert r.fuller_tabor_theta is None and r.plasticity_index is None and r.coated is None
    # dry air: no Kelvin radius, no meniscus, t_a infinite under nucleation or the declared one
    assert r.kelvin_radius is None and r.meniscus is None
    with pytest.raises(ValueError, match="relative_humidity"):
        r.meniscus_parameters()


def test_rough_summits_regime_is_its_closed_forms_and_the_old_derivations():
    """rough_silica with a hardness: the summits' E* (summit_modulus where the set gives one, else Johnson's sum),
    theta = E* sigma^(3/2)/(beta^(1/2) w), psi = (E*/H) sqrt(sigma/beta); the first impact's estimate at the scene's
    speed; each field equal to the derivation it replaces."""
    resolved = resolve_scene("rough_silica", overrides={"surfaces.substrate.hardness": 9e9,
                                                        "surfaces.roughness.mode": "mean_field"},
                             override_label="test")
    scene, v = resolved.scene, first_impact_speed(resolved)
    r = regime_module.regime_of(scene, v)
    rough, surf = scene.surfaces.roughness, scene.surfaces
    e = rough.summit_modulus if rough.summit_modulus is not None else _johnson_e_star(scene)
    beta, w, sigma = rough.summit_radius, surf.interface_work_of_adhesion, rough.sigma
    assert r.rough and r.radius == beta and r.speed == v
    assert r.e_star == pytest.approx(e, rel=1e-12, abs=0) and r.e_star == regime_module.summit_e_star(scene)
    assert r.substrate_e_star == regime_module.substrate_e_star(scene)
    assert r.fuller_tabor_theta == pytest.approx(e * sigma**1.5 / (math.sqrt(beta) * w), rel=1e-12, abs=0)
    assert r.plasticity_index == pytest.approx(e / 9e9 * math.sqrt(sigma / beta), rel=1e-12, abs=0)
    again = regime_module.impact_estimate(scene, v, r.e_star)
    assert (again.depth, again.contacts, again.peak_force) == (r.estimate.depth, r.estimate.contacts,
                                                               r.estimate.peak_force)   # deterministic: same code
    assert (r.condensation_time, r.condensation_time_source) == regime_module.condensation_time(scene)
    assert pickle.loads(pickle.dumps(r)) == r


def test_a_humid_scene_without_contact_angles_has_a_kelvin_radius_and_no_meniscus():
    """jkr_sphere's `silica` set gives no water contact angles: with menisci off, humid air derives r_K but no
    bridge (before, nothing derived them for a scene whose menisci are off)."""
    scene = resolve_scene("jkr_sphere", overrides={"environment.relative_humidity": 0.4, "physics.menisci": "off"},
                          override_label="test").scene
    assert scene.surfaces.contact_angles == (None, None)
    r = regime_module.regime_of(scene, 0.15)
    assert r.kelvin_radius > 0 and r.meniscus is None
    with pytest.raises(ValueError, match="contact angles"):
        r.meniscus_parameters()


def test_a_humid_regime_holds_the_kelvin_radius_and_the_meniscus_record():
    """afm_tip_humidity (40 % RH): r_K = gamma V_m / (R T ln(1/RH)) by hand; the meniscus record is the one the
    reader's shortcut gives."""
    scene = resolve_scene("afm_tip_humidity").scene
    r = regime_module.regime_of(scene, 0.1)
    env, m = scene.environment, scene.menisci
    r_k = m.surface_tension * m.molar_volume / (R_GAS * env.temperature * math.log(1.0 / env.relative_humidity))
    assert r.kelvin_radius == pytest.approx(r_k, rel=1e-12, abs=0)
    assert dict(r.meniscus_parameters()) == regime_module.meniscus_parameters(scene)
    assert r.meniscus["kelvin_radius"] == r.kelvin_radius
    assert r.meniscus["condensation_time"] == r.condensation_time
    assert (r.kelvin_radius, r.min_kelvin_radius, r.min_kelvin_radius_source) == \
        regime_module.kelvin_radius_cutoff(scene)
    with pytest.raises(TypeError):
        r.meniscus["kelvin_radius"] = 0.0          # read-only: the regime is frozen through and through
    back = pickle.loads(pickle.dumps(r))           # an ensemble's members carry it to other processes
    assert back == r and dict(back.meniscus) == dict(r.meniscus) and back.estimate == r.estimate
    with pytest.raises(TypeError):
        back.meniscus["kelvin_radius"] = 0.0


def test_run_impact_returns_the_typed_result_whose_record_is_result_json(tmp_path):
    resolved = resolve_scene("hertz_roller", overrides={"numerics.max_bounces": 2}, override_label="test")
    run = run_impact(resolved)
    assert isinstance(run, ImpactResult)
    assert run.release_height == resolved.scene.release_height and run.release_height > 0
    assert run.input_hash == resolved.input_hash
    assert run.rebound_heights() == [b["rebound_height"] or 0.0 for b in run.record["bounces"]]
    assert run.n_bounces == run.record["n_bounces"] == 2
    run.write_record(tmp_path)
    written = json.loads((tmp_path / "result.json").read_text())
    assert written == json.loads(dumps(run.to_dict()))          # the same record the command line writes


def test_the_api_builds_a_runs_law_again_on_its_regime_without_deriving(counted):
    """calibration's escape search: `contact_law(resolved, result.regime)` derives nothing; a single impact on it at
    the first-impact speed is the run's first bounce (same law, same integrator)."""
    from continuum.api import contact_law, load_scene, run_scene, single_impact

    resolved = load_scene("hertz_roller", overrides={"numerics.max_bounces": 1})
    result = run_scene(resolved)
    assert counted["regime_of"] == 1
    law = contact_law(resolved, result.regime)
    assert counted["regime_of"] == 1
    sc = resolved.scene
    first = single_impact(law, sc.body.mass, sc.environment.gravity, result.regime.speed, sc.numerics.rtol)
    assert first.bounces[0].restitution == pytest.approx(result.bounces[0].restitution, rel=1e-6, abs=0)
