"""Compiled footprint quadrature of a GW surface of branch-law summits: `GWBranchSurface._chunk` in numba.

The rigid rough roller's footprint tables evaluate the surface's pressure and energy at ~1e5 states (d, zeta) per
build; in NumPy every state carries all the panels of its chunk's deepest state and each quantity is a pass over
(states x panels x 8) arrays with a linear interpolation in the summit law's branch tables (~4000 points): memory
bound, most of a Maugis-Dugdale scene's CPU. `integrals` does the same quadrature one state at a time:

    q_n(d, zeta) = sum_branches sum_panels sum_nodes Q_n(x, branch) phi((d + x)/sigma) w,

over the panels [e_j, e_j+1] of `GWBranchSurface._panel_edges` clipped to the branch's interval (approach:
below the threshold x_th = zeta_eff - d; retreat: above it; both below x_top = z_max - d), 8 Gauss-Legendre
nodes per panel, phi the Gaussian summit-height density. Panels that a state's interval leaves empty add nothing
and are skipped; the panel loop ends at the state's own x_top. The interpolation is np.interp's (clamped ends,
slope times offset plus left value). Only the (at most two) panels per branch that a state's threshold or top cuts
interpolate at their own nodes; every whole panel's nodes and values are computed once per call (`_panel_values`),
which halves the cost per state. Only the order of the sums differs from the NumPy form (a loop here, pairwise
there), so the two agree to round-off: tests/continuum/test_gw_branches_fast.py compares them.

`integrals_by_threshold` evaluates a grid of separations times thresholds (a rigid roller's footprint tables: the
same deep separations for every window): each panel's approach and retreat sums once per separation, and per
threshold only the panel the threshold cuts.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["integrals", "integrals_by_threshold"]

_SQRT2PI = math.sqrt(2.0 * math.pi)


@njit(cache=True, error_model="numpy")
def _cell(x, xp):
    """np.interp's cell of x in xp (strictly increasing): -1 below xp[0], n - 1 at or above xp[n - 1], else the
    lo with xp[lo] <= x < xp[lo + 1]."""
    n = xp.size
    if x < xp[0]:
        return -1
    if x >= xp[n - 1]:
        return n - 1
    lo, hi = 0, n - 1
    while hi - lo > 1:
        mid = (lo + hi) >> 1
        if xp[mid] <= x:
            lo = mid
        else:
            hi = mid
    return lo


@njit(cache=True, error_model="numpy")
def _cell_from(x, xp, lo):
    """`_cell` of x, walking up from the cell lo of a smaller x (the nodes of a branch come in increasing order)."""
    n = xp.size
    if 0 <= lo < n - 1 and xp[lo] <= x:
        for _ in range(8):
            if x < xp[lo + 1]:
                return lo
            lo += 1
            if lo >= n - 1:
                return n - 1
    return _cell(x, xp)


@njit(cache=True, error_model="numpy")
def _interp(x, lo, xp, f):
    """np.interp(x, xp, f) in the cell `_cell` found (clamped ends, slope times offset plus left value)."""
    if lo < 0:
        return f[0]
    if lo >= xp.size - 1:
        return f[xp.size - 1]
    if x == xp[lo]:
        return f[lo]
    slope = (f[lo + 1] - f[lo]) / (xp[lo + 1] - xp[lo])
    return slope * (x - xp[lo]) + f[lo]


@njit(cache=True, error_model="numpy")
def _panel_values(edges, gl_x, gl_w, xa, fa, xr, fr):
    """Nodes x, weights w and the branch tables' values at the nodes of every whole panel, shape (panels, nodes)
    and (2, rows of fa, panels, nodes): what a panel that no state's threshold or top cuts reads, computed once
    per call instead of once per state (the same expressions, so the same numbers)."""
    n_p, n_k, n_r = edges.size - 1, gl_x.size, fa.shape[0]
    xs = np.empty((n_p, n_k))
    ws = np.empty((n_p, n_k))
    vals = np.empty((2, n_r, n_p, n_k))
    for j in range(n_p):
        a, b = edges[j], edges[j + 1]
        half = 0.5 * max(b - a, 0.0)
        mid = 0.5 * (a + b)
        for k in range(n_k):
            xs[j, k] = mid + half * gl_x[k]
            ws[j, k] = half * gl_w[k]
    for branch in range(2):
        xp = xa if branch == 0 else xr
        fp = fa if branch == 0 else fr
        for j in range(n_p):
            for k in range(n_k):
                lo = _cell(xs[j, k], xp)
                for row in range(n_r):
                    vals[branch, row, j, k] = _interp(xs[j, k], lo, xp, fp[row])
    return xs, ws, vals


@njit(cache=True, error_model="numpy")
def _mode(q, mode):
    """A tabulated value as quantity `mode` reads it: 0 value, 1 positive part, 2 negative part, 3 pi value^2."""
    if mode == 1:
        return max(q, 0.0)
    if mode == 2:
        return min(q, 0.0)
    if mode == 3:
        return math.pi * q * q
    return q


@njit(cache=True, error_model="numpy")
def integrals(d, x_th, x_top, edges, gl_x, gl_w, sigma, xa, fa, xr, fr, kinds, out):
    """Add to out[n, i] the quadrature of quantity n at state i (out zeroed by the caller; times the density there).

    d, x_th, x_top: separation, threshold and top of the summits in delta (m), per state; edges: panel edges in
    delta; xa, fa / xr, fr: the approach / retreat branch tables (delta, and one row of values per table column);
    kinds[n]: (column of fa/fr, mode) with mode 0 value, 1 positive part, 2 negative part, 3 pi value^2.
    A panel that the state's branch interval holds whole reads its nodes' values from `_panel_values`; a cut
    one (at the threshold or the top) interpolates at its own nodes."""
    xs, ws, vals = _panel_values(edges, gl_x, gl_w, xa, fa, xr, fr)
    for i in range(d.size):
        di, th, top = d[i], x_th[i], x_top[i]
        for branch in range(2):
            xp = xa if branch == 0 else xr
            fp = fa if branch == 0 else fr
            # panels wholly above the threshold (approach) or below it (retreat) are empty: not visited
            j0 = 0 if branch == 0 else max(np.searchsorted(edges, th, side="right") - 1, 0)
            for j in range(j0, edges.size - 1):
                e0, e1 = edges[j], edges[j + 1]
                if e0 >= top or (branch == 0 and e0 >= th):
                    break
                if branch == 0:
                    a, b = e0, min(min(e1, th), top)
                else:
                    a, b = max(e0, th), min(e1, top)
                _add_panel(out[:, i], di, a, b, edges, j, branch, xs, ws, vals, gl_x, gl_w, xp, fp, sigma, kinds)


@njit(cache=True, error_model="numpy")
def _add_panel(acc, di, a, b, edges, j, branch, xs, ws, vals, gl_x, gl_w, xp, fp, sigma, kinds):
    """Add to acc[n] panel j's sum of quantity n over [a, b] on `branch` (0 approach, 1 retreat), as `integrals`
    sums it: the once-computed nodes and values where [a, b] is the whole panel, else its own nodes."""
    half = 0.5 * max(b - a, 0.0)
    if half == 0.0:
        return
    whole = a == edges[j] and b == edges[j + 1]
    norm = _SQRT2PI * sigma
    mid = 0.5 * (a + b)
    lo = -1
    for k in range(gl_x.size):
        if whole:
            x, w = xs[j, k], ws[j, k]
        else:
            x = mid + half * gl_x[k]
            w = half * gl_w[k]
            lo = _cell_from(x, xp, lo)
        z = (di + x) / sigma
        phi = math.exp(-0.5 * z * z) / norm
        for n in range(kinds.shape[0]):
            q = vals[branch, kinds[n, 0], j, k] if whole else _interp(x, lo, xp, fp[kinds[n, 0]])
            acc[n] += _mode(q, kinds[n, 1]) * phi * w


@njit(cache=True, error_model="numpy")
def integrals_by_threshold(d, x_top, x_th, edges, gl_x, gl_w, sigma, xa, fa, xr, fr, kinds, out):
    """Add to out[n, i, c] what `integrals` adds to out[n, i] for the state (d[i], threshold x_th[c]), for a grid of
    separations and thresholds at once (the same panels, nodes and values; only the order of the sums differs).

    Per separation, each panel's sum on the retreat branch (every panel below the top) and on the approach branch
    (the panels below the largest threshold) is taken once; a threshold then adds the approach sums of the panels
    below its own panel, that panel cut at the threshold as `integrals` cuts it, and the retreat sums above it."""
    nq, n_p = kinds.shape[0], edges.size - 1
    xs, ws, vals = _panel_values(edges, gl_x, gl_w, xa, fa, xr, fr)
    th_max = np.max(x_th)
    below = np.zeros((nq, n_p + 1))      # below[n, j]: approach sums of panels 0..j-1
    above = np.zeros((nq, n_p + 1))      # above[n, j]: retreat sums of panels j..
    part = np.zeros(nq)
    for i in range(d.size):
        di, top = d[i], x_top[i]
        below[:, 0] = 0.0
        above[:, :] = 0.0
        for j in range(n_p):
            part[:] = 0.0
            if edges[j] < min(th_max, top):
                _add_panel(part, di, edges[j], min(edges[j + 1], top), edges, j, 0, xs, ws, vals, gl_x, gl_w, xa, fa,
                           sigma, kinds)
            below[:, j + 1] = below[:, j] + part
        for j in range(n_p - 1, -1, -1):
            part[:] = 0.0
            if edges[j] < top:
                _add_panel(part, di, edges[j], min(edges[j + 1], top), edges, j, 1, xs, ws, vals, gl_x, gl_w, xr, fr,
                           sigma, kinds)
            above[:, j] = above[:, j + 1] + part
        for c in range(x_th.size):
            th = x_th[c]
            jc = min(max(np.searchsorted(edges, th, side="right") - 1, 0), n_p - 1)
            if edges[jc] >= top:                  # the threshold's panel lies above the top: approach only
                for n in range(nq):
                    out[n, i, c] += below[n, jc]
                continue
            part[:] = 0.0
            e0, e1 = edges[jc], edges[jc + 1]
            _add_panel(part, di, e0, min(min(e1, th), top), edges, jc, 0, xs, ws, vals, gl_x, gl_w, xa, fa, sigma,
                       kinds)
            _add_panel(part, di, max(e0, th), min(e1, top), edges, jc, 1, xs, ws, vals, gl_x, gl_w, xr, fr, sigma,
                       kinds)
            for n in range(nq):
                out[n, i, c] += below[n, jc] + part[n] + above[n, jc + 1]
