"""Adhesive elastic-plastic summits (continuum.rough.plastic_summits, continuum.laws.plastic_rough) against closed
forms and their own limits.

References independent of the module's sums: the JKR closed forms (`continuum.reference.jkr`), the Thornton-Ning
closed-form impact of one sphere (`continuum.reference.thornton_ning.impact`: a quadratic for the maximum approach,
the JKR energy integrals), scipy's adaptive quadrature of the GW integral, the tabulated elastic GW surface
(`GWBranchSurface` with JKR summits), and the driver's energy audit (the motion integrated at rtol 1e-9 against
the losses the law books from its own terms).
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from continuum.dynamics.driver import DriverSettings, simulate
from continuum.laws.plastic_rough import PlasticGWPunch, PlasticGWRoller, PlasticSummitsPunch
from continuum.reference import jkr
from continuum.reference import thornton_ning as tn
from continuum.rough.branch_laws import make_summit_law
from continuum.rough.gw_branches import GWBranchSurface
from continuum.rough.plastic_summits import PlasticGWSurface, PlasticSummitLaw, RollerFootprint
from continuum.rough.summits import SummitStatistics

BETA, W, E = 1e-6, 0.1, 1e11            # summit tip radius (m), work of adhesion (J/m^2), contact modulus (Pa)
P_Y = 3e9                                # limiting contact pressure (Pa): yield approach ~2.2 nm
SIGMA, DENSITY, ZMAX = 5e-9, 1e13, 4.0   # summit heights rms (m), summits per m^2, truncation (sigma)
AREA, MASS, SPEED = 1e-8, 1e-9, 0.05     # punch: nominal area (m^2), mass (kg), impact speed (m/s)
SETTINGS = DriverSettings(rtol=1e-9, max_bounces=1)


def _punch(p_y):
    return PlasticGWPunch(PlasticGWSurface(PlasticSummitLaw(BETA, W, E, p_y), SIGMA, DENSITY, ZMAX), AREA)


# ----------------------------------------------------------------------------- (a) p_y -> inf is elastic JKR
def test_infinite_limiting_pressure_is_the_jkr_summit():
    law = PlasticSummitLaw(BETA, W, E, math.inf)
    dc = float(jkr.critical_approach(BETA, W, E))
    delta = np.linspace(-dc, 20 * dc, 301)
    f, u = law.branch(delta, np.maximum(delta, 30 * dc))
    pc = 1.5 * math.pi * W * BETA
    # the same closed form reached through the contact radius: round-off apart
    np.testing.assert_allclose(f, jkr.force_from_approach(delta, BETA, W, E), rtol=1e-12, atol=1e-12 * pc)
    np.testing.assert_allclose(u, jkr.energy_from_approach(delta, BETA, W, E), rtol=1e-12, atol=1e-12 * dc * pc)
    np.testing.assert_array_equal(law.plastic_work(delta), 0.0)
    np.testing.assert_allclose(law.loop_energy(delta), jkr.loop_area(BETA, W, E), rtol=1e-12)
    # a finite p_y that the summit never reaches gives the same numbers bit for bit
    high = PlasticSummitLaw(BETA, W, E, 0.5 * E)
    assert high.yield_approach > delta[-1]
    np.testing.assert_array_equal(high.branch(delta, delta)[0], law.branch(delta, delta)[0])


def test_elastic_mean_field_is_the_gw_jkr_surface():
    """p_y = inf: the mean field equals the tabulated elastic GW surface (threshold zeta = d_c for JKR summits)
    within that surface's table error, and adaptive quadrature of the JKR closed form to 1e-7."""
    surf = PlasticGWSurface(PlasticSummitLaw(BETA, W, E, math.inf), SIGMA, DENSITY, ZMAX)
    stats = SummitStatistics(SIGMA, DENSITY, BETA)
    elastic = GWBranchSurface(stats, make_summit_law("jkr", BETA, W, E, delta_max=10 * SIGMA), z_max=ZMAX)
    scale = DENSITY * 1.5 * math.pi * W * BETA
    for depth, back in ((1.0, 0.0), (2.5, 0.0), (2.5, 0.5), (3.0, 1.2)):
        d_c = surf.z_top - depth * SIGMA
        d = d_c + back * SIGMA
        p, energy, _ = surf.state(d, d_c, d_c)
        assert abs(p - float(elastic.pressure(d, d_c))) < 2e-5 * max(abs(p), scale)
        assert abs(energy - float(elastic.energy(d, d_c))) < 2e-5 * max(abs(energy), scale * SIGMA)
        # independent: quad over summit heights of the JKR closed form (attached: met, z >= d_c, and above the fold)
        dc = float(jkr.critical_approach(BETA, W, E))

        def f(z):
            return float(jkr.force_from_approach(z - d, BETA, W, E)) * math.exp(-0.5 * (z / SIGMA) ** 2)

        lo = max(d_c, d - dc)
        ref, _ = integrate.quad(f, lo, surf.z_top, epsabs=0, epsrel=1e-11, limit=400)
        ref *= DENSITY / (math.sqrt(2 * math.pi) * SIGMA)
        assert abs(p - ref) < 1e-7 * max(abs(ref), scale * 1e-3)


# ----------------------------------------------------------------------------- (b) one summit = Thornton-Ning
@pytest.mark.parametrize("speed", [3.0, 10.0, 30.0])
def test_one_summit_is_the_thornton_ning_sphere(speed):
    """A summit loaded to delta* by an impact of a sphere of the summit's radius: flattened radius, residual
    indentation, force at the maximum, plastic loss and unloading loop are Thornton-Ning's closed forms."""
    rho = 2330.0
    ref = tn.impact(speed, BETA, W, E, rho, P_Y)
    assert ref.yielded[0]
    law = PlasticSummitLaw(BETA, W, E, P_Y)
    d_star = law.yield_approach + (ref.max_force[0] - law.yield_force) / law.plastic_slope
    r_p, d_p = law.flattening(d_star)
    assert r_p == pytest.approx(ref.plastic_radius[0], rel=1e-11)
    assert d_p == pytest.approx(ref.plastic_approach[0], rel=1e-9)
    f, stored = law.branch(d_star, d_star)
    assert f == pytest.approx(ref.max_force[0], rel=1e-11)
    assert law.plastic_work(d_star) == pytest.approx(ref.plastic_loss[0], rel=1e-9)
    assert law.loop_energy(d_star) == pytest.approx(ref.adhesive_loss[0], rel=1e-9)
    # loading: the force on the plastic line, F_y + pi p_y beta (delta - delta_y) (Thornton & Ning eq. for F_p)
    a_y = float(tn.yield_radius(P_Y, BETA, W, E))
    delta = law.yield_approach + np.linspace(0.0, 1.0, 7) * (d_star - law.yield_approach)
    line = float(jkr.force_from_radius(a_y, BETA, W, E)) + math.pi * P_Y * BETA * (delta - law.yield_approach)
    np.testing.assert_allclose(law.branch(delta, delta)[0], line, rtol=1e-10)
    # unloading: JKR of R_p shifted by delta_p, through (delta*, F*), letting go at delta_p - delta_c(R_p)
    back = np.linspace(d_p - float(jkr.critical_approach(r_p, W, E)), d_star, 9)
    np.testing.assert_allclose(law.branch(back, d_star)[0], jkr.force_from_approach(back - d_p, r_p, W, E), rtol=1e-12)


def test_summit_sets_are_one_interval_in_height():
    """The mean field's attached summits are one interval because g(u) = u - delta_p and h = g + delta_c(R_p)
    increase with the deepest approach u."""
    surf = PlasticGWSurface(PlasticSummitLaw(BETA, W, E, P_Y), SIGMA, DENSITY, ZMAX)
    u = np.linspace(0.0, 10 * SIGMA, 2001)
    assert np.all(np.diff(surf.recovery(u)) > 0.0)
    assert np.all(np.diff(surf.hold(u)) > 0.0)


# ----------------------------------------------------------------------------- (c), (d) impacts with the audit
def test_plastic_summits_dissipate_more_and_the_audit_closes():
    runs = {}
    for p_y in (math.inf, P_Y):
        punch = _punch(p_y)
        run = simulate(punch, MASS, 0.0, impact_velocity=SPEED, settings=SETTINGS)
        assert run.status == "escaped"
        b = run.bounces[0]
        plastic = punch.diagnostics()["plastic_work"]
        # the motion's loss is the booked plastic work plus the loops of the summits that let go
        assert run.audit["max_relative_error"] < 1e-6
        assert b.energy_lost == pytest.approx(b.energy_booked, rel=1e-5)
        runs[p_y] = (b.energy_lost, plastic)
    (lost_el, w_el), (lost_pl, w_pl) = runs[math.inf], runs[P_Y]
    assert w_el == 0.0 and w_pl > 0.0
    assert lost_pl > 2.0 * lost_el
    assert lost_pl > w_pl


def test_second_impact_meets_the_flattened_summits():
    punch = _punch(P_Y)
    first = simulate(punch, MASS, 0.0, impact_velocity=SPEED, settings=SETTINGS)
    w1 = punch.diagnostics()["plastic_work"]
    punch.reset()                       # a new contact on the same spot: the flattening stays
    second = simulate(punch, MASS, 0.0, impact_velocity=SPEED, settings=SETTINGS)
    w2 = punch.diagnostics()["plastic_work"]
    lost1, lost2 = first.bounces[0].energy_lost, second.bounces[0].energy_lost
    assert second.audit["max_relative_error"] < 1e-6
    assert lost2 < 0.5 * lost1
    assert lost2 == pytest.approx(second.bounces[0].energy_booked, rel=1e-5)
    assert w2 - w1 < 0.5 * w1           # little new plastic work: the summits are already flattened
    punch.forget_history()              # a fresh spot: the first impact again
    again = simulate(punch, MASS, 0.0, impact_velocity=SPEED, settings=SETTINGS)
    assert again.bounces[0].energy_lost == pytest.approx(lost1, rel=1e-9)


def test_discrete_summits_carry_their_flattening():
    rng = np.random.default_rng(1)
    heights = rng.normal(0.0, SIGMA, 40)
    lost, yielded = {}, {}
    for p_y in (math.inf, P_Y):
        punch = PlasticSummitsPunch(PlasticSummitLaw(BETA, W, E, p_y), heights)
        for k in range(2):
            run = simulate(punch, 1e-11, 0.0, impact_velocity=0.1, settings=SETTINGS)
            b = run.bounces[0]
            assert run.audit["max_relative_error"] < 1e-6
            assert b.energy_lost == pytest.approx(b.energy_booked, rel=1e-4)
            lost[p_y, k] = b.energy_lost
            yielded[p_y] = punch.diagnostics()["summits_yielded"]
            punch.reset()
    assert yielded[math.inf] == 0 and yielded[P_Y] > 0
    assert lost[math.inf, 1] == pytest.approx(lost[math.inf, 0], rel=1e-9)    # elastic: no memory
    assert lost[P_Y, 0] > 2.0 * lost[math.inf, 0]
    assert lost[P_Y, 1] < 0.5 * lost[P_Y, 0]


def test_limiting_pressure_below_the_adhesive_stress_is_refused():
    p_a = float(tn.adhesive_stress_scale(BETA, W, E))
    with pytest.raises(Exception, match="limiting_pressure"):
        PlasticSummitLaw(BETA, W, E, 0.5 * p_a)


# ----------------------------------------------------------------------------- (e) auto by the plasticity index
@pytest.mark.parametrize("hardness,yields", [(8.3e9, False), (0.25e9, True)])
def test_auto_decides_summit_plasticity_by_the_plasticity_index(hardness, yields):
    """The paper's silica set with silicon's hardness (Knoop 850 kg/mm^2 = 8.3 GPa, K. E. Petersen, Proc. IEEE 70
    (1982) 420): psi well below 0.6, elastic summits; a soft metal's hardness (0.25 GPa): psi > 1. psi is recorded
    beside the decision and is Greenwood-Williamson's (E*/H) sqrt(sigma/beta)."""
    from pathlib import Path

    from continuum.model.decisions import plasticity_decision
    from continuum.model.regime import regime_of, summit_e_star
    from continuum.scene import resolve_scene

    scene = resolve_scene(Path(__file__).resolve().parents[2] / "inputs" / "scenes" / "rough_silica.toml",
                          overrides={"surfaces.substrate.hardness": hardness}).scene
    rec = plasticity_decision(scene, regime_of(scene), "jkr").record()
    rough = scene.surfaces.roughness
    psi = summit_e_star(scene) / hardness * math.sqrt(rough.sigma / rough.summit_radius)
    assert rec["plasticity_index"] == pytest.approx(psi, rel=1e-12)
    assert rec["decided_by"] == "plasticity_index" and rec["summits_yield"] is yields
    assert (psi > 1.0) if yields else (psi < 0.6)
    assert rec["used"] is yields     # JKR summits over a rigid substrate: the plastic mean field can run
    blocked = plasticity_decision(scene, regime_of(scene), "jkr", half_space=True).record()
    assert blocked["used"] is False and blocked["summits_yield"] is yields
    assert ("half-space roller carries elastic summits only" in blocked["why"]) is yields


@pytest.mark.parametrize("mode,names", [("mean_field", ("rough_roller_gw_jkr_rigid", "rough_roller_gw_plastic_rigid")),
                                        ("discrete", ("rough_roller_discrete_jkr", "rough_roller_discrete_plastic"))])
def test_rough_scene_runs_plastic_summits_where_they_yield(mode, names):
    """The paper's silica roller with a soft hardness: the plastic roller runs (recorded) and its first impact loses
    more of the impact energy than the elastic summits' (silicon's hardness) do, in the mean field and on one
    realisation of discrete summits."""
    from pathlib import Path

    from continuum.dynamics.impact import run_impact
    from continuum.scene import resolve_scene

    path = Path(__file__).resolve().parents[2] / "inputs" / "scenes" / "rough_silica.toml"
    out = {}
    for hardness in (8.3e9, 0.25e9):
        result = run_impact(resolve_scene(path, overrides={"surfaces.substrate.hardness": hardness,
                                                              "surfaces.roughness.mode": mode,
                                                              "physics.half_space": "off",
                                                              "numerics.max_bounces": 1})).to_dict()
        assert result["energy_audit"]["max_relative_error"] < 1e-5
        out[hardness] = result
    elastic, plastic = out[8.3e9], out[0.25e9]
    assert elastic["models"]["contact_law"]["name"] == names[0]
    assert plastic["models"]["contact_law"]["name"] == names[1]
    assert plastic["models"]["plasticity"]["used"] and plastic["models"]["plasticity"]["plasticity_index"] > 1.0
    assert plastic["bounces"][0]["energy_booked"] > 2.0 * elastic["bounces"][0]["energy_booked"]


# ----------------------------------------------------------------------------- rigid roller on plastic summits
R_ROLLER, L_ROLLER, M_ROLLER, V_ROLLER = 1e-3, 1e-3, 1e-8, 0.01


def _roller(p_y):
    return PlasticGWRoller(PlasticSummitLaw(BETA, W, E, p_y), SIGMA, DENSITY, ZMAX, R_ROLLER, L_ROLLER)


@pytest.mark.parametrize("h,h_c,h_p", [(-3e-9, -3e-9, -3e-9), (-1e-9, -3e-9, -3e-9), (-1e-9, -2e-9, -4e-9),
                                       (-0.5e-9, -2e-9, -4e-9)])
def test_roller_footprint_is_the_mean_field_integrated_across_the_footprint(h, h_c, h_p):
    """The footprint kernel K(z) against the per-area mean field integrated over x by adaptive quadrature, with the
    separations d + x^2/2R (attached summits end where z_max - d_p(x) = u_a)."""
    law = PlasticSummitLaw(BETA, W, E, P_Y)
    area = PlasticGWSurface(law, SIGMA, DENSITY, ZMAX)
    foot = RollerFootprint(law, SIGMA, DENSITY, ZMAX, R_ROLLER, L_ROLLER)
    top = area.z_top
    shift = lambda x: x * x / (2.0 * R_ROLLER)                                       # noqa: E731
    u_a = max(*area.bounds(top + h, top + h_c, top + h_p), 0.0)
    x_end = math.sqrt(2.0 * R_ROLLER * (-h_p - u_a))
    for n, what in enumerate(("pressure", "energy")):
        ref, _ = integrate.quad(lambda x: area.state(top + h + shift(x), top + h_c + shift(x), top + h_p + shift(x))[n],
                                0.0, x_end, epsabs=0, epsrel=1e-12, limit=400)
        got = foot.state(top + h, top + h_c, top + h_p)[n]
        assert got == pytest.approx(2.0 * L_ROLLER * ref, rel=1e-6), what


def test_elastic_roller_is_the_rigid_gw_jkr_roller():
    """p_y = inf: the restitution and loss of the project's rigid roller on tabulated GW/JKR summits."""
    from continuum.laws.rough_rigid import RigidRoughRoller
    from continuum.rough.gw import GWJKRSurface
    ours = simulate(_roller(math.inf), M_ROLLER, 0.0, impact_velocity=V_ROLLER, settings=SETTINGS).bounces[0]
    surface = GWJKRSurface(SummitStatistics(SIGMA, DENSITY, BETA), W, E, z_max=ZMAX)
    theirs = RigidRoughRoller(surface, R_ROLLER, L_ROLLER)
    ref = simulate(theirs, M_ROLLER, 0.0, impact_velocity=V_ROLLER, settings=SETTINGS).bounces[0]
    assert ours.restitution == pytest.approx(ref.restitution, abs=1e-7)
    assert ours.energy_lost == pytest.approx(ref.energy_lost, rel=1e-5)
    assert ours.max_penetration == pytest.approx(ref.max_penetration, rel=1e-6)


def test_plastic_roller_dissipates_more_and_remembers_the_spot():
    elastic = simulate(_roller(math.inf), M_ROLLER, 0.0, impact_velocity=V_ROLLER, settings=SETTINGS)
    roller = _roller(P_Y)
    first = simulate(roller, M_ROLLER, 0.0, impact_velocity=V_ROLLER, settings=SETTINGS)
    roller.reset()
    second = simulate(roller, M_ROLLER, 0.0, impact_velocity=V_ROLLER, settings=SETTINGS)
    for run in (elastic, first, second):
        assert run.audit["max_relative_error"] < 1e-6
        assert run.bounces[0].energy_lost == pytest.approx(run.bounces[0].energy_booked, rel=1e-5)
    lost = [r.bounces[0].energy_lost for r in (elastic, first, second)]
    assert lost[1] > 2.0 * lost[0] and lost[2] < 0.5 * lost[1]


def test_auto_takes_plastic_summits_when_the_impact_reaches_their_yield_approach():
    """psi < 0.6 (a hard surface) but an impact estimated deeper than a summit's yield approach delta_y (JKR centre
    pressure = p_y at a_y, Thornton & Ning 1998) yields the tallest summits: 'auto' takes them, decided by the
    depth; shallower, it stays elastic."""
    from pathlib import Path

    from continuum.model.decisions import plasticity_decision
    from continuum.model.regime import regime_of, summit_e_star
    from continuum.scene import resolve_scene

    hardness = 3.5e9
    scene = resolve_scene(Path(__file__).resolve().parents[2] / "inputs" / "scenes" / "rough_silica.toml",
                          overrides={"surfaces.substrate.hardness": hardness}).scene
    rough, w, e_s = scene.surfaces.roughness, scene.surfaces.interface_work_of_adhesion, summit_e_star(scene)
    a_y = float(tn.yield_radius(hardness, rough.summit_radius, w, e_s))
    d_y = float(jkr.approach_from_radius(a_y, rough.summit_radius, w, e_s))
    deep = plasticity_decision(scene, regime_of(scene), "jkr", depth=1.5 * d_y).record()
    shallow = plasticity_decision(scene, regime_of(scene), "jkr", depth=0.5 * d_y).record()
    assert deep["plasticity_index"] < 0.6 and deep["summit_yield_approach"] == pytest.approx(d_y, rel=1e-12)
    assert deep["used"] and deep["decided_by"] == "estimated_depth" and deep["estimated_depth"] == 1.5 * d_y
    assert not shallow["used"] and not shallow["summits_yield"] and shallow["decided_by"] == "plasticity_index"


@pytest.mark.parametrize("speed", [3.0, 10.0])
def test_one_discrete_summit_in_the_driver_is_the_thornton_ning_impact(speed):
    """A punch on one summit is a sphere of the summit's radius hitting a flat: the driver's restitution and booked
    loss equal Thornton-Ning's closed-form impact (a sphere of that mass), to the integrator's tolerance."""
    rho = 2330.0
    mass = float(tn.sphere_mass(BETA, rho))
    punch = PlasticSummitsPunch(PlasticSummitLaw(BETA, W, E, P_Y), [0.0])
    run = simulate(punch, mass, 0.0, impact_velocity=speed, settings=DriverSettings(rtol=1e-10, max_bounces=1))
    ref = tn.impact(speed, BETA, W, E, rho, P_Y)
    b = run.bounces[0]
    assert ref.yielded[0] and run.status == "escaped"
    assert b.restitution == pytest.approx(ref.restitution[0], rel=1e-6)
    assert b.energy_booked == pytest.approx(ref.plastic_loss[0] + ref.adhesive_loss[0], rel=1e-9)


@pytest.mark.parametrize("hardness,name", [(8.3e9, "rough_roller_discrete_jkr"),
                                           (0.25e9, "rough_roller_discrete_plastic")])
def test_ensemble_members_take_the_scenes_summit_plasticity(hardness, name):
    """An ensemble member's realisation runs plastic summits exactly where the mean field does."""
    from pathlib import Path

    from continuum.dynamics.ensemble_run import member_law, member_plan
    from continuum.model.regime import first_impact_speed
    from continuum.scene import resolve_scene

    resolved = resolve_scene(Path(__file__).resolve().parents[2] / "inputs" / "scenes" / "rough_silica.toml",
                             overrides={"surfaces.substrate.hardness": hardness, "physics.half_space": "off"})
    scene = resolved.scene
    plan = member_plan(scene, first_impact_speed(scene))
    _, law = member_law(scene, 3, plan)
    assert law.name == name
