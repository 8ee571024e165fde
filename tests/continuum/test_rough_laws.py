"""Rough roller laws in the driver: the tabulated rigid law against the grid law, energy books, limits.

Tolerances: the two averaged laws differ only by the grid discretisation of the footprint
integral (and, with the half-space on, by femtometre deflections): restitution and duration agree
to 1e-4. Energy audits of rough runs at `standard` stay below 1e-5 of the impact energy (GW
tables carry ~1e-6 relative error; see docs/model.md).
"""
import math
from pathlib import Path

import pytest

from continuum.dynamics.driver import DriverSettings, simulate
from continuum.dynamics.impact import run_impact
from continuum.laws.rough_rigid import RigidRoughRoller
from continuum.laws.rough_roller import RoughRoller
from continuum.model import rough_law
from continuum.scene import resolve_scene

ROOT = Path(__file__).resolve().parents[2]
SILICA = ROOT / "inputs" / "scenes" / "rough_silica.toml"


def _scene(**overrides):
    return resolve_scene(SILICA, overrides={"numerics.max_bounces": 2, **overrides}).scene


def _run(law, scene, bounces=2):
    return simulate(law, scene.body.mass, scene.environment.gravity, release_height=scene.release_height,
                    settings=DriverSettings(rtol=scene.numerics.rtol, max_bounces=bounces))


@pytest.fixture(scope="module")
def rigid_and_grid():
    scene = _scene(**{"physics.half_space": "off"})
    rigid, _ = rough_law(scene)
    assert isinstance(rigid, RigidRoughRoller)
    grid = RoughRoller(rigid.surface, scene.body.radius, scene.body.length, scene.surfaces.e_star,
                       half_space=False, grid_points=512)
    return scene, _run(rigid, scene), _run(grid, scene)


def test_tabulated_rigid_law_matches_the_grid_law(rigid_and_grid):
    _, a, b = rigid_and_grid
    for x, y in zip(a.bounces, b.bounces):
        assert x.restitution == pytest.approx(y.restitution, rel=1e-4, abs=0)
        assert x.duration == pytest.approx(y.duration, rel=1e-4, abs=0)
        assert x.peak_force == pytest.approx(y.peak_force, rel=1e-3, abs=0)


def test_rough_energy_audit_and_booked_loss_match_the_motion(rigid_and_grid):
    _, a, b = rigid_and_grid
    for run in (a, b):
        assert run.audit["max_relative_error"] < 1e-5
        for bounce in run.bounces:
            assert bounce.energy_booked > 0
            assert bounce.energy_lost == pytest.approx(bounce.energy_booked, rel=1e-4, abs=0)


def test_without_adhesion_rough_impacts_are_elastic():
    scene = _scene(**{"physics.half_space": "off", "physics.adhesion_law": "none"})
    law, _ = rough_law(scene)
    run = _run(law, scene, bounces=3)
    assert run.status == "max_bounces"
    for b in run.bounces:
        assert b.restitution == pytest.approx(1.0, abs=1e-6)
        assert b.energy_booked == 0.0
    assert run.audit["max_relative_error"] < 1e-6


def test_half_space_matters_in_the_heavy_scene_and_not_under_the_paper_roller():
    heavy = ROOT / "inputs" / "scenes" / "rough_halfspace_heavy.toml"
    jkr = {"physics.adhesion_law": "jkr"}       # the half-space under test, with the tabulated law's audit bound
    on = run_impact(resolve_scene(heavy, overrides=jkr)).to_dict()
    off = run_impact(resolve_scene(heavy, overrides={**jkr, "physics.half_space": "off"})).to_dict()
    sigma = on["scene"]["si"]["surfaces"]["roughness"]["sigma"]
    deflection = on["models"]["diagnostics"]["max_deflection"]
    assert deflection > 0.05 * sigma
    b_on, b_off = on["bounces"][0], off["bounces"][0]
    assert abs(b_on["peak_force"] / b_off["peak_force"] - 1) > 0.01
    assert on["energy_audit"]["max_relative_error"] < 1e-5
    # the paper's roller: femtometres (~20 fm) against sigma = 6 nm
    paper = run_impact(resolve_scene(SILICA, overrides={"numerics.max_bounces": 1, "physics.half_space": "on",
                                                               "surfaces.roughness.mode": "mean_field"})).to_dict()
    assert (paper["models"]["diagnostics"]["max_deflection"]
            < 1e-4 * paper["scene"]["si"]["surfaces"]["roughness"]["sigma"])
    assert math.isfinite(paper["energy_audit"]["max_relative_error"])


def test_mean_plane_datum_shifts_the_release_by_the_tallest_summit_or_refuses():
    base = {"numerics.max_bounces": 1, "physics.half_space": "off"}
    top = run_impact(resolve_scene(SILICA, overrides=base)).to_dict()
    z_top = top["models"]["contact_law"]["z_max"]
    h0 = top["scene"]["si"]["release_height"]
    shifted = run_impact(resolve_scene(SILICA, overrides={**base, "surfaces.roughness.datum": "mean_plane",
                                                             "release_height": h0 + z_top})).to_dict()
    assert shifted["bounces"][0]["v_impact"] == pytest.approx(top["bounces"][0]["v_impact"], rel=1e-9, abs=0)
    from continuum.scene import SceneError
    with pytest.raises(SceneError, match="start in contact"):
        run_impact(resolve_scene(SILICA, overrides={**base, "surfaces.roughness.datum": "mean_plane",
                                                    "release_height": 0.5 * z_top}))


def test_footprint_tables_of_the_compiled_quadrature_are_the_numpy_quadratures():
    """A rigid roller's whole footprint tables on Maugis-Dugdale summits (the paper's calibrated sets' summits), built
    by the compiled quadrature (whole panels read once-computed node values, cut panels interpolate per state) and
    by its NumPy reference form (`GWBranchSurface._integrals_numpy`, every node interpolated): the same panels,
    nodes and interpolation, so the tables agree to the round-off of a few hundred terms (1e-12 of their largest
    value), far inside the tables' own spline error (docs/model.md)."""
    import numpy as np

    from continuum.rough.branch_laws import make_summit_law
    from continuum.rough.gw_branches import GWBranchSurface
    from continuum.rough.summits import SummitStatistics

    sigma, beta = 6e-9, 0.2e-6
    law = make_summit_law("maugis_dugdale", beta, 0.12, 30e9, z0=0.3e-9, delta_max=30 * sigma)
    tables = []
    for form in ("compiled", "numpy"):
        surface = GWBranchSurface(SummitStatistics(sigma, 1e13, beta), law, z_max=4.07)
        if form == "numpy":
            surface._integrals = surface._integrals_numpy
        roller = RigidRoughRoller(surface, 5e-6, 3.28e-3, resolution="fast")
        roller._shared_key = None              # built here, not read from the other form's shared tables
        roller._build(1.5 * sigma)
        tables.append((roller._force.get_coeffs(), roller._energy.get_coeffs(), roller._count.c))
    for ours, ref in zip(*tables):
        assert np.max(np.abs(ref)) > 0
        np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-12 * np.max(np.abs(ref)))


@pytest.mark.parametrize("name, z0", [("maugis_dugdale", 0.3e-9), ("maugis_dugdale", 1e-9), ("jkr", 0.3e-9),
                                      ("dmt", 0.3e-9)])
def test_footprint_tables_by_threshold_are_the_state_by_state_sums(name, z0):
    """The tables' deep states summed for every window at once (`GWBranchSurface.values_by_threshold`: each panel's
    sums once per separation, only the panel a threshold cuts per window) against `_integrate` state by state on
    the same (gap, window) grid: the same panels, nodes and values, so they agree to the round-off of reordered
    sums (1e-12 of the largest value; cutting the threshold's panel differently moves them by ~1e-6)."""
    import numpy as np

    from continuum.rough.branch_laws import make_summit_law
    from continuum.rough.gw_branches import GWBranchSurface
    from continuum.rough.summits import SummitStatistics

    sigma, beta = 3e-9, 0.2e-6
    law = make_summit_law(name, beta, 0.12, 10e9, z0=z0, delta_max=30 * sigma)
    roller = RigidRoughRoller(GWBranchSurface(SummitStatistics(sigma, 1e13, beta), law, z_max=4.07), 5e-6, 3.28e-3,
                              resolution="fast")
    h = np.linspace(-2 * sigma, roller.end_gap, 61)
    w = np.linspace(0.0, 1.0, roller.res[2])
    r = roller.release_stretch - (roller.release_stretch - roller._r_in) * w * w
    ours = roller._table_values(h, r)
    H, R = np.meshgrid(h, r, indexing="ij")
    ref = roller._integrate(("pressure", "energy"), H, R)
    for q, q_ref in zip(ours, ref):
        assert np.max(np.abs(q_ref)) > 0
        np.testing.assert_allclose(q, q_ref, rtol=0, atol=1e-12 * np.max(np.abs(q_ref)))
