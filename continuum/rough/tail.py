"""The summit-height distribution an ensemble member draws its strip from: two declared tail models of a map.

The roller's strip holds far more summits (10^5-10^7) than a scan (tens to thousands), so what touches first is a
summit from the far tail of the height distribution, beyond the tallest the map holds. The map cannot fix that tail;
the run therefore states the model it extrapolates with, and reports the outcome under two (result.json ->
ensemble.tail_models):

- ``gaussian``: Gaussian summit heights of the map's standard deviation sigma_s (the Greenwood-Williamson surface
  the mean-field law uses; Greenwood & Williamson, Proc. R. Soc. Lond. A 295 (1966) 300). The member's own draw
  (`continuum.laws.discrete_roller`), nothing else.
- ``empirical_gpd``: the map's own summit heights (about their mean) below a threshold u, and above it a generalised
  Pareto distribution fitted to the exceedances by maximum likelihood (peaks over threshold: Pickands, Ann. Stat. 3
  (1975) 119, the GPD is the limit law of exceedances over a high threshold for any distribution in an extreme-value
  domain of attraction; Coles, *An Introduction to Statistical Modeling of Extreme Values*, Springer 2001, ch. 4;
  `scipy.stats.genpareto`). A draw is the threshold plus a GPD variate with probability p_u = (exceedances /
  summits), else one of the heights below u, uniformly (the empirical distribution).

Estimator (declared): probability-weighted moments (Hosking & Wallis, Technometrics 29 (1987) 339), closed form,
with a0 = mean excess and a1 = mean of y_(i) (n - i)/(n - 1) over the ascending excesses y_(i):
xi = 2 - a0/(a0 - 2 a1), scale = 2 a0 a1/(a0 - 2 a1). A map offers tens of exceedances, where maximum likelihood
is erratic (for xi < -1 its likelihood is unbounded at the sample maximum; Smith, Biometrika 72 (1985) 67, regular
only for xi > -0.5) and PWM has the smaller error (Hosking & Wallis 1987, n <= 50). The maximum-likelihood fit
(`scipy.stats.genpareto.fit`, loc 0) is recorded beside it.

Threshold (declared): the k-th largest summit height with k = max(MIN_EXCEEDANCES, ceil(TAIL_FRACTION n)) of n
summits, so the fit has at least MIN_EXCEEDANCES points and the top fifth of a large map. Shape xi < 0 is a tail
bounded at u - scale/xi (lighter than Gaussian), xi = 0 exponential (Gaussian-like), xi > 0 heavy.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats as sps

from .datum import FOOTPRINT_BAND, tallest_summit

__all__ = ["TAIL_MODELS", "MIN_EXCEEDANCES", "TAIL_FRACTION", "TailFitError", "EmpiricalGPD", "fit_empirical_gpd",
           "map_summit_record", "strip_half_width"]

#: The tail models an ensemble of a height map is run under (the first is what a scene without a map has).
TAIL_MODELS = ("gaussian", "empirical_gpd")
#: Fewest exceedances a generalised Pareto fit is made with.
MIN_EXCEEDANCES = 10
#: Fraction of the map's summits above the threshold where that is more than MIN_EXCEEDANCES.
TAIL_FRACTION = 0.2
#: Below this shape the maximum-likelihood estimate is not regular (Smith 1985).
REGULAR_XI = -0.5
#: PWM estimates exist for xi < 1/2 (the excesses' variance is finite there).
PWM_XI_MAX = 0.5


class TailFitError(ValueError):
    """The map's summits cannot carry a tail fit (too few of them)."""


@dataclass(frozen=True, eq=False)
class EmpiricalGPD:
    """Summit heights (m, about the map summits' mean): the map's own below `threshold`, a fitted generalised Pareto
    tail (shape `xi`, `scale` m) above it, reached with probability `p_exceed`. Picklable (members on a pool)."""

    body: np.ndarray
    """The map's summit heights at or below the threshold (m, sorted)."""
    threshold: float
    xi: float
    scale: float
    p_exceed: float
    summits: int
    mle: tuple[float, float] = (math.nan, math.nan)
    """The maximum-likelihood (xi, scale) of the same excesses, for the record."""

    def sample(self, rng: np.random.Generator, m: int) -> np.ndarray:
        """m heights (m): one uniform per summit decides body or tail and, in the tail, its GPD quantile."""
        u = rng.random(m)
        tail = u < self.p_exceed
        out = np.empty(m)
        nb = int(m - np.count_nonzero(tail))
        out[~tail] = self.body[rng.integers(0, self.body.size, nb)]
        out[tail] = self.threshold + sps.genpareto.ppf(u[tail] / self.p_exceed, self.xi, scale=self.scale)
        return out

    def quantile(self, q: float) -> float:
        """The height (m) below which a fraction q of the summits lie."""
        if q > 1.0 - self.p_exceed:
            return self.threshold + float(sps.genpareto.ppf((q - (1.0 - self.p_exceed)) / self.p_exceed, self.xi,
                                                            scale=self.scale))
        return float(np.quantile(self.body, q / (1.0 - self.p_exceed)))

    @property
    def upper_end(self) -> float:
        """The tallest height the model allows (m; inf for xi >= 0)."""
        return self.threshold - self.scale / self.xi if self.xi < 0.0 else math.inf

    def record(self, sigma_s: float, strip_summits: float | None = None) -> dict:
        """result.json's description of the fit; heights also in units of the map's sigma_s."""
        rec = {"model": "empirical_gpd", "summits_on_map": self.summits,
               "exceedances": int(round(self.p_exceed * self.summits)), "threshold_m": self.threshold,
               "threshold_over_sigma_s": self.threshold / sigma_s, "xi": self.xi, "scale_m": self.scale,
               "p_exceed": self.p_exceed, "upper_end_over_sigma_s": self.upper_end / sigma_s,
               "fit": "probability-weighted moments (Hosking & Wallis 1987); threshold: the k-th largest summit, "
                      f"k = max({MIN_EXCEEDANCES}, ceil({TAIL_FRACTION:g} n))",
               "maximum_likelihood": {"xi": self.mle[0], "scale_m": self.mle[1], "regular": self.mle[0] > REGULAR_XI,
                                      "how": "scipy.stats.genpareto.fit(excesses, floc=0); not used"},
               "sources": "Pickands, Ann. Stat. 3 (1975) 119; Hosking & Wallis, Technometrics 29 (1987) 339; Coles, "
                          "Statistical Modeling of Extreme Values (2001) ch. 4"}
        if strip_summits is not None and strip_summits > 1.0:
            rec["expected_tallest_in_strip_over_sigma_s"] = self.quantile(1.0 - 1.0 / strip_summits) / sigma_s
        return rec


def fit_empirical_gpd(heights: np.ndarray) -> EmpiricalGPD:
    """The `empirical_gpd` model of a map's summit heights (m); raises TailFitError with fewer than
    MIN_EXCEEDANCES + 1 summits."""
    h = np.sort(np.asarray(heights, float))
    n = h.size
    k = max(MIN_EXCEEDANCES, math.ceil(TAIL_FRACTION * n))
    if n <= k:
        raise TailFitError(f"{n} summits on the map: a generalised Pareto tail needs more than {k} "
                           f"({MIN_EXCEEDANCES} exceedances and the body below them)")
    h = h - h.mean()
    threshold = float(h[n - k - 1])
    excess = h[n - k:] - threshold
    xi, scale = gpd_pwm(excess)
    mle_xi, _, mle_scale = sps.genpareto.fit(excess, floc=0.0)
    return EmpiricalGPD(body=h[:n - k].copy(), threshold=threshold, xi=xi, scale=scale, p_exceed=k / n,
                        summits=int(n), mle=(float(mle_xi), float(mle_scale)))


def gpd_pwm(excess: np.ndarray) -> tuple[float, float]:
    """(xi, scale) of a generalised Pareto distribution from its sample `excess` (> 0) by probability-weighted
    moments (Hosking & Wallis 1987, eqs 4-5 with their k = -xi)."""
    y = np.sort(np.asarray(excess, float))
    n = y.size
    a0 = float(y.mean())
    a1 = float(np.sum(y * (n - 1 - np.arange(n)) / (n - 1)) / n)
    d = a0 - 2.0 * a1
    if not d > 0.0:
        raise TailFitError(f"the map's summit-height excesses give no PWM estimate (a0 - 2 a1 = {d:.3g})")
    xi = 2.0 - a0 / d
    if not xi < PWM_XI_MAX:
        raise TailFitError(f"the map's summit-height excesses give xi = {xi:.3g} >= {PWM_XI_MAX}: no PWM estimate")
    return xi, 2.0 * a0 * a1 / d


def map_summit_record(summits, sigma_s: float) -> dict:
    """What the map's summits (`continuum.rough.topography.Summits`) say about the distributions a member draws
    from: count, tallest and excess kurtosis of the heights (in sigma_s), the tip radii's percentiles and the
    Spearman rank correlation of height with curvature (members carry one radius, beta; docs/model.md)."""
    h = np.asarray(summits.height, float)
    kappa = np.asarray(summits.curvature, float)
    z = (h - h.mean()) / sigma_s
    rec = {"count": int(h.size), "tallest_over_sigma_s": float(z.max()),
           "excess_kurtosis": float(sps.kurtosis(h)), "skewness": float(sps.skew(h))}
    radius = 1.0 / kappa[kappa > 0]
    if radius.size:
        rec["tip_radius_m"] = {f"p{p}": float(v) for p, v in zip((5, 50, 95), np.percentile(radius, (5, 50, 95)))}
    if h.size > 2:
        rho = sps.spearmanr(h, kappa)
        rec["height_curvature_spearman"] = {"rho": float(rho.statistic), "p_value": float(rho.pvalue)}
    return rec


def strip_half_width(model: EmpiricalGPD | None, sigma: float, density: float, radius: float, length: float) -> float:
    """Half-width (m) of the strip a member draws: the Gaussian nominal footprint (`continuum.rough.datum`), widened
    where `model`'s tallest summit expected in it lies higher, so that it still reaches FOOTPRINT_BAND sigma below
    the mean plane from the model's tallest summit: x_f^2 / 2R = z_max + 3 sigma."""
    half = tallest_summit(sigma, density, radius, length)["footprint_half_width"]
    if model is None:
        return half
    out = half
    for _ in range(20):
        top = model.quantile(1.0 - 1.0 / (2.0 * out * length * density))
        new = max(half, math.sqrt(2.0 * radius * max(top + FOOTPRINT_BAND * sigma, 0.0)))
        if abs(new - out) <= 1e-9 * out:
            break
        out = new
    return out
