"""The discrete plastic summits' per-summit state carried from contact to contact
(`continuum.laws.plastic_rough.PlasticSummitsPunch._rows`): it must be the summit law evaluated afresh on the present
deepest approaches whatever changed them, so the compiled tables and the release gap built from it are those the law
gives summit by summit."""
from __future__ import annotations

import numpy as np
import pytest

from continuum.laws.plastic_rough import PlasticSummitsPunch
from continuum.rough.plastic_branches import PlasticBranchSummitLaw
from continuum.rough.plastic_kernel import compiled_tables

# the calibrated set's summits (as tests/continuum/test_plastic_branches.py)
BETA, W, E, P_Y, Z0, SIGMA = 0.2e-6, 0.192, 89e9, 11e9, 0.207e-9, 6e-9
DMAX = 30 * SIGMA


@pytest.fixture(scope="module")
def md():
    return PlasticBranchSummitLaw("maugis_dugdale", BETA, W, E, P_Y, z0=Z0, delta_max=DMAX)


def _fresh(law, dm):
    r0, dp0 = law.flattening(dm)
    return np.vstack([r0, dp0, law.plastic_work(dm), law.jump_in(r0), law.jump_out(r0)])


def _release_reference(punch, law):
    """The release gap's rule evaluated on every summit afresh."""
    r_p, d_p = law.flattening(punch.delta_max)
    if not punch._met.any():
        return float(np.max(punch.heights - d_p)) - punch.z_top + law.max_stretch
    met = punch._met
    held = float(np.max(punch.heights[met] - d_p[met] - law.jump_out(r_p[met]))) - punch.z_top
    return max(held, punch._approach_reach) if punch._approach_reach > 0.0 else held


def test_carried_rows_follow_every_change_of_the_deepest_approaches(md):
    rng = np.random.default_rng(7)
    n = 300
    punch = PlasticSummitsPunch(md, -np.sort(rng.uniform(0.0, 3 * SIGMA, n)))
    assert punch.release_gap() == pytest.approx(_release_reference(punch, md), rel=1e-14, abs=1e-24)
    yielded_before = 0
    for round_ in range(4):
        # in-place changes, as `accept`, `compiled_commit` and the wet law's take-back make them
        idx = rng.choice(n, 40, replace=False)
        punch.delta_max[idx] = rng.uniform(0.0, DMAX, idx.size)
        if round_ == 2:
            punch.delta_max[:3] = DMAX            # the tallest summits flattened: the highest flattened one moves
        punch._met[:] = False
        punch._met[rng.choice(n, 5, replace=False)] = round_ % 2 == 1
        rows = punch._rows(md)
        np.testing.assert_allclose(rows, _fresh(md, punch.delta_max), rtol=1e-13, atol=0.0)
        assert punch.release_gap() == pytest.approx(_release_reference(punch, md), rel=1e-13, abs=1e-24)
        P0, T0 = compiled_tables(md, punch._below, punch.delta_max, 1e-9, md.max_stretch, -np.inf)
        P1, T1 = compiled_tables(md, punch._below, punch.delta_max, 1e-9, md.max_stretch, -np.inf, rows=rows)
        np.testing.assert_array_equal(P0, P1)
        np.testing.assert_allclose(T1[5], T0[5], rtol=1e-13, atol=0.0)
        yielded_before = max(yielded_before, int(np.sum(punch.delta_max > md.yield_approach)))
    assert yielded_before > 0                        # the flattened summits' rows were tested, not only beta's
    # a fresh history returns every summit to beta's values
    punch.forget_history()
    np.testing.assert_allclose(punch._rows(md), _fresh(md, punch.delta_max), rtol=1e-13, atol=0.0)
