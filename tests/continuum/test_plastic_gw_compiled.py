"""The plastic GW mean field as a law of the compiled contact phase (`continuum.numerics.kernel_laws.LAW_PLASTIC_GW`,
`continuum.rough.plastic_gw_kernel.law_value`) against the same law on the driver's Python stepper
(`PlasticGWPunch.compiled_contact = False`), the reference.

Point by point both call the same compiled sums on the same history, so force, stored energy, the loss booked, the
loss at release and the release gap agree to round-off (1e-12 relative; a wrong d_0, the history a loss depends on,
moves the loss by far more: the negative control). Whole impacts take different step sequences (the error estimate
of a step is a difference of the stages, so round-off in its summation order moves a step size by ~1e-8, and the
summit law's piecewise-linear tables make the force's derivatives jump): the runs then agree to the accuracy the
integration reaches, which the driver's own energy audit measures (the largest energy error of the run over its
energy turnover), not to rtol.
"""
from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from continuum.dynamics.driver import DriverSettings, simulate
from continuum.laws.plastic_rough import PlasticGWPunch, PlasticGWRoller
from continuum.numerics import compiled_contact as cc
from continuum.numerics import kernel_laws as kl
from continuum.rough import plastic_gw_kernel as pgk
from continuum.rough.plastic_branches import PlasticBranchSummitLaw
from continuum.rough.plastic_gw_branches import PlasticBranchGWSurface

BETA, W, Z0 = 1e-6, 0.1, 0.3e-9          # summit tip radius (m), work of adhesion (J/m^2), MD range (m)
SIGMA, DENSITY, ZMAX = 5e-9, 1e13, 4.0   # summit heights rms (m), summits per m^2, truncation (sigma)
R_ROLLER, L_ROLLER = 1e-3, 1e-3          # roller radius and length (m)
AREA = 1e-10                             # the flat punch's nominal area (m^2)


def _law(name="maugis_dugdale", p_y=3e9):
    return PlasticBranchSummitLaw(name, BETA, W, 1e11, p_y, z0=Z0, delta_max=30 * SIGMA)


def _contact_law(roller, name="maugis_dugdale"):
    if roller:
        return PlasticGWRoller(_law(name), SIGMA, DENSITY, ZMAX, R_ROLLER, L_ROLLER)
    return PlasticGWPunch(PlasticBranchGWSurface(_law(name), SIGMA, DENSITY, ZMAX), AREA)


def _close(a, b, scale):
    return abs(a - b) <= 1e-12 * max(abs(a), abs(b), scale)


def _histories(law):
    """A virgin contact, and one on a spot flattened by an earlier contact, taken part way into this one."""
    yield law
    flat = copy.deepcopy(law)
    flat.accept(-2.0 * SIGMA)
    flat.reset()                                # d_0 = d_p: the spot's flattening before this contact
    flat.accept(-1.0 * SIGMA)
    flat.accept(-2.5 * SIGMA)                   # deeper than before: d_p moves, d_0 stays
    flat.accept(-2.0 * SIGMA)
    yield flat


@pytest.mark.parametrize("name", ["maugis_dugdale", "dmt"])
@pytest.mark.parametrize("roller", [False, True])
def test_the_compiled_law_is_the_python_law_point_by_point(roller, name):
    law = _contact_law(roller, name)
    assert law.surface.compiled
    gaps = np.linspace(-3.0 * SIGMA, law.touch_gap + 2.0 * Z0, 41)
    for state in _histories(law):
        c = state.compiled(0.0)
        assert c.kind == kl.LAW_PLASTIC_GW
        f_scale = abs(state.force(-2.0 * SIGMA))
        e_scale = abs(state.stored_energy(-2.0 * SIGMA))
        for gap in gaps:
            assert _close(kl.law_force(c.kind, gap, c.S, c.P, c.T), state.force(gap), 1e-9 * f_scale), gap
            assert _close(kl.law_stored(c.kind, gap, c.S, c.P, c.T), state.stored_energy(gap), 1e-9 * e_scale)
            assert _close(kl.law_dissipated(c.kind, gap, c.S, c.P, c.T), state.dissipated(gap), 1e-9 * e_scale)
        release = state.release_gap()
        assert kl.law_release_gap(c.kind, c.S, c.P, c.T, math.nan) == pytest.approx(release, rel=1e-12)
        assert _close(kl.law_release_loss(c.kind, release, c.S, c.P, c.T), state.on_release(), 1e-9 * e_scale)
        # the history the kernel accepts is the law's
        S = c.S.copy()
        probe = copy.deepcopy(state)
        for gap in (-2.8 * SIGMA, -2.9 * SIGMA, -1.0 * SIGMA):
            kl.law_accept(c.kind, gap, S, c.P, c.T)
            probe.accept(gap)
        assert (S[pgk.S_D_C], S[pgk.S_D_P]) == (probe._d_c, probe._d_p)
        assert S[pgk.S_FLAG] == 0.0


def test_a_wrong_history_fails_the_point_by_point_comparison():
    """Negative control: the loss depends on d_0 (the flattening a summit met this contact with); a compiled form
    built with d_0 moved by a tenth of sigma books a different loss, by far more than the comparison allows."""
    state = list(_histories(_contact_law(True)))[1]
    c = state.compiled(0.0)
    wrong = copy.deepcopy(state)
    wrong._d_0 += 0.1 * SIGMA
    w = wrong.compiled(0.0)
    e_scale = abs(state.stored_energy(-2.0 * SIGMA))
    gap = -2.0 * SIGMA
    assert _close(kl.law_dissipated(c.kind, gap, c.S, c.P, c.T), state.dissipated(gap), 1e-9 * e_scale)
    assert not _close(kl.law_dissipated(w.kind, gap, w.S, w.P, w.T), state.dissipated(gap), 1e-9 * e_scale)


def test_a_state_beyond_the_summit_table_is_flagged():
    law = _contact_law(True)
    c = law.compiled(0.0)
    kl.law_accept(c.kind, -25.0 * SIGMA, c.S, c.P, c.T)
    assert c.S[pgk.S_FLAG] == 0.0
    kl.law_accept(c.kind, -(law.surface.u_table - law.surface.z_top) - 31.0 * SIGMA, c.S, c.P, c.T)
    assert c.S[pgk.S_FLAG] == 1.0


def _pair(law, mass):
    """The same three-bounce drop with the compiled contact phase, then on the Python stepper; the contacts each ran
    compiled and on the Python stepper (`KernelStats`), the law's history and diagnostics after each."""
    runs = []
    for flag in (True, False):
        law.forget_history()
        type(law).compiled_contact = flag
        try:
            before = (cc.STATS.compiled, cc.STATS.python)
            run = simulate(law, mass, 9.81, release_height=40e-9, settings=DriverSettings(rtol=1e-9, max_bounces=3))
            ran = (cc.STATS.compiled - before[0], cc.STATS.python - before[1])
        finally:
            type(law).compiled_contact = True
        runs.append((run, ran, (law._d_c, law._d_p), law.diagnostics()))
    return runs


@pytest.mark.parametrize("roller", [True, False])
def test_compiled_impacts_match_the_python_stepper(roller):
    """Three bounces of a drop that flattens the summits, then bounces on the flattened spot: the same bounces, the
    same ends, and rebound heights, contact times, deepest approach, peak force and booked loss within the accuracy
    the runs' energy audit measures; the law keeps the same history (d_c, d_p) and diagnostics."""
    law = _contact_law(roller)
    mass = 1e-6 if roller else 1e-12
    (fast, ran_fast, hist_fast, diag_fast), (slow, ran_slow, hist_slow, diag_slow) = _pair(law, mass)
    assert ran_fast[0] == len(fast.bounces) and ran_fast[1] == 0       # every contact ran compiled
    assert ran_slow == (0, 0)
    assert fast.status == slow.status and len(fast.bounces) == len(slow.bounces) == 3
    tol = max(fast.audit["max_error_over_turnover"], slow.audit["max_error_over_turnover"])
    assert tol < 1e-4
    for a, b in zip(fast.bounces, slow.bounces):
        assert (a.t_release is None) == (b.t_release is None)
        for key in ("duration", "max_penetration", "peak_force", "rebound_height", "v_rebound"):
            assert getattr(a, key) == pytest.approx(getattr(b, key), rel=tol), key
        # the booked loss against the impact's energy (the audit's own scale)
        assert a.energy_booked == pytest.approx(b.energy_booked, rel=0, abs=tol * 0.5 * mass * b.v_impact ** 2)
    assert hist_fast == pytest.approx(hist_slow, rel=tol * 1e-2)
    assert diag_fast["plastic_work"] == pytest.approx(diag_slow["plastic_work"], rel=tol)


@pytest.mark.parametrize("sigma,depth", [(5e-9, 30), (2e-9, 100)])
def test_the_tabulated_footprint_kernel_is_its_node_sum(sigma, depth):
    """The compiled sums interpolate the footprint kernel's 24-node sum (`plastic_gw_kernel.footprint_table`): within
    1e-12 of the sum at every height the table covers, and summed beyond it; a table 8x coarser misses that bound
    (the negative control: the bound resolves the interpolation's error)."""
    law = PlasticBranchSummitLaw("maugis_dugdale", BETA, W, 1e11, 3e9, z0=Z0, delta_max=depth * sigma)
    surf = _contact_law(True).surface.__class__(law, sigma, DENSITY, ZMAX, R_ROLLER, L_ROLLER)
    tx, tw, kt = surf._tx_tw
    assert kt.size > 0
    reach = surf.FOOTPRINT_DEPTH * surf.u_table + surf.FOOTPRINT_MARGIN * sigma
    z = surf.z_top - np.random.default_rng(1).uniform(0.0, 1.0, 4000) ** 2 * reach * 1.05
    z = np.concatenate((z, [surf.z_top, surf.z_top - reach]))

    def weights(table):
        return np.array([pgk._weight(h, 1.0, 0.0, True, surf._C, tx, tw, table) for h in z])

    summed = weights(np.empty(0))
    assert summed[-2] == 0.0 and np.all(summed[:-2] > 0.0) and summed[-1] > 0.0     # K(z_top) = 0
    assert np.all(np.abs(weights(kt) - summed) <= 1e-12 * summed)
    coarse = pgk.footprint_table(surf.z_top, sigma, reach, tx, tw, per_scale=25.0)
    assert not np.all(np.abs(weights(coarse) - summed) <= 1e-12 * summed)


def test_an_impact_beyond_the_summit_table_is_refused_on_both_paths():
    """`check_depth`: an accepted state deeper than the summit law's table is refused. The compiled phase flags it
    and hands the contact to the Python stepper, which raises there, as the Python stepper alone does."""
    shallow = PlasticBranchSummitLaw("maugis_dugdale", BETA, W, 1e11, 3e9, z0=Z0, delta_max=2 * SIGMA)
    law = PlasticGWRoller(shallow, SIGMA, DENSITY, ZMAX, R_ROLLER, L_ROLLER)
    for flag in (True, False):
        law.forget_history()
        type(law).compiled_contact = flag
        try:
            before = cc.STATS.python
            with pytest.raises(ValueError, match="beyond the summit law's table"):
                simulate(law, 1e-6, 9.81, impact_velocity=0.05, settings=DriverSettings(rtol=1e-9, max_bounces=1))
            assert cc.STATS.python - before == (1 if flag else 0)    # the kernel gave the contact back
        finally:
            type(law).compiled_contact = True
