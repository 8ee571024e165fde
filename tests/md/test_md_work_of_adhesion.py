"""md.analysis's works of adhesion against curves with closed-form answers (no LAMMPS needed): energy separation,
force integration (zero-crossing start, correlated windows, chain correlation, grid error), registry averages and
their consistency, z0/sigma0 of flat slabs, the dispersion tail beyond the cutoff, the window-length check, T dS and
the cutoff-crossing work."""
from __future__ import annotations

import math

import numpy as np
import pytest

from md.analysis import (
    KCALMOL_PER_A2_TO_J_PER_M2,
    energy_separation_work,
    timeseries_stats,
    work_from_energy_curve,
)

N_A = 6.02214076e23          # CODATA 2018 / SI 2019, exact
KCAL = 4184.0                # J, thermochemical


def rel(x, r):
    return pytest.approx(x, rel=r, abs=0)


# ------------------------------------------------------------------------------------ works of adhesion

def test_energy_separation_work_is_the_energy_difference_per_area():
    rng = np.random.default_rng(3)
    noise = rng.normal(0, 5.0, 1000)
    e_c, e_s = -1000.0 + noise, -800.0 + noise[::-1]       # same noise, exact means
    out = energy_separation_work(e_c, e_s, area_A2=400.0)
    assert out["value"] == rel(200.0 / 400.0 * KCAL / (N_A * 1e-20), 1e-12)
    sc, ss = timeseries_stats(e_c)["stderr"], timeseries_stats(e_s)["stderr"]     # statistical inefficiency
    assert out["stderr"] == rel(math.hypot(sc, ss) / 400.0 * KCAL / (N_A * 1e-20), 1e-12)
    assert math.hypot(sc, ss) == rel(5.0 * math.sqrt(2 / 1000), 0.15)               # white noise: g = 1
    assert out["units"] == "J/m^2"
    assert "not a free energy" in out["note"] and "entropic" in out["note"]


def lj93_energy(d, eps, sig):
    return eps * (2.0 / 15.0 * (sig / d) ** 9 - (sig / d) ** 3)


LJ93_EMIN = -(2.0 / 3.0) * math.sqrt(2.5)      # min of (2/15) x^9 - x^3 (x = sig/D), at D = (2/5)^(1/6) sig


def test_force_integration_of_a_lj93_traction_law_gives_its_work():
    """The 9-3 traction law sigma(g) = (8W/3z0)[(z0/g)^3 - (z0/g)^9] integrates to W from z0 to infinity;
    as a mean-force curve F = -A sigma (attraction negative) on a dense grid both quadratures recover W, on a
    coarse grid they part, and the stated discretisation error covers the trapezoid's true error."""
    from md.analysis import force_integration_work
    W, z0, area = 0.2, 2.0, 500.0                           # kcal/mol/A^2, A, A^2
    sigma = lambda g: 8 * W / (3 * z0) * ((z0 / g) ** 3 - (z0 / g) ** 9)
    exact = W * (1 - 4 / 3 * (z0 / 40.0) ** 2 + (z0 / 40.0) ** 8 / 3) * KCALMOL_PER_A2_TO_J_PER_M2   # z0 to 40 A
    for n, tol in ((400, 1e-3), (12, None)):
        d = z0 + (40.0 - z0) * (np.arange(n) / (n - 1)) ** 2
        f = -area * sigma(d)
        r = force_integration_work(d[::-1], f[::-1], np.full(n, 0.5), area)     # any order
        if tol:
            assert r["value"] == pytest.approx(exact, rel=tol) and r["value_pchip"] == pytest.approx(exact, rel=tol)
        else:
            assert abs(r["value"] - exact) > 1e-3 * exact             # the coarse grid misses part of the well
            assert abs(r["value"] - exact) <= 1.5 * r["discretisation_error"]
    # statistical error: trapezoid weights times the window errors, in quadrature
    d = np.array([0.0, 1.0, 3.0])
    r = force_integration_work(d, np.zeros(3), np.array([1.0, 2.0, 3.0]), 1.0)
    assert r["stderr"] == pytest.approx(math.sqrt(0.5 ** 2 + 3.0 ** 2 + 3.0 ** 2) * KCALMOL_PER_A2_TO_J_PER_M2)
    with pytest.raises(ValueError, match="same separation"):
        force_integration_work([0.0, 0.0, 1.0], [1, 2, 3], [1, 1, 1], 1.0)


def _lj93_window_curve(W, z0, area, d):
    """Mean force on the upper slab (kcal/mol/A, repulsion positive) for the 9-3 traction law whose zero-force
    point (the contact at zero load) is at d = 0: separations d are measured from the contact, as in the MD."""
    g = d + z0
    return area * 8 * W / (3 * z0) * ((z0 / g) ** 9 - (z0 / g) ** 3)


def test_force_integration_starts_at_the_zero_force_point_of_a_grid_reaching_into_compression():
    """Compressive windows (d < 0, repulsive) and the quadratic outward grid: W_F is integrated from the
    interpolated zero crossing, so the repulsive windows do not cut into it (the old rule, from the first window,
    subtracts their positive force: W too small); a grid that never turns repulsive is flagged."""
    from md.analysis import force_integration_work
    W, z0, area = 0.06, 2.5, 600.0                            # kcal/mol/A^2, A, A^2
    exact = W * (1 - 4 / 3 * (z0 / (20 + z0)) ** 2 + (z0 / (20 + z0)) ** 8 / 3) * KCALMOL_PER_A2_TO_J_PER_M2
    d = np.concatenate([-np.linspace(0.8, 0.1, 8), 20.0 * (np.arange(300) / 299) ** 2])
    f = _lj93_window_curve(W, z0, area, d)
    r = force_integration_work(d, f, np.full(d.size, 0.5), area)
    assert r["repulsive_end"] and r["zero_force_separation_A"] == pytest.approx(0.0, abs=2e-3)
    assert r["value"] == rel(exact, 2e-3) and r["value_pchip"] == rel(exact, 2e-3)
    assert r["pmf_J_per_m2"].min() == pytest.approx(0.0, abs=1e-4 * exact)      # the PMF's minimum: the contact
    old = force_integration_work(d, f, np.full(d.size, 0.5), area, from_zero_crossing=False)
    assert old["value"] < 0.9 * exact                           # integrated through the repulsive wall
    # outward windows only, starting inside the well (d = 0.3 A): no repulsive window, flagged, a lower bound
    out = d[d >= 0.3]
    r2 = force_integration_work(out, _lj93_window_curve(W, z0, area, out), np.full(out.size, 0.5), area)
    assert not r2["repulsive_end"] and math.isnan(r2["zero_force_separation_A"])
    assert r2["value"] < exact


def test_registry_average_carries_the_spread_between_registries():
    """The spread of n registries enters with the Student-t factor of n - 1 degrees of freedom at 68.27 %: the
    t quantiles checked here against the closed forms of t with 1 dof (Cauchy: tan(pi (p - 1/2))) and 2 dof
    (x / sqrt(2 + x^2) = 2p - 1), p = (1 + erf(1/sqrt 2)) / 2."""
    from md.analysis import registry_average, student_t_factor
    p = 0.5 * (1.0 + math.erf(1.0 / math.sqrt(2.0)))
    t1, t2 = math.tan(math.pi * (p - 0.5)), math.sqrt(2.0 * (2 * p - 1) ** 2 / (1.0 - (2 * p - 1) ** 2))
    assert student_t_factor(2) == rel(t1, 1e-9) and student_t_factor(3) == rel(t2, 1e-9)
    assert t1 == pytest.approx(1.84, abs=0.005) and t2 == pytest.approx(1.32, abs=0.005)
    with pytest.raises(ValueError, match="two samples"):
        student_t_factor(1)
    one = registry_average([[1.0, 2.0]], [[0.1, 0.2]])
    assert np.allclose(one["mean"], [1, 2]) and np.allclose(one["stderr"], [0.1, 0.2])
    three = registry_average([1.0, 2.0, 3.0], [0.01, 0.01, 0.01])       # spread dominates
    assert three["mean"] == 2.0 and three["stderr"] == rel(t2 / math.sqrt(3), 1e-9)
    two = registry_average([1.0, 2.0], [0.01, 0.01])
    assert two["stderr"] == rel(t1 * math.sqrt(0.5) / math.sqrt(2), 1e-9) and two["t_factor"] == rel(t1, 1e-9)
    agree = registry_average([2.0, 2.0, 2.0], [0.3, 0.3, 0.3])          # agreement by chance: statistics remain
    assert agree["stderr"] == rel(0.3 / math.sqrt(3), 1e-12) and agree["registry_spread"] == 0.0


def test_registry_consistency_flags_the_windows_where_registries_disagree_beyond_their_stderrs():
    """Three registries drawn around one curve with their stated stderrs: chi^2/dof follows its distribution,
    about 1 % of 2000 points flagged at p < 0.01. Shift one registry by 8 stderrs at 5 points: exactly those are
    flagged. One registry: nothing to compare."""
    from md.analysis import registry_consistency

    rng = np.random.default_rng(5)
    e = rng.uniform(0.1, 1.0, (3, 2000))
    v = np.sin(np.linspace(0, 6, 2000)) + e * rng.normal(size=e.shape)
    c = registry_consistency(v, e)
    assert c["dof"] == 2 and np.mean(c["chi2_per_dof"]) == rel(1.0, 0.1)
    assert 0.002 < np.mean(c["inconsistent"]) < 0.025
    clean = registry_consistency(e[:, :40] * rng.normal(size=(3, 40)), e[:, :40])
    v2 = e[:, :40] * 0.0
    v2[1, [3, 9, 17, 25, 33]] += 8.0 * e[1, [3, 9, 17, 25, 33]]
    shifted = registry_consistency(v2, e[:, :40])
    assert sorted(np.flatnonzero(shifted["inconsistent"]).tolist()) == [3, 9, 17, 25, 33]
    assert clean["inconsistent"].sum() <= 2
    one = registry_consistency(v[:1], e[:1])
    assert one["dof"] == 0 and not one["inconsistent"].any()
    with pytest.raises(ValueError, match="shape"):
        registry_consistency(v, e[:, :5])


def test_z0_and_sigma0_from_a_coarse_noisy_flat_slab_curve():
    """sigma0 from the quadratic through the three windows around the peak, z0 = 1.026 W / sigma0: on the 9-3
    law (seeded noise, 30 draws) both come back within their stated errors, the stated noise error is the scatter's
    size, and the 3- vs 5-point difference (the grid's discretisation error) covers the bias."""
    from md import units as U
    from md.analysis import MAUGIS_LJ93, flat_slab_range, traction_peak
    W, z0, area = 0.06, 2.5, 600.0
    W_si = W * KCALMOL_PER_A2_TO_J_PER_M2
    sigma0_pa = float(U.kcal_per_mol_A3_to_Pa(MAUGIS_LJ93 * W / z0))
    d = np.concatenate([-np.linspace(1.0, 0.25, 4), 20.0 * (np.arange(14) / 13) ** 2])
    f0 = _lj93_window_curve(W, z0, area, d)
    noise = 0.5                                                  # kcal/mol/A per window
    rng = np.random.default_rng(8)
    peaks = [traction_peak(d, f0 + rng.normal(0, noise, d.size), np.full(d.size, noise), area) for _ in range(30)]
    assert all(p["method"] == "quadratic" for p in peaks)
    sg = np.array([p["sigma0"] for p in peaks])
    se = np.array([p["stderr"] for p in peaks])
    disc = np.median([p["discretisation_error"] for p in peaks])
    assert 0.5 < np.median(se) / sg.std() < 2.0                  # the stated noise error is the scatter's size
    assert abs(sg.mean() - sigma0_pa) < 2 * math.hypot(sg.std() / math.sqrt(30), disc)
    best_window = float(U.kcal_per_mol_A3_to_Pa(-f0.min() / area))
    assert best_window < sg.mean()                               # the vertex, not the coarse grid's best window
    z = [flat_slab_range(W_si, 0.0, p["sigma0"], math.hypot(p["stderr"], p["discretisation_error"])) for p in peaks]
    z_mean = np.mean([r["z0"] for r in z])
    assert abs(z_mean - z0 * 1e-10) < 2 * np.median([r["stderr"] for r in z])
    assert flat_slab_range(0.1, 0.01, 1e8, 1e7)["stderr"] == rel(MAUGIS_LJ93 * 1e-9 * math.sqrt(0.02), 1e-12)
    with pytest.raises(ValueError, match="no attractive window"):
        traction_peak(d, np.abs(f0), np.ones(d.size), area)


def _lattice_slab(n_side, nz, a, z0):
    g = np.arange(n_side) * a
    x, y, z = np.meshgrid(g, g, np.arange(nz) * a, indexing="ij")
    return np.column_stack([x.ravel(), y.ravel(), z.ravel() + z0])


def test_dispersion_tail_between_two_slabs_has_the_sign_size_and_force_expected():
    """Two simple-cubic LJ slabs (CH2-like: eps 0.0914 kcal/mol, sigma 3.95 A, 0.034 sites/A^3) 3.5 A apart, cut
    at 12 A: the interaction beyond the cutoff is attractive, converges with the explicit radius (the smeared
    images take over beyond it), is within 10 % of two laterally smeared stacks of planes (about 7 mJ/m^2 here),
    and its force is minus the energy's derivative."""
    from md.analysis import lj_tail_between
    a, n_side, nz, gap = 3.1, 8, 10, 3.5
    L = n_side * a
    lo, up = _lattice_slab(n_side, nz, a, 0.0), _lattice_slab(n_side, nz, a, (nz - 1) * a + gap)
    E, S, I = np.array([[0.0914]]), np.array([[3.95]]), np.array([[True]])
    z_lo, z_up = np.zeros(len(lo), int), np.zeros(len(up), int)
    tail = {rm: lj_tail_between(lo, z_lo, up, z_up, E, S, I, (L, L), 12.0, rm) for rm in (20.0, 30.0)}
    e20, e30 = tail[20.0]["energy"], tail[30.0]["energy"]
    assert e20 < 0 and e20 == rel(e30, 0.02)
    ns = 1 / a ** 2
    planes = sum(ns * ns * 2 * math.pi * 4 * 0.0914 * (3.95 ** 12 / (10 * x ** 10) - 3.95 ** 6 / (4 * x ** 4))
                 for x in (max(gap + a * (k1 + k2), 12.0) for k1 in range(nz) for k2 in range(nz))) * L * L
    assert e30 == rel(planes, 0.10)
    w_tail = -e30 / (L * L) * KCALMOL_PER_A2_TO_J_PER_M2
    assert 0.004 < w_tail < 0.012                                # J/m^2
    h = 1e-3
    ep = lj_tail_between(lo, z_lo, up + [0, 0, h], z_up, E, S, I, (L, L), 12.0, 30.0)["energy"]
    em = lj_tail_between(lo, z_lo, up - [0, 0, h], z_up, E, S, I, (L, L), 12.0, 30.0)["energy"]
    assert tail[30.0]["force_z"] == rel(-(ep - em) / (2 * h), 1e-4) and tail[30.0]["force_z"] < 0
    # pairs left out count nothing; the partner types decide
    none = lj_tail_between(lo, z_lo, up, z_up, E, S, np.array([[False]]), (L, L), 12.0, 20.0)
    assert none["energy"] == 0.0 and none["pairs"] == 0


def test_work_from_lj93_wall_energy_curve_long_tail():
    eps, sig, area = 3.0, 3.5, 250.0
    d = np.linspace(2.6, 40 * sig, 4000)
    out = work_from_energy_curve(d, lj93_energy(d, eps, sig), area)
    expected = -LJ93_EMIN * eps / area * KCAL / (N_A * 1e-20)
    assert out["value"] == rel(expected, 1e-3)
    assert out["separation_at_min"] == rel(0.4 ** (1 / 6) * sig * 1e-10, 1e-3)


def test_work_from_lj93_wall_energy_curve_short_tail_extrapolated():
    eps, sig, area = 3.0, 3.5, 250.0
    rng = np.random.default_rng(0)
    d = np.sort(rng.uniform(2.7, 5 * sig, 120))            # irregular grid, stops at 5 sigma
    e = lj93_energy(d, eps, sig)
    expected = -LJ93_EMIN * eps / area * KCALMOL_PER_A2_TO_J_PER_M2
    plain = work_from_energy_curve(d, e, area)
    fitted = work_from_energy_curve(d, e, area, tail_power=3)
    assert fitted["value"] == rel(expected, 1e-3)
    assert abs(plain["value"] / expected - 1) > 3e-3        # the short plateau alone would be biased
    with_err = work_from_energy_curve(d, e, area, tail_power=3, energy_stderr_kcal=np.full(d.size, 0.01))
    per_area = KCALMOL_PER_A2_TO_J_PER_M2 / area                   # J/m^2 per kcal/mol
    assert 0.01 * per_area < with_err["stderr"] < 0.05 * per_area  # min point + extrapolated plateau



# ---------------------------------------------------------------------- dispersion beyond the cutoff
@pytest.mark.parametrize("d", [-30.0, -12.0, -5.0, 0.0, 3.0, 11.9, 12.0, 12.1, 20.0, 45.0])
def test_tail_antiderivative_is_the_half_space_integral_beyond_the_cutoff(d):
    """(pi/2) F(d) is the r^-6 sum of one site with a uniform half-space (unit density, unit C6) over the pairs
    beyond r_c, done independently shell by shell: the part of a sphere of radius r about the site that lies in
    the half-space (its plane d above the site) has area clip(2 pi r (r - d), 0, 4 pi r^2)."""
    from scipy.integrate import quad

    from md.analysis import tail_antiderivative

    rc = 12.0

    def shell(r):
        return min(max(2.0 * np.pi * r * (r - d), 0.0), 4.0 * np.pi * r * r) * r**-6

    points = [p for p in (abs(d),) if p > rc]
    exact = quad(shell, rc, np.inf, epsabs=0, epsrel=1e-13, limit=200)[0] if not points else \
        quad(shell, rc, points[0], epsabs=0, epsrel=1e-13)[0] + \
        quad(shell, points[0], np.inf, epsabs=0, epsrel=1e-13)[0]
    assert 0.5 * np.pi * float(tail_antiderivative(d, rc)) == pytest.approx(exact, rel=1e-10)


def test_dispersion_tail_work_reaches_hamaker_for_a_solid_half_space_beyond_the_cutoff():
    """A solid of uniform density starting D >= r_c below the liquid: no pair is cut, so dW is the whole
    dispersion work, A_H / (12 pi D^2) with A_H = pi^2 C6 rho_s n (Israelachvili). Sites on a fine lattice
    approximate the solid; the error is that of the midpoint rule in depth."""
    from md.analysis import dispersion_tail_work

    c6, rho_s, n, D, rc = 2.0e4, 0.03, 0.0334, 15.0, 12.0
    dz, depth = 0.02, 4000.0
    z = -(D + dz * (np.arange(int(depth / dz)) + 0.5))         # layers below the plane at z = 0
    area = 1.0 / (rho_s * dz)                                   # one site per layer: density rho_s
    w = dispersion_tail_work(z, c6, 0.0, n, rc, area)
    hamaker = np.pi**2 * c6 * rho_s * n
    expected = hamaker / (12.0 * np.pi) * (D**-2 - (D + depth) ** -2)
    assert w == pytest.approx(expected, rel=1e-5)
    assert 0.0 < dispersion_tail_work(z, c6, 0.0, n, 2.0 * D, area) < w   # a longer cutoff leaves less beyond it


# ------------------------------------------------------------------ chained windows, window length, grid, T dS

def test_correlated_window_errors_follow_the_lag1_covariance():
    """sqrt(g^T C g) with C_kl = rho^|k-l| e_k e_l, against the sum written out: grid 0, 1, 3 A (trapezoid weights
    0.5, 1.5, 1), errors 1, 2, 3: g e = (0.5, 3, 3), so var = 18.25 + 2 rho (1.5 + 9) + 2 rho^2 1.5."""
    from md.analysis import force_integration_work
    d, e = np.array([0.0, 1.0, 3.0]), np.array([1.0, 2.0, 3.0])
    for rho in (0.0, 0.5, 0.9):
        r = force_integration_work(d, np.zeros(3), e, 1.0, correlation=rho)
        var = 18.25 + 2 * rho * 10.5 + 2 * rho ** 2 * 1.5
        assert r["stderr"] == rel(math.sqrt(var) * KCALMOL_PER_A2_TO_J_PER_M2, 1e-6)
    with pytest.raises(ValueError, match="correlation"):
        force_integration_work(d, np.zeros(3), e, 1.0, correlation=1.0)


def test_chain_correlation_recovers_the_replicates_lag1_and_the_stderr_that_covers_their_scatter():
    """Replicate chains whose window errors are AR(1) along the chain (rho = 0.7, unit stderrs): the pooled estimate
    from 4 chains x 300 windows is 0.7 within 0.08, and independent errors give ~0. On 3000 such chains of 20
    windows the scatter of W is what the lag-1 covariance propagates (within 8 %), while independent propagation
    understates it more than 1.8-fold."""
    from md.analysis import chain_correlation, force_integration_work
    rng = np.random.default_rng(3)

    def ar1(n_chains, n, rho):
        z = rng.normal(size=(n_chains, n))
        x = np.empty_like(z)
        x[:, 0] = z[:, 0]
        for k in range(1, n):
            x[:, k] = rho * x[:, k - 1] + math.sqrt(1 - rho * rho) * z[:, k]
        return x

    curve = -np.sin(np.linspace(0, np.pi, 300))
    e = np.ones((4, 300))
    assert chain_correlation(curve + ar1(4, 300, 0.7), e) == pytest.approx(0.7, abs=0.08)
    assert chain_correlation(curve + rng.normal(size=(4, 300)), e) < 0.08
    assert chain_correlation(curve[None, :20], np.ones((1, 20))) == 0.0          # one chain: nothing to compare
    d = np.linspace(0.0, 10.0, 20)
    f0 = -np.sin(np.linspace(0, np.pi, 20)) - 0.1
    ws = [force_integration_work(d, f0 + x, np.ones(20), 1.0, from_zero_crossing=False)["value"]
          for x in ar1(3000, 20, 0.7)]
    corr = force_integration_work(d, f0, np.ones(20), 1.0, from_zero_crossing=False, correlation=0.7)["stderr"]
    indep = force_integration_work(d, f0, np.ones(20), 1.0, from_zero_crossing=False)["stderr"]
    assert np.std(ws) == rel(corr, 0.08) and np.std(ws) > 1.8 * indep


def _two_registry_curve(d):
    """A flat-slab-like curve (repulsive below 0, a well, back to 0) on d (A), kcal/mol/A."""
    return 40.0 * np.exp(-2.0 * (d + 0.5)) - 30.0 * np.exp(-((d - 1.0) / 1.2) ** 2) - 10.0 * np.exp(-d - 0.5)


def test_window_length_check_fails_on_a_drift_that_a_tolerance_holding_the_registry_spread_passes():
    """Two registries that differ by a registry offset (their W_F 10 % apart) with small within-window stderrs;
    the second half of every window is more attractive than the first by 3 statistical stderrs. The check from the
    statistical stderrs flags it; the tolerance that held the registries' spread (2 x 2 x max(stat, Student-t spread
    of the registries' W)) passes it. Negative control: halves that differ only by their own noise pass in about 95
    % of 400 seeded draws (2 sigma)."""
    from md.analysis import force_integration_work, registry_average, window_length_check
    d = np.concatenate([-np.linspace(1.5, 0.25, 6), 0.2 + 8.0 * (np.arange(14) / 13) ** 2])
    area, stat = 500.0, np.full(d.size, 0.3)
    base = _two_registry_curve(d)
    regs = np.array([base * 0.95, base * 1.05])                                  # registry dependence
    w_reg = [force_integration_work(d, f, stat, area)["value"] for f in regs]
    avg = registry_average(w_reg, [force_integration_work(d, f, stat, area)["stderr"] for f in regs])
    old_tol = 2.0 * 2.0 * max(force_integration_work(d, regs.mean(0), registry_average(regs, np.broadcast_to(
        stat, regs.shape))["stderr"], area)["stderr"], avg["stderr"])
    drift = 3.0 * stat * np.sqrt(2.0) * (base < 0)                              # attractive windows drift
    first, second = regs.mean(0) + 0.5 * drift, regs.mean(0) - 0.5 * drift
    chk = window_length_check(d, first, second, stat / math.sqrt(2.0), area)
    assert not chk["converged"] and abs(chk["difference_J_m2"]) <= old_tol      # old tolerance: passes the drift
    rng = np.random.default_rng(11)
    ok = [window_length_check(d, base + rng.normal(0, 0.3 * math.sqrt(2), d.size),
                              base + rng.normal(0, 0.3 * math.sqrt(2), d.size), stat, area)["converged"]
          for _ in range(400)]
    assert 0.90 <= np.mean(ok) <= 0.99


def test_grid_error_bounds_a_rupture_between_two_windows_that_the_quadrature_difference_misses():
    """A step curve: repulsive at -1 A, -F0 from the zero crossing to a rupture at r, 0 beyond; windows at
    -1, 0, 1, 2, 4, 6 A, so the rupture falls in the interval 2-4 A wherever r lies there. The true work (the
    linear repulsive piece, then F0 to r) differs from the trapezoid by up to F0 x 1 A; the interval bound
    1/2 |df| dd = F0 x 1 A covers it for every r, the trapezoid-PCHIP difference does not, and 2-4 A is flagged
    for refinement. Negative control: a dense smooth 9-3 curve flags nothing and keeps its small grid error."""
    from md.analysis import force_integration_work
    f0, area = 10.0, 100.0
    d = np.array([-1.0, 0.0, 1.0, 2.0, 4.0, 6.0])
    f = np.array([f0, -f0, -f0, -f0, 0.0, 0.0])
    r0 = force_integration_work(d, f, np.full(6, 0.1), area)
    start = r0["zero_force_separation_A"]
    assert start == pytest.approx(-0.5)
    for rupture in (2.02, 3.0, 3.98):
        exact = (f0 * (0.0 - start) / 2 + f0 * (rupture - 0.0)) * KCALMOL_PER_A2_TO_J_PER_M2 / area
        err = abs(r0["value"] - exact)
        assert err <= r0["discretisation_error"] * (1 + 1e-9)
    worst = 0.98 * f0 * KCALMOL_PER_A2_TO_J_PER_M2 / area
    assert r0["quadrature_difference"] < 0.5 * worst                          # PCHIP follows the trapezoid
    assert r0["grid_bound_max"] == rel(f0 * 1.0 * KCALMOL_PER_A2_TO_J_PER_M2 / area, 1e-12)
    assert r0["refine_intervals_A"] == [[2.0, 4.0]] or [2.0, 4.0] in r0["refine_intervals_A"]
    W, z0 = 0.06, 2.5
    dd = np.concatenate([-np.linspace(0.8, 0.1, 8), 20.0 * (np.arange(300) / 299) ** 2])
    smooth = force_integration_work(dd, _lj93_window_curve(W, z0, area, dd), np.full(dd.size, 0.5), area)
    assert smooth["refine_intervals_A"] == [] and smooth["discretisation_error"] < 0.02 * smooth["value"]


def test_entropic_term_compares_energy_and_free_energy_of_the_same_registry():
    """dE/A of registry 0 only (its zero-load contact leg), W_F of three registries: T dS is registry 0's
    dE - dF (0.292 - 0.256 = 0.036), not dE against the registries' mean W_F (0.292 - 0.197 = 0.095)."""
    from md.analysis import entropic_term
    r = entropic_term({0: (0.292, 0.002)}, {0: (0.256, 0.01), 1: (0.124, 0.01), 2: (0.21, 0.01)})
    assert r["registries"] == [0] and r["per_registry"][0][0] == pytest.approx(0.036)
    assert r["per_registry"][0][1] == rel(math.hypot(0.002, 0.01), 1e-12) and r["mean"] == pytest.approx(0.036)
    both = entropic_term({0: (0.3, 0.0), 1: (0.2, 0.0)}, {0: (0.25, 0.01), 1: (0.18, 0.01)})
    assert both["registries"] == [0, 1] and both["mean"] == pytest.approx(0.035)
    with pytest.raises(ValueError, match="no registry"):
        entropic_term({1: (0.3, 0.0)}, {0: (0.25, 0.01)})


@pytest.mark.parametrize("d, fraction", [(0.0, 0.5), (12.0, 0.0), (30.0, 0.0), (-12.0, 1.0), (-40.0, 1.0),
                                         (6.0, 5.0 / 32.0)])
def test_cutoff_crossing_work_counts_the_liquid_inside_the_cutoff_sphere(d, fraction):
    """One site at depth d below the liquid's plane misses C6 / r_c^6 for every liquid site within r_c: n C6 V / r_c^6
    with V the sphere's part inside the liquid (half at the plane, none a cutoff below it, all of it a cutoff inside;
    at d = r_c/2 the cap of height r_c/2 holds 5/32 of the sphere)."""
    from md.analysis import cutoff_crossing_work

    c6, n, rc = 1.5e3, 0.0334, 12.0
    full = n * c6 * (4.0 / 3.0) * np.pi * rc**3 / rc**6
    assert cutoff_crossing_work([-d], c6, 0.0, n, rc, 1.0) == pytest.approx(fraction * full, rel=1e-12, abs=1e-300)


def test_cutoff_crossing_work_is_half_the_tail_beyond_the_cutoff_for_two_half_spaces():
    """Two half-spaces in contact: beyond-cutoff tail pi C n rho / (2 r_c^2), shifted pairs inside pi C n rho /
    (4 r_c^2) (md-review-2 section 3), so the shifted potential's W_SL misses 1.5 times the tail, not the tail alone.
    A wrong cap volume or a missing sign moves the ratio off 1/2."""
    from md.analysis import cutoff_crossing_work, dispersion_tail_work

    c6, n, rho_s, rc, dz = 1.0e3, 0.0334, 0.03, 12.0, 0.01
    z = -(dz * (np.arange(int(300.0 / dz)) + 0.5))
    area = 1.0 / (rho_s * dz)
    crossing = cutoff_crossing_work(z, c6, 0.0, n, rc, area)
    assert crossing == pytest.approx(np.pi * c6 * n * rho_s / (4.0 * rc**2), rel=1e-4)
    assert crossing / dispersion_tail_work(z, c6, 0.0, n, rc, area) == pytest.approx(0.5, rel=2e-3)
