"""A body dropped through the impact driver (continuum/dynamics/driver.py) on a tabulated hysteretic law
(continuum/dynamics/tabulated_cycle.py), against closed forms: a JKR summit's displacement-controlled loop (Fuller &
Tabor; `continuum.reference.jkr.loop_area`) is what the body loses, e^2 = 1 - W/K0, and a body arriving with less
than the loop sticks; without adhesion nothing is lost. The driver's rebound also equals the quasi-static energy
balance through the same table (`bem_impact.impact_outcome`, exact for a rate-independent law up to gravity's work
over the contact). And the roller's geometry (`bem_impact.Roller`): composite heights, the GW strips."""
from __future__ import annotations

import math

import numpy as np
import pytest

from continuum.dynamics.driver import DriverSettings, simulate
from continuum.dynamics.tabulated_cycle import PiecewiseLinear, TabulatedCycleLaw
from continuum.reference import hertz, jkr
from continuum.rough.bem_impact import Roller, approach_work, impact_outcome, roller_gw_cycle, turn_for_energy
from continuum.rough.branch_laws import make_summit_law
from continuum.rough.gw_branches import GWBranchSurface
from continuum.rough.quasistatic import ForceCycle, discrete_cycle, gw_cycle, separation_path
from continuum.rough.summits import SummitStatistics

G, MASS = 9.80665, 1e-15
R, W, E = 1e-6, 0.1, 50e9


def _drop(cycle, mass=MASS):
    """The driver's first impact of a body whose energy turns it at the table's deepest state."""
    law = TabulatedCycleLaw(cycle, "test")
    k0 = approach_work(cycle)[-1] - mass * G * (cycle.separation[0] - cycle.separation[cycle.turn])
    run = simulate(law, mass, G, impact_velocity=math.sqrt(2 * k0 / mass), settings=DriverSettings(max_bounces=1))
    return run, law, k0


@pytest.mark.parametrize("times_loop, stuck", [(3.0, False), (0.8, True)])
def test_jkr_summit_dropped_through_the_driver_loses_the_fuller_tabor_loop(times_loop, stuck):
    loop = float(jkr.loop_area(R, W, E))
    dc = float(jkr.critical_approach(R, W, E))
    law = make_summit_law("jkr", R, W, E, delta_max=200 * dc)
    step = dc / 40
    deep = discrete_cycle(law, [0.0], separation_path(2 * dc, -100 * dc, step))
    turn = turn_for_energy(deep, times_loop * loop)
    cycle = discrete_cycle(law, [0.0], separation_path(2 * dc, turn, step))
    run, tab, k0 = _drop(cycle)
    b = run.bounces[0]
    assert (run.status == "stuck") is stuck
    # the turn solved on the table's exact approach work is where the driver's body turns
    speed = math.sqrt(2 * k0 / MASS)
    assert TabulatedCycleLaw(cycle, "c").turn_for(speed, MASS, G, below=step) == pytest.approx(-b.max_penetration,
                                                                                     abs=1e-4 * step)
    assert abs(tab.diagnostics()["turn_shift_over_step"]) < 1e-3       # it turned where the table turns
    assert run.audit["max_relative_error"] < 1e-5
    if stuck:
        assert k0 < loop
        return
    # the loop the body ran is the closed form's, within the trapezoids' jump error (P_c step ~ 1 % here)
    assert b.energy_booked == pytest.approx(loop, rel=0.01)
    assert b.restitution**2 == pytest.approx(1 - loop / k0, rel=0.01)
    # and the driver's rebound is the energy balance through the same table (gravity's work ~1e-9 of K0)
    assert b.restitution**2 == pytest.approx(impact_outcome(cycle, k0).restitution**2, rel=1e-5)
    assert b.rebound_height == pytest.approx(b.v_rebound**2 / (2 * G), rel=1e-6)


def test_hertz_table_returns_the_energy():
    """No adhesion: approach and retraction coincide, e = 1 to the driver's tolerance, nothing booked."""
    s = np.linspace(1e-9, -2e-9, 301)
    f = np.where(s < 0, np.asarray(hertz.sphere_force(np.maximum(-s, 0.0), R, E)), 0.0)
    path = np.concatenate([s, s[-2::-1]])
    cycle = ForceCycle(path, np.concatenate([f, f[-2::-1]]), np.zeros(path.size), s.size - 1)
    run, _, _ = _drop(cycle)
    assert run.status != "stuck"
    assert run.bounces[0].restitution == pytest.approx(1.0, abs=1e-6)
    assert abs(run.bounces[0].energy_booked) < 1e-6 * float(hertz.sphere_energy(2e-9, R, E))


def test_piecewise_linear_integral_is_exact():
    p = PiecewiseLinear([0.0, 1.0, 3.0], [0.0, 2.0, -2.0])
    assert p.integral(3.0) == pytest.approx(1.0 + 0.0, abs=1e-15)
    assert p.integral(0.5) == pytest.approx(0.25, abs=1e-15)
    assert p(-1.0) == pytest.approx(-2.0) and p.integral(-1.0) == pytest.approx(1.0)   # y = 2x extended: int_0^-1
    assert p(5.0) == -2.0 and p.integral(4.0) == pytest.approx(1.0 - 2.0)


def test_roller_composite_and_gw_strips():
    """The composite surface is the map minus the roller's drop with zero mean, its drop (x - L/2)^2/2R; with the
    roller's radius going to infinity the GW strips add up to the flat patch's mean field."""
    n, size = 32, 100e-9
    h = np.random.default_rng(1).normal(size=(n, n)) * 1e-9
    h -= h.mean()
    roller = Roller(1e-6, size)
    c = roller.heights(h)
    assert abs(c.mean()) < 1e-24
    x = np.arange(n) * size / n
    assert np.allclose(h - c, roller.drop(x, n)[:, None], rtol=0, atol=1e-24)
    assert roller.drop(x, n)[n // 2 + 4] - roller.drop(x, n)[n // 2] == pytest.approx((4 * size / n) ** 2 / 2e-6)
    assert roller.mass(2000.0) == pytest.approx(2000.0 * math.pi * 1e-12 * size)
    stats = SummitStatistics(1e-9, 1e15, 100e-9)
    surf = GWBranchSurface(stats, make_summit_law("maugis_dugdale", 100e-9, 0.1, 50e9, z0=0.2e-9, delta_max=2e-8),
                           z_max=3.0)
    path = separation_path(4e-9, 0.0, 0.05e-9)
    flat = gw_cycle(surf, size * size, path, 0.0)
    far = roller_gw_cycle(surf, Roller(1e3, size), n, path, 0.0)
    assert np.allclose(far.force, flat.force, rtol=1e-6, atol=1e-12 * np.abs(flat.force).max())
    near = roller_gw_cycle(surf, roller, n, path, 0.0)
    assert near.hysteresis_energy < flat.hysteresis_energy          # the curved body reaches fewer summits
