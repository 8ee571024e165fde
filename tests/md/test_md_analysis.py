"""md.analysis against synthetic inputs with known answers (no LAMMPS needed).

The contact-angle tests build fake MDAnalysis universes (MDAnalysis is part of the md extra): without it
they skip -- except when CI is "true", where a missing MDAnalysis is a failure.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import require_backend
from md.analysis import (
    ATM_A_TO_N_PER_M,
    KCALMOL_PER_A2_TO_J_PER_M2,
    KCALMOL_PER_A_TO_N,
    ContactAngle,
    block_analysis,
    block_average,
    blocking_stderr,
    density_profile,
    detect_equilibration,
    energy_separation_work,
    fit_contact_angle,
    fit_traction_law,
    lj_tail_correction,
    pull_off_analysis,
    rate_extrapolation,
    slab_density,
    statistical_inefficiency,
    surface_tension,
    timeseries_stats,
    work_from_energy_curve,
)

N_A = 6.02214076e23          # CODATA 2018 / SI 2019, exact
KCAL = 4184.0                # J, thermochemical
ATM = 101325.0               # Pa


def rel(x, r):
    return pytest.approx(x, rel=r, abs=0)


# ----------------------------------------------------------------------------------------------- units

def test_unit_conversions_are_the_codata_values():
    assert KCALMOL_PER_A2_TO_J_PER_M2 == rel(KCAL / (N_A * 1e-20), 1e-12)
    assert KCALMOL_PER_A2_TO_J_PER_M2 == rel(0.69477, 1e-4)          # 1 kcal/mol/A^2 = 0.695 J/m^2
    assert KCALMOL_PER_A_TO_N == rel(KCAL / (N_A * 1e-10), 1e-12)
    assert ATM_A_TO_N_PER_M == rel(ATM * 1e-10, 1e-12)


# ---------------------------------------------------------------------------------------- block errors

def ar1(phi, n, rng, sigma=1.0):
    """Stationary AR(1) series x_t = phi x_{t-1} + e_t, e ~ N(0, sigma^2)."""
    from scipy.signal import lfilter

    e = rng.normal(0.0, sigma, n)
    e[0] *= 1.0 / math.sqrt(1.0 - phi**2)     # start in the stationary distribution
    return lfilter([1.0], [1.0, -phi], e)


def ar1_exact_stderr(phi, n, sigma=1.0):
    """Exact standard deviation of the mean of n stationary AR(1) samples."""
    var_x = sigma**2 / (1.0 - phi**2)
    k = np.arange(1, n)
    return math.sqrt(var_x / n**2 * (n + 2.0 * np.sum((n - k) * phi**k)))


def test_block_average_is_exact_on_hand_made_blocks():
    x = np.array([99.0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5])    # the leading 99 is dropped (11 % 5 == 1)
    mean, err = block_average(x, n_blocks=5)
    assert mean == 3.0
    assert err == rel(np.std([1, 2, 3, 4, 5], ddof=1) / math.sqrt(5), 1e-14)


def test_block_average_of_correlated_ar1_noise_gives_the_exact_stderr():
    rng = np.random.default_rng(11)
    phi, n = 0.95, 20000                        # integrated correlation time ~ 39 samples
    exact = ar1_exact_stderr(phi, n)
    series = [ar1(phi, n, rng) for _ in range(40)]
    est = np.array([block_average(s, n_blocks=5)[1] for s in series])
    rms = math.sqrt(np.mean(est**2))
    assert exact / 1.5 < rms < 1.5 * exact
    assert rms == rel(exact, 0.15)
    naive = math.sqrt(np.mean([np.var(s, ddof=1) / n for s in series]))   # what ignoring correlation gives
    assert naive < exact / 4


def test_block_analysis_levels_off_at_the_exact_stderr():
    rng = np.random.default_rng(5)
    phi, n = 0.9, 2**18
    x = ar1(phi, n, rng)
    res = block_analysis(x)
    exact = ar1_exact_stderr(phi, n)
    assert res["block_size"][0] == 1 and res["stderr"][0] < exact / 3      # unblocked: far too small
    assert exact / 1.5 < res["stderr_plateau"] < 1.5 * exact


# ------------------------------------------------------------------------- statistical inefficiency (Chodera)

def test_statistical_inefficiency_of_ar1_is_1_plus_phi_over_1_minus_phi():
    rng = np.random.default_rng(21)
    for phi in (0.0, 0.5, 0.9):
        x = ar1(phi, 200_000, rng)
        assert statistical_inefficiency(x) == rel((1 + phi) / (1 - phi), 0.05)
    assert statistical_inefficiency(np.full(50, 3.0)) == 1.0          # no variance: no correlation
    assert statistical_inefficiency([1.0]) == 1.0


def test_stderr_from_statistical_inefficiency_covers_the_true_mean_on_100_ar1_series():
    """100 seeded AR(1) series (phi = 0.9: g = 19, ~105 effective samples in 2000): the stderr of the mean is
    the exact one within the spread that an estimated g must have at this length, and the 95 % intervals cover
    the true mean (0) about 95 % of the time. The spread: g is a sum over ~M lags of C(t), M about 3
    exponential times (where C(t) first drops into its noise), so var(g)/g^2 ~ 2 (2M + 1)/N (Sokal) and the
    stderr, which goes as sqrt(g), scatters by sqrt((2M + 1)/(2N))."""
    rng = np.random.default_rng(1799)
    phi, n = 0.9, 2000
    exact = ar1_exact_stderr(phi, n)
    m_lags = 3 * (-1.0 / math.log(phi))                       # 3 exponential correlation times
    spread = math.sqrt((2 * m_lags + 1) / (2 * n))            # ~0.12
    ratios, covered = [], 0
    for _ in range(100):
        st = timeseries_stats(ar1(phi, n, rng), equilibrate=False)
        ratios.append(st["stderr"] / exact)
        covered += abs(st["mean"]) < 1.96 * st["stderr"]
    lo, med, hi = np.percentile(ratios, [5, 50, 95])
    assert 1 - spread < med < 1 + spread / 2                   # a slight downward bias (truncated sum), no more
    assert 1 - 2.5 * spread < lo and hi < 1 + 2.5 * spread
    assert 88 <= covered <= 99
    # five fixed blocks (the old estimator) scatter about twice as much on the same kind of series
    five = [block_average(ar1(phi, n, rng), 5)[1] / exact for _ in range(100)]
    f_lo, f_hi = np.percentile(five, [5, 95])
    assert f_hi - f_lo > 1.5 * (hi - lo)


def test_an_oscillating_autocorrelation_does_not_hide_a_slow_one():
    """A slow AR(1) (phi = 0.95, g = 39) under a stronger quasi-periodic AR(2) (poles at 0.8 e^(+-i pi/3), period 6
    samples: the shape of a pressure tensor's autocorrelation, which dips below zero within a few samples and
    recovers). The sum behind g stops at that first dip and misses the slow part: its stderr is 0.65x the exact
    one. The blocking check restores it (the exact stderr of the mean of a sum of independent stationary
    processes: sigma_e^2 / (1 - sum a_k)^2 / n each, at this length within 1 % of the finite-n value)."""
    from scipy.signal import lfilter

    rng = np.random.default_rng(89)
    n, phi, r, w, b = 16000, 0.95, 0.8, math.pi / 3, 10.0
    a1, a2 = 2 * r * math.cos(w), -r * r
    exact = math.sqrt((1.0 / (1.0 - phi) ** 2 + b * b / (1.0 - a1 - a2) ** 2) / n)
    new, old, covered = [], [], 0
    for _ in range(60):
        slow = lfilter([1.0], [1.0, -phi], rng.normal(size=n + 2000))[2000:]
        osc = b * lfilter([1.0], [1.0, -a1, -a2], rng.normal(size=n + 2000))[2000:]
        st = timeseries_stats(slow + osc, equilibrate=False)
        new.append(st["stderr"] / exact)
        old.append(st["std"] * math.sqrt(st["g_si"] / n) / exact)
        covered += abs(st["mean"]) < 1.96 * st["stderr"]
        assert (st["g"] == pytest.approx(n * (st["stderr"] / st["std"]) ** 2)
                and st["n_eff"] == pytest.approx(n / st["g"]))
    assert np.median(old) < 0.75                                  # the failure: the truncated sum alone
    lo, med, hi = np.percentile(new, [5, 50, 95])
    assert 0.85 < med < 1.15 and 0.75 < lo and hi < 1.3
    assert covered >= 50                                          # of 60, at 95 % intervals


def test_a_fluctuation_slower_than_the_window_does_not_make_the_detection_keep_only_a_tail():
    """A window whose mean force wanders over more than the window (a sinusoid of 2/3 the window's frequency,
    amplitude 8x the fast noise): unbounded, the detection keeps the last few percent, where the series looks
    flat, and its stderr there would be far too small. Capped at half, the mean is taken over at least the last
    half and the stderr covers the true mean (0) in all 20 seeded phases."""
    rng = np.random.default_rng(1992)
    n = 1500
    t = np.arange(n)
    for _ in range(20):
        x = 4.0 * np.sin(2 * np.pi * t / 1000 + rng.uniform(0, 2 * np.pi)) + rng.normal(0.0, 0.5, n)
        assert detect_equilibration(x, max_discard=0.999)["t0"] > 0.8 * n          # the failure, unbounded
        st = timeseries_stats(x)
        assert st["t0"] <= n // 2 and abs(st["mean"]) < 2.0 * st["stderr"]


def test_blocking_stderr_of_white_noise_and_of_a_series_too_short_to_block():
    rng = np.random.default_rng(461)
    x = rng.normal(size=4096)
    assert blocking_stderr(x) == rel(1.0 / 64.0, 0.3)             # the largest of 8 levels, each within ~13 %
    assert blocking_stderr(x[:31]) == 0.0                         # fewer than 32 samples: no level
    st = timeseries_stats(np.sin(np.arange(40.0)), equilibrate=False)
    assert st["error_method"] in ("statistical inefficiency", "blocking") and st["stderr"] > 0


def test_equilibration_detection_drops_the_transient():
    """A relaxing start (an exponential decay of 18 sd, time constant 200 samples) on AR(1) noise: the detected
    start lies past the transient's bulk, and the mean of what is kept is unbiased within its stderr; using every
    sample would be biased by many stderrs."""
    rng = np.random.default_rng(16)
    n, tau = 4000, 200.0
    x = ar1(0.8, n, rng) + 30.0 * np.exp(-np.arange(n) / tau)
    det = detect_equilibration(x)
    assert 2 * tau < det["t0"] < 0.5 * n
    st = timeseries_stats(x)
    assert st["t0"] == det["t0"] and abs(st["mean"]) < 3 * st["stderr"]
    naive = timeseries_stats(x, equilibrate=False)
    assert naive["mean"] > 5 * st["stderr"]
    assert st["g"] == rel(9.0, 0.35) and st["n_eff"] == pytest.approx((n - st["t0"]) / st["g"])


def test_surface_tension_stderr_uses_the_statistical_inefficiency():
    rng = np.random.default_rng(4)
    n, lz = 20000, 60.0
    c = ar1(0.9, n, rng) * 100.0                               # correlated Pzz fluctuation (atm)
    out = surface_tension(np.zeros(n), np.zeros(n), c, lz, n_blocks=5)
    exact = 0.5 * lz * 100.0 * ar1_exact_stderr(0.9, n) * ATM * 1e-10
    assert out["stderr"] == rel(exact, 0.25)
    assert out["statistical_inefficiency"] == rel(19.0, 0.25) and "stderr_blocks" in out


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


def test_traction_law_fit_stderr_matches_the_scatter_of_repeated_fits():
    rng = np.random.default_rng(12)
    amp, z0, off = 1.5, 2.8, 4.0
    d = np.linspace(off + 2.4, off + 14.0, 120)
    clean = lj93_force(d - off, amp, z0)
    fits = [fit_traction_law(d, clean + rng.normal(0, 0.05, d.size), offset=True) for _ in range(40)]
    zs = np.array([f["z0"] for f in fits])
    es = np.array([f["stderr"]["z0"] for f in fits])
    assert 0.6 < np.median(es) / zs.std() < 1.6
    w = fit_traction_law(d, clean + rng.normal(0, 0.05, d.size), offset=True, force_stderr=np.full(d.size, 0.05))
    assert abs(w["z0"] - z0) < 4 * w["stderr"]["z0"] and w["stderr"]["w"] > 0


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


# ------------------------------------------------------------------------------------ surface tension

def test_surface_tension_of_known_anisotropy_is_exact():
    rng = np.random.default_rng(7)
    common = rng.normal(0.0, 300.0, 5000)                  # isotropic fluctuation: cancels exactly
    pzz = 12.0 + common
    pxx = -480.0 + common
    pyy = -520.0 + common
    lz = 80.0
    expected = 0.5 * lz * (12.0 + 500.0) * ATM * 1e-10     # N/m
    out = surface_tension(pxx, pyy, pzz, lz)
    assert out["value"] == rel(expected, 1e-12)
    assert out["stderr"] < 1e-12 * expected
    tail = 1.5e-3
    out2 = surface_tension(pxx, pyy, pzz, np.full(5000, lz), tail_correction_N_per_m=tail)
    assert out2["value"] == rel(expected + tail, 1e-12)
    assert out2["tail_correction"] == tail and out2["units"] == "N/m"


def test_surface_tension_error_reflects_independent_noise():
    rng = np.random.default_rng(8)
    n, sd, lz = 50000, 200.0, 60.0
    pxx, pyy, pzz = (rng.normal(0.0, sd, n) for _ in range(3))
    out = surface_tension(pxx, pyy, pzz, lz)
    exact = 0.5 * lz * sd * math.sqrt(1.5) / math.sqrt(n) * ATM * 1e-10
    assert exact / 1.5 < out["stderr"] < 1.5 * exact
    assert abs(out["value"]) < 4 * exact


def test_lj_tail_correction_sharp_limit_and_width_dependence():
    eps, sig, rho, rc = 0.1553, 3.166, 0.0334, 10.0            # SPC/E oxygens, 10 A cutoff
    sharp = lj_tail_correction(eps, sig, rho, rc)
    closed = 1.5 * math.pi * eps * sig**6 * rho**2 / rc**2 * KCAL / (N_A * 1e-20)
    assert sharp == rel(closed, 1e-12)
    assert lj_tail_correction(eps, sig, rho, rc, width_A=1e-3) == rel(sharp, 1e-3)
    wide = lj_tail_correction(eps, sig, rho, rc, width_A=2.0)
    assert 0 < wide < sharp                                       # a diffuse interface lowers the tail
    assert lj_tail_correction(eps, sig, rho, 2 * rc) == rel(sharp / 4, 1e-12)


# ------------------------------------------------------------------------------------------- densities

def test_density_profile_conserves_mass():
    rng = np.random.default_rng(1)
    z = rng.uniform(0, 50, (4, 300))
    m = rng.uniform(1, 20, 300)
    area = 900.0
    prof = density_profile(z, m, area, np.linspace(0, 50, 101))
    dz = np.diff(prof["edges_A"]) * 1e-10
    mass = np.sum(prof["density"] * dz * area * 1e-20)           # kg per frame
    assert mass == rel(m.sum() * 1e-3 / N_A, 1e-12)


@pytest.mark.parametrize("centre", [40.0, 2.0])                  # 2.0: the slab straddles z = 0
def test_slab_density_recovers_water_density(centre):
    rng = np.random.default_rng(4)
    lx = ly = 30.0
    lz, half, rho = 100.0, 20.0, 997.0                            # kg/m^3
    n = int(rho / (18.015e-3 / N_A) * lx * ly * 2 * half * 1e-30)
    frames = []
    for _ in range(50):
        zz = rng.normal(0, 1.0, n) + rng.uniform(-half, half, n)   # smeared slab edges
        frames.append((zz + centre + rng.normal(0, 1.0)) % lz)
    out = slab_density(np.array(frames), np.full(n, 18.015), lx * ly, lz_A=lz)
    assert out["value"] == rel(rho, 0.01)
    assert out["half_thickness_A"] == pytest.approx(half, abs=0.3)
    assert 0 < out["stderr"] < 10.0


# -------------------------------------------------------------------------------------------- pull-off

def lj93_force(d, amp, z0):
    return amp * ((z0 / d) ** 9 - (z0 / d) ** 3)


def test_pull_off_of_lj93_force_curve_is_analytic():
    amp, z0 = 2.0, 3.0                                             # kcal/mol/A, A
    d = np.linspace(2.5, 15.0, 2501)
    out = pull_off_analysis(d, lj93_force(d, amp, z0), radius_m=5e-9)
    fmax = amp * 2.0 / (3.0 * math.sqrt(3.0)) * KCAL / (N_A * 1e-10)   # N
    assert out["max_tensile_force"] == rel(fmax, 1e-6)
    assert out["separation_at_max"] == rel(3 ** (1 / 6) * z0 * 1e-10, 1e-5)
    assert out["zero_force_separation"] == rel(z0 * 1e-10, 1e-5)
    assert out["z0_zero_to_min"] == rel((3 ** (1 / 6) - 1) * z0 * 1e-10, 1e-4)
    assert out["z0"] == rel(z0 * 1e-10, 1e-6)                          # the fitted law's z0
    fit = out["traction_fit"]
    assert fit["w"] == rel(3 * z0 * amp / 8 * KCAL / N_A, 1e-6)      # J (force x length)
    assert fit["offset"] == pytest.approx(0.0, abs=1e-15)
    assert fit["h0_maugis"] == rel(9 * math.sqrt(3) / 16 * z0 * 1e-10, 1e-6)
    f = out["max_tensile_force"]
    assert out["eff_work_jkr"] == rel(f / (1.5 * math.pi * 5e-9), 1e-12)
    assert out["eff_work_dmt"] == rel(f / (2.0 * math.pi * 5e-9), 1e-12)


def test_traction_law_fit_recovers_an_offset_origin():
    amp, z0, off = 1.5, 2.8, 4.0
    d = np.linspace(off + 2.4, off + 14.0, 600)
    fit = fit_traction_law(d, lj93_force(d - off, amp, z0), offset=True)
    assert fit["z0"] == rel(z0, 1e-5)
    assert fit["offset"] == pytest.approx(off, abs=1e-4)
    assert fit["w"] == rel(3 * z0 * amp / 8, 1e-5)


def test_traction_law_fit_works_when_separations_start_below_zero():
    """A compressed MD contact reports separations below zero (the rigid-holder gap); the law's origin is then
    negative and the curve includes a stiff wall, which the fit must leave out and still recover the law."""
    amp, z0, off = 1.5, 2.8, -5.0
    d = np.linspace(off + 1.6, off + 14.0, 800)
    f = lj93_force(d - off, amp, z0)
    assert f.max() > 3 * abs(f.min()) and d.min() < 0
    fit = fit_traction_law(d, f, offset=True)
    assert fit["z0"] == rel(z0, 1e-5) and fit["offset"] == pytest.approx(off, abs=1e-4)
    with pytest.raises(ValueError, match="positive"):
        fit_traction_law(d, f, offset=False)


def test_sphere_law_gives_dmt_work_for_rigid_sphere():
    r_m, w_si, z0 = 4e-9, 0.1, 3.2                                     # m, J/m^2, A
    fc = 2 * math.pi * r_m * w_si / (KCAL / (N_A * 1e-10))           # kcal/mol/A
    d = np.linspace(2.7, 20.0, 3000)
    f = fc * ((z0 / d) ** 8 / 3 - 4 * (z0 / d) ** 2 / 3)
    out = pull_off_analysis(d, f, radius_m=r_m, law="sphere_lj93", fit_offset=False)
    assert out["eff_work_dmt"] == rel(w_si, 1e-6)
    assert out["separation_at_max"] == rel(z0 * 1e-10, 1e-5)
    assert out["z0"] == rel(z0 * 1e-10, 1e-6)
    assert out["traction_fit"]["w"] == rel(w_si, 1e-6)


def test_pull_off_of_noisy_curve_with_smoothing():
    rng = np.random.default_rng(9)
    amp, z0 = 2.0, 3.0
    d = np.linspace(2.6, 12.0, 1000)
    f = lj93_force(d, amp, z0) + rng.normal(0, 0.05 * amp, d.size)
    out = pull_off_analysis(d, f, smooth=51)
    fmax = amp * 2.0 / (3.0 * math.sqrt(3.0)) * KCAL / (N_A * 1e-10)
    assert out["max_tensile_force"] == rel(fmax, 0.03)
    assert out["z0"] == rel(z0 * 1e-10, 0.03)


def test_rate_extrapolation_recovers_bell_evans_line():
    rates = np.array([1.0, 3.0, 10.0, 30.0, 100.0])                  # m/s
    kt, xb, f_ref = 1.380649e-23 * 300.0, 2e-10, 1e-9
    forces = f_ref + kt / xb * np.log(rates)
    out = rate_extrapolation(rates, forces, target_rate=1e-3, temperature_K=300.0)
    assert out["F0"] == rel(f_ref + kt / xb * math.log(1e-3), 1e-9)
    assert out["slope"] == rel(kt / xb, 1e-9)
    assert out["x_beta"] == rel(xb, 1e-9)
    assert out["stderr"] < 1e-6 * abs(out["F0"])
    rng = np.random.default_rng(2)
    noisy = rate_extrapolation(rates, forces + rng.normal(0, 1e-12, 5), target_rate=1e-3,
                               forces_stderr=np.full(5, 1e-12))
    assert abs(noisy["F0"] - out["F0"]) < 4 * noisy["stderr"]
    assert noisy["stderr"] > 1e-12


# --------------------------------------------------------------------------------------- contact angle

@pytest.fixture
def mda():
    require_backend("MDAnalysis", "MDAnalysis")
    import MDAnalysis

    return MDAnalysis


WATER_N = 0.0334                  # water molecules per A^3
WATER_G_CM3 = WATER_N * 18.015 / N_A * 1e24


def cap_universe(mda, theta_deg, radius, box, surface_z, n_frames, x_centre, rng, width=0.0,
                 layering=False, vapour=0.0):
    """A cylindrical cap (axis along y) of water oxygens, uniform in the cap, one frame per draw.

    ``width`` > 0 smears the interface with a tanh profile of that width; ``layering`` adds decaying
    density oscillations next to the wall; ``vapour`` (1/A^3) scatters atoms over the whole box.  The
    droplet is placed at ``x_centre`` (wrapped into the box) with a 2 A random drift per frame.
    """
    from MDAnalysis.coordinates.memory import MemoryReader

    lx, ly, lz = box
    th = math.radians(theta_deg)
    zc = surface_z - radius * math.cos(th)
    xw = (radius if theta_deg >= 90 else radius * math.sin(th)) + 4 * width
    ztop = zc + radius + 4 * width
    pmax = 1.8 if layering else 1.0

    def accept(x, z):
        p = 0.5 * (1 - np.tanh((np.hypot(x, z - zc) - radius) / width)) if width > 0 else \
            (np.hypot(x, z - zc) < radius).astype(float)
        if layering:
            p *= 1 + 0.8 * np.exp(-(z - surface_z) / 2.0) * np.cos(2 * np.pi * (z - surface_z) / 2.8)
        return p

    n_box = int(WATER_N * 2 * xw * (ztop - surface_z) * ly * pmax)
    n_vap = int(vapour * lx * ly * (lz - surface_z))
    expected = None
    frames = []
    for _ in range(n_frames):
        x, z = rng.uniform(-xw, xw, n_box), rng.uniform(surface_z, ztop, n_box)
        keep = rng.uniform(0, pmax, n_box) < accept(x, z)
        if expected is None:
            expected = int(0.9 * keep.sum())            # fixed atom count: thin every frame to it
        p = np.column_stack([x[keep], z[keep]])[:expected]
        assert len(p) == expected
        if n_vap:
            vap = np.column_stack([rng.uniform(0, lx, n_vap), rng.uniform(surface_z, lz, n_vap)])
            p = np.vstack([p[:expected - n_vap], vap])
        xs = (p[:, 0] + x_centre + 2.0 * rng.standard_normal()) % lx
        frames.append(np.column_stack([xs, rng.uniform(0, ly, expected), p[:, 1]]))
    u = mda.Universe.empty(expected, trajectory=True)
    u.load_new(np.array(frames, dtype=np.float32), format=MemoryReader,
               dimensions=np.array([lx, ly, lz, 90.0, 90.0, 90.0]))
    return u


CAPS = {30: (150.0, 260.0), 90: (40.0, 120.0), 120: (30.0, 110.0)}     # theta: (radius, box x) in A


@pytest.mark.parametrize("straddle", [False, True], ids=["centred", "straddling"])
@pytest.mark.parametrize("theta", sorted(CAPS))
def test_contact_angle_of_uniform_circular_cap(mda, theta, straddle):
    radius, lx = CAPS[theta]
    rng = np.random.default_rng(theta + 7 * straddle)
    s = 10.0
    u = cap_universe(mda, theta, radius, (lx, 50.0, 120.0), s, 60, 1.0 if straddle else lx / 2, rng)
    res = ContactAngle(u.atoms, surface_z=s, axis="y").run().results
    assert res.angle_deg == pytest.approx(theta, abs=1.0)
    assert 0 < res.stderr_deg < 1.0
    xc, zc, r = res.circle
    assert r == rel(radius, 0.01)
    assert xc == pytest.approx(0.0, abs=1.0)                      # centred on the droplet
    if theta != 90:
        assert (zc < s) == (theta < 90)                            # centre below the wall: theta < 90
    assert res.bulk_density == rel(0.9 * WATER_G_CM3, 0.03)
    assert res.density_map.shape == (len(res.edges[0]) - 1, len(res.edges[1]) - 1)
    assert np.all(res.interface_points[:, 1] > s + 5.0)


def wobbling_cap(mda, theta_series, area, box, s, rng):
    """A cylindrical cap of fixed cross-section ``area`` (A^2) whose angle follows ``theta_series`` frame by frame:
    a droplet whose shape relaxes over many frames. A fixed number of uniform atoms per frame."""
    from MDAnalysis.coordinates.memory import MemoryReader

    lx, ly, lz = box
    n_atoms = int(0.9 * WATER_N * area * ly)
    frames = []
    for th_deg in theta_series:
        th = math.radians(th_deg)
        radius = math.sqrt(area / (th - math.sin(th) * math.cos(th)))
        zc = s - radius * math.cos(th)
        xw = radius if th_deg >= 90 else radius * math.sin(th)
        pts = np.zeros((0, 2))
        while len(pts) < n_atoms:
            x, z = rng.uniform(-xw, xw, 4 * n_atoms), rng.uniform(s, zc + radius, 4 * n_atoms)
            inside = np.hypot(x, z - zc) < radius
            pts = np.vstack([pts, np.column_stack([x[inside], z[inside]])])
        p = pts[:n_atoms]
        frames.append(np.column_stack([(p[:, 0] + lx / 2) % lx, rng.uniform(0, ly, n_atoms), p[:, 1]]))
    u = mda.Universe.empty(n_atoms, trajectory=True)
    u.load_new(np.array(frames, dtype=np.float32), format=MemoryReader,
               dimensions=np.array([lx, ly, lz, 90.0, 90.0, 90.0]))
    return u


def test_contact_angle_blocks_are_sized_by_how_often_the_droplet_shape_decorrelates(mda):
    """Frames whose angle is independent keep the recipe's 5 blocks; a droplet still relaxing through the run
    (its angle a half sine over 120 frames, +-6 deg, under 1 deg of noise) gets the fewest blocks (3), and the
    run says they are not independent: its stderr is then a lower bound, not an error bar."""
    box, area = (160.0, 30.0, 100.0), math.pi * 35.0 ** 2 / 2
    rng = np.random.default_rng(3)
    free = ContactAngle(wobbling_cap(mda, 90.0 + rng.normal(0, 2.0, 60), area, box, 10.0, rng).atoms,
                        surface_z=10.0, n_blocks=5).run().results
    assert free.n_blocks_used == 5 and free.blocks_independent and free.shape_statistical_inefficiency < 2.0
    assert free.angle_deg == pytest.approx(90.0, abs=1.5) and len(free.block_angles_deg) == 5
    theta = 90.0 + 6.0 * np.cos(np.pi * np.arange(120) / 119) + rng.normal(0, 1.0, 120)
    slow = ContactAngle(wobbling_cap(mda, theta, area, box, 10.0, rng).atoms, surface_z=10.0,
                        n_blocks=5).run().results
    assert slow.n_blocks_used == 3 and not slow.blocks_independent
    assert slow.shape_statistical_inefficiency > 10.0 and len(slow.shape_series_A) == 120


def test_contact_angle_with_diffuse_interface_wall_layering_and_vapour(mda):
    rng = np.random.default_rng(21)
    s = 10.0
    u = cap_universe(mda, 120, 30.0, (110.0, 50.0, 120.0), s, 60, 3.0, rng, width=1.5, layering=True,
                     vapour=2e-5)
    res = ContactAngle(u.atoms, surface_z=s).run().results
    assert res.angle_deg == pytest.approx(120.0, abs=1.0)


def test_contact_angle_along_x_axis(mda):
    """A droplet periodic along x: the map is in (y, z)."""
    rng = np.random.default_rng(4)
    u = cap_universe(mda, 90, 40.0, (120.0, 50.0, 120.0), 10.0, 30, 60.0, rng)
    pos = u.trajectory.coordinate_array
    u.trajectory.coordinate_array[:] = pos[:, :, [1, 0, 2]]        # swap x and y
    u.trajectory.dimensions_array[:, [0, 1]] = u.trajectory.dimensions_array[:, [1, 0]]
    res = ContactAngle(u.atoms, surface_z=10.0, axis="x").run().results
    assert res.angle_deg == pytest.approx(90.0, abs=1.0)


def test_fit_contact_angle_on_exact_coverage_map():
    """Bins filled with the exact area fraction of a 60 deg cap: the half-density contour is the circle."""
    radius, s, th = 50.0, 0.0, math.radians(60)
    zc = s - radius * math.cos(th)
    ue, ze = np.arange(-60, 60.01, 0.5), np.arange(s, 40.01, 0.5)
    sub = (np.arange(8) + 0.5) / 8 * 0.5                               # 8 x 8 samples per bin
    uu, zz = ue[:-1, None] + sub, ze[:-1, None] + sub
    cov = (np.hypot(uu[:, None, :, None], zz[None, :, None, :] - zc) < radius).mean(axis=(2, 3))
    fit = fit_contact_angle(cov, ue, ze, surface_z=s, exclude_layer=3.0)
    assert fit["angle_deg"] == pytest.approx(60.0, abs=0.1)
    assert fit["bulk_density"] == rel(1.0, 1e-9)
    assert fit["fit_rms_A"] < 0.1


def test_contact_angle_needs_a_box(mda):
    from MDAnalysis.coordinates.memory import MemoryReader

    u = mda.Universe.empty(10, trajectory=True)
    u.load_new(np.zeros((2, 10, 3), np.float32), format=MemoryReader)
    with pytest.raises(ValueError, match="box"):
        ContactAngle(u.atoms, surface_z=0.0).run()
    with pytest.raises(ValueError, match="axis"):
        ContactAngle(u.atoms, surface_z=0.0, axis="z")


def test_fit_circle_is_unbiased_on_a_short_noisy_arc():
    """A 30 deg arc with 1 A noise: the algebraic (Kasa) fit alone returns about half the radius."""
    from md.analysis import fit_circle

    rng = np.random.default_rng(3)
    radius = 100.0
    t = np.radians(np.linspace(75, 105, 400))
    radii = [fit_circle(radius * np.cos(t) + rng.normal(0, 1.0, t.size),
                        radius * np.sin(t) + rng.normal(0, 1.0, t.size))[2] for _ in range(5)]
    assert np.mean(radii) == rel(radius, 0.05)
    xc, zc, r = fit_circle([1.0, -1.0, 0.0], [2.0, 2.0, 3.0])      # exact circle through 3 points
    assert (xc, zc, r) == pytest.approx((0.0, 2.0, 1.0), abs=1e-9)


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
