"""The compiled flattening table of a plastic summit (`continuum.rough.flattening_kernel`) against scipy's brentq on
the same equation (the Python loop it replaces), the law's contact against the reference solutions, and the
sharing of summit laws built from equal values (`make_summit_law`, the factory's plastic summit law)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from continuum.reference import jkr as jkr_ref
from continuum.reference import maugis as md_ref
from continuum.rough.branch_laws import DUGDALE_FACTOR, make_summit_law
from continuum.rough.plastic_branches import FLATTENING_POINTS, PlasticBranchSummitLaw

# the calibrated set's summits (tests/continuum/test_plastic_branches.py): silicon E*, MD work of adhesion and range
BETA, W, E, P_Y, Z0, SIGMA = 0.2e-6, 0.192, 89e9, 11e9, 0.207e-9, 6e-9
SIGMA0 = DUGDALE_FACTOR * W / Z0


def _scipy_force_approach(name, a, radius):
    """The Python contact the compiled one replaces: JKR's and DMT's closed forms, Maugis-Dugdale by scipy."""
    if name == "jkr":
        return float(jkr_ref.force_from_radius(a, radius, W, E)), float(jkr_ref.approach_from_radius(a, radius, W, E))
    if name == "dmt":
        return 4.0 * E * a**3 / (3.0 * radius) - 2.0 * math.pi * W * radius, a * a / radius
    a_s, p_s, d_s = (float(x) for x in md_ref.md_scales(radius, W, E))
    p, d, _ = md_ref._pdt_scipy(a / a_s, float(md_ref.md_parameter(radius, W, E, SIGMA0)))
    return p * p_s, d * d_s


def _scipy_table(name, law):
    """Thornton-Ning's flattening by scipy's brentq, point by point (the loop the kernel replaces)."""
    a_y, f_y, d_y = law.yield_radius, law.yield_force, law.yield_approach
    r_p, d_p = np.empty_like(law._d), np.zeros_like(law._d)
    r_p[0] = BETA
    for i, dd in enumerate(law._d[1:], 1):
        a, f = math.sqrt(a_y * a_y + BETA * dd), f_y + law.plastic_slope * dd
        g = lambda r, a=a, f=f: _scipy_force_approach(name, a, r)[0] - f          # noqa: E731
        lo, hi = r_p[i - 1], 1.5 * r_p[i - 1]
        if g(lo) <= 0.0:
            r_p[i] = lo
        else:
            while g(hi) > 0.0:
                lo, hi = hi, 2.0 * hi
            r_p[i] = brentq(g, lo, hi, xtol=1e-14 * hi, rtol=1e-13)
        d_p[i] = d_y + dd - _scipy_force_approach(name, a, r_p[i])[1]
    return r_p, d_p


@pytest.mark.parametrize("name", ["maugis_dugdale", "dmt", "jkr"])
def test_compiled_contact_is_the_reference_contact(name):
    law = PlasticBranchSummitLaw(name, BETA, W, E, P_Y, z0=Z0, delta_max=30 * SIGMA)
    for a, r in ((1e-9, BETA), (5e-9, 2 * BETA), (3e-8, 7 * BETA)):
        f, d = law.force_approach(a, r)
        fr, dr = _scipy_force_approach(name, a, r)
        hertz_f, hertz_d = 4.0 * E * a**3 / (3.0 * r), a * a / r                  # the terms' sizes
        assert abs(f - fr) <= 1e-12 * (hertz_f + 2.0 * math.pi * W * r)
        assert abs(d - dr) <= 1e-12 * (hertz_d + abs(dr))


@pytest.mark.parametrize("name", ["maugis_dugdale", "dmt", "jkr"])
def test_compiled_flattening_table_is_scipys(name):
    """R_p to 1e-12 (both roots are Brent's to rtol 1e-13 on contacts equal to a few ulp), delta_p to 1e-12 of the
    approach it is the difference of; and the table solves F_L(a*; R_p) = F* to the root's tolerance where R_p grew
    (where it did not, F_L(a*; R_p) <= F* already)."""
    law = PlasticBranchSummitLaw(name, BETA, W, E, P_Y, z0=Z0, delta_max=30 * SIGMA)
    assert law._d.size == FLATTENING_POINTS
    r_ref, d_ref = _scipy_table(name, law)
    np.testing.assert_allclose(law._r_p, r_ref, rtol=1e-12, atol=0.0)
    assert np.all(np.abs(law._d_p - d_ref) <= 1e-12 * (law.yield_approach + law._d))
    grew = 0
    for i in (1, 2, 57, FLATTENING_POINTS - 1):
        dd = law._d[i]
        a = math.sqrt(law.yield_radius**2 + BETA * dd)
        f_star = law.yield_force + law.plastic_slope * dd
        f_l = law.force_approach(a, law._r_p[i])[0]
        if law._r_p[i] == law._r_p[i - 1]:
            assert f_l <= f_star
            continue
        # F_L falls with R at slope ~ -F_hertz/R: a root within rtol 1e-13 in R leaves ~1e-13 F_hertz in force
        assert abs(f_l - f_star) <= 1e-11 * 4.0 * E * a**3 / (3.0 * law._r_p[i])
        grew += 1
    assert grew >= 2


def test_summit_laws_of_equal_values_are_one_object_however_spelled():
    """make_summit_law is keyed by values: keywords, defaults and NumPy floats give the same law; z0 enters only
    Maugis-Dugdale; other values give another law; `__wrapped__` builds afresh with the same tables."""
    args = ("maugis_dugdale", BETA, W, E)
    shared = make_summit_law(*args, z0=Z0, delta_max=30 * SIGMA)
    assert make_summit_law("maugis_dugdale", np.float64(BETA), W, np.float64(E), delta_max=np.float64(30 * SIGMA),
                           detachment="displacement", z0=Z0) is shared
    assert make_summit_law(*args, z0=1.5 * Z0, delta_max=30 * SIGMA) is not shared
    assert make_summit_law("dmt", BETA, W, E, delta_max=1e-7) is make_summit_law("dmt", BETA, W, E, z0=Z0,
                                                                                 delta_max=1e-7)
    fresh = make_summit_law.__wrapped__(*args, z0=Z0, delta_max=30 * SIGMA)
    assert fresh is not shared
    np.testing.assert_array_equal(fresh.retreat.force, shared.retreat.force)
    with pytest.raises(ValueError, match="detachment"):
        make_summit_law(*args, z0=Z0, detachment="load", delta_max=30 * SIGMA)


def test_the_factory_shares_a_plastic_summit_law_and_its_nodes():
    """Two requests with equal numbers (Python or NumPy floats) give one plastic law; its node laws are the shared
    elastic laws of their radii."""
    from continuum.model.factory import _plastic_summit_law

    one = _plastic_summit_law("maugis_dugdale", BETA, W, E, P_Y, Z0, 30 * SIGMA)
    two = _plastic_summit_law("maugis_dugdale", float(np.float64(BETA)), W, E, P_Y, Z0, 30 * SIGMA)
    assert one is two
    for node in one._laws:
        assert node is make_summit_law("maugis_dugdale", node.radius_tip, W, E, z0=Z0, delta_max=30 * SIGMA)


def test_joined_pieces_step_only_where_delta_does_not_increase():
    """`_concat` separates equal (or falling) deltas at the joins by a rounding-level step: the result is strictly
    increasing and is the left-to-right pass over every point (written out here), on pieces with repeated points,
    runs of equal values and zero, tiny and large steps."""
    from continuum.rough.branch_laws import _concat

    def every_point(pieces):
        d = np.concatenate([p[0] for p in pieces])
        for i in range(1, d.size):
            if d[i] <= d[i - 1]:
                d[i] = np.nextafter(d[i - 1], np.inf) + 1e-15 * abs(d[i - 1])
        return d

    rng = np.random.default_rng(3)
    for _ in range(200):
        pieces = []
        for _ in range(rng.integers(1, 6)):
            m = rng.integers(1, 8)
            d = rng.choice([0.0, 1e-9, -1e-9, 5.0]) + np.cumsum(rng.choice([0.0, 1e-30, 1e-24, 1e-9], m))
            pieces.append((d, rng.normal(size=m), rng.normal(size=m)))
        want = every_point([tuple(x.copy() for x in p) for p in pieces])
        d, f, a = _concat(pieces)
        np.testing.assert_array_equal(d, want)
        assert np.all(np.diff(d) > 0.0)
        np.testing.assert_array_equal(f, np.concatenate([p[1] for p in pieces]))
