"""The GW mean field of adhesive elastic-plastic summits (continuum.rough.plastic_summits): its quadrature stays
bounded whatever the separation the integrator tries, over many impacts, and still equals the elastic law at
infinite hardness.

References independent of the module's sums: the JKR closed form integrated over the Gaussian by scipy's adaptive
quadrature, and the per-area mean field integrated across the roller's footprint by adaptive quadrature.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from continuum.dynamics.driver import DriverSettings, simulate
from continuum.laws.plastic_rough import PlasticGWRoller
from continuum.reference import jkr
from continuum.rough import plastic_summits as ps
from continuum.rough.plastic_summits import LOWER_TAIL, PlasticGWSurface, PlasticSummitLaw, RollerFootprint

BETA, W = 1e-6, 0.1                      # summit tip radius (m), work of adhesion (J/m^2)
SIGMA, DENSITY, ZMAX = 5e-9, 1e13, 4.0   # summit heights rms (m), summits per m^2, truncation (sigma)
R_ROLLER, L_ROLLER = 1e-3, 1e-3          # roller radius and length (m)


@pytest.fixture
def node_counts(monkeypatch):
    """Every quadrature of every plastic surface: (nodes, its bound)."""
    seen = []
    nodes = ps.PlasticGWSurface._nodes

    def counted(self, lo, hi, floor=-math.inf):
        x, w = nodes(self, lo, hi, floor)
        seen.append((x.size, self.node_bound(hi - lo) if hi > lo else 0))
        return x, w
    monkeypatch.setattr(ps.PlasticGWSurface, "_nodes", counted)
    return seen


def test_the_lower_truncation_drops_half_an_epsilon_of_the_summits():
    from scipy.special import ndtr
    assert ndtr(-LOWER_TAIL) == pytest.approx(np.finfo(float).eps / 2.0, rel=1e-9)


@pytest.mark.parametrize("e_star", [1e11, 1e12])
def test_any_separation_costs_a_bounded_quadrature(node_counts, e_star):
    """Separations from the tallest summit to 1e4 m below it (an integrator's wild trial stage): the surface's
    integrals keep at most node_bound((z_max + K) sigma) nodes, a footprint's at most its bound at that depth
    (logarithmic in it), and the values stay finite."""
    law = PlasticSummitLaw(BETA, W, e_star, 3e9)
    area = PlasticGWSurface(law, SIGMA, DENSITY, ZMAX)
    foot = RollerFootprint(law, SIGMA, DENSITY, ZMAX, R_ROLLER, L_ROLLER)
    cap_area = area.node_bound((ZMAX + LOWER_TAIL) * SIGMA)
    for depth in (0.5 * SIGMA, 3 * SIGMA, 20 * SIGMA, 1e-3, 1e4):
        d_p = area.z_top - depth
        for surf in (area, foot):
            start = len(node_counts)
            values = [*surf.state(d_p, d_p, d_p), *surf.state(d_p + 0.3 * SIGMA, d_p, d_p),
                      surf.plastic_work(d_p), surf.released(d_p + 2 * SIGMA, d_p, d_p)]
            assert np.all(np.isfinite(values))
            counts = node_counts[start:]
            assert all(n <= bound for n, bound in counts)
            if surf is area:
                assert max(n for n, _ in counts) <= cap_area < 1000
            else:
                assert max(n for n, _ in counts) <= foot.node_bound(depth) < 2500


def test_a_long_plastic_mean_field_run_keeps_its_quadrature_bounded(node_counts):
    """Five impacts of a roller on stiff plastic summits (1 TPa): every quadrature within its bound and the
    energy audit closed."""
    law = PlasticSummitLaw(BETA, W, 1e12, 1e10)
    roller = PlasticGWRoller(law, SIGMA, DENSITY, ZMAX, R_ROLLER, L_ROLLER)
    run = simulate(roller, 1e-8, 9.81, release_height=1e-7, settings=DriverSettings(max_bounces=5))
    assert len(run.bounces) == 5
    assert all(n <= bound for n, bound in node_counts)
    assert max(n for n, _ in node_counts) <= roller.surface.node_bound(20 * SIGMA)
    assert run.audit["max_relative_error"] < 1e-5


@pytest.mark.parametrize("depth,back", [(9.0, 0.0), (11.0, 0.5)])
def test_infinite_hardness_deep_below_the_floor_is_the_elastic_jkr_mean_field(depth, back):
    """p_y = inf, separations below the lower truncation (-K sigma): the mean field equals adaptive quadrature of
    the JKR closed form over the whole Gaussian to 1e-7 (the dropped tail is eps/2 of the summits)."""
    e = 1e11
    surf = PlasticGWSurface(PlasticSummitLaw(BETA, W, e, math.inf), SIGMA, DENSITY, ZMAX)
    d_c = surf.z_top - (ZMAX + depth) * SIGMA
    d = d_c + back * SIGMA
    dc = float(jkr.critical_approach(BETA, W, e))

    def f(z):
        return float(jkr.force_from_approach(z - d, BETA, W, e)) * math.exp(-0.5 * (z / SIGMA) ** 2)

    ref = sum(integrate.quad(f, lo, hi, epsabs=0, epsrel=1e-12, limit=400)[0]
              for lo, hi in ((max(d_c, d - dc), 0.0), (0.0, surf.z_top)))
    ref *= DENSITY / (math.sqrt(2 * math.pi) * SIGMA)
    p = surf.state(d, d_c, d_c)[0]
    assert p == pytest.approx(ref, rel=1e-7)


@pytest.mark.parametrize("p_y", [math.inf, 3e9])
def test_a_footprint_deeper_than_the_floor_is_the_mean_field_across_it(p_y):
    """A roller pressed 12 sigma below the mean plane (its axis height below the floor): the footprint integral
    equals the per-area mean field integrated across the footprint by adaptive quadrature, to 1e-6."""
    law = PlasticSummitLaw(BETA, W, 1e11, p_y)
    area = PlasticGWSurface(law, SIGMA, DENSITY, ZMAX)
    foot = RollerFootprint(law, SIGMA, DENSITY, ZMAX, R_ROLLER, L_ROLLER)
    top, h_p = area.z_top, -(ZMAX + 12.0) * SIGMA
    shift = lambda x: x * x / (2.0 * R_ROLLER)                                       # noqa: E731
    x_end = math.sqrt(2.0 * R_ROLLER * -h_p)
    breaks = [math.sqrt(2.0 * R_ROLLER * (-h_p - k * SIGMA)) for k in range(1, 16) if k * SIGMA < -h_p]
    for n, what in enumerate(("pressure", "energy")):
        ref, _ = integrate.quad(lambda x: area.state(top + h_p + shift(x), top + h_p + shift(x),
                                                     top + h_p + shift(x))[n],
                                0.0, x_end, epsabs=0, epsrel=1e-11, limit=800, points=sorted(breaks))
        got = foot.state(top + h_p, top + h_p, top + h_p)[n]
        assert got == pytest.approx(2.0 * L_ROLLER * ref, rel=1e-6), what
