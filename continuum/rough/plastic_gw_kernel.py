"""Compiled sums of the GW mean field of plastic branch summits (`continuum.rough.plastic_gw_branches`).

The same quadrature as `PlasticGWSurface._nodes` (geometric Gauss-Legendre panels from a set's lower edge, the
first in u = lo + t^2, with a square-root top the last in u = hi - t^2), the same weights (the Gaussian density or
the roller footprint's kernel K(z), `RollerFootprint._weight`) and the same summit states as
`PlasticBranchGWSurface._summits`, evaluated on the law's compiled tables (`continuum.rough.plastic_kernel`: the
node laws' branches and the flattening table, blended over R_p as `PlasticBranchSummitLaw._scaled` does). One call
per summit set instead of a few dozen NumPy calls: the values are those of the NumPy form up to the order of the
sums (tests/continuum/test_plastic_gw_kernel.py compares both).

Edge functions (`edge`, kind): 0 g(u) = u - delta_p, 1 m(u) = g - delta_in(R_p), 2 h(u) = g - delta_out(R_p),
3 r(u) = g + reach(R_p) (reach_ratio cbrt(R_p)), with u clipped to [0, u_table] for the flattening.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .plastic_kernel import P_P_D_Y, P_P_F_Y, P_P_SLOPE, _blend, _flattening

__all__ = ["edge", "set_sums", "gl_nodes"]

_SQRT2PI = math.sqrt(2.0 * math.pi)


@njit(cache=True)
def edge(u, kind, u_table, reach_ratio, P, T):
    """The summit-set edge functions of `PlasticBranchGWSurface` (see the module docstring) at u (m)."""
    flag = np.zeros(5)
    r_p, d_p = _flattening(min(max(u, 0.0), u_table), flag, P, T)
    g = u - d_p
    if kind == 0:
        return g
    if kind == 1:
        return g - _blend(4, 0.0, r_p, P, T)
    if kind == 2:
        return g - _blend(5, 0.0, r_p, P, T)
    return g + r_p ** (1.0 / 3.0) * reach_ratio


@njit(cache=True)
def gl_nodes(lo, hi, floor, offsets, first, quarter, breaks, root_at_top, gl_x, gl_w):
    """`PlasticGWSurface._nodes` (same edges, same panels, same order of the nodes)."""
    if not hi > lo:
        return np.empty(0), np.empty(0)
    raw = []
    if floor <= lo and hi - lo < offsets[-1]:
        for o in offsets:
            if o < hi - lo:
                raw.append(lo + o)
        raw.append(hi)
    else:
        raw.append(lo)
        x, width = lo + min(first, hi - lo), first
        while x < hi:
            raw.append(x)
            width = min(1.5 * width, max(quarter, 0.5 * (floor - x)))
            x += width
        raw.append(hi)
    for b in breaks:
        if lo < b < hi:
            raw.append(b)
    srt = np.sort(np.array(raw))
    edges = np.empty(srt.size)
    m = 0
    for v in srt:
        if m == 0 or v != edges[m - 1]:
            edges[m] = v
            m += 1
    edges = edges[:m]
    if root_at_top:
        if edges.size > 3:
            last = 1
            for i in range(1, edges.size - 1):
                if hi - edges[i] >= edges[i] - edges[i - 1]:
                    last = i
            trimmed = np.empty(last + 2)
            trimmed[:last + 1] = edges[:last + 1]
            trimmed[last + 1] = hi
            edges = trimmed
        if edges.size == 2:
            edges = np.array([lo, 0.5 * (lo + hi), hi])
    top = root_at_top and edges.size > 2
    first_inner = 1
    last_inner = edges.size - 2 if top else edges.size - 1        # inner edges: edges[first_inner..last_inner]
    plain = max(last_inner - first_inner, 0)
    k = gl_x.size
    ends = 2 if top else 1
    xs, ws = np.empty(k * (ends + plain)), np.empty(k * (ends + plain))
    n = 0
    for end_panel in range(ends):
        start, stop, sign = (edges[0], edges[1], 1.0) if end_panel == 0 else (hi, edges[-2], -1.0)
        t1 = math.sqrt(abs(stop - start))
        for j in range(k):
            t = 0.5 * t1 * (gl_x[j] + 1.0)
            xs[n], ws[n] = start + sign * t * t, 0.5 * t1 * gl_w[j] * 2.0 * t
            n += 1
    for i in range(first_inner, last_inner):
        a, b = edges[i], edges[i + 1]
        for j in range(k):
            xs[n], ws[n] = 0.5 * (a + b) + 0.5 * (b - a) * gl_x[j], 0.5 * (b - a) * gl_w[j]
            n += 1
    return xs, ws


@njit(cache=True)
def _weight(u, w, d_p, roller, G, tx, tw):
    """Summits per unit height times the quadrature weight: n phi(z) (G: density, sigma) or the roller footprint's
    K(z) (G: density, sigma, z_top, length, roller radius), z = d_p + u."""
    density, sigma = G[0], G[1]
    z = d_p + u
    if not roller:
        y = z / sigma
        return density * w * math.exp(-0.5 * y * y) / (_SQRT2PI * sigma)
    top = math.sqrt(max(G[2] - z, 0.0))
    s = 0.0
    for j in range(tx.size):
        t = 0.5 * top * (tx[j] + 1.0)
        y = (z + t * t) / sigma
        s += math.exp(-0.5 * y * y) * tw[j]
    k = 0.5 * top * s * 2.0 / (_SQRT2PI * sigma)
    return density * w * G[3] * math.sqrt(2.0 * G[4]) * k


@njit(cache=True)
def set_sums(u, w, shift, d_p, attached, u_table, roller, G, tx, tw, P, T):
    """(sum q F, sum q U, sum q) over the nodes u (m) of one summit set: the summits at approach delta = u - shift
    (shift = d - d_p), deepest approach clip(u, 0, u_table), all on the retreat branch (`attached`, with Thornton-
    Ning's plastic line where delta >= delta_max > delta_y) or all on the approach branch."""
    flag = np.zeros(5)
    fs = es = qs = 0.0
    d_y = P[P_P_D_Y]
    for i in range(u.size):
        q = _weight(u[i], w[i], d_p, roller, G, tx, tw)
        dm = min(max(u[i], 0.0), u_table)
        r_p, dp = _flattening(dm, flag, P, T)
        delta = u[i] - shift
        eps = delta - dp
        base = 2 if attached else 0
        f = _blend(base, eps, r_p, P, T)
        if attached and delta >= dm and dm > d_y:
            f = P[P_P_F_Y] + P[P_P_SLOPE] * (delta - d_y)
        fs += q * f
        es += q * _blend(base + 1, eps, r_p, P, T)
        qs += q
    return fs, es, qs
