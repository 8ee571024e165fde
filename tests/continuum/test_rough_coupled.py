"""The GW law is continuous where a summit threshold changes branch, so the rough roller's coupled
pressure-deflection solve can converge (issue 12; docs/halfspace.md, docs/rough-gw.md). The whole
runs that crashed are in tests/continuum/test_scene_ranges.py (the "-sticks" points).

A threshold leaves the stretched window at xi = 0 (approach branch) and at xi = -x_r (release
branch). Evaluated from different tables, the law used to jump there by the tables' interpolation
error, 1e-10 - 2e-6 of n P_c: a residual no coupled solve can reduce. Here the two sides of each
join are probed 1e-12 of the release stretch apart, so what a continuous law can change across the
probe is ~1e-12 of the scale; the old jumps were at least 2e-10 (and up to 2e-6).
"""
import numpy as np
import pytest

from continuum.reference import jkr
from continuum.rough.gw import GWJKRSurface
from continuum.rough.summits import SummitStatistics, expected_max_height

BETA, DGAMMA, ESTAR, DENSITY = 1e-7, 0.1, 38e9, 1e14
DELTA_C = float(jkr.critical_approach(BETA, DGAMMA, ESTAR))
ZMAX = float(expected_max_height(1e5))
PROBE = 1e-12           # relative to the release stretch
JUMP_BOUND = 1e-10      # relative to n P_c, n P_c delta_c, n pi beta delta_c


@pytest.mark.parametrize("ratio,resolution,detachment,z_max", [
    (0.3, "standard", "displacement", ZMAX), (13.7, "fast", "displacement", ZMAX),
    (13.7, "standard", "load", None), (100.0, "standard", "displacement", ZMAX)])
def test_no_jump_where_a_threshold_joins_the_approach_or_the_release_branch(ratio, resolution, detachment, z_max):
    s = GWJKRSurface(SummitStatistics(ratio * DELTA_C, DENSITY, BETA), DGAMMA, ESTAR, z_max=z_max,
                     detachment=detachment, resolution=resolution)
    top = s.z_max if s.truncated else 5.0 * s.sigma
    D = s.release_stretch
    d = top + np.linspace(-4.0 * s.sigma, 0.999 * D, 3001)     # below and above z_max
    for j, f in enumerate((s.pressure, s.energy, s.contact_fraction)):
        scale = s._as[j]
        release = np.abs(f(d, d - D * (1 + PROBE)) - f(d, d - D * (1 - PROBE))) / scale
        approach = np.abs(f(d, d + D * PROBE) - f(d, d - D * PROBE)) / scale
        assert release.max() < JUMP_BOUND and approach.max() < JUMP_BOUND
