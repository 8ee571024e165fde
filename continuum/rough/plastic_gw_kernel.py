"""Compiled sums of the GW mean field of plastic branch summits (`continuum.rough.plastic_gw_branches`).

The same quadrature as `PlasticGWSurface._nodes` (geometric Gauss-Legendre panels from a set's lower edge, the
first in u = lo + t^2, with a square-root top the last in u = hi - t^2), the same weights (the Gaussian density or
the roller footprint's kernel K(z), `RollerFootprint._weight`) and the same summit states as
`PlasticBranchGWSurface._summits`, evaluated on the law's compiled tables (`continuum.rough.plastic_kernel`: the
node laws' branches and the flattening table, blended over R_p as `PlasticBranchSummitLaw._scaled` does). One call
per state (`state_values`: the sets' edges by scipy's brentq algorithm, `inverse`, then both sets' sums) instead of
a few dozen NumPy calls and a Python root-finder's callbacks: the values are those of the NumPy form up to the
order of the sums (tests/continuum/test_plastic_gw_kernel.py compares both).

Edge functions (`edge`, kind): 0 g(u) = u - delta_p, 1 m(u) = g - delta_in(R_p), 2 h(u) = g - delta_out(R_p),
3 r(u) = g + reach(R_p) (reach_ratio cbrt(R_p)), with u clipped to [0, u_table] for the flattening.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..physics.brent import brent_step
from .plastic_kernel import (
    P_P_BETA,
    P_P_D_Y,
    P_P_F_Y,
    P_P_LOG_RATIO,
    P_P_NODES,
    P_P_SELF_SIMILAR,
    P_P_SLOPE,
    _blend,
    _flattening,
    _plastic_work,
)
from .plastic_summits import _GL_W, _GL_X

__all__ = ["edge", "inverse", "set_sum", "span_sum", "state_values", "gl_nodes", "law_arrays", "law_value",
           "law_accept", "law_release_gap", "footprint_table"]

_SQRT2PI = math.sqrt(2.0 * math.pi)


@njit(cache=True)
def _lin2(x, tab, row, n):
    """(`plastic_kernel._lin`(x, xs, ya), `_lin`(x, xs, yb)) on the table rows xs, ya, yb = tab[row], tab[row + 1],
    tab[row + 2], the same arithmetic, one bisection for both; the rows are read in place (a row view per call costs
    more than the search)."""
    ya, yb = row + 1, row + 2
    if x <= tab[row, 0]:
        return tab[ya, 0], tab[yb, 0]
    if x >= tab[row, n - 1]:
        return tab[ya, n - 1], tab[yb, n - 1]
    lo, hi = 0, n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if tab[row, mid] <= x:
            lo = mid
        else:
            hi = mid
    x0, x1 = tab[row, lo], tab[row, hi]
    return (tab[ya, lo] + (x - x0) / (x1 - x0) * (tab[ya, hi] - tab[ya, lo]),
            tab[yb, lo] + (x - x0) / (x1 - x0) * (tab[yb, hi] - tab[yb, lo]))


@njit(cache=True)
def _flat(dm, P, xs, ys, zs):
    """`plastic_kernel._flattening` for dm within the table (xs, ys, zs = T[2], T[3], T[4], taken out of T once by
    the caller): the same interval of its grid D_i = D_top (i/(n-1))^2 (the largest i <= n - 2 with D_i <= D), found
    from its square root instead of by bisection, the same arithmetic."""
    over = dm - P[P_P_D_Y]
    if not over > 0.0:
        return P[P_P_BETA], 0.0
    n = xs.size
    if over >= xs[n - 1]:
        return ys[n - 1], zs[n - 1]
    lo = min(int(math.sqrt(over / xs[n - 1]) * (n - 1)), n - 2)
    while lo > 0 and xs[lo] > over:
        lo -= 1
    while lo < n - 2 and xs[lo + 1] <= over:
        lo += 1
    hi = lo + 1
    return (ys[lo] + (over - xs[lo]) / (xs[hi] - xs[lo]) * (ys[hi] - ys[lo]),
            zs[lo] + (over - xs[lo]) / (xs[hi] - xs[lo]) * (zs[hi] - zs[lo]))


@njit(cache=True)
def _branch_pair(retreat, eps, r, P, info, tab):
    """(force, energy) on the approach or the retreat branch: `plastic_kernel._blend`'s (0, 1) or (2, 3), the same
    arithmetic, each node law's table searched once for both (info, tab = T[6], T[7], taken out once by the caller)."""
    nodes = int(P[P_P_NODES])
    side = 1 if retreat else 0
    if r == P[P_P_BETA]:            # an unflattened summit: node 0's own curve, no scaling
        return _lin2(eps, tab, 3 * side, int(info[3 + side]))
    k, t = 0, 0.0
    if nodes > 1 and P[P_P_SELF_SIMILAR] == 0.0:
        x = math.log(max(r / P[P_P_BETA], 1.0)) / P[P_P_LOG_RATIO]
        k = min(int(math.floor(x)), nodes - 2)
        t = min(max(x - k, 0.0), 1.0)
    force = energy = 0.0
    for j in range(k, k + 2):
        wgt = 1.0 - t if j == k else t
        if wgt == 0.0 or j >= nodes:
            continue
        s = r / info[5 * j]
        c = np.cbrt(s)                  # as `PlasticBranchSummitLaw._scaled` takes it
        a, b = _lin2(eps / c, tab, 6 * j + 3 * side, int(info[5 * j + 3 + side]))
        force += wgt * s * a
        energy += wgt * s * c * b
    return force, energy


@njit(cache=True)
def edge(u, kind, u_table, reach_ratio, P, T):
    """The summit-set edge functions of `PlasticBranchGWSurface` (see the module docstring) at u (m)."""
    r_p, d_p = _flat(min(max(u, 0.0), u_table), P, T[2], T[3], T[4])
    g = u - d_p
    if kind == 0:
        return g
    if kind == 1:
        return g - _blend(4, 0.0, r_p, P, T)
    if kind == 2:
        return g - _blend(5, 0.0, r_p, P, T)
    return g + np.cbrt(r_p) * reach_ratio


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


#: C slots (the surface's constants, `PlasticBranchGWSurface._kernel_constants`)
(C_FIRST, C_QUARTER, C_ROOT_AT_TOP, C_U_TABLE, C_DENSITY, C_SIGMA, C_Z_TOP, C_LENGTH, C_ROLLER_RADIUS,
 C_REACH_RATIO, C_Z_FLOOR, C_CLIP_FLOOR, C_IN0, C_OUT0, C_REACH0) = range(15)
#: what `set_sum` sums
APPROACH, RETREAT, IN_SWITCH, OUT_SWITCH, PLASTIC_WORK = range(5)


def footprint_table(z_top: float, sigma: float, depth: float, tx, tw, per_scale: float = 200.0) -> np.ndarray:
    """The footprint kernel's node sum G(s) = sum_j tw_j exp(-y_j^2 / 2), y_j = (z + t_j^2) / sigma, t_j = s (tx_j + 1)
    / 2, z = z_top - s^2 (`RollerFootprint._weight`: K(z) = s G(s) / (sqrt(2 pi) sigma)), and its derivative, on a
    uniform grid in s from 0 to sqrt(depth) (z from z_top down to z_top - depth, m): [step, points, G..., G'...] for
    `_weight`'s cubic Hermite interpolation. G is an entire function of s whose terms vary on the scale
    sigma / (2 s); the step is that scale at the grid's end over `per_scale`, so the cubic's error, of order
    (1/per_scale)^4 of G's size, stays below 1e-12 of it at 200 (tests/continuum/test_plastic_gw_compiled.py)."""
    top_max = math.sqrt(depth)
    step = sigma / (2.0 * top_max) / per_scale
    n = int(math.ceil(top_max / step)) + 2
    s = step * np.arange(n)
    a = (0.5 * (np.asarray(tx, float) + 1.0)) ** 2           # t_j^2 = s^2 a_j
    y = (z_top - np.outer(s * s, 1.0 - a)) / sigma
    e = np.exp(-0.5 * y * y) * np.asarray(tw, float)
    g = e.sum(axis=1)
    dg = (e * y * (1.0 - a)).sum(axis=1) * 2.0 * s / sigma      # dy_j/ds = -2 s (1 - a_j) / sigma
    return np.concatenate(([step, float(n)], g, dg))


@njit(cache=True)
def _weight(u, w, d_p, footprint, C, tx, tw, kt):
    """Summits per unit height times the quadrature weight at z = d_p + u: n phi(z) (`PlasticGWSurface._weight`)
    or the roller footprint's kernel K(z) (`footprint`, `RollerFootprint._weight`, 24-node rule tx, tw), its node sum
    interpolated in the table `kt` (`footprint_table`) where it covers z, else summed."""
    density, sigma = C[C_DENSITY], C[C_SIGMA]
    z = d_p + u
    if not footprint:
        y = z / sigma
        return density * w * math.exp(-0.5 * y * y) / (_SQRT2PI * sigma)
    top = math.sqrt(max(C[C_Z_TOP] - z, 0.0))
    s = 0.0
    tabled = False
    if kt.size > 0:
        step = kt[0]
        n = int(kt[1])
        x = top / step
        i = int(x)
        if i < n - 1:
            t = x - i
            t2 = t * t
            g0, g1 = kt[2 + i], kt[3 + i]
            d0, d1 = kt[2 + n + i] * step, kt[3 + n + i] * step
            s = (g0 + t2 * (3.0 * (g1 - g0) - 2.0 * d0 - d1) + t2 * t * (2.0 * (g0 - g1) + d0 + d1)
                 + t * d0)
            tabled = True
    if not tabled:
        for j in range(tx.size):
            t = 0.5 * top * (tx[j] + 1.0)
            y = (z + t * t) / sigma
            s += math.exp(-0.5 * y * y) * tw[j]
    k = 0.5 * top * s * 2.0 / (_SQRT2PI * sigma)
    return density * w * C[C_LENGTH] * math.sqrt(2.0 * C[C_ROLLER_RADIUS]) * k


@njit(cache=True)
def set_sum(what, lo, hi, floor, touch, d_p, shift, footprint, C, offsets, gl_x, gl_w, tx, tw, kt, P, T):
    """(sum q a, sum q b, sum q) over the quadrature of [lo, hi] (m, in u; `gl_nodes`, split at delta_y and
    `touch`) of one summit set, q the weight (`_weight`) and, by `what`:

    * APPROACH / RETREAT: a = force F, b = stored energy U of summits at approach delta = u - shift (shift =
      d - d_p), deepest approach clip(u, 0, u_table), on that branch (the retreat branch with Thornton-Ning's
      plastic line where delta >= delta_max > delta_y): `PlasticBranchGWSurface._summits`;
    * IN_SWITCH: a = U_A - U_R at delta_in of the flattening of clip(u - shift, 0, u_table) (shift = d_0 - d_p:
      the flattening a summit met this contact with); OUT_SWITCH: a = U_R - U_A at delta_out of clip(u, 0,
      u_table)'s (`PlasticBranchSummitLaw.in_switch`, `out_switch`);
    * PLASTIC_WORK: a = W_p(min(u, u_table)) (`PlasticBranchSummitLaw.plastic_work`)."""
    u, w = gl_nodes(lo, hi, floor, offsets, C[C_FIRST], C[C_QUARTER], np.array([P[P_P_D_Y], touch]),
                    C[C_ROOT_AT_TOP] != 0.0, gl_x, gl_w)
    flag = np.zeros(5)
    fx, fr, fp, info, tab = T[2], T[3], T[4], T[6], T[7]
    u_table, d_y = C[C_U_TABLE], P[P_P_D_Y]
    sa = sb = sq = 0.0
    virgin = math.nan           # the switch term of an unflattened summit (R_p = beta): one value, computed once
    for i in range(u.size):
        q = _weight(u[i], w[i], d_p, footprint, C, tx, tw, kt)
        a = b = 0.0
        if what == IN_SWITCH or what == OUT_SWITCH:
            r_p, dp = _flattening(min(max(u[i] - shift if what == IN_SWITCH else u[i], 0.0), u_table), flag, P, T)
            if r_p == P[P_P_BETA] and virgin == virgin:
                a = virgin
            else:
                if what == IN_SWITCH:
                    e = _blend(4, 0.0, r_p, P, T)
                    a = _blend(1, e, r_p, P, T) - _blend(3, e, r_p, P, T)
                else:
                    e = _blend(5, 0.0, r_p, P, T)
                    a = _blend(3, e, r_p, P, T) - _blend(1, e, r_p, P, T)
                if r_p == P[P_P_BETA]:
                    virgin = a
        elif what == PLASTIC_WORK:
            dm = min(u[i], u_table)
            r_p, dp = _flattening(max(dm, d_y), flag, P, T)
            a = _plastic_work(dm, r_p, dp, P, T)
        else:
            dm = min(max(u[i], 0.0), u_table)
            r_p, dp = _flat(dm, P, fx, fr, fp)
            delta = u[i] - shift
            a, b = _branch_pair(what == RETREAT, delta - dp, r_p, P, info, tab)
            if what == RETREAT and delta >= dm and dm > d_y:
                a = P[P_P_F_Y] + P[P_P_SLOPE] * (delta - d_y)
        sa += q * a
        sb += q * b
        sq += q
    return sa, sb, sq


@njit(cache=True)
def _brentq(kind, value, xa, xb, xtol, rtol, C, P, T):
    """The root of edge(u, kind) = value in [xa, xb]: scipy.optimize.brentq's algorithm (scipy's brentq.c, step for
    step, maxiter 100), so the same root as `PlasticGWSurface._inverse` finds with it."""
    u_table, ratio = C[C_U_TABLE], C[C_REACH_RATIO]
    xpre, xcur = xa, xb
    fpre = edge(xpre, kind, u_table, ratio, P, T) - value
    fcur = edge(xcur, kind, u_table, ratio, P, T) - value
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    xblk = fblk = spre = scur = 0.0
    for _ in range(100):
        done, xpre, xcur, xblk, fpre, fblk, spre, scur = brent_step(xpre, xcur, xblk, fpre, fcur, fblk, spre,
                                                                    scur, xtol, rtol)
        if done:
            return xcur
        fcur = edge(xcur, kind, u_table, ratio, P, T) - value
    return xcur


@njit(cache=True)
def inverse(kind, value, offset, C, P, T):
    """`PlasticGWSurface._inverse` of edge `kind`: u with edge(u) = value, edge(u) = u + offset up to delta_y."""
    d_y = P[P_P_D_Y]
    if value - offset <= d_y:
        return value - offset
    hi = max(2.0 * (value - offset), d_y + C[C_SIGMA])
    while edge(hi, kind, C[C_U_TABLE], C[C_REACH_RATIO], P, T) < value:
        hi *= 2.0
    return _brentq(kind, value, d_y, hi, 1e-15 * hi, 1e-14, C, P, T)


@njit(cache=True)
def span_sum(what, lo, hi, touch, d_p, shift, footprint, C, offsets, gl_x, gl_w, tx, tw, kt, P, T):
    """`set_sum` over `PlasticGWSurface._span(lo, d_p, hi)`."""
    floor = C[C_Z_FLOOR] - d_p
    if C[C_CLIP_FLOOR] != 0.0:
        lo = max(lo, floor)
    hi = min(hi, C[C_Z_TOP] - d_p)
    if not hi > lo:
        return 0.0, 0.0, 0.0
    return set_sum(what, lo, hi, floor, touch, d_p, shift, footprint, C, offsets, gl_x, gl_w, tx, tw, kt, P, T)


@njit(cache=True)
def state_values(d, d_c, d_p, footprint, C, offsets, gl_x, gl_w, tx, tw, kt, P, T):
    """`PlasticBranchGWSurface._values` in one call: (pressure or force, stored energy, attached summits) at
    (d, d_c, d_p), the sets' edges (`inverse`, as `sets`) and the touch break included."""
    u_met = inverse(1, d_c - d_p, -C[C_IN0], C, P, T) if math.isfinite(d_c) else math.inf
    if math.isfinite(d):
        u_att = max(u_met, inverse(2, d - d_p, -C[C_OUT0], C, P, T))
        u_r = inverse(3, d - d_p, C[C_REACH0], C, P, T)
    else:
        u_att = u_r = math.inf
    touch = inverse(0, d - d_p, 0.0, C, P, T)
    f, en, q = span_sum(RETREAT, u_att, math.inf, touch, d_p, d - d_p, footprint, C, offsets, gl_x, gl_w, tx, tw, kt,
                         P, T)
    fa, ea, _ = span_sum(APPROACH, u_r, u_att, touch, d_p, d - d_p, footprint, C, offsets, gl_x, gl_w, tx, tw, kt,
                          P, T)
    return f + fa, en + ea, q


# ----------------------------------------------------------------------------- the contact law, compiled
# `continuum.laws.plastic_rough.PlasticGWPunch` (and its roller) as a law of the compiled contact phase
# (`continuum.numerics.kernel_laws.LAW_PLASTIC_GW`): the same values as its Python methods, which call the sums
# above once per state, here called from the kernel's stages and samples.
#
# P: the summit law's slots (`plastic_kernel.PLASTIC_PARAMS`), the surface's C from L_C, then the law's own slots.
# T: (quadrature offsets `PlasticGWSurface._offsets`, Gauss-Legendre nodes then weights, the flattening table's three
# rows, the footprint's 24-node rule's nodes then weights (empty for a flat punch), node-law info, node-law rows):
# the summit law's tables keep the places `plastic_kernel` reads them from.
# S: (d_c, d_p, unused, unused, beyond-the-table flag at the kernel's S_BEYOND_FLAG, then a memo of the last state
# evaluated: d, d_c, d_p, force, stored energy, and of the plastic work W_p(d_p) and the jump-in sum at (d_c, d_p)).
L_C = 12
(L_AREA, L_D0, L_W0, L_FOOTPRINT, L_N_GL, L_N_TX) = range(L_C + 15, L_C + 21)
GW_LAW_PARAMS = L_C + 21
(S_D_C, S_D_P, S_FLAG) = 0, 1, 4
(S_M_D, S_M_DC, S_M_DP, S_M_F, S_M_E, S_M_WDP, S_M_W, S_M_IDC, S_M_IDP, S_M_I) = range(5, 15)
GW_LAW_STATE = 15
#: what `law_value` returns
LAW_FORCE, LAW_STORED, LAW_DISSIPATED, LAW_RELEASE_LOSS = range(4)


def law_arrays(surface, area: float, d_c: float, d_p: float, d_0: float, w0: float):
    """(P, T, S) of the compiled contact law on `surface` (a compiled `PlasticBranchGWSurface`, m and J/m^2):
    nominal area (m^2; 1 for a roller, whose values are per roller), history (d_c, d_p), the deepest separation
    before this contact d_0 and its plastic work w0 (per unit area)."""
    tx, tw, kt = surface._tx_tw
    P = np.zeros(GW_LAW_PARAMS)
    P[:L_C] = surface._P
    P[L_C:L_C + 15] = surface._C
    P[L_AREA], P[L_D0], P[L_W0] = area, d_0, w0
    P[L_FOOTPRINT], P[L_N_GL], P[L_N_TX] = float(surface._footprint), _GL_X.size, tx.size
    _, _, flat_d, flat_r, flat_p, _, info, tab = surface._T
    T = (np.ascontiguousarray(surface._offsets(), float), np.concatenate((_GL_X, _GL_W)), flat_d, flat_r,
         flat_p, np.concatenate((np.asarray(tx, float), np.asarray(tw, float), kt)), info, tab)
    S = np.full(GW_LAW_STATE, math.nan)
    S[S_D_C], S[S_D_P], S[2], S[3], S[S_FLAG] = d_c, d_p, 0.0, 0.0, 0.0
    return P, T, S


@njit(cache=True)
def _sum(what, lo, hi, touch, d_p, shift, P, T):
    """`span_sum` with the quadrature rules and constants packed in (P, T) (`law_arrays`)."""
    n, m = int(P[L_N_GL]), int(P[L_N_TX])
    return span_sum(what, lo, hi, touch, d_p, shift, P[L_FOOTPRINT] != 0.0, P[L_C:L_C + 15], T[0], T[1][:n],
                    T[1][n:], T[5][:m], T[5][m:2 * m], T[5][2 * m:], P, T)


@njit(cache=True)
def _pair(d, d_c, d_p, S, P, T):
    """(force N, stored energy J) at (d, d_c, d_p): `state_values` times the area, remembered for the next call at
    the same state (a sample asks for both)."""
    if d == S[S_M_D] and d_c == S[S_M_DC] and d_p == S[S_M_DP]:
        return S[S_M_F], S[S_M_E]
    C = P[L_C:L_C + 15]
    n, m = int(P[L_N_GL]), int(P[L_N_TX])
    f, en, _ = state_values(d, d_c, d_p, P[L_FOOTPRINT] != 0.0, C, T[0], T[1][:n], T[1][n:], T[5][:m],
                            T[5][m:2 * m], T[5][2 * m:], P, T)
    S[S_M_D], S[S_M_DC], S[S_M_DP] = d, d_c, d_p
    S[S_M_F], S[S_M_E] = P[L_AREA] * f, P[L_AREA] * en
    return S[S_M_F], S[S_M_E]


@njit(cache=True)
def _plastic_work_at(d_p, S, P, T):
    """W_p(d_p) (J/m^2): `PlasticBranchGWSurface.plastic_work`, remembered while d_p stays."""
    if d_p != S[S_M_WDP]:
        S[S_M_W] = _sum(PLASTIC_WORK, max(P[P_P_D_Y], 0.0), math.inf, math.nan, d_p, 0.0, P, T)[0]
        S[S_M_WDP] = d_p
    return S[S_M_W]


@njit(cache=True)
def _jumps(d, d_c, d_p, S, P, T):
    """`PlasticBranchGWSurface.jumps` (J/m^2; d = inf: every summit met has let go), its jump-in sum remembered
    while (d_c, d_p) stay."""
    if not math.isfinite(d_c):
        return 0.0
    C = P[L_C:L_C + 15]
    u_met = inverse(1, d_c - d_p, -C[C_IN0], C, P, T)
    if d_c != S[S_M_IDC] or d_p != S[S_M_IDP]:
        S[S_M_I] = _sum(IN_SWITCH, u_met, math.inf, math.nan, d_p, P[L_D0] - d_p, P, T)[0]
        S[S_M_IDC], S[S_M_IDP] = d_c, d_p
    u_held = inverse(2, d - d_p, -C[C_OUT0], C, P, T) if math.isfinite(d) else math.inf
    return S[S_M_I] + _sum(OUT_SWITCH, u_met, max(u_held, u_met), math.nan, d_p, 0.0, P, T)[0]


@njit(cache=True)
def law_value(what, gap, S, P, T):
    """`PlasticGWPunch`'s force (N), stored energy (J), loss booked so far (J) at `gap` (m) on the trial history
    (d, min(d_c, d), min(d_p, d)), d = z_top + gap; LAW_RELEASE_LOSS: its `on_release` (every summit met lets go)."""
    if what == LAW_RELEASE_LOSS:
        d, d_c, d_p = math.inf, S[S_D_C], S[S_D_P]
    else:
        d = P[L_C + C_Z_TOP] + gap
        d_c, d_p = min(S[S_D_C], d), min(S[S_D_P], d)
    if what == LAW_FORCE:
        return _pair(d, d_c, d_p, S, P, T)[0]
    if what == LAW_STORED:
        return _pair(d, d_c, d_p, S, P, T)[1]
    return P[L_AREA] * (_plastic_work_at(d_p, S, P, T) - P[L_W0] + _jumps(d, d_c, d_p, S, P, T))


@njit(cache=True)
def law_accept(gap, S, P, T):
    """`PlasticGWPunch.accept`: the history takes the state; one deeper than the summit law's table is flagged
    (`check_depth` refuses it: the kernel hands the contact to the Python stepper, which raises there)."""
    d = P[L_C + C_Z_TOP] + gap
    S[S_D_C], S[S_D_P] = min(S[S_D_C], d), min(S[S_D_P], d)
    if P[L_C + C_Z_TOP] - S[S_D_P] > P[L_C + C_U_TABLE] * (1.0 + 1e-12):
        S[S_FLAG] = 1.0


@njit(cache=True)
def law_release_gap(S, P, T):
    """`PlasticGWPunch.release_gap` on the accepted history (`PlasticBranchGWSurface.release_separation`)."""
    C = P[L_C:L_C + 15]
    d_p, z_top = S[S_D_P], C[C_Z_TOP]
    u_top = z_top - d_p
    sep = edge(u_top, 3, C[C_U_TABLE], C[C_REACH_RATIO], P, T)
    if math.isfinite(S[S_D_C]):
        sep = max(edge(u_top, 2, C[C_U_TABLE], C[C_REACH_RATIO], P, T), sep)
    return d_p + sep - z_top
