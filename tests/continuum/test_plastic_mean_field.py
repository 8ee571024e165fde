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


# ----------------------------------------------------------------------------- Maugis-Dugdale and DMT summits
Z0 = 0.3e-9                              # interaction range of the Maugis-Dugdale summits (m)


def _branch_law(name, p_y, e=1e11):
    from continuum.rough.plastic_branches import PlasticBranchSummitLaw
    return PlasticBranchSummitLaw(name, BETA, W, e, p_y, z0=Z0, delta_max=30 * SIGMA)


def _table_integral(law, d, zeta_eff, top, what):
    """n int F(z - d) phi(z) dz of the tabulated elastic law, exact for its piecewise-linear table: 6-point
    Gauss-Legendre on every piece between table points (approach branch below zeta_eff, retreat above)."""
    x, wx = np.polynomial.legendre.leggauss(6)
    total = 0.0
    for branch, a, b in (("approach", d - law.reach, zeta_eff), ("retreat", zeta_eff, top)):
        if not b > a:
            continue
        br = law.approach if branch == "approach" else law.retreat
        e = np.array([a, *(d + t for t in br.delta if a < d + t < b), b])
        lo, hi = e[:-1, None], e[1:, None]
        z = (0.5 * (lo + hi) + 0.5 * (hi - lo) * x).ravel()
        fn = law.force if what == "pressure" else law.energy
        values = np.asarray(fn(z - d, branch)) * np.exp(-0.5 * (z / SIGMA) ** 2)
        total += float((0.5 * (hi - lo) * wx).ravel() @ values)
    return DENSITY * total / (math.sqrt(2 * math.pi) * SIGMA)


@pytest.mark.parametrize("name", ["maugis_dugdale", "dmt"])
def test_infinite_hardness_is_the_elastic_mean_field_of_the_law(name):
    """p_y = inf: the mean field of Thornton-Ning summits on the law is the elastic GW mean field of that law
    (summits z >= zeta_eff = max(d_c + delta_in, d + delta_out) on the retreat branch, the others on the approach
    branch with its attraction), against the exact integral of the tabulated law. Tolerance 1e-6: the table is
    piecewise linear with a kink at each of its ~2000 points, and Gauss-Legendre panels leave 1e-7 - 3e-7 of the
    exact integral whatever their width (sigma/4 to sigma/32 measured), the same as the elastic law's own
    quadrature (`GWBranchSurface`); a wrong summit set (one jump point off) moves the sum by 1e-3 or more."""
    from continuum.rough.plastic_gw_branches import PlasticBranchGWSurface
    law = _branch_law(name, math.inf)
    elastic = law._laws[0]
    surf = PlasticBranchGWSurface(law, SIGMA, DENSITY, ZMAX)
    scale = DENSITY * 2.0 * math.pi * W * BETA                 # the summits' pull-off per unit area
    for depth, back in ((1.0, 0.0), (2.5, 0.0), (2.5, 0.5), (3.0, 1.2), (0.3, 0.35), (-0.02, 0.0)):
        d_c = surf.z_top - depth * SIGMA
        d = d_c + back * SIGMA
        zeta = max(d_c + elastic.delta_in, d + elastic.delta_out)
        p, energy, _ = surf.state(d, d_c, d_c)
        ref_p = _table_integral(elastic, d, zeta, surf.z_top, "pressure")
        ref_e = _table_integral(elastic, d, zeta, surf.z_top, "energy")
        assert abs(p - ref_p) <= 1e-6 * max(abs(ref_p), 1e-3 * scale), (depth, back)
        assert abs(energy - ref_e) <= 1e-6 * max(abs(ref_e), 1e-3 * scale * SIGMA), (depth, back)


def test_the_summit_sets_are_monotonic_in_the_deepest_approach():
    """m(u), h(u), r(u) and g(u) increase with u across the yield approach (the sets are u above one edge)."""
    from continuum.rough.plastic_gw_branches import PlasticBranchGWSurface
    surf = PlasticBranchGWSurface(_branch_law("maugis_dugdale", 3e9), SIGMA, DENSITY, ZMAX)
    u = np.linspace(-SIGMA, 25 * SIGMA, 2001)
    assert surf.law.yield_approach < 25 * SIGMA
    for fn in (surf.met_edge, surf.hold, surf.reach_edge, surf.recovery):
        assert np.all(np.diff(fn(u)) > 0.0), fn.__name__


def test_tabulated_jkr_summits_give_the_closed_form_plastic_mean_field():
    """Thornton-Ning's construction on the tabulated JKR law, summed by the general mean field, against the JKR
    closed-form plastic mean field (`PlasticGWSurface`): the same sets and values within the tables' errors as
    tests/continuum/test_plastic_branches.py measures them on one summit (force and loops ~1e-5; stored energy and
    plastic work, differences of energies on the flattening table, 1e-3), yielded and elastic summits alike."""
    from continuum.rough.plastic_gw_branches import PlasticBranchGWSurface
    closed = PlasticGWSurface(PlasticSummitLaw(BETA, W, 1e11, 3e9), SIGMA, DENSITY, ZMAX)
    table = PlasticBranchGWSurface(_branch_law("jkr", 3e9), SIGMA, DENSITY, ZMAX)
    scale = DENSITY * 1.5 * math.pi * W * BETA
    top = closed.z_top
    for d, d_c, d_p in ((top - 2 * SIGMA,) * 3, (top - 1.5 * SIGMA, top - 2 * SIGMA, top - 2 * SIGMA),
                        (top - 1 * SIGMA, top - 1.5 * SIGMA, top - 3 * SIGMA)):
        a, b = closed.state(d, d_c, d_p), table.state(d, d_c, d_p)
        assert abs(a[0] - b[0]) < 1e-5 * max(abs(a[0]), scale)
        assert abs(a[1] - b[1]) < 1e-3 * max(abs(a[1]), scale * SIGMA)
        jumps = closed.jumps(d, d_c, d_p, d_p), table.jumps(d, d_c, d_p, d_p)
        # the loops agree to 2e-5 summit by summit, but the let-go edge moves with delta_p's table interpolation,
        # up to ~4e-3 of delta* just past yield (where the second state's edge lies): 1e-2 of the booked loops
        assert abs(jumps[0] - jumps[1]) < 1e-2 * max(abs(jumps[0]), scale * 1e-3 * SIGMA)
        # W_p = work in - stored energy at the deepest state: the stored energy's table error, absolute
        stored = closed.state(d_p, d_p, d_p)[1]
        assert abs(table.plastic_work(d_p) - closed.plastic_work(d_p)) < 1e-3 * stored


@pytest.mark.parametrize("name", ["maugis_dugdale", "dmt"])
def test_plastic_roller_on_the_law_closes_its_energy_audit_and_remembers_the_spot(name):
    """A rigid roller on the mean field of the law's Thornton-Ning summits. p_y = inf: the impact of the project's
    elastic rigid roller on the GW mean field of the same law (`RigidRoughRoller` on `GWBranchSurface`): the same
    restitution (1e-6, the runs' residuals) and booked loops (1e-5). p_y = 3 GPa, two impacts on the same spot:
    the driver's audit closes as the elastic law's own does (its tables' F = dU/d delta holds to ~1e-5 of the
    turnover: both laws measure 1.3e-5 - 2e-5, so 1e-4), the loss equals what the law books (plastic work and
    jumps) to 1e-4 of the impact's energy, the first impact loses more than on elastic summits, mostly as plastic
    work, the second less than the first (the spot is flattened)."""
    from continuum.laws.rough_rigid import RigidRoughRoller
    from continuum.rough.gw_branches import GWBranchSurface
    from continuum.rough.summits import SummitStatistics
    settings = DriverSettings(rtol=1e-7, max_bounces=1)
    mass, speed = 1e-8, 0.01
    kinetic = 0.5 * mass * speed**2
    elastic_law = _branch_law(name, math.inf)
    elastic = simulate(PlasticGWRoller(elastic_law, SIGMA, DENSITY, ZMAX, R_ROLLER, L_ROLLER),
                       mass, 0.0, impact_velocity=speed, settings=settings)
    surface = GWBranchSurface(SummitStatistics(SIGMA, DENSITY, BETA), elastic_law._laws[0], z_max=ZMAX)
    ref = simulate(RigidRoughRoller(surface, R_ROLLER, L_ROLLER), mass, 0.0, impact_velocity=speed,
                   settings=settings).bounces[0]
    # each restitution carries its run's residual (lost - booked, ~3e-7 of the impact's energy at rtol 1e-7)
    assert elastic.bounces[0].restitution == pytest.approx(ref.restitution, abs=1e-6)
    assert elastic.bounces[0].energy_booked == pytest.approx(ref.energy_booked, rel=1e-5, abs=1e-12 * kinetic)
    roller = PlasticGWRoller(_branch_law(name, 3e9), SIGMA, DENSITY, ZMAX, R_ROLLER, L_ROLLER)
    first = simulate(roller, mass, 0.0, impact_velocity=speed, settings=settings)
    work = roller.diagnostics()["plastic_work"]
    roller.reset()
    second = simulate(roller, mass, 0.0, impact_velocity=speed, settings=settings)
    for run in (elastic, first, second):
        assert run.audit["max_relative_error"] < 1e-4
        assert abs(run.bounces[0].energy_lost - run.bounces[0].energy_booked) < 1e-4 * kinetic
    lost = [r.bounces[0].energy_lost for r in (elastic, first, second)]
    assert lost[1] > 2.0 * lost[0] and lost[2] < 0.5 * lost[1]
    assert work > 0.5 * lost[1]
