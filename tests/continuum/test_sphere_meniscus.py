"""The smooth sphere's capillary bridge (continuum.laws.sphere_meniscus) against closed forms.

Closed forms: the sphere-flat bridge pulls F0 = 2 pi R gamma (cos t1 + cos t2) at touch (4 pi R gamma cos t for
equal angles; Israelachvili 2011 eq 17.23) and stores F0 D_K / 2 there (its energy is -int F, zero at rupture);
a DMT sphere's wet pull-off is F0 + 2 pi R max(W_wet, 0) (Israelachvili eq 17.25), the additive one
F0 + 2 pi R dgamma; below the declared Kelvin-radius cutoff no bridge exists and the pull-off is the dry one.
"""
from __future__ import annotations

import math

import pytest

from continuum import load_scene, run_scene
from continuum.laws.hertz import HertzSphere
from continuum.laws.sphere_meniscus import SphereBridge, pull_off
from continuum.model.regime import first_impact_speed
from continuum.model.select import select_law
from continuum.scene import SceneError
from continuum.wet import menisci

RADIUS = 20e-9
GAMMA = 0.072


def _scene(rh=0.4, law="dmt", solid="wet", t_a=1e-15, velocity=30.0, menisci_choice="on", **surfaces):
    return {"name": "t", "description": "wet nanosphere", "params": "silicon", "impact_velocity": velocity,
            "body": {"shape": "sphere", "radius": RADIUS, "density": 2330.0},
            "surfaces": surfaces, "environment": {"relative_humidity": rh, "gravity": 0.0},
            "physics": {"adhesion_law": law, "menisci": menisci_choice},
            "menisci": {"solid_adhesion": solid, "condensation_time": t_a, "surface_tension": GAMMA},
            "numerics": {"max_bounces": 1}}


def _models(table):
    scene = load_scene(table).scene
    return select_law(scene, first_impact_speed(scene))


@pytest.mark.parametrize("theta", [0.0, 20.0, 60.0])
def test_pull_at_contact_is_four_pi_r_gamma_cos_theta(theta):
    """A bridge alone on a non-adhesive (Hertz) sphere: the quasi-static pull-off is F0 = 4 pi R gamma cos t, taken
    at the touch (the elastic force grows as depth^(3/2) against the bridge's linear gain: 1e-6 of F0)."""
    t = math.radians(theta)
    r_k = menisci.kelvin_radius(0.5, 298.15, GAMMA, 1.807e-5)
    bridge = SphereBridge(menisci.bridge_pull_off(RADIUS, GAMMA, t, t), menisci.kelvin_gap(r_k, t, t), 0.0, 1e-10)
    f0 = 4.0 * math.pi * RADIUS * GAMMA * math.cos(t)
    assert bridge.force(0.0) == pytest.approx(f0, rel=1e-12)
    assert bridge.energy(0.0) == pytest.approx(-0.5 * f0 * bridge.d_k, rel=1e-12)
    assert bridge.force(bridge.d_k) == 0.0 and bridge.energy(bridge.d_k) == 0.0
    res = pull_off(HertzSphere(RADIUS, 80e9), bridge)
    assert res["pull_off_force"] == pytest.approx(f0, rel=1e-6)


@pytest.mark.parametrize("solid", ["wet", "additive"])
@pytest.mark.parametrize("w", [0.063, 0.3])
def test_dmt_pull_off_in_the_bridge_is_israelachvilis(solid, w):
    """DMT sphere in the bridge: F0 + 2 pi R max(W_wet, 0) ('wet': W_wet < 0 at w = 0.063, > 0 at w = 0.3) or
    F0 + 2 pi R dgamma ('additive'); the record's dry pull-off is DMT's 2 pi R dgamma."""
    _, models = _models(_scene(solid=solid, work_of_adhesion=w))
    men = models["menisci"]
    t1, t2 = (math.radians(20.0),) * 2
    f0 = 2.0 * math.pi * RADIUS * GAMMA * (math.cos(t1) + math.cos(t2))
    w_solid = max(w - GAMMA * (math.cos(t1) + math.cos(t2)), 0.0) if solid == "wet" else w
    q = models["contact_law"]["quasi_static"]
    assert men["bridge_pull_off"] == pytest.approx(f0, rel=1e-12)
    assert men["solid_work_of_adhesion"] == pytest.approx(w_solid, rel=1e-12, abs=1e-15)
    assert q["pull_off_force"] == pytest.approx(f0 + 2.0 * math.pi * RADIUS * w_solid, rel=1e-4)
    assert q["dry_pull_off_force"] == pytest.approx(2.0 * math.pi * RADIUS * w, rel=1e-4)


def test_humidity_below_the_molecular_cutoff_leaves_the_dry_sphere():
    """r_K = 0.525 nm / ln(1/RH) falls below one water molecule (0.31 nm) under RH = exp(-0.525/0.31) = 0.18: no
    bridge, the dry law, and the decision names the Kelvin radius; just above it the bridge is there."""
    cut = menisci.WATER_MOLECULE_DIAMETER
    kelvin_length = GAMMA * 1.807e-5 / (menisci.R_GAS * 298.15)
    rh_cut = math.exp(-kelvin_length / cut)
    law, models = _models(_scene(rh=0.9 * rh_cut, menisci_choice="auto"))
    assert models["menisci"]["decided_by"] == "kelvin_radius" and models["menisci"]["used"] is False
    assert "meniscus" not in law.name
    law, models = _models(_scene(rh=1.1 * rh_cut, menisci_choice="on"))
    assert "meniscus" in law.name and models["menisci"]["kelvin_radius"] > cut
    table = _scene(rh=0.9 * rh_cut, menisci_choice="auto")
    table["menisci"]["min_kelvin_radius"] = 0.1e-9
    law, models = _models(table)
    assert models["menisci"]["decided_by"] != "kelvin_radius"


@pytest.mark.parametrize("law", ["dmt", "jkr"])
@pytest.mark.parametrize("solid", ["wet", "additive"])
def test_impact_with_a_bridge_keeps_the_energy_books_and_loses_the_formation_work(law, solid):
    """A bridge condensing t_a = 1e-15 s after touch (the sphere 3e-14 m deep) and rupturing at D_K: the books
    close to the integrator's tolerance, and a DMT sphere (no loop of its own) loses F0 D_K/2 (the work of the
    bridge from touch to rupture, 1e-4 for the depth it formed at); a JKR one that plus its own loop."""
    result = run_scene(_scene(law=law, solid=solid))
    rec = result.record
    assert rec["energy_audit"]["max_relative_error"] < 1e-6
    assert rec["models"]["diagnostics"]["menisci"]["contacts_with_bridge"] == 1
    men = rec["models"]["menisci"]
    mass = 4.0 / 3.0 * math.pi * RADIUS ** 3 * 2330.0
    lost = (1.0 - result.bounces[0].restitution ** 2) * 0.5 * mass * 30.0 ** 2
    bridge = 0.5 * men["bridge_pull_off"] * men["kelvin_gap"]
    if law == "dmt":
        assert lost == pytest.approx(bridge, rel=1e-4)
    else:
        assert lost > bridge


def test_slow_sphere_is_held_by_the_bridge_and_dry_one_rebounds():
    wet = run_scene(_scene(velocity=5.0))
    dry = run_scene(_scene(velocity=5.0, menisci_choice="off"))
    assert wet.stuck and not dry.stuck


@pytest.mark.parametrize("key, value", [("environment.relative_humidity", 1.0),
                                        ("surfaces.body.contact_angle", 190.0),
                                        ("surfaces.substrate.contact_angle", -5.0)])
def test_bad_wet_sphere_input_names_the_key(key, value):
    table = _scene()
    section, _, leaf = key.rpartition(".")
    node = table
    for part in section.split("."):
        node = node.setdefault(part, {})
    node[leaf] = value
    with pytest.raises(SceneError) as err:
        load_scene(table)
    assert key in str(err.value) and "\n" not in str(err.value)


def test_wet_solids_with_plasticity_are_refused_naming_the_key():
    table = _scene(law="jkr")
    table["surfaces"] = {"body": {"hardness": 5e9}}
    table["physics"]["plasticity"] = "on"
    with pytest.raises(SceneError, match="menisci.solid_adhesion"):
        _models(table)


def test_pull_off_without_a_bridge_is_jkrs_load_controlled_1p5_pi_r_w():
    from continuum.laws.jkr import JKRSphere
    w = 0.1
    res = pull_off(JKRSphere(RADIUS, w, 80e9), None)
    assert res["pull_off_force"] == pytest.approx(1.5 * math.pi * RADIUS * w, rel=1e-6)


def test_auto_sphere_meniscus_left_out_when_no_contact_lasts_t_a():
    """Default t_a = 25 us against a nanosecond impact: the dry run is the wet run, recorded with its numbers."""
    result = run_scene(_scene(menisci_choice="auto", t_a=25e-6))
    men = result.record["models"]["menisci"]
    assert men["used"] is False and men["decided_by"] == "longest_contact_time"
    assert men["longest_contact_s"] < men["condensation_time_s"] == 25e-6


def test_humidity_sweep_steps_from_the_dry_to_the_bridged_pull_off():
    """benchmarks/validation/pull_off_humidity.py: below the cutoff the dry DMT pull-off 2 pi R dgamma, above it
    (W_wet < 0 for the silicon set) the bridge's F0 = 4 pi R gamma cos 20 deg."""
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks" / "validation"))
    try:
        import pull_off_humidity as sweep
    finally:
        sys.path.pop(0)
    rows = sweep.pull_off_curve("afm_tip_humidity", [0.1, 0.5])
    assert [r["bridge"] for r in rows] == [False, True]
    assert rows[0]["pull_off_force"] == pytest.approx(2.0 * math.pi * RADIUS * 0.063, rel=1e-4)
    assert rows[1]["pull_off_force"] == pytest.approx(4.0 * math.pi * RADIUS * GAMMA * math.cos(math.radians(20.0)),
                                                      rel=1e-4)
