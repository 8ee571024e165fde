"""Thornton-Ning's construction on every summit law (continuum.rough.plastic_branches) against closed forms, the
elastic laws it must reduce to, and the driver's energy audit.

Independent references: JKR's Thornton-Ning closed forms (`continuum.rough.plastic_summits.PlasticSummitLaw`, itself
checked against `continuum.reference.thornton_ning`), DMT's closed form (R_p from a quadratic), the elastic
tabulated laws (`continuum.rough.branch_laws`), and the driver's audit (work done by the contact force, integrated
with the motion, against stored energy plus the losses the law books from its own terms).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from continuum.dynamics.driver import DriverSettings, simulate
from continuum.laws.plastic_rough import PlasticSummitsPunch
from continuum.rough.branch_laws import make_summit_law
from continuum.rough.plastic_branches import NODE_RATIO, PlasticBranchSummitLaw
from continuum.rough.plastic_summits import PlasticSummitLaw

# the calibrated set's summits: silicon E*, MD-measured work of adhesion and range, hardness 11 GPa
BETA, W, E, P_Y, Z0, SIGMA = 0.2e-6, 0.192, 89e9, 11e9, 0.207e-9, 6e-9
DMAX = 30 * SIGMA


@pytest.fixture(scope="module")
def md():
    return PlasticBranchSummitLaw("maugis_dugdale", BETA, W, E, P_Y, z0=Z0, delta_max=DMAX)


@pytest.mark.parametrize("name", ["maugis_dugdale", "dmt", "jkr"])
def test_infinite_hardness_is_the_elastic_law(name):
    """p_y = inf: no summit yields and force, energy and jumps are the elastic law's own (the same table, scale 1:
    equal to rounding, far inside the 1e-7 asked)."""
    law = PlasticBranchSummitLaw(name, BETA, W, E, math.inf, z0=Z0, delta_max=DMAX)
    ref = make_summit_law(name, BETA, W, E, z0=Z0, delta_max=DMAX)
    d = np.linspace(-1.5e-9, 20e-9, 301)
    r_p, d_p = law.flattening(d)
    assert np.all(r_p == BETA) and np.all(d_p == 0.0)
    for branch, att in (("retreat", True), ("approach", False)):
        f, u = law.state(d, np.maximum(d, 0.0), np.full(d.shape, att))
        np.testing.assert_allclose(f, ref.force(d, branch), rtol=1e-12, atol=1e-12 * ref.pull_off_force)
        np.testing.assert_allclose(u, ref.energy(d, branch), rtol=1e-12, atol=1e-30)
    r = np.array([BETA])
    assert law.jump_in(r)[0] == pytest.approx(ref.delta_in, rel=1e-12, abs=1e-30)
    assert law.jump_out(r)[0] == pytest.approx(ref.delta_out, rel=1e-12, abs=1e-30)
    assert (law.in_switch(r) + law.out_switch(r))[0] == pytest.approx(ref.loop_energy, rel=1e-9, abs=1e-30)
    assert law.plastic_work(d).max() == 0.0


def test_on_jkr_it_is_thornton_ning_closed_form():
    """The construction on the tabulated JKR law equals Thornton-Ning's closed forms: yield to rounding, R_p,
    delta_p, the loop and the force to the tables' interpolation (~1e-5), the plastic work (a difference of two
    energies) to 1e-3 once it exceeds 1e-3 of the stored energy."""
    gen = PlasticBranchSummitLaw("jkr", BETA, W, E, P_Y, delta_max=DMAX)
    tn = PlasticSummitLaw(BETA, W, E, P_Y)
    assert gen.yield_radius == pytest.approx(tn.yield_radius, rel=1e-12)
    assert gen.yield_approach == pytest.approx(tn.yield_approach, rel=1e-12)
    dm = tn.yield_approach + np.array([2e-9, 1e-8, 4e-8, 1e-7])
    (rg, dg), (rc, dc) = gen.flattening(dm), tn.flattening(dm)
    np.testing.assert_allclose(rg, rc, rtol=2e-5)
    # delta_p = delta* - delta(a*; R_p) is a difference of numbers of size delta*: its error scales with delta*
    assert np.all(np.abs(dg - dc) <= 2e-5 * dc + 2e-6 * dm)
    np.testing.assert_allclose(gen.out_switch(rg), tn.loop_energy(dm), rtol=2e-5)
    np.testing.assert_allclose(gen.plastic_work(dm), tn.plastic_work(dm), rtol=1e-3)
    f, u = gen.state(dm - 1e-9, dm, True)
    fc, uc = tn.branch(dm - 1e-9, dm)
    np.testing.assert_allclose(f, fc, rtol=2e-5)
    np.testing.assert_allclose(u, uc, rtol=2e-5)


def test_on_dmt_the_flattening_is_the_quadratics_root():
    """DMT: F = 4E*a^3/(3R) - 2 pi w R, delta = a^2/R; through (a*, F*) R_p is the positive root of
    2 pi w R^2 + F* R - 4E*a*^3/3 = 0, delta_p = delta* - a*^2/R_p; yield where 2E*a/(pi beta) = p_y; no loop;
    pull-off 2 pi w R_p."""
    law = PlasticBranchSummitLaw("dmt", BETA, W, E, P_Y, delta_max=DMAX)
    a_y = math.pi * BETA * P_Y / (2.0 * E)
    assert law.yield_radius == pytest.approx(a_y, rel=1e-10)
    assert law.yield_approach == pytest.approx(a_y * a_y / BETA, rel=1e-10)
    dd = np.array([3e-9, 2e-8, 8e-8])
    a = np.sqrt(a_y**2 + BETA * dd)
    f = law.yield_force + math.pi * P_Y * BETA * dd
    r_p = (-f + np.sqrt(f * f + 4.0 * 2.0 * math.pi * W * 4.0 * E * a**3 / 3.0)) / (4.0 * math.pi * W)
    got_r, got_d = law.flattening(law.yield_approach + dd)
    np.testing.assert_allclose(got_r, r_p, rtol=2e-5)
    want_d = law.yield_approach + dd - a * a / r_p
    # linear interpolation in the 400-point D table: error ~1e-5 of delta* (a difference of numbers of that size)
    assert np.all(np.abs(got_d - want_d) <= 2e-5 * (law.yield_approach + dd))
    assert np.all(law.out_switch(got_r) + law.in_switch(got_r) == 0.0)
    np.testing.assert_allclose(law.branch_force(np.zeros(3) + 1e-18, got_r, "retreat"), -2 * math.pi * W * got_r,
                               rtol=1e-6)


def test_maugis_dugdale_yield_and_flattened_pull_off(md):
    """MD: yield where its centre pressure reaches p_y (between DMT's and JKR's criteria at this lambda); on the
    flattened radius R_p the curve is MD's own at R_p: at a tabulation radius exactly, between them the pull-off
    (the largest tension) within 1e-3 of MD built at R_p (interpolation error measured here)."""
    jkr_, dmt_ = (PlasticBranchSummitLaw(n, BETA, W, E, P_Y, delta_max=DMAX) for n in ("jkr", "dmt"))
    assert dmt_.yield_radius <= md.yield_radius <= jkr_.yield_radius
    assert md.centre_pressure(md.yield_radius, BETA) == pytest.approx(P_Y, rel=1e-9)
    for s in (NODE_RATIO, NODE_RATIO**0.5, NODE_RATIO**1.5):
        own = make_summit_law("maugis_dugdale", BETA * s, W, E, z0=Z0, delta_max=DMAX)
        r = np.full(4000, BETA * s)
        eps = np.linspace(own.delta_out, 2e-9, 4000)
        pull = -float(np.min(md.branch_force(eps, r, "retreat")))
        assert pull == pytest.approx(own.pull_off_force, rel=1e-3 if s != NODE_RATIO else 1e-9)


def test_maugis_dugdale_summits_dissipate_and_the_audit_closes(md):
    """Three MD summits under a punch: the first impact yields the tallest; the driver's audit (work of the force
    against stored + plastic work + booked jumps) closes, the loss is the booked one, and the second impact on the
    flattened summits loses less with little new plastic work."""
    heights = np.array([0.0, -2e-9, -5e-9])
    elastic = PlasticSummitsPunch(PlasticBranchSummitLaw("maugis_dugdale", BETA, W, E, math.inf, z0=Z0,
                                                         delta_max=DMAX), heights)
    punch = PlasticSummitsPunch(md, heights)
    settings = DriverSettings(rtol=1e-9, max_bounces=1)
    mass, speed = 1e-11, 0.3
    el = simulate(elastic, mass, 0.0, impact_velocity=speed, settings=settings)
    assert el.audit["max_relative_error"] < 1e-4
    lost = []
    for k in range(2):
        run = simulate(punch, mass, 0.0, impact_velocity=speed, settings=settings)
        b = run.bounces[0]
        assert run.status == "escaped"
        # MD's force jumps (snap-in, release) fall inside steps: the elastic tabulated MD summits close their audit
        # to the same ~1e-5 (the stepper's, not the law's: the law books U_A - U_R at each jump exactly)
        assert run.audit["max_relative_error"] < 1e-4
        assert b.energy_lost == pytest.approx(b.energy_booked, rel=1e-4)
        lost.append((b.energy_lost, punch.diagnostics()["plastic_work"]))
        punch.reset()
    assert punch.diagnostics()["summits_yielded"] >= 1
    assert lost[0][0] > 10.0 * el.bounces[0].energy_lost
    assert lost[1][0] < 0.5 * lost[0][0]
    assert lost[1][1] - lost[0][1] < 0.5 * lost[0][1]


def test_the_compiled_contact_is_the_python_law(md):
    """The compiled form (continuum.rough.plastic_kernel) runs the same law as the Python one: two impacts on the
    same summits, each run by both, agree in restitution to the steppers' tolerance and in the booked plastic work
    to rounding (one h_min fixes the same flattening)."""
    heights = np.array([0.0, -1.5e-9, -4e-9, -9e-9])
    out = {}
    for compiled in (True, False):
        punch = PlasticSummitsPunch(md, heights)
        settings = DriverSettings(rtol=1e-9, max_bounces=1, compiled=compiled)
        out[compiled] = []
        for _ in range(2):
            b = simulate(punch, 1e-11, 0.0, impact_velocity=0.3, settings=settings).bounces[0]
            out[compiled].append((b.restitution, b.energy_booked, punch.diagnostics()["plastic_work"]))
            punch.reset()
    for (e_c, booked_c, w_c), (e_p, booked_p, w_p) in zip(out[True], out[False]):
        assert e_c == pytest.approx(e_p, rel=1e-6)
        assert booked_c == pytest.approx(booked_p, rel=1e-5)
        assert w_c == pytest.approx(w_p, rel=1e-6)
    assert out[True][0][2] > 0.0


def test_calibrated_rough_silica_members_run_plastic_maugis_dugdale_summits_and_off_still_records_psi():
    """The calibrated set (silicon hardness, MD-measured range: Maugis-Dugdale summits, psi > 1): auto gives each
    ensemble member plastic Maugis-Dugdale summits; physics.plasticity = 'off' keeps them elastic and still
    records psi = (E*/H) sqrt(sigma/beta)."""
    from pathlib import Path

    from continuum.dynamics.ensemble_run import member_law, member_plan
    from continuum.model import plasticity_decision
    from continuum.model.regime import first_impact_speed, regime_of, summit_e_star
    from continuum.scene import resolve_scene

    path = Path(__file__).resolve().parents[2] / "inputs" / "scenes" / "rough_silica.toml"
    scene = resolve_scene(path, params="calibrated").scene
    plan = member_plan(scene, first_impact_speed(scene))
    _, law = member_law(scene, 3, plan)
    assert law.name == "rough_roller_discrete_plastic"
    assert isinstance(law.law, PlasticBranchSummitLaw) and law.law.name == "maugis_dugdale"
    off = resolve_scene(path, params="calibrated", overrides={"physics.plasticity": "off"}).scene
    rec = plasticity_decision(off, regime_of(off), "maugis_dugdale").record()
    rough = off.surfaces.roughness
    psi = summit_e_star(off) / off.surfaces.substrate.hardness * math.sqrt(rough.sigma / rough.summit_radius)
    assert not rec["used"] and rec["decided_by"] == "scene"
    assert rec["plasticity_index"] == pytest.approx(psi, rel=1e-12) and rec["plasticity_index"] > 1.0


def test_just_past_yield_the_construction_never_sharpens_a_summit_where_thornton_ning_does():
    """Within 1 nm past yield (docs/model.md, 'Just past yield'): the construction holds R_p >= beta and growing,
    delta_p >= 0 and the plastic work >= 0 and growing, on JKR and on Maugis-Dugdale. Thornton-Ning's closed forms
    on adhesive JKR summits (the reference elsewhere) dip below beta there, with a negative plastic work: the two
    forms differ by design in this band and agree from ~2 nm on (test_on_jkr_it_is_thornton_ning_closed_form)."""
    beta, w, e, p_y = 1e-6, 0.1, 1e11, 3e9                  # a JKR summit whose plastic line is the stiffer at yield
    tn = PlasticSummitLaw(beta, w, e, p_y)
    d = np.array([1e-12, 1e-11, 1e-10, 3e-10, 1e-9])
    r_c, dp_c = tn.flattening(tn.yield_approach + d)
    assert r_c[2] < beta and dp_c[2] < 0.0 and tn.plastic_work(tn.yield_approach + d[2:3])[0] < 0.0
    for law in (PlasticBranchSummitLaw("jkr", beta, w, e, p_y, delta_max=30 * SIGMA),
                PlasticBranchSummitLaw("maugis_dugdale", BETA, W, E, P_Y, z0=Z0, delta_max=DMAX)):
        dm = law.yield_approach + d
        r_p, d_p = law.flattening(dm)
        work = law.plastic_work(dm)
        assert np.all(r_p >= law.radius) and np.all(np.diff(r_p) >= 0.0)
        assert np.all(d_p >= 0.0) and np.all(work >= 0.0) and np.all(np.diff(work) > 0.0)
