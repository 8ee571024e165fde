"""md.analysis's statistics against series with exact answers (no LAMMPS needed): unit conversions, block
averages and blocking, the statistical inefficiency (Chodera), equilibration detection, a surface tension's stderr."""
from __future__ import annotations

import math

import numpy as np
import pytest

from md.analysis import (
    ATM_A_TO_N_PER_M,
    KCALMOL_PER_A2_TO_J_PER_M2,
    KCALMOL_PER_A_TO_N,
    block_analysis,
    block_average,
    blocking_stderr,
    detect_equilibration,
    statistical_inefficiency,
    surface_tension,
    timeseries_stats,
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
