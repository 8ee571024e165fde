"""Has a time series stopped drifting? A least-squares linear trend tested against two stderrs: one corrected for
the series' autocorrelation, one from block means.

An equilibration (a SAM annealed before contact, a contact leg) is long enough when its observables no longer
trend. The slope b of the ordinary least-squares line through (t, y) has, for white noise, the stderr
s_res / sqrt(sum (t - mean t)^2); correlated residuals carry fewer independent samples, so that stderr is
multiplied by sqrt(g), g the statistical inefficiency of the residuals (the effective-sample-size correction of
the regression slope for a slowly decorrelating series; e.g. Chodera, J. Chem. Theory Comput. 12 (2016) 1799 for g,
and Santer et al., J. Geophys. Res. 105 (2000) 7337 for the effective sample size of a trend).

Why a second stderr. g sums the residuals' autocorrelation up to its first zero crossing, so a series with a fast
oscillation (an MD potential energy: the vibrational exchange with the kinetic energy makes C(t) negative within
a fraction of a picosecond) stops the sum before a slower fluctuation (collective SAM rearrangements over tens of
ps) has contributed: g then comes out near 1 and the slope's stderr several times too small. The regression of
block means (the series cut into :data:`DRIFT_BLOCKS` contiguous blocks, the slope's stderr from the scatter of
the block means about their line, m - 2 degrees of freedom) needs no autocorrelation model, only blocks longer
than the correlation time (the blocking idea of Flyvbjerg & Petersen, J. Chem. Phys. 91 (1989) 461, applied to
a trend); its critical value is Student's t at the level that ``z_max`` sets for the normal test. Each misses a
different thing (the ACF misses what is slower than its first zero, the blocks what is slower than a block, and
with few degrees of freedom the blocks lose power), so a series is reported as drifting when its slope exceeds
both critical values, and ``slope_stderr`` is the larger of the two stderrs.
"""
from __future__ import annotations

import math

import numpy as np

from md.analysis.stats import statistical_inefficiency, student_t_factor

#: |slope| / stderr above which a series is reported as drifting (two-sided 95 %)
DRIFT_Z_MAX = 2.0
#: blocks of the block-means test: 6 degrees of freedom; on a fast oscillation plus an AR(1) whose correlation
#: time is a fifth of a block the test keeps about its nominal false-positive rate
#: (tests/md/test_md_adhesion_drift.py), and more blocks would be shorter than a SAM's slow fluctuations in a
#: 250 ps half-anneal
DRIFT_BLOCKS = 8
#: fewest blocks the block-means test runs on (2 degrees of freedom); shorter series get the ACF test alone
MIN_DRIFT_BLOCKS = 4


def ols_trend(t, y) -> dict:
    """Ordinary least-squares line of ``y`` against ``t``: ``slope``, its white-noise ``stderr`` (residual
    variance over n - 2 degrees of freedom), ``dof`` and the ``residuals``. Needs at least 3 points at two distinct
    times."""
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    tc = t - t.mean()
    sxx = float(np.sum(tc * tc))
    if t.size < 3 or sxx <= 0.0:
        raise ValueError(f"a linear trend needs at least 3 points at two distinct times, got {t.size} points "
                         f"spanning {float(np.ptp(t)) if t.size else 0.0:g}")
    slope = float(np.sum(tc * (y - y.mean())) / sxx)
    resid = y - y.mean() - slope * tc
    dof = t.size - 2
    return {"slope": slope, "stderr": math.sqrt(float(np.sum(resid * resid)) / dof / sxx), "dof": dof,
            "residuals": resid}


def linear_drift(t, y, z_max: float = DRIFT_Z_MAX, blocks: int = DRIFT_BLOCKS) -> dict:
    """Linear trend of ``y`` against ``t`` and whether it is real (module docstring).

    Returns ``slope``; ``slope_stderr_acf`` (white-noise stderr x sqrt(g), ``g`` the residuals' statistical
    inefficiency); ``slope_stderr_blocks`` (from the regression of ``n_blocks`` block means; nan where the series
    has fewer than 2 x :data:`MIN_DRIFT_BLOCKS` points, and the ACF test then decides alone) with its critical
    value ``t_crit``; ``slope_stderr`` (the larger stderr), ``drift`` = slope x span with ``drift_stderr``,
    ``z`` = slope / slope_stderr, ``threshold`` (the smallest |slope| that both tests call a trend;
    ``drift_threshold`` over the span) and
    ``drifting`` = |slope| > threshold. Needs at least 4 points."""
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    if t.shape != y.shape or t.size < 4:
        raise ValueError(f"linear_drift needs matching series of at least 4 points, got {t.size} and {y.size}")
    fit = ols_trend(t, y)
    slope = fit["slope"]
    g = statistical_inefficiency(fit["residuals"]) if fit["stderr"] > 0 else 1.0
    se_acf = fit["stderr"] * math.sqrt(max(g, 1.0))
    m = min(int(blocks), t.size // 2)
    if m >= MIN_DRIFT_BLOCKS:
        idx = np.array_split(np.arange(t.size), m)
        blk = ols_trend([t[i].mean() for i in idx], [y[i].mean() for i in idx])
        # Student's t at the two-sided level that |z| > z_max has for a normal variable
        se_blk, t_crit = blk["stderr"], student_t_factor(blk["dof"] + 1, math.erf(z_max / math.sqrt(2.0)))
    else:
        m, se_blk, t_crit = 0, math.nan, math.nan
    threshold = max(z_max * se_acf, t_crit * se_blk) if m else z_max * se_acf
    stderr = max(se_acf, se_blk) if m else se_acf
    z = slope / stderr if stderr > 0 else (0.0 if slope == 0 else math.inf)
    span = float(t[-1] - t[0])
    return {"slope": slope, "slope_stderr": stderr, "drift": slope * span, "drift_stderr": stderr * abs(span),
            "slope_stderr_acf": se_acf, "g": float(g), "slope_stderr_blocks": se_blk, "n_blocks": m,
            "t_crit": t_crit, "threshold": threshold, "drift_threshold": threshold * abs(span), "z": float(z),
            "z_max": float(z_max), "drifting": bool(abs(slope) > threshold), "n": int(t.size)}


def block_drift(values, times=None) -> dict:
    """Linear trend of a block series (drift check): ordinary least squares of ``values`` against ``times``
    (default 0, 1, 2, ...) with the slope's standard error from the residual scatter (n - 2 degrees of
    freedom). ``drifting`` when |slope| > 2 stderr: the series has not levelled off, so its mean depends on
    where the run stopped. ``change`` is slope x the time span covered. Non-finite values are left out;
    fewer than 3 points give nan."""
    from scipy import stats

    y = np.asarray(values, float)
    t = np.arange(len(y), dtype=float) if times is None else np.asarray(times, float)
    ok = np.isfinite(y) & np.isfinite(t)
    y, t = y[ok], t[ok]
    nan = float("nan")
    if len(y) < 3 or np.ptp(t) == 0:
        return {"slope": nan, "stderr": nan, "t": nan, "p": nan, "change": nan, "drifting": False, "n": int(len(y))}
    fit = ols_trend(t, y)
    slope, se = fit["slope"], fit["stderr"]
    tval = slope / se if se > 0 else (math.inf if slope else 0.0)
    p = float(2 * stats.t.sf(abs(tval), fit["dof"])) if np.isfinite(tval) else 0.0
    return {"slope": slope, "stderr": se, "t": float(tval), "p": p, "change": slope * float(np.ptp(t)),
            "drifting": bool(abs(slope) > 2 * se), "n": int(len(y))}
