"""Sphere JKR impacts: each impact loses one closed-form hysteresis loop; restitution follows from it."""
import math

import numpy as np
import pytest

from continuum.dynamics.driver import DriverSettings, simulate
from continuum.laws.jkr import JKRSphere
from continuum.reference import jkr as ref

RADIUS, W, E_STAR = 5e-6, 0.1, 37.6e9
MASS = 4 / 3 * math.pi * RADIUS**3 * 2200.0


@pytest.mark.parametrize("detachment,coefficient", [("displacement", 0.93550), ("load", 0.46201)])
def test_energy_lost_per_impact_is_one_jkr_loop(detachment, coefficient):
    law = JKRSphere(RADIUS, W, E_STAR, detachment)
    loop = coefficient * law.pull_off_force * law.delta_c
    assert law.loop_energy == pytest.approx(loop, rel=1e-4, abs=0)  # the law's loss term, checked against the notes
    v = 2.0 * law.escape_velocity(MASS)
    run = simulate(law, MASS, 0.0, impact_velocity=v)
    b = run.bounces[0]
    assert b.energy_lost == pytest.approx(float(ref.loop_area(RADIUS, W, E_STAR, detachment=detachment)),
                                          rel=1e-4, abs=0)
    assert run.audit["max_relative_error"] < 1e-6


@pytest.mark.parametrize("detachment", ["displacement", "load"])
# 1.001: slow release, turn and re-cross within one step
@pytest.mark.parametrize("ratio", [1.001, 1.02, 1.2, 2.0, 5.0, 20.0])
def test_restitution_follows_escape_velocity_law(detachment, ratio):
    law = JKRSphere(RADIUS, W, E_STAR, detachment)
    v_s = law.escape_velocity(MASS)
    v = ratio * v_s
    run = simulate(law, MASS, 0.0, impact_velocity=v)
    assert run.status == "escaped"
    assert run.bounces[0].restitution == pytest.approx(math.sqrt(1.0 - (v_s / v) ** 2), abs=1e-3)
    assert run.audit["max_relative_error"] < 1e-6


@pytest.mark.parametrize("detachment", ["displacement", "load"])
@pytest.mark.parametrize("ratio", [0.2, 0.9, 0.99])
def test_below_escape_velocity_the_sphere_sticks(detachment, ratio):
    law = JKRSphere(RADIUS, W, E_STAR, detachment)
    run = simulate(law, MASS, 0.0, impact_velocity=ratio * law.escape_velocity(MASS))
    assert run.status == "stuck" and run.stuck
    assert run.bounces[0].v_rebound == 0.0 and run.bounces[0].t_release is None
    assert run.audit["max_relative_error"] < 1e-6


def test_contact_force_starts_at_minus_eight_ninths_pull_off_and_releases_at_the_criterion():
    law = JKRSphere(RADIUS, W, E_STAR, "displacement")
    assert law.force(0.0) == pytest.approx(-8 / 9 * law.pull_off_force, rel=1e-10, abs=0)
    # The release gap delta_c is the fold of the JKR curve (a double root of the contact-radius
    # quartic): an input rounding of k eps there moves the root by ~sqrt(k eps), i.e. P by
    # 1.7 sqrt(k eps) relative (1.9e-8 for the one ulp that critical_approach's rounding can give).
    # 8 sqrt(eps) = 1.2e-7 covers ~20 eps; releasing 1e-6 delta_c early (P off by 1.7e-3) still fails.
    fold_rtol = 8 * math.sqrt(np.finfo(float).eps)
    assert law.force(law.release_gap()) == pytest.approx(-5 / 9 * law.pull_off_force, rel=fold_rtol, abs=0)
    load = JKRSphere(RADIUS, W, E_STAR, "load")
    assert load.force(load.release_gap()) == pytest.approx(-load.pull_off_force, rel=1e-10, abs=0)


def test_with_gravity_rebounds_shrink_until_the_sphere_sticks():
    law = JKRSphere(RADIUS, W, E_STAR, "displacement")
    run = simulate(law, MASS, 9.80665, impact_velocity=0.1, settings=DriverSettings(max_bounces=50))
    heights = [b.rebound_height for b in run.bounces if b.rebound_height is not None]
    assert run.status == "stuck"
    assert np.all(np.diff(heights) < 0)
    assert run.bounces[-1].v_impact < law.escape_velocity(MASS) < run.bounces[-2].v_impact
    assert run.audit["max_relative_error"] < 1e-6
