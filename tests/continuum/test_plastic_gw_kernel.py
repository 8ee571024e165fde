"""The compiled sums of the plastic branch mean field (`continuum.rough.plastic_gw_kernel`) against the NumPy form
they replace (`PlasticBranchGWSurface` with `compiled = False`): the same quadrature, so the same values up to the
order of the sums and the root finder's tolerance on the set edges (xtol 1e-15 of the edge, rtol 1e-14). The
tolerance, 1e-9 of the value (or of the summits' pull-off scale where the value crosses zero), sits a hundred times
below the quadrature's own error against the exact integral (1e-7, tests/continuum/test_plastic_mean_field.py):
the fast form changes nothing the quadrature resolves, and a wrong node, weight, branch or edge moves the sums by
1e-4 or more."""
from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from continuum.rough import plastic_gw_kernel as kernel
from continuum.rough.plastic_branches import PlasticBranchSummitLaw
from continuum.rough.plastic_gw_branches import BranchRollerFootprint, PlasticBranchGWSurface
from continuum.rough.plastic_summits import _GL_W, _GL_X

BETA, W, Z0 = 1e-6, 0.1, 0.3e-9          # summit tip radius (m), work of adhesion (J/m^2), MD range (m)
SIGMA, DENSITY, ZMAX = 5e-9, 1e13, 4.0   # summit heights rms (m), summits per m^2, truncation (sigma)
R_ROLLER, L_ROLLER = 1e-3, 1e-3          # roller radius and length (m)
TOL = 1e-9


def _pair(surface):
    slow = copy.copy(surface)
    slow.compiled = False
    return surface, slow


@pytest.mark.parametrize("name,p_y", [("maugis_dugdale", 3e9), ("dmt", 3e9), ("maugis_dugdale", math.inf)])
@pytest.mark.parametrize("roller", [False, True])
def test_compiled_sums_equal_the_numpy_form(name, p_y, roller):
    law = PlasticBranchSummitLaw(name, BETA, W, 1e11, p_y, z0=Z0, delta_max=30 * SIGMA)
    surf = (BranchRollerFootprint(law, SIGMA, DENSITY, ZMAX, R_ROLLER, L_ROLLER) if roller
            else PlasticBranchGWSurface(law, SIGMA, DENSITY, ZMAX))
    fast, slow = _pair(surf)
    assert fast.compiled
    scale = DENSITY * 2.0 * math.pi * W * BETA * (L_ROLLER * math.sqrt(2 * R_ROLLER * SIGMA) if roller else 1.0)
    top = surf.z_top
    states = [(top - 2 * SIGMA,) * 3, (top - 1.5 * SIGMA, top - 2 * SIGMA, top - 2 * SIGMA),
              (top - 1 * SIGMA, top - 1.5 * SIGMA, top - 3 * SIGMA), (top + 0.5 * Z0, math.inf, top),
              (top - 0.2 * SIGMA, top - 0.3 * SIGMA, top - 0.3 * SIGMA),
              (top - 4 * SIGMA, top - 4 * SIGMA, top - 5 * SIGMA), (top + 2 * SIGMA, top - 1 * SIGMA, top - 3 * SIGMA)]
    for d, d_c, d_p in states:
        assert fast.sets(d, d_c, d_p) == pytest.approx(slow.sets(d, d_c, d_p), rel=1e-12, abs=1e-14 * SIGMA)
        for what in ("state", "axis_state"):
            a, b = getattr(fast, what)(d, d_c, d_p), getattr(slow, what)(d, d_c, d_p)
            assert abs(a[0] - b[0]) <= TOL * max(abs(b[0]), scale), (what, d, d_c, d_p)
            assert abs(a[-1] - b[-1]) <= TOL * max(abs(b[-1]), DENSITY * 1e-3), (what, d, d_c, d_p)
            if what == "state":
                assert abs(a[1] - b[1]) <= TOL * max(abs(b[1]), scale * SIGMA * 1e-3), (d, d_c, d_p)
        a, b = fast.plastic_work(d_p), slow.plastic_work(d_p)
        assert abs(a - b) <= TOL * max(abs(b), scale * SIGMA * 1e-3), d_p
        for d_0 in (d_p, d_p + 0.5 * SIGMA):
            a, b = fast.jumps(d, d_c, d_p, d_0), slow.jumps(d, d_c, d_p, d_0)
            assert abs(a - b) <= TOL * max(abs(b), scale * SIGMA * 1e-3), (d, d_c, d_p, d_0)


@pytest.mark.parametrize("roller", [False, True])
def test_compiled_nodes_are_the_numpy_quadratures(roller):
    """`gl_nodes` gives `PlasticGWSurface._nodes`'s nodes and weights (so its node bound too), on spans inside the
    template, past it, below the floor (a footprint's deep axis) and split at breaks."""
    law = PlasticBranchSummitLaw("maugis_dugdale", BETA, W, 1e11, 3e9, z0=Z0, delta_max=30 * SIGMA)
    surf = (BranchRollerFootprint(law, SIGMA, DENSITY, ZMAX, R_ROLLER, L_ROLLER) if roller
            else PlasticBranchGWSurface(law, SIGMA, DENSITY, ZMAX))
    for lo, hi, floor, brk in ((0.1 * SIGMA, 2 * SIGMA, -10 * SIGMA, ()),
                               (-SIGMA, 3 * SIGMA, -9 * SIGMA, (0.7 * SIGMA,)),
                               (-1e-3, 2 * SIGMA, -8 * SIGMA, (1e-12,)),
                               (0.0, 1e-3 * SIGMA, -8 * SIGMA, ()),
                               (-20 * SIGMA, 30 * SIGMA, -8 * SIGMA, (0.0, 5 * SIGMA))):
        x, w = surf._nodes(lo, hi, floor, breaks=brk)
        breaks = np.array([law.yield_approach, *brk])
        y, v = kernel.gl_nodes(lo, hi, floor, surf._offsets(), surf._first, surf.panel_width * SIGMA, breaks,
                               surf._root_at_top, _GL_X, _GL_W)
        assert x.size == y.size and x.size > 0
        assert np.allclose(y, x, rtol=0.0, atol=1e-15 * max(abs(lo), abs(hi)))
        assert np.allclose(v, w, rtol=1e-12, atol=0.0)
