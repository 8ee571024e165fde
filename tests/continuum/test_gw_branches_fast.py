"""The compiled footprint quadrature of a GW surface of branch-law summits (`continuum.rough.branch_kernel`)
against its NumPy form and against adaptive quadrature, the one-pass profile against the separate sums, and the
tables a rigid rough roller shares with another of the same surface against tables built afresh."""
from __future__ import annotations

import numpy as np
import pytest

from continuum.laws.rough_rigid import RigidRoughRoller
from continuum.rough.branch_laws import make_summit_law
from continuum.rough.gw_branches import GWBranchSurface, quadrature_pressure
from continuum.rough.summits import SummitStatistics

BETA, W, E = 0.2e-6, 0.12, 30e9
SIGMA, DENSITY = 5e-9, 1e13
QUANTITIES = (("pressure", "total"), ("pressure", "compressive"), ("pressure", "tensile"), ("energy", "total"),
              ("area", "total"))


def _surface(name, z_max=4.07):
    law = make_summit_law(name, BETA, W, E, z0=0.3e-9, delta_max=30 * SIGMA)
    return GWBranchSurface(SummitStatistics(SIGMA, DENSITY, BETA), law, z_max=z_max)


def _states(n=3000, seed=3):
    """Separations from deep contact to beyond the tallest summit, thresholds on both sides of every jump."""
    rng = np.random.default_rng(seed)
    d = rng.uniform(-5 * SIGMA, 4.5 * SIGMA, n)
    return d, d - rng.uniform(-3e-9, 6e-9, n)


@pytest.mark.parametrize("name", ["maugis_dugdale", "jkr", "dmt"])
def test_compiled_quadrature_is_the_numpy_quadrature(name):
    """Same panels, nodes and interpolation: only the order of the sums differs (round-off, 1e-16 relative per
    term; a few hundred terms), relative to each quantity's largest magnitude."""
    surf = _surface(name)
    d, zeta = _states()
    fast = surf._integrals(QUANTITIES, d, zeta)
    ref = surf._integrals_numpy(QUANTITIES, d, zeta)
    for n, q in enumerate(QUANTITIES):
        scale = np.max(np.abs(ref[n]))
        assert scale > 0 or q[1] != "total", q
        np.testing.assert_allclose(fast[n], ref[n], rtol=0, atol=1e-12 * scale, err_msg=str(q))


@pytest.mark.parametrize("name", ["maugis_dugdale", "jkr"])
def test_compiled_pressure_meets_adaptive_quadrature(name):
    """p(d, zeta) against scipy.integrate.quad over z split at the jump points (the panels' accuracy)."""
    surf = _surface(name)
    for d, back in ((-1.0 * SIGMA, 0.0), (0.5 * SIGMA, 2e-9), (2.0 * SIGMA, -1e-9), (-3.0 * SIGMA, 4e-9)):
        got = float(surf.pressure(d, d - back))
        ref = quadrature_pressure(d, d - back, surf)
        scale = abs(float(surf.pressure(-1.0 * SIGMA, -1.0 * SIGMA)))
        assert abs(got - ref) < 5e-5 * scale, (d, back, got, ref)


def test_profile_is_the_separate_sums():
    """pressure, its parts and the contact fraction in one pass are the sums each gives alone; the parts add up
    to the pressure."""
    surf = _surface("maugis_dugdale")
    d, zeta = _states(400)
    p, comp, tens, area = surf.profile(d, zeta)
    np.testing.assert_array_equal(p, surf.pressure(d, zeta))
    c2, t2 = surf.pressure_parts(d, zeta)
    np.testing.assert_array_equal(comp, c2)
    np.testing.assert_array_equal(tens, t2)
    np.testing.assert_array_equal(area, surf.contact_fraction(d, zeta))
    np.testing.assert_allclose(comp + tens, p, rtol=0, atol=1e-12 * np.max(np.abs(p)))
    assert np.all(comp >= 0) and np.all(tens <= 0) and np.all((area >= 0) & (area <= 1))


def test_rollers_of_one_surface_share_identical_tables():
    """A second roller on an equal surface (the same law object) reads the first one's tables: its forces and
    energies are those of tables built from scratch for a fresh law, to round-off of the same quadrature."""
    first = RigidRoughRoller(_surface("maugis_dugdale"), 5e-6, 3.28e-3)
    second = RigidRoughRoller(_surface("maugis_dugdale"), 5e-6, 3.28e-3)
    depth = 2 * SIGMA
    first._build(depth)
    second._build(depth)
    assert second._force is first._force
    law = make_summit_law.__wrapped__("maugis_dugdale", BETA, W, E, z0=0.3e-9, delta_max=30 * SIGMA)
    fresh = RigidRoughRoller(GWBranchSurface(SummitStatistics(SIGMA, DENSITY, BETA), law, z_max=4.07), 5e-6,
                             3.28e-3)
    fresh._build(depth)
    assert fresh._force is not first._force
    gaps = np.linspace(-depth, fresh.end_gap, 50)
    for g in gaps:
        assert second.force(g) == pytest.approx(fresh.force(g), rel=1e-9, abs=1e-12 * abs(fresh.force(-depth)))
        assert second.stored_energy(g) == pytest.approx(fresh.stored_energy(g), rel=1e-9,
                                                        abs=1e-12 * abs(fresh.stored_energy(-depth)))


def test_one_pass_values_are_the_separate_sums():
    """Pressure and energy summed in one pass are bit for bit the sums each gives alone (independent
    accumulators), so the rigid roller's tables do not depend on how many quantities a pass carries."""
    surf = _surface("maugis_dugdale")
    d, zeta = _states(400)
    p, e, a = surf.values(("pressure", "energy", "area"), d, zeta)
    np.testing.assert_array_equal(p, surf.pressure(d, zeta))
    np.testing.assert_array_equal(e, surf.energy(d, zeta))
    np.testing.assert_array_equal(a, surf.contact_fraction(d, zeta))
    roller = RigidRoughRoller(surf, 5e-6, 3.28e-3)
    h = np.linspace(-2 * SIGMA, roller.end_gap, 40)
    r = np.full_like(h, roller.release_stretch)
    force, energy = roller._integrate(("pressure", "energy"), h, r)
    np.testing.assert_array_equal(force, roller._integrate("pressure", h, r))
    np.testing.assert_array_equal(energy, roller._integrate("energy", h, r))


def test_a_shared_summit_law_is_the_law_built_afresh():
    """make_summit_law hands one law per argument set; it is the law a fresh build gives (same branches, jumps
    and loop), and other arguments give another law."""
    args = ("maugis_dugdale", BETA, W, E)
    shared = make_summit_law(*args, z0=0.3e-9, delta_max=30 * SIGMA)
    assert make_summit_law(*args, z0=0.3e-9, delta_max=30 * SIGMA) is shared
    assert make_summit_law(*args, z0=0.4e-9, delta_max=30 * SIGMA) is not shared
    fresh = make_summit_law.__wrapped__(*args, z0=0.3e-9, delta_max=30 * SIGMA)
    for branch in ("approach", "retreat"):
        a, b = getattr(shared, branch), getattr(fresh, branch)
        for what in ("delta", "force", "radius", "energy", "contact"):
            np.testing.assert_array_equal(getattr(a, what), getattr(b, what))
    assert (shared.delta_in, shared.delta_out, shared.loop_energy) == (fresh.delta_in, fresh.delta_out,
                                                                        fresh.loop_energy)
