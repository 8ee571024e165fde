"""Has a time series stopped drifting? A least-squares linear trend with a stderr that accounts for the series'
autocorrelation.

An equilibration (a SAM annealed before contact, a contact leg) is long enough when its observables no longer
trend. The slope b of the ordinary least-squares line through (t, y) has, for white noise, the stderr
s_res / sqrt(sum (t - mean t)^2); correlated residuals carry fewer independent samples, so that stderr is
multiplied by sqrt(g), g the statistical inefficiency of the residuals (the effective-sample-size correction of
the regression slope for a slowly decorrelating series; e.g. Chodera, J. Chem. Theory Comput. 12 (2016) 1799 for g,
and Santer et al., J. Geophys. Res. 105 (2000) 7337 for the effective sample size of a trend). The series drifts
when |b| exceeds ``z_max`` such stderrs (2: the two-sided 95 % test).
"""
from __future__ import annotations

import math

import numpy as np

from md.analysis.stats import statistical_inefficiency

#: |slope| / stderr above which a series is reported as drifting (two-sided 95 %)
DRIFT_Z_MAX = 2.0


def linear_drift(t, y, z_max: float = DRIFT_Z_MAX) -> dict:
    """Linear trend of ``y`` against ``t``: slope and its autocorrelation-corrected stderr, the drift over the
    series (slope x span) with its stderr, the statistical inefficiency g of the residuals, z = slope / stderr,
    and ``drifting`` = |z| > z_max. Needs at least 4 points."""
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    if t.shape != y.shape or t.size < 4:
        raise ValueError(f"linear_drift needs matching series of at least 4 points, got {t.size} and {y.size}")
    tc = t - t.mean()
    sxx = float(np.sum(tc * tc))
    if sxx <= 0.0:
        raise ValueError("linear_drift needs at least two distinct times")
    slope = float(np.sum(tc * (y - y.mean())) / sxx)
    resid = y - y.mean() - slope * tc
    s2 = float(np.sum(resid * resid)) / (t.size - 2)
    g = statistical_inefficiency(resid) if s2 > 0 else 1.0
    stderr = math.sqrt(s2 / sxx * max(g, 1.0))
    z = slope / stderr if stderr > 0 else (0.0 if slope == 0 else math.inf)
    span = float(t[-1] - t[0])
    return {"slope": slope, "slope_stderr": stderr, "drift": slope * span, "drift_stderr": stderr * abs(span),
            "g": float(g), "z": float(z), "z_max": float(z_max), "drifting": bool(abs(z) > z_max), "n": int(t.size)}
