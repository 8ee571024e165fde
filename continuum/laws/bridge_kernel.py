"""Compiled sum over capillary bridges under a roller: `MeniscusBridges._integral` in numba.

The wet law (`continuum.laws.wet`) evaluates this double integral (Gauss-Legendre in x across the
roller, closed-form Gaussian moments in the summit height z) at every force evaluation after t_a:
~50 us of NumPy overhead on 16-48 nodes, ~60 % of a wet near-escape sweep in the paper.
Compiled, the same arithmetic costs ~1-2 us. The NumPy form stays in `continuum.laws.wet`
(`MeniscusBridges._integral_numpy`) as the reference `tests/continuum/test_menisci.py` compares this kernel with.

The normal CDF takes scipy's `ndtr` branches (erf near zero, erfc in the tails) with the C library's erf and
erfc, so the two forms agree to round-off, not bit for bit.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Quantities (the `kind` argument).
KIND_COUNT, KIND_FORCE, KIND_ENERGY = 0, 1, 2
KINDS = {"count": KIND_COUNT, "force": KIND_FORCE, "energy": KIND_ENERGY}

_GL_X, _GL_W = np.polynomial.legendre.leggauss(16)
_SQRT2 = math.sqrt(2.0)
_SQRT2PI = math.sqrt(2.0 * math.pi)


@njit(cache=True)
def _ndtr(a):
    """Phi(a), the standard normal CDF, by the branches of scipy.special.ndtr (Cephes): erf near 0, the tail by
    erfc, so the difference of two CDFs cancels the same way in both forms of the sum."""
    x = a / _SQRT2
    z = abs(x)
    if z < 1.0 / _SQRT2:
        return 0.5 + 0.5 * math.erf(x)
    y = 0.5 * math.erfc(z)
    return 1.0 - y if x > 0 else y


@njit(cache=True)
def _moments(a, b):
    """int_a^b t^k phi(t) dt, k = 0, 1, 2 (standard normal; zero where b <= a)."""
    if b < a:
        b = a
    pa = math.exp(-0.5 * a * a) / _SQRT2PI
    pb = math.exp(-0.5 * b * b) / _SQRT2PI
    m0 = _ndtr(-a) - _ndtr(-b) if a > 0 else _ndtr(b) - _ndtr(a)
    m1 = pa - pb
    ta = a * pa if math.isfinite(a) else 0.0
    tb = b * pb if math.isfinite(b) else 0.0
    return m0, m1, m0 + ta - tb


@njit(cache=True)
def _piece(c, alpha, beta, za, zb, sig):
    """scale-free contribution of one piece of the bridge law, coefficients c = (a0, a1, a2), g/D_K = alpha + beta t."""
    c0 = c[0] + c[1] * alpha + c[2] * alpha * alpha
    c1 = (c[1] + 2.0 * c[2] * alpha) * beta
    c2 = c[2] * beta * beta
    m0, m1, m2 = _moments(za / sig, zb / sig)
    return c0 * m0 + c1 * m1 + c2 * m2


@njit(cache=True)
def bridge_integral(kind, gap, s_lo, s_hi, formed, g_hi, g_lo, z_top, radius, length, density, sigma, f0, d_k,
                    comp, stretch, gl_x, gl_w):
    """Sum over bridged summits with s_lo <= u <= s_hi of F (KIND_FORCE, N), U (KIND_ENERGY, J) or their number
    (KIND_COUNT); with `formed`, U at the formation gaps, linear in u from g_hi (u = s_hi) to g_lo (u = s_lo).
    `comp`, `stretch`: the bridge law's coefficients on g <= 0 and 0 < g < D_K (`continuum.wet.menisci`)."""
    q_top = min(-s_lo, d_k - gap)
    if not q_top > 0.0 or s_hi <= s_lo:
        return 0.0
    two_r = 2.0 * radius
    x_top = math.sqrt(two_r * q_top)
    edges = np.empty(4)
    n_edges = 1
    edges[0] = 0.0
    k1 = -gap
    k2 = -s_hi
    a1 = math.sqrt(two_r * k1) if 0.0 < k1 < q_top else -1.0
    a2 = math.sqrt(two_r * k2) if 0.0 < k2 < q_top else -1.0
    lo_k, hi_k = (a1, a2) if a1 <= a2 else (a2, a1)
    if lo_k >= 0.0:
        edges[n_edges] = lo_k
        n_edges += 1
    if hi_k >= 0.0:
        edges[n_edges] = hi_k
        n_edges += 1
    edges[n_edges] = x_top
    n_edges += 1
    scale = f0 if kind == KIND_FORCE else f0 * d_k
    if formed:
        k_lin = (g_hi - g_lo) / (s_hi - s_lo)
    else:
        k_lin = 0.0
    total = 0.0
    for p in range(n_edges - 1):
        a, b = edges[p], edges[p + 1]
        half, mid = 0.5 * (b - a), 0.5 * (a + b)
        for n in range(gl_x.size):
            x = mid + half * gl_x[n]
            w = half * gl_w[n]
            q = x * x / two_r
            d = z_top + gap + q
            lo = max(z_top + q + s_lo, d - d_k)
            hi = min(z_top, z_top + q + s_hi)
            if kind == KIND_COUNT:
                val = _moments(lo / sigma, hi / sigma)[0]
            elif formed:
                alpha = (g_hi - k_lin * (z_top + q + s_hi)) / d_k
                beta = k_lin * sigma / d_k
                val = scale * _piece(stretch, alpha, beta, lo, hi, sigma)
            else:
                alpha, beta = d / d_k, -sigma / d_k
                val = scale * (_piece(comp, alpha, beta, max(lo, d), hi, sigma)
                               + _piece(stretch, alpha, beta, lo, min(hi, d), sigma))
            total += val * w
    return 2.0 * length * density * total
