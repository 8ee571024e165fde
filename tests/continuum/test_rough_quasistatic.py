"""Quasi-static approach-retraction cycles of summit models (continuum/rough/quasistatic.py) against the
single-summit closed forms and the mean-field limit of many summits."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import special

from continuum.reference import jkr as jkr_ref
from continuum.rough.branch_laws import make_summit_law
from continuum.rough.gw_branches import GWBranchSurface
from continuum.rough.quasistatic import discrete_cycle, gw_cycle, separation_path, thresholds
from continuum.rough.summits import SummitStatistics
from nanoimpact.errors import InputError

BETA, W, E = 0.2e-6, 0.12, 10e9
DC = float(jkr_ref.critical_approach(BETA, W, E))
PC = float(jkr_ref.pull_off_force(BETA, W))


def test_one_jkr_summit_gives_the_fuller_tabor_loop_and_the_pull_off_force():
    """A single JKR summit under displacement control: the cycle's tension peaks at P_c on retraction (the
    load-controlled pull-off point lies on the stable branch) and the area of the loop is Fuller & Tabor's
    0.9355 P_c delta_c (continuum.reference.jkr.loop_area). Trapezoids along a path of step h: each of the two
    force jumps costs at most |jump| h/2, |jump| <= P_c, and the smooth parts O(h^2)."""
    z = 3e-9
    law = make_summit_law("jkr", BETA, W, E, delta_max=10 * DC)
    step = DC / 400
    cycle = discrete_cycle(law, [z], separation_path(z + 2 * DC, z - 2 * DC, step))
    loop = float(jkr_ref.loop_area(BETA, W, E))
    assert cycle.hysteresis_energy == pytest.approx(loop, abs=PC * step)
    # the sampled minimum misses the true one by the curvature of P near its minimum: (1/2) P'' h^2, tiny here
    assert cycle.pull_off_force == pytest.approx(PC, rel=1e-3)
    # on approach the summit snaps in at touch (delta = 0) to -8/9 P_c (JKR at a0), from zero
    approach = cycle.force[:cycle.turn + 1]
    k = int(np.argmax(approach != 0.0))
    assert cycle.separation[k] == pytest.approx(z, abs=step) and np.all(approach[:k] == 0.0)
    assert approach[k] == pytest.approx(-8 / 9 * PC, rel=0.02)


def test_thresholds_follow_the_jump_points():
    """zeta holds the lowest attached height: it follows s + delta_in down and s + delta_out up."""
    path = np.array([3.0, 2.0, 1.0, 2.0, 3.0, 4.0])
    assert thresholds(path, 0.0, -1.5).tolist() == [3.0, 2.0, 1.0, 1.0, 1.5, 2.5]


def test_many_discrete_summits_tend_to_the_gw_mean_field():
    """Summit heights at the Gaussian quantiles (i + 1/2)/N are a quadrature of the GW integral: the discrete
    sum per unit area must approach the mean-field pressure and area, with an error falling like 1/N. Checked at
    N = 4000 (1 % of the largest force) for a Maugis-Dugdale law, on approach and retraction alike, and the
    hysteresis (2 %). Not the pull-off: on retraction the largest net tension comes from the few summits
    above ~3 sigma (5 of the 4000 here), a small difference of large compressive and tensile sums, where no
    quadrature of N points converges like 1/N: that is the few-summits problem the ensembles address."""
    sigma, n_sum = 3e-9, 4000
    law = make_summit_law("maugis_dugdale", BETA, W, E, z0=0.3e-9, delta_max=12 * sigma)
    area = n_sum / 1e13
    heights = sigma * special.ndtri((np.arange(n_sum) + 0.5) / n_sum)
    surface = GWBranchSurface(SummitStatistics(sigma, 1e13, BETA), law, z_max=float(heights.max() / sigma))
    path = separation_path(4 * sigma, 1 * sigma, sigma / 40)
    gw = gw_cycle(surface, area, path, 0.0)
    disc = discrete_cycle(law, heights, path)
    scale = np.max(np.abs(gw.force))
    assert np.max(np.abs(gw.force - disc.force)) < 0.01 * scale
    assert np.max(np.abs(gw.contact_area - disc.contact_area)) < 0.01 * np.max(gw.contact_area)
    assert disc.hysteresis_energy == pytest.approx(gw.hysteresis_energy, rel=0.02)


def test_the_summits_mean_plane_offset_shifts_the_gw_curve():
    """gw_cycle's summit_mean_height moves the curve along the separation by exactly that offset."""
    sigma = 3e-9
    law = make_summit_law("jkr", BETA, W, E, delta_max=12 * sigma)
    surface = GWBranchSurface(SummitStatistics(sigma, 1e13, BETA), law, z_max=4.0)
    path = separation_path(4 * sigma, 1 * sigma, sigma / 10)
    a = gw_cycle(surface, 1e-10, path, 0.0)
    b = gw_cycle(surface, 1e-10, path + 1e-9, 1e-9)
    np.testing.assert_allclose(a.force, b.force, rtol=1e-12, atol=1e-30)


def test_bad_paths_are_refused_in_one_line():
    with pytest.raises(InputError, match="deepest"):
        separation_path(1e-9, 2e-9, 1e-10)
    with pytest.raises(InputError, match="step"):
        separation_path(2e-9, 1e-9, 0.0)
    law = make_summit_law("jkr", BETA, W, E, delta_max=1e-9)
    with pytest.raises(InputError, match="beyond its law's table"):
        discrete_cycle(law, [5e-9], separation_path(6e-9, 1e-9, 1e-10))
    with pytest.raises(InputError, match="must decrease strictly"):
        discrete_cycle(law, [0.0], np.array([2e-9, 1e-9, 1.5e-9, 1e-9, 2e-9]))
    assert math.isfinite(PC)
