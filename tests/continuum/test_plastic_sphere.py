"""The adhesive elastic-plastic sphere law in the driver against the Thornton-Ning closed forms.

The closed forms (`continuum.reference.thornton_ning`) are independent of the driver: energies of
the JKR curve and of the plastic line, a quadratic for the maximum approach. The driver integrates
the motion (DOP853 at rtol 1e-10) with the law's force, so agreement to ~1e-7 tests the law's
force, its history (the flattened branch), and the release it reports.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from continuum.dynamics.driver import DriverSettings, simulate
from continuum.dynamics.escape import escape_velocity, single_impact
from continuum.laws.jkr import JKRSphere
from continuum.laws.plastic_sphere import PlasticJKRSphere
from continuum.reference import jkr as ref
from continuum.reference import thornton_ning as tn
from nanoimpact.errors import InputError

# The case: a 4.9 um sphere, E = 1.2 GPa, nu = 0.3, rho = 1350 kg/m^3, w = 0.2 J/m^2,
# limiting contact pressure 35.3 MPa, on silicon (E = 169 GPa, nu = 0.28).
R = 4.9e-6 / 2.0
E_STAR = 1.0 / ((1.0 - 0.3**2) / 1.2e9 + (1.0 - 0.28**2) / 169e9)
RHO, W, P_Y = 1350.0, 0.2, 35.3e6
MASS = float(tn.sphere_mass(R, RHO))
RTOL = 1e-10


def _law(p_y=P_Y, detachment="displacement", radius=R, w=W):
    return PlasticJKRSphere(radius, w, E_STAR, p_y, detachment)


@pytest.mark.parametrize("detachment", ["displacement", "load"])
@pytest.mark.parametrize("speed", [1.2, 2.0, 20.0])
def test_first_bounce_restitution_is_thornton_ning(speed, detachment):
    run = single_impact(_law(detachment=detachment), MASS, 0.0, speed, RTOL)
    expected = float(tn.restitution(speed, R, W, E_STAR, RHO, P_Y, detachment))
    assert run.status == "escaped"
    assert run.bounces[0].restitution == pytest.approx(expected, rel=1e-6)
    assert run.audit["max_relative_error"] < 1e-6


def test_plastic_loss_and_flattening_are_thornton_ning():
    """Booked loss and the flattened radius R_p, delta_p of the law equal the closed form's."""
    speed = 20.0
    law = _law()
    run = single_impact(law, MASS, 0.0, speed, RTOL)
    ie = tn.impact(speed, R, W, E_STAR, RHO, P_Y)
    b = run.bounces[0]
    assert b.energy_booked == pytest.approx(float(ie.plastic_loss[0] + ie.adhesive_loss[0]), rel=1e-6)
    diag = law.diagnostics()
    assert diag["plastic_radius"] == pytest.approx(float(ie.plastic_radius[0]), rel=1e-6)
    assert diag["plastic_approach"] == pytest.approx(float(ie.plastic_approach[0]), rel=1e-5)
    assert b.peak_force == pytest.approx(float(ie.max_force[0]), rel=1e-6)


def test_done_when_case_loses_a_large_share_and_captures_faster():
    """Restitution at 20 m/s far below the elastic JKR value; capture velocity above the elastic one."""
    elastic = single_impact(JKRSphere(R, W, E_STAR), MASS, 0.0, 20.0, RTOL).bounces[0].restitution
    plastic = single_impact(_law(), MASS, 0.0, 20.0, RTOL).bounces[0].restitution
    loop = float(ref.loop_area(R, W, E_STAR))
    assert elastic == pytest.approx(math.sqrt(1.0 - loop / (0.5 * MASS * 400.0)), rel=1e-8)
    assert elastic > 0.999 and plastic < 0.5
    v_el = float(tn.capture_velocity_elastic(R, W, E_STAR, RHO))
    v_tn = float(tn.capture_velocity(R, W, E_STAR, RHO, P_Y))
    esc = escape_velocity(_law(), MASS, 0.0, 0.5 * v_el, 2.0 * v_tn, rel_tol=1e-4, rtol=RTOL)
    assert esc["lower"] <= v_tn * (1 + 1e-6) and esc["upper"] >= v_tn * (1 - 1e-6)
    assert esc["escape_velocity"] > 1.5 * v_el


def test_second_impact_reloads_elastically_on_the_flattened_radius():
    """A slower second impact on the flattened spot stays below delta*: elastic JKR on R_p, shifted by delta_p.

    Its restitution is then sqrt(1 - W_loop(R_p) / (m v^2/2)) and it dissipates no plasticity."""
    law = _law()
    first = single_impact(law, MASS, 0.0, 20.0, RTOL)
    r_p, d_p = law.diagnostics()["plastic_radius"], law.diagnostics()["plastic_approach"]
    run = simulate(law, MASS, 0.0, impact_velocity=2.0, settings=DriverSettings(rtol=RTOL, max_bounces=1))
    ke = 0.5 * MASS * 4.0
    expected = math.sqrt(1.0 - float(ref.loop_area(r_p, W, E_STAR)) / ke)
    assert first.bounces[0].restitution < 0.5
    assert run.bounces[0].restitution == pytest.approx(expected, rel=1e-6)
    assert law.diagnostics()["plastic_radius"] == r_p and law.diagnostics()["plastic_approach"] == d_p
    assert law.diagnostics()["impacts_yielded"] == 1
    # it met the flattened spot at delta_p: the deepest approach is delta_p + the JKR approach on R_p
    a_max = float(ref.radius_from_approach(run.bounces[0].max_penetration - d_p, r_p, W, E_STAR))
    assert 0.5 * MASS * 4.0 == pytest.approx(float(ref.energy_from_radius(a_max, r_p, W, E_STAR)), rel=1e-6)


def test_forget_history_restores_the_virgin_sphere():
    law = _law()
    single_impact(law, MASS, 0.0, 20.0, RTOL)
    law.forget_history()
    assert law.diagnostics()["plastic_radius"] == R and law.diagnostics()["plastic_approach"] == 0.0


def test_restitution_falls_with_speed_above_yield_as_v_to_minus_quarter():
    """Above the yield velocity, e(v) falls; at high speed as v^-1/4 (Johnson 1985 §11.5; Thornton 1997)."""
    p_y, w = 60e6, 0.01                           # weaker adhesion: a finite yield velocity (0.66 m/s)
    speeds = np.array([2.0, 6.0, 20.0, 60.0])
    v_y = float(tn.yield_velocity(p_y, R, w, E_STAR, RHO))
    assert v_y < speeds[0]
    e = [single_impact(_law(p_y, w=w), MASS, 0.0, float(v), RTOL).bounces[0].restitution for v in speeds]
    closed = tn.restitution(speeds, R, w, E_STAR, RHO, p_y)
    np.testing.assert_allclose(e, closed, rtol=1e-6)
    assert np.all(np.diff(e) < 0.0)
    slope = math.log(e[-1] / e[-2]) / math.log(speeds[-1] / speeds[-2])
    assert slope == pytest.approx(-0.25, abs=0.01)


def test_bad_limiting_pressure_names_the_key():
    p_a = float(tn.adhesive_stress_scale(R, W, E_STAR))
    with pytest.raises(InputError, match="limiting_pressure"):
        _law(p_y=0.5 * p_a)
    with pytest.raises(InputError, match="limiting_pressure"):
        _law(p_y=2.0 * E_STAR)


# ----------------------------------------------------------------------------- scenes
def _scene(hardness=P_Y, **overrides):
    """The issue's sphere as a scene: hardness 35.3 MPa (= the limiting contact pressure) on the body; the
    substrate is silicon, E = 169 GPa (the <110> modulus, Hopcroft et al., JMEMS 19 (2010) 229), nu = 0.28."""
    from continuum.scene import resolve_scene
    table = {"name": "plastic_sphere", "impact_velocity": 20.0, "contact": "smooth",
             "body": {"shape": "sphere", "radius": R, "density": RHO},
             "surfaces": {"work_of_adhesion": W,
                          "body": {"youngs_modulus": 1.2e9, "poisson_ratio": 0.3},
                          "substrate": {"youngs_modulus": 169e9, "poisson_ratio": 0.28}},
             "environment": {"gravity": 0.0}, "physics": {"adhesion_law": "jkr"},
             "numerics": {"max_bounces": 1}}
    if hardness is not None:
        table["surfaces"]["body"]["hardness"] = hardness
    return resolve_scene(table=table, overrides=overrides or None)


def test_scene_runs_the_plastic_law_when_faster_than_the_yield_velocity():
    from continuum.dynamics.impact import run_impact
    result = run_impact(_scene()).to_dict()
    plastic = result["models"]["plasticity"]
    assert plastic["used"] and plastic["decided_by"] == "yield_velocity"
    assert plastic["limiting_pressure"] == P_Y and plastic["from_key"] == "surfaces.body.hardness"
    assert plastic["impact_speed"] > plastic["yield_velocity"]
    assert result["models"]["contact_law"]["name"] == "plastic_jkr_sphere"
    e = result["bounces"][0]["restitution"]
    assert e == pytest.approx(float(tn.restitution(20.0, R, W, E_STAR, RHO, P_Y)), rel=1e-6)


def test_scene_without_yield_key_stays_elastic_and_says_why():
    from continuum.dynamics.impact import run_impact
    result = run_impact(_scene(hardness=None)).to_dict()
    plastic = result["models"]["plasticity"]
    assert not plastic["used"] and plastic["decided_by"] == "yield_strength"
    assert result["models"]["contact_law"]["name"] == "jkr_sphere"


def test_softer_partner_sets_the_limiting_pressure():
    """A yield strength on the substrate (p_y = 2.8 Y) below the body's hardness decides."""
    from continuum.model.decisions import plasticity_decision
    from continuum.model.regime import regime_of
    scene = _scene(**{"surfaces.substrate.yield_strength": 12e6}).scene
    d = plasticity_decision(scene, regime_of(scene, 20.0), "jkr")
    assert d.from_key == "surfaces.substrate.yield_strength"
    assert d.limiting_pressure == pytest.approx(tn.TABOR_CONSTRAINT_FACTOR * 12e6)


@pytest.mark.parametrize("key,value", [("surfaces.body.yield_strength", 1.1e6), ("surfaces.body.hardness", 2e9)])
def test_scene_rejects_a_limiting_pressure_out_of_range_naming_the_key(key, value):
    """Below the adhesive stress scale (the contact would yield on snap-in), or above E*."""
    from continuum.scene import SceneError
    with pytest.raises(SceneError) as err:
        _scene(hardness=None, **{key: value})
    assert err.value.key == key and f"{key} = " in str(err.value) and "\n" not in str(err.value)


def test_plasticity_on_needs_a_yield_key():
    from continuum.scene import SceneError
    with pytest.raises(SceneError) as err:
        _scene(hardness=None, **{"physics.plasticity": "on"})
    assert err.value.key == "physics.plasticity"


def test_capture_velocity_size_exponent_departs_from_minus_five_sixths_where_yield_sets_in():
    """Simulated capture velocities (escape bisection) of one material, p_y = 100 MPa: large spheres capture
    before they yield, V ~ R^-5/6 (Thornton & Ning's elastic V_s); small ones yield first (the adhesive stress
    scale grows as R^-1/3) and the exponent steepens to the closed form's."""
    p_y = 100e6

    def capture(radius):
        mass = float(tn.sphere_mass(radius, RHO))
        v_el = float(tn.capture_velocity_elastic(radius, W, E_STAR, RHO))
        law = PlasticJKRSphere(radius, W, E_STAR, p_y)
        return escape_velocity(law, mass, 0.0, 0.5 * v_el, 3.0 * v_el, rel_tol=1e-5, rtol=RTOL)["escape_velocity"]

    def exponent(r1, r2, v1, v2):
        return math.log(v2 / v1) / math.log(r2 / r1)

    large = exponent(2e-6, 4e-6, capture(2e-6), capture(4e-6))
    small = exponent(0.25e-6, 0.5e-6, capture(0.25e-6), capture(0.5e-6))
    closed = exponent(0.25e-6, 0.5e-6, *(tn.capture_velocity(r, W, E_STAR, RHO, p_y) for r in (0.25e-6, 0.5e-6)))
    assert large == pytest.approx(-5.0 / 6.0, abs=1e-4)
    assert small == pytest.approx(closed, abs=1e-4)
    assert small < -5.0 / 6.0 - 0.2


def test_bounces_under_gravity_meet_the_flattened_spot():
    """Thrown up again, the sphere falls back onto its flattened spot (the jump onto it is a time event of the law):
    every later impact, slower than the first, is elastic JKR on R_p and loses one R_p loop."""
    law = _law()
    run = simulate(law, MASS, 9.80665, impact_velocity=20.0, settings=DriverSettings(rtol=RTOL, max_bounces=4,
                                                                                   max_time=100.0))
    assert run.status == "max_bounces" and len(run.bounces) == 4
    r_p = law.diagnostics()["plastic_radius"]
    loop = float(ref.loop_area(r_p, W, E_STAR))
    assert run.bounces[0].restitution == pytest.approx(float(tn.restitution(20.0, R, W, E_STAR, RHO, P_Y)), rel=1e-6)
    for b in run.bounces[1:]:
        assert b.restitution == pytest.approx(math.sqrt(1.0 - loop / (0.5 * MASS * b.v_impact**2)), rel=1e-6)
    assert law.diagnostics()["impacts_yielded"] == 1
    assert run.audit["max_relative_error"] < 1e-6


@pytest.mark.parametrize("speed,beyond", [(2.0, False), (50.0, True)])
def test_the_sphere_reports_its_contact_radius_against_the_laws_range(speed, beyond):
    """a*/R at the deepest state is the closed form's (the law's own flattening) and is flagged beyond the
    small-strain bound: 2 m/s stays inside it, 50 m/s (a*/R ~ 0.6) does not."""
    law = _law()
    single_impact(law, MASS, 0.0, speed, RTOL)
    diag = law.diagnostics()
    assert diag["max_contact_radius_ratio"] == pytest.approx(
        tn.contact_radius_ratio(speed, R, W, E_STAR, RHO, P_Y), rel=1e-6)
    assert diag["beyond_law_range"] is beyond
