"""A fraction of trials and its Wilson score interval: the one place the project computes binomial intervals.

Wilson, J. Am. Stat. Assoc. 22 (1927) 209: the interval of the true fraction p whose score test at level z accepts
k successes in n trials. Unlike the Wald interval p_hat +- z sqrt(p_hat (1 - p_hat) / n) it stays inside [0, 1]
and is not empty at k = 0 or k = n (0/64 gives 0-5.7 %, not "0 +- 0"), and its coverage is close to nominal down
to a handful of trials (Brown, Cai & DasGupta, Stat. Sci. 16 (2001) 101).
"""
from __future__ import annotations

import math

__all__ = ["Z95", "wilson_interval", "wilson_half_width"]

#: The standard normal's 97.5 % quantile: a two-sided 95 % interval.
Z95 = 1.959964


def wilson_interval(k: int, n: int, z: float = Z95) -> tuple[float, float]:
    """(lower, upper) Wilson score interval of the fraction behind k successes in n > 0 trials."""
    if n <= 0 or not 0 <= k <= n:
        raise ValueError(f"wilson_interval: need 0 <= k <= n and n > 0 (k = {k!r}, n = {n!r})")
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def wilson_half_width(k: int, n: int, z: float = Z95) -> float:
    """Half the width of the Wilson interval of k in n (the precision an adaptive sample is run to)."""
    lo, hi = wilson_interval(k, n, z)
    return 0.5 * (hi - lo)
