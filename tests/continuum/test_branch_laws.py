"""Summit laws under displacement control (JKR, DMT, Maugis-Dugdale) and their GW average (coated summits:
tests/continuum/test_coated.py)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from continuum.laws.rough_rigid import RigidRoughRoller
from continuum.reference import jkr as jkr_ref
from continuum.reference import maugis as md_ref
from continuum.rough.branch_laws import DUGDALE_FACTOR, make_summit_law
from continuum.rough.datum import tallest_summit
from continuum.rough.gw import GWJKRSurface
from continuum.rough.gw_branches import GWBranchSurface, quadrature_pressure
from continuum.rough.summits import SummitStatistics, gw_integral

BETA, W, E = 0.2e-6, 0.12, 10e9                 # the `paper` set's summits
SIGMA, DENSITY = 6e-9, 1e13
PC = float(jkr_ref.pull_off_force(BETA, W))
DC = float(jkr_ref.critical_approach(BETA, W, E))
DMAX = 30 * SIGMA


def _law(name, z0=0.3e-9):
    return make_summit_law(name, BETA, W, E, z0=z0, delta_max=DMAX)


# ------------------------------------------------------------------------------ single summits
def test_jkr_law_has_the_fuller_tabor_jumps_and_loop():
    law = _law("jkr")
    assert law.delta_in == 0.0 and law.reach == 0.0
    assert law.delta_out == pytest.approx(-DC, rel=1e-6, abs=0)
    assert float(law.force(1e-15 * DC, "approach")) == pytest.approx(-8 / 9 * PC, rel=1e-5, abs=0)
    assert float(law.force(-0.5 * DC, "approach")) == 0.0
    assert law.loop_energy == pytest.approx(0.9355027833 * PC * DC, rel=1e-5, abs=0)
    d = np.array([-0.99, -0.5, 0.0, 1.0, 10.0, 100.0]) * DC
    np.testing.assert_allclose(law.force(d, "retreat"), jkr_ref.force_from_approach(d, BETA, W, E), rtol=1e-6,
                               atol=2e-5 * PC)
    u = np.asarray(jkr_ref.energy_from_approach(d, BETA, W, E))
    np.testing.assert_allclose(law.energy(d, "retreat"), u, rtol=1e-5, atol=3e-5 * PC * DC)


def test_dmt_law_has_no_loop_and_pulls_off_at_two_pi_beta_dgamma():
    law = _law("dmt")
    assert law.loop_energy == pytest.approx(0.0, abs=1e-9 * PC * DC)
    assert law.delta_in == law.delta_out == 0.0
    assert law.load_pull_off_force == pytest.approx(2 * math.pi * BETA * W, rel=1e-9, abs=0)
    d = np.array([0.5, 3.0, 30.0]) * DC
    hertz = 4 / 3 * E * math.sqrt(BETA) * d**1.5
    np.testing.assert_allclose(law.force(d, "approach"), hertz - 2 * math.pi * BETA * W, rtol=1e-5, atol=0)
    np.testing.assert_allclose(law.energy(d, "retreat"), 0.4 * hertz * d - 2 * math.pi * BETA * W * d,
                               rtol=1e-4, atol=0)


def test_maugis_dugdale_branches_meet_at_the_edge_of_contact():
    """The non-contact (a = 0) branch derived in branch_laws ends where Maugis' contact branch starts."""
    for z0 in (0.05e-9, 0.3e-9, 3e-9):
        sigma0 = DUGDALE_FACTOR * W / z0
        h0, k = W / sigma0, sigma0 / E
        c_e = BETA * (-(2 - 4 / math.pi) * k + math.sqrt((2 - 4 / math.pi) ** 2 * k * k + 2 * h0 / BETA))
        lam = float(md_ref.md_parameter(BETA, W, E, sigma0))
        a_s, p_s, d_s = (float(x) for x in md_ref.md_scales(BETA, W, E))
        A = 1e-7
        p, d = md_ref.md_force_and_approach(A, lam)
        m = float(md_ref.md_m_of_A(A, lam))
        assert m * A * a_s == pytest.approx(c_e, rel=1e-5, abs=0)
        assert float(d) * d_s == pytest.approx(-2 * sigma0 * c_e / E, rel=1e-5, abs=0)
        assert float(p) * p_s == pytest.approx(-math.pi * sigma0 * c_e**2, rel=1e-5, abs=0)


@pytest.mark.parametrize("lam", [0.05, 1.0, 30.0])
def test_one_maugis_solve_gives_force_approach_and_m(lam):
    """`md_solution` (one root per radius, what the Maugis-Dugdale summit law is built from) is
    `md_force_and_approach` and `md_m_of_A` (a root each), number for number, with m = c/a >= 1."""
    A = np.geomspace(1e-6, 30.0, 60)
    p, d, m = md_ref.md_solution(A, lam)
    p2, d2 = md_ref.md_force_and_approach(A, lam)
    np.testing.assert_array_equal(p, p2)
    np.testing.assert_array_equal(d, d2)
    np.testing.assert_array_equal(m, md_ref.md_m_of_A(A, lam))
    assert np.all(m >= 1.0)


@pytest.mark.parametrize("z0", [0.05e-9, 0.3e-9, 1e-9, 8e-9])
def test_maugis_dugdale_pull_off_matches_the_reference_solution(z0):
    law = _law("maugis_dugdale", z0)
    ref = float(md_ref.md_pull_off_force(BETA, W, E, DUGDALE_FACTOR * W / z0))
    assert law.load_pull_off_force == pytest.approx(ref, rel=2e-3, abs=0)


def test_maugis_dugdale_goes_from_dmt_to_jkr():
    z0s = [20e-9, 8e-9, 3e-9, 1e-9, 0.3e-9, 0.1e-9, 0.02e-9, 0.005e-9]
    laws = [_law("maugis_dugdale", z) for z in z0s]
    lams = [law.extra["maugis_lambda"] for law in laws]
    loops = [law.loop_energy / (PC * DC) for law in laws]
    pulls = [law.load_pull_off_force / (math.pi * BETA * W) for law in laws]
    assert lams == sorted(lams)
    assert all(b >= a for a, b in zip(loops, loops[1:]))            # the loop grows with lambda
    assert all(b <= a + 1e-9 for a, b in zip(pulls, pulls[1:]))     # pull-off falls from 2 to 1.5
    assert loops[0] < 1e-6 and pulls[0] == pytest.approx(2.0, rel=5e-3, abs=0)          # lambda ~ 0.02: DMT
    assert loops[-1] == pytest.approx(0.9355, rel=0.03, abs=0)                         # lambda ~ 70: JKR
    assert pulls[-1] == pytest.approx(1.5, rel=2e-3, abs=0)
    assert laws[-1].delta_out == pytest.approx(-DC, rel=0.01, abs=0)


# ------------------------------------------------------------------------------ GW averages
def _states(n, seed=0):
    rng = np.random.default_rng(seed)
    h = rng.uniform(-4, 4.5, n) * SIGMA
    kind = np.arange(n) % 3
    zeta = np.where(kind == 0, np.inf, np.where(kind == 1, h - DC * rng.uniform(0, 1, n),
                                                h - DC - SIGMA * rng.uniform(0, 1, n)))
    return h, zeta


def test_generic_surface_with_jkr_summits_is_the_tabulated_gw_jkr_surface():
    stats = SummitStatistics(SIGMA, DENSITY, BETA)
    generic = GWBranchSurface(stats, _law("jkr"), z_max=4.07)
    tables = GWJKRSurface(stats, W, E, z_max=4.07)
    d, zeta = _states(600)
    scale = DENSITY * PC
    for fn in ("pressure", "energy", "contact_fraction"):
        a, b = getattr(generic, fn)(d, zeta), getattr(tables, fn)(d, zeta)
        norm = {"pressure": scale, "energy": scale * DC, "contact_fraction": DENSITY * math.pi * BETA * DC}[fn]
        assert np.max(np.abs(a - b) / np.maximum(np.abs(b), norm)) < 2e-5, fn
    # the law's delta_out is found on its tabulated curve (1e-6 of delta_c from the exact fold)
    np.testing.assert_allclose(generic.contacts(d, zeta), tables.contacts(d, zeta), rtol=1e-4)
    np.testing.assert_allclose(generic.dissipation(zeta - 1e-9, zeta + 1e-9),
                               tables.dissipation(zeta - 1e-9, zeta + 1e-9), rtol=2e-5, atol=1e-30)


def test_dmt_surface_is_the_closed_form_gw_integral():
    stats = SummitStatistics(SIGMA, DENSITY, BETA)
    surf = GWBranchSurface(stats, _law("dmt"), z_max=None)
    h = np.array([-2.0, 0.0, 1.5, 3.0])
    p = surf.pressure(h * SIGMA, np.inf)
    tail = 0.5 * np.array([math.erfc(x / math.sqrt(2)) for x in h])
    closed = DENSITY * (4 / 3 * E * math.sqrt(BETA) * SIGMA**1.5 * gw_integral(1.5, h) - 2 * math.pi * BETA * W * tail)
    np.testing.assert_allclose(p, closed, rtol=2e-5)


@pytest.mark.parametrize("z0", [0.3e-9, 1e-9])
def test_maugis_dugdale_surface_matches_adaptive_quadrature(z0):
    stats = SummitStatistics(SIGMA, DENSITY, BETA)
    surf = GWBranchSurface(stats, _law("maugis_dugdale", z0), z_max=4.07)
    d, zeta = _states(9, seed=3)
    for di, zi in zip(d, zeta):
        ref = quadrature_pressure(float(di), float(zi), surf)
        assert abs(float(surf.pressure(di, zi)) - ref) < 5e-5 * DENSITY * PC


@pytest.mark.parametrize("name", ["jkr", "maugis_dugdale", "dmt"])
def test_quasi_static_cycle_of_the_rigid_roller_closes_on_the_booked_loss(name):
    """-oint W dh over approach and retreat equals the summed summit loops (0 for DMT)."""
    stats = SummitStatistics(SIGMA, DENSITY, BETA)
    z_max = tallest_summit(SIGMA, DENSITY, 5e-6, 3.28e-3)["z_max"]
    roller = RigidRoughRoller(GWBranchSurface(stats, _law(name), z_max=z_max), 5e-6, 3.28e-3)
    roller.prepare(0.6e-9, 1.4e-3, 9.80665)
    roller.reset()
    path = np.concatenate([np.linspace(roller.touch_gap, -3e-9, 2001),
                           np.linspace(-3e-9, roller.release_gap(), 2001)[1:]])
    work = 0.0
    for a, b in zip(path[:-1], path[1:]):
        work += 0.5 * (roller.force(a) + roller.force(b)) * (b - a)
        roller.accept(b)
    booked = roller.dissipated(roller.release_gap())
    scale = 0.5 * 0.6e-9 * 1.4e-3**2            # the paper's impact energy
    assert abs(-work - booked) < 1e-4 * scale
    if name == "dmt":
        assert booked == 0.0
    else:
        assert booked > 0.01 * scale
