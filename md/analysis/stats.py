"""Statistical errors of MD time series: block averaging (Flyvbjerg & Petersen, J. Chem. Phys. 91 (1989)
461), statistical inefficiency, equilibration detection.
"""
from __future__ import annotations

import math

import numpy as np

#: probability inside one standard deviation of a normal distribution, erf(1/sqrt 2): the level a "stderr" states
ONE_SIGMA_LEVEL = math.erf(1.0 / math.sqrt(2.0))


# ---------------------------------------------------------------------------------------- block errors

def block_average(x, n_blocks: int = 5) -> tuple[float, float]:
    """Mean and standard error of a correlated time series by block averaging (Flyvbjerg-Petersen 1989).

    The series is cut into ``n_blocks`` contiguous blocks of equal length (the first ``len(x) % n_blocks``
    samples -- the oldest -- are dropped); ``stderr = std(block means, ddof=1) / sqrt(n_blocks)``.  The
    blocks must be longer than the correlation time for the error to be right; check with
    :func:`block_analysis`.
    """
    x = np.asarray(x, dtype=float).ravel()
    n_blocks = int(n_blocks)
    if n_blocks < 2:
        raise ValueError(f"n_blocks must be >= 2, got {n_blocks}")
    m = x.size // n_blocks
    if m < 1:
        raise ValueError(f"{x.size} samples cannot fill {n_blocks} blocks")
    means = x[x.size - m * n_blocks:].reshape(n_blocks, m).mean(axis=1)
    return float(means.mean()), float(means.std(ddof=1) / math.sqrt(n_blocks))


def block_analysis(x, min_blocks: int = 4) -> dict:
    """Standard error of the mean against block size: the Flyvbjerg-Petersen blocking transformation.

    The series is halved repeatedly (pairs of neighbours averaged); at each level with ``n`` blocks the
    error estimate is ``sqrt(var(ddof=0) / (n - 1))`` with its own uncertainty ``estimate / sqrt(2 (n -
    1))``.  The estimate grows with the block size and levels off once blocks are longer than the
    correlation time; ``stderr_plateau`` is a heuristic reading of that plateau (the first level whose
    estimate agrees within errors with every larger block size), ``nan`` when none does.

    Returns ``block_size``, ``n_blocks``, ``stderr``, ``stderr_error`` (arrays) and ``stderr_plateau``.
    """
    y = np.asarray(x, dtype=float).ravel()
    sizes, counts, errs, derrs = [], [], [], []
    size = 1
    while y.size >= max(2, min_blocks):
        n = y.size
        se = math.sqrt(y.var() / (n - 1))
        sizes.append(size), counts.append(n), errs.append(se), derrs.append(se / math.sqrt(2.0 * (n - 1)))
        if n % 2:
            y = y[1:]
        y = 0.5 * (y[0::2] + y[1::2])
        size *= 2
    errs_a, derrs_a = np.array(errs), np.array(derrs)
    plateau = float("nan")
    for i in range(len(errs_a) - 1):
        later = slice(i + 1, None)
        if np.all(np.abs(errs_a[later] - errs_a[i]) <= derrs_a[later] + derrs_a[i]):
            plateau = float(errs_a[i])
            break
    return {"block_size": np.array(sizes), "n_blocks": np.array(counts), "stderr": errs_a,
            "stderr_error": derrs_a, "stderr_plateau": plateau}


# ----------------------------------------------------------------------------- statistical inefficiency
#
# Chodera, "A simple method for automated equilibration detection in molecular simulations", J. Chem. Theory
# Comput. 12 (2016) 1799, the estimators of pymbar.timeseries (statisticalInefficiency, detectEquilibration),
# written here with an FFT autocovariance so that pymbar is not a dependency. Every MD quantity's stderr goes
# through timeseries_stats (or, for a derived quantity, through the stderrs it returns), not fixed block counts.

def _autocorrelation(x: np.ndarray) -> np.ndarray:
    """Normalised autocorrelation C(t) = <dx_i dx_{i+t}>_{i < N-t} / var, t = 0 .. N-1 (FFT, zero padded)."""
    n = x.size
    dx = x - x.mean()
    var = float(dx @ dx) / n
    size = 1 << int(2 * n - 1).bit_length()
    f = np.fft.rfft(dx, size)
    acov = np.fft.irfft(f * np.conj(f), size)[:n] / np.arange(n, 0, -1)
    return acov / var


def statistical_inefficiency(x, mintime: int = 3) -> float:
    """Statistical inefficiency g of a stationary series (Chodera 2016, eq. 7; pymbar.timeseries):

        g = 1 + 2 sum_{t=1}^{N-1} (1 - t/N) C(t),

    the sum truncated at the first t > ``mintime`` with C(t) <= 0 (beyond it C(t) is noise), g >= 1. The number
    of effectively uncorrelated samples is N/g and the integrated autocorrelation time (tau = (g - 1)/2) in
    sample intervals. A constant series (zero variance) has g = 1.
    """
    x = np.asarray(x, float).ravel()
    n = x.size
    if n < 2:
        return 1.0
    if not float(np.ptp(x)) > 0.0:
        return 1.0
    c = _autocorrelation(x)
    t = np.arange(1, n - 1)
    stop = np.flatnonzero((c[1:n - 1] <= 0.0) & (t > mintime))
    end = int(stop[0]) if stop.size else t.size
    g = 1.0 + 2.0 * float(np.sum((1.0 - t[:end] / n) * c[1:end + 1]))
    return max(1.0, g)


#: the largest fraction of a series that equilibration detection may discard
MAX_DISCARD = 0.5


def detect_equilibration(x, nskip: int | None = None, min_samples: int = 10,
                         max_discard: float = MAX_DISCARD) -> dict:
    """Automated equilibration detection (Chodera 2016, pymbar.timeseries.detectEquilibration): the start t0
    that maximises the effective number of uncorrelated samples N_eff(t0) = (N - t0) / g(t0) of the production
    part x[t0:], with t0 at most ``max_discard`` N. ``nskip``: candidate starts every nskip samples (default:
    about 100 candidates); at least ``min_samples`` are kept. Returns ``t0``, ``g`` (of x[t0:]) and ``n_eff``.

    Why the cap: a fluctuation slower than the series makes a late tail look stationary, and N_eff(t0) then
    peaks there: in a force window held at contact whose force wanders over most of the window, unbounded
    detection keeps only the last few percent of the samples and gives a stderr far below the blocking estimate
    over the whole window. A mean is therefore never taken over less than the last half, the usual warm-up convention
    (Gelman & Rubin, Statist. Sci. 7 (1992) 457). A slow drift then shows in the stderr instead of vanishing from it."""
    x = np.asarray(x, float).ravel()
    n = x.size
    if n < 2:
        return {"t0": 0, "g": 1.0, "n_eff": float(n)}
    step = max(1, n // 100) if nskip is None else max(1, int(nskip))
    last = min(n - max(2, min_samples), int(max_discard * n))
    best = (0, 1.0, -1.0)
    for t0 in range(0, max(1, last + 1), step):
        g = statistical_inefficiency(x[t0:])
        ne = (n - t0) / g
        if ne > best[2]:
            best = (t0, g, ne)
    return {"t0": int(best[0]), "g": float(best[1]), "n_eff": float(best[2])}


def timeseries_stats(x, *, equilibrate: bool = True, mintime: int = 3) -> dict:
    """Mean of a correlated series and its standard error from the statistical inefficiency (Chodera 2016),
    checked by blocking.

    With ``equilibrate`` the start is chosen by :func:`detect_equilibration` (the samples before t0 are discarded
    as not yet equilibrated); then ``stderr = sqrt(var(x[t0:], ddof=1) g / (N - t0))``, or the blocking estimate
    (:func:`blocking_stderr`) where that is larger: the sum behind g stops at the first lag where C(t) <= 0,
    which an autocorrelation that oscillates before it decays reaches early. The pressure tensor of SPC/E water
    dips below zero at 60 fs and is positive again at 100 fs; there g came out 2 where the blocking plateau
    says 4-8, so the stderr of gamma_lv was low by 1.5-1.8x. On AR(1) series and the adhesion runs' potential
    energies the blocking estimate is the smaller one and changes nothing.

    Returns ``mean``, ``stderr``, ``g`` (the statistical inefficiency the stderr implies: N (stderr / std)^2),
    ``g_si`` (the truncated sum's), ``stderr_blocking``, ``error_method`` ('statistical inefficiency' or
    'blocking'), ``tau`` ((g - 1)/2, sample intervals), ``t0`` (first sample used), ``n`` (samples used),
    ``n_eff`` = n/g and ``std``. A series of one sample has an undefined (nan) stderr.
    """
    x = np.asarray(x, float).ravel()
    if x.size == 0:
        raise ValueError("empty series")
    t0 = detect_equilibration(x)["t0"] if equilibrate and x.size >= 4 else 0
    y = x[t0:]
    n = y.size
    g_si = statistical_inefficiency(y, mintime)
    if n < 2:
        return {"mean": float(y.mean()), "stderr": float("nan"), "g": 1.0, "g_si": 1.0,
                "stderr_blocking": float("nan"), "error_method": "statistical inefficiency", "tau": 0.0, "t0": t0,
                "n": n, "n_eff": float(n), "std": float("nan")}
    sd = float(y.std(ddof=1))
    se_si, se_b = sd * math.sqrt(g_si / n), blocking_stderr(y)
    blocked = se_b > se_si
    se = se_b if blocked else se_si
    g = n * (se / sd) ** 2 if blocked else g_si
    return {"mean": float(y.mean()), "stderr": se, "g": g, "g_si": g_si, "stderr_blocking": se_b,
            "error_method": "blocking" if blocked else "statistical inefficiency", "tau": 0.5 * (g - 1.0),
            "t0": t0, "n": n, "n_eff": n / g, "std": sd}


#: fewest blocks a blocking level may have for :func:`blocking_stderr` (its own relative error is then at most
#: 1/sqrt(2 x 31) = 13 %)
BLOCKING_MIN_BLOCKS = 32


def blocking_stderr(x, min_blocks: int = BLOCKING_MIN_BLOCKS) -> float:
    """The largest standard error of the mean over the blocking levels of :func:`block_analysis` (block sizes 1,
    2, 4, ...) that keep at least ``min_blocks`` blocks (Flyvbjerg & Petersen, J. Chem. Phys. 91 (1989) 461: the
    estimate rises with the block size until the blocks outlast the correlations). A lower bound where the
    correlations outlast the largest such block; 0.0 for a series too short for any level."""
    levels = block_analysis(x, min_blocks=min_blocks)
    errs = levels["stderr"][levels["n_blocks"] >= min_blocks]
    return float(errs.max()) if errs.size else 0.0


# ------------------------------------------------------------------------------------- few samples

def student_t_factor(n_samples: int, level: float = ONE_SIGMA_LEVEL) -> float:
    """Student-t coverage factor for the mean of ``n_samples`` independent samples whose stderr is estimated from
    their own spread (std / sqrt n, n - 1 degrees of freedom): the half-width of the ``level`` interval is
    t * stderr, t = the (1 + level)/2 quantile of Student's t with n - 1 degrees of freedom (JCGM 100:2008, the GUM,
    annex G.3-G.4). At the one-sigma level (68.27 %) t = 1.84 for two samples and 1.32 for three; it tends to 1 for
    many. A "stderr" multiplied by it is the one-sigma-equivalent half-width that a normal error would have.
    One sample or none: no spread to estimate from (ValueError)."""
    from scipy.stats import t as student_t

    n = int(n_samples)
    if n < 2:
        raise ValueError(f"n_samples = {n_samples}: a spread needs at least two samples")
    if not 0.0 < level < 1.0:
        raise ValueError(f"level = {level}: must lie in (0, 1)")
    return float(student_t.ppf(0.5 * (1.0 + level), n - 1))
