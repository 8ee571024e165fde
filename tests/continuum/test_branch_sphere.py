"""Smooth spheres on Maugis-Dugdale and DMT branches: the driver against the branches' own loop and limits.

The branch laws (`continuum.rough.branch_laws`) are tested against the closed forms in
tests/continuum/test_branch_laws.py; here the sphere law that drives them must lose exactly one tabulated loop
per impact (restitution sqrt(1 - loop / (m v^2/2))), stick below that energy, lose nothing under DMT,
and the scene must pick the law by the sphere's Tabor parameter.
"""
from __future__ import annotations

import math

import pytest

from continuum.dynamics.escape import single_impact
from continuum.laws.branch_sphere import BranchSphere
from continuum.model import regimes
from continuum.reference import jkr as jkr_ref
from continuum.reference import thornton_ning as tn

# a 100 nm silver sphere on aluminium (E* ~ 45 GPa), w = 0.5 J/m^2, z0 = 0.3 nm: Tabor mu ~ 0.6
R, W, E_STAR, RHO, Z0 = 50e-9, 0.5, 45e9, 10490.0, 0.3e-9
MASS = float(tn.sphere_mass(R, RHO))


def test_maugis_dugdale_sphere_loses_one_tabulated_loop():
    law = BranchSphere("maugis_dugdale", R, W, E_STAR, Z0)
    assert 0.1 < regimes.tabor_parameter(R, W, E_STAR, Z0) < 5.0
    loop = law.loop_energy_used
    assert loop == pytest.approx(law.law.loop_energy, rel=1e-6)     # the smooth branch keeps the table's loop
    assert 0.0 < loop < float(jkr_ref.loop_area(R, W, E_STAR))      # MD's loop is below JKR's at mu < 5
    v_s = math.sqrt(2.0 * loop / MASS)
    run = single_impact(law, MASS, 0.0, 2.0 * v_s, 1e-10)
    assert run.status == "escaped"
    assert run.bounces[0].restitution == pytest.approx(math.sqrt(0.75), rel=1e-6)
    assert run.bounces[0].energy_booked == pytest.approx(loop, rel=1e-12)
    assert run.audit["max_error_over_turnover"] < 1e-4
    stuck = single_impact(law, MASS, 0.0, 0.9 * v_s, 1e-10)
    assert stuck.status == "stuck"


def test_maugis_dugdale_sphere_bounces_under_gravity():
    """Each impact of a thrown sphere loses one loop: e_k = sqrt(1 - loop / (m v_k^2 / 2))."""
    from continuum.dynamics.driver import DriverSettings, simulate
    law = BranchSphere("maugis_dugdale", R, W, E_STAR, Z0)
    run = simulate(law, MASS, 9.80665, impact_velocity=5.0, settings=DriverSettings(rtol=1e-10, max_bounces=3,
                                                                                    max_time=10.0))
    assert len(run.bounces) == 3
    for b in run.bounces:
        assert b.restitution == pytest.approx(math.sqrt(1.0 - law.loop_energy_used / (0.5 * MASS * b.v_impact**2)),
                                              rel=1e-6)
    assert run.audit["max_relative_error"] < 1e-6


def test_dmt_sphere_loses_nothing():
    law = BranchSphere("dmt", R, W, E_STAR, Z0)
    run = single_impact(law, MASS, 0.0, 1.0, 1e-10)
    assert run.status == "escaped"
    assert run.bounces[0].restitution == pytest.approx(1.0, abs=1e-6)
    # it was pulled: the deepest approach exceeds Hertz's at the same speed
    hertz = (15.0 * MASS / (16.0 * E_STAR * math.sqrt(R))) ** 0.4
    assert run.bounces[0].max_penetration > hertz


def _scene(radius, **physics):
    from continuum.scene import resolve_scene
    table = {"name": "sphere", "impact_velocity": 5.0, "contact": "smooth",
             "body": {"shape": "sphere", "radius": radius, "density": RHO},
             "surfaces": {"work_of_adhesion": W, "interaction_range": Z0,
                          "body": {"youngs_modulus": 83e9, "poisson_ratio": 0.37},
                          "substrate": {"youngs_modulus": 70e9, "poisson_ratio": 0.35}},
             "environment": {"gravity": 0.0}, "physics": physics, "numerics": {"max_bounces": 1}}
    return resolve_scene(table=table)


@pytest.mark.parametrize("radius,law", [(50e-9, "maugis_dugdale"), (1e-3, "jkr")])
def test_auto_picks_the_sphere_law_by_its_tabor_parameter(radius, law):
    from continuum.model.decisions import adhesion_decision
    from continuum.model.regime import regime_of
    scene = _scene(radius).scene
    d = adhesion_decision(scene, regime_of(scene))
    assert d.law == law and d.decided_by == "tabor_parameter"
    assert d.record()["tabor_bounds"]["jkr_above"] == 5.0


def test_auto_keeps_jkr_under_load_control_and_explicit_md_refuses_it():
    from continuum.model.decisions import adhesion_decision
    from continuum.model.regime import regime_of
    from continuum.scene import SceneError
    scene = _scene(50e-9, detachment="load").scene
    assert adhesion_decision(scene, regime_of(scene)).law == "jkr"
    with pytest.raises(SceneError) as err:
        _scene(50e-9, detachment="load", adhesion_law="maugis_dugdale")
    assert err.value.key == "physics.detachment"


def test_scene_runs_the_maugis_dugdale_sphere():
    from continuum.dynamics.impact import run_impact
    result = run_impact(_scene(50e-9)).to_dict()
    assert result["models"]["contact_law"]["name"] == "maugis_dugdale_sphere"
    assert result["models"]["adhesion"]["law"] == "maugis_dugdale"
    loop = result["models"]["contact_law"]["loop_energy_used"]
    ke = 0.5 * result["bounces"][0]["v_impact"] ** 2 * float(tn.sphere_mass(50e-9, RHO))
    assert result["bounces"][0]["restitution"] == pytest.approx(math.sqrt(1.0 - loop / ke), rel=1e-6)
