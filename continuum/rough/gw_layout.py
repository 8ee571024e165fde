"""Layout of the GW surface's tables: node spacings per fidelity preset, panel and Gauss-Legendre node
helpers for the build quadratures, the window table's shape and `table_size` (what a surface would allocate,
without building it), and the piecewise-cubic Hermite interpolants the tables are evaluated with.

Measured errors and costs: docs/rough-gw.md.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..reference import jkr as _jkr
from .summits import TENSILE_ONSET

__all__ = ["RESOLUTIONS", "table_size"]

#: spacing multipliers of the fidelity presets (tables are 4th-order: error ~ multiplier^4)
RESOLUTIONS = {"fast": 2.0, "standard": 1.0, "reference": 0.5}
_DH = 0.05          # node spacing in h (units of sigma) at resolution 1
_DT_W = 0.15        # largest t-step (sigma) between w-nodes of the 2-D table at resolution 1
_NW_MIN = 24        # fewest w-cells at resolution 1
_T_CUT = 8.5        # untruncated: adhesive tables neglect summits above 8.5 sigma (mass 9.5e-18)
_H_ZERO = 30.0      # F_nu(h) < 1e-195 beyond h = 30: taken as 0
_H_DEEP = -20.0     # tables cover h >= -20; deeper states use on-the-fly quadrature
_DT_PANEL = 0.25    # largest t-span (sigma) of one Gauss-Legendre panel in the build quadratures
_BUILD_BLOCK = 2_000_000   # most floats in one block of the window table's build quadrature
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
_HERTZ_NU = (1.5, 2.5, 1.0)            # pressure, energy, contact area


def _panels(bounds, t_of, dt_max):
    """Split the intervals between sorted `bounds` so that each spans at most dt_max in t_of(.)."""
    b = np.asarray(bounds, float)
    span = np.abs(np.diff(t_of(b)))
    k = np.maximum(1, np.ceil(span / dt_max).astype(int))
    lo = np.repeat(b[:-1], k)
    width = np.repeat(np.diff(b) / k, k)
    frac = np.concatenate([np.arange(m) for m in k])
    left = lo + frac * width
    return np.append(left, b[-1])


def _gl_nodes(bounds):
    """Gauss-Legendre (8-point) nodes, weights and panel index for panels between `bounds`."""
    a, b = bounds[:-1, None], bounds[1:, None]
    half = 0.5 * (b - a)
    x = (a + b) * 0.5 + half * _GL_X[None, :]
    w = half * _GL_W[None, :]
    pid = np.broadcast_to(np.arange(len(bounds) - 1)[:, None], x.shape)
    return x.ravel(), w.ravel(), pid.ravel()


def _window_shape(lam, xr, ttop, scale):
    """(h-cells, w-cells, sub-panels per w-cell, band cells) of the window tables (`_build_window`)."""
    dh = _DH * scale
    h0, h1 = -_T_CUT, ttop + lam * xr
    nh = max(4, int(math.ceil((h1 - h0) / dh)))
    # w-cells: the resolution of a table in sqrt((xi + x_r)/(x_r + x0)) with max(24, 2 (x_r + x0) lam / 0.15)
    # cells over [-x_r, x0] (the earlier layout, measured in docs/rough-gw.md), of which the window
    # [-x_r, 0] is the fraction sqrt(x_r/(x_r + x0)) of the cells
    span = xr + TENSILE_ONSET
    nw = int(math.ceil(max(_NW_MIN, 2.0 * span * lam / _DT_W) * math.sqrt(xr / span) / scale))
    # largest xi-step between w-nodes: the last cell (xi = -x_r (1 - w^2) is steepest at w = 1)
    dxi = xr * (1.0 - (1.0 - 1.0 / nw) ** 2)
    nsub = max(1, int(math.ceil(dxi * lam / _DT_PANEL)))
    # along the band h moves by up to 2 lam x_r per unit w: keep its h-steps <= dh
    nband = max(nw, int(math.ceil(2.0 * xr * lam / dh)))
    return nh, nw, nsub, nband


#: Peak bytes per node of the 2-D window table while it is built: node values and derivatives of three
#: quantities (4 x 3 x 8 B), the Gaussian at the w-nodes (2 x 8 B), one quantity's Hermite blocks and
#: monomial coefficients (2 x 16 x 8 B) and the coefficients already kept (2 x 16 x 8 B): 624 B, rounded up
#: after measuring with tracemalloc (tests/continuum/test_extremes.py checks the estimate bounds the measured peak).
_BYTES_PER_NODE = 800
#: Fixed part of the build's peak: quadrature blocks of `_BUILD_BLOCK` floats (about six arrays of them).
_BUILD_FIXED_BYTES = 6 * 8 * 2_000_000


def table_size(stats, work_of_adhesion: float, e_star: float, z_max=None, detachment: str = "displacement",
               resolution="standard") -> dict:
    """What `GWJKRSurface(...)` with these arguments would allocate and compute, without building it.

    Returns ``nodes`` (2-D window table), ``shape`` (h-cells, w-cells), ``band_cells``,
    ``quadrature_points`` (integrand evaluations of the build), ``peak_bytes`` (an upper estimate of
    the build's peak allocation) and ``lambda`` = delta_c/sigma. The window table spans the release
    stretch Delta = x_r delta_c in steps of ~0.15 sigma and h from -8.5 sigma to z_max + Delta in steps
    of 0.05 sigma (x the resolution multiplier), so its size grows like (delta_c/sigma)^2: with sigma
    well below delta_c (soft, strongly adhesive summits on a very smooth surface) it outgrows any
    memory. Hertz summits (work of adhesion 0) have no adhesive tables.
    """
    scale = RESOLUTIONS.get(resolution, resolution) if isinstance(resolution, str) else float(resolution)
    scale = float(scale)
    sigma = stats.sigma
    out = {"nodes": 0, "shape": (0, 0), "band_cells": 0, "quadrature_points": 0,
           "peak_bytes": 1_000_000, "lambda": 0.0}
    if not work_of_adhesion > 0.0:
        return out
    delta_c = float(_jkr.critical_approach(stats.radius, work_of_adhesion, e_star))
    lam = delta_c / sigma
    xr = 1.0 if detachment == "displacement" else -_jkr.LOAD_DETACH_APPROACH_RATIO
    tmax = math.inf if z_max is None or not math.isfinite(z_max) else float(z_max)
    ttop = min(tmax, _T_CUT)
    nh, nw, nsub, nband = _window_shape(lam, xr, ttop, scale)
    nodes = (nh + 1) * (nw + 1)
    band = nband if math.isfinite(tmax) else 0
    # band: node i integrates up to its own s_i over panels of <= 0.25 sigma in t (about 4 lam x_r of them)
    band_points = band * 8 * max(50, int(4.0 * lam * xr / _DT_PANEL)) // 2
    out.update(nodes=nodes, shape=(nh, nw), band_cells=band, lambda_=lam,
               quadrature_points=int((nh + 1) * nw * nsub * 8 + band_points),
               peak_bytes=int(nodes * _BYTES_PER_NODE + _BUILD_FIXED_BYTES))
    out["lambda"] = out.pop("lambda_")
    return out


# ==============================================================================================
# Piecewise-cubic Hermite tables on uniform grids
# ==============================================================================================
_M = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [-3.0, -2.0, 3.0, -1.0], [2.0, 1.0, -2.0, 1.0]])


class _Cubic1D:
    """Columns of C1 piecewise cubics on x0 + i dx, from node values and exact node derivatives."""

    def __init__(self, x0, dx, values, derivs):
        v = np.asarray(values, float)          # (K, n)
        m = np.asarray(derivs, float) * dx
        v0, v1, m0, m1 = v[:, :-1], v[:, 1:], m[:, :-1], m[:, 1:]
        coef = np.stack([v0, m0, 3.0 * (v1 - v0) - 2.0 * m0 - m1, 2.0 * (v0 - v1) + m0 + m1], axis=-1)
        self.coef = np.ascontiguousarray(coef.transpose(1, 0, 2))   # (ncell, K, 4)
        self.x0, self.dx, self.ncell = float(x0), float(dx), v.shape[1] - 1
        self.x1 = self.x0 + self.ncell * self.dx


class _Hermite2D:
    """Bicubic Hermite interpolant on a uniform (a, b) grid; one coefficient block per cell."""

    def __init__(self, a0, da, b0, db, F, Fa, Fb, Fab):
        na, nb = F.shape
        Fa, Fb, Fab = Fa * da, Fb * db, Fab * da * db
        # D[cell, (a-basis), (b-basis)], basis order (value@0, deriv@0, value@1, deriv@1)
        D = np.empty((na - 1, nb - 1, 4, 4))
        for ia, (sa, ka) in enumerate(((0, 0), (0, 1), (1, 0), (1, 1))):
            for ib, (sb, kb) in enumerate(((0, 0), (0, 1), (1, 0), (1, 1))):
                src = (F, Fb, Fa, Fab)[2 * ka + kb]
                D[:, :, ia, ib] = src[sa:na - 1 + sa, sb:nb - 1 + sb]
        # monomial coefficients of b^l a^m: C[., ., l, m] = sum_tu M[m, t] D[., ., t, u] M[l, u], as batched
        # 4x4 products (a 4-index einsum here cost ~7 us per cell)
        C = np.swapaxes(_M @ D @ _M.T, -1, -2)
        del D
        self.coef = np.ascontiguousarray(C).reshape((na - 1) * (nb - 1), 16)
        self.a0, self.inv_da, self.b0, self.inv_db = float(a0), 1.0 / da, float(b0), 1.0 / db
        self.na, self.nb = na - 1, nb - 1

    def __call__(self, a, b, deriv=True):
        """(F, dF/da, dF/db) at points (a, b); b must lie in the grid, a outside it takes edge values.

        Compiled (`_hermite2d_eval`): the same operations in the same order as `evaluate_numpy`, one point at a
        time without the NumPy temporaries (a footprint-table build spends ~40 % of its time here)."""
        a = np.ascontiguousarray(a, dtype=float).reshape(-1)
        b = np.ascontiguousarray(b, dtype=float).reshape(-1)
        F, Fa, Fb = _hermite2d_eval(self.coef, self.a0, self.inv_da, self.na, self.b0, self.inv_db, self.nb, a, b,
                                    deriv)
        return (F, Fa, Fb) if deriv else (F, None, None)

    def evaluate_numpy(self, a, b, deriv=True):
        """`__call__` in NumPy: the reference the compiled evaluation is tested against."""
        ta = (a - self.a0) * self.inv_da
        np.minimum(ta, self.na * (1.0 - 1e-15), out=ta)
        np.maximum(ta, 0.0, out=ta)
        tb = (b - self.b0) * self.inv_db
        ia = ta.astype(np.intp)
        ib = tb.astype(np.intp)
        np.minimum(ib, self.nb - 1, out=ib)
        ta -= ia
        tb -= ib
        ia *= self.nb
        ia += ib
        c = np.take(self.coef, ia, axis=0).T.reshape(4, 4, -1)        # [l, m, n], contiguous rows
        c0, c1, c2, c3 = c
        T = ((c3 * tb + c2) * tb + c1) * tb + c0                          # T[m] = sum_l c[l, m] b^l
        T0, T1, T2, T3 = T
        F = ((T3 * ta + T2) * ta + T1) * ta + T0
        if not deriv:
            return F, None, None
        Fa = ((3.0 * T3 * ta + 2.0 * T2) * ta + T1) * self.inv_da
        S0, S1, S2, S3 = (3.0 * c3 * tb + 2.0 * c2) * tb + c1
        Fb = (((S3 * ta + S2) * ta + S1) * ta + S0) * self.inv_db
        return F, Fa, Fb


@njit(cache=True)
def _hermite2d_eval(coef, a0, inv_da, na, b0, inv_db, nb, a, b, deriv):
    """`_Hermite2D.__call__` point by point: clamp a to the grid, locate the cell, Horner in b then in a."""
    n = a.size
    F = np.empty(n)
    Fa = np.empty(n if deriv else 0)
    Fb = np.empty(n if deriv else 0)
    top = na * (1.0 - 1e-15)
    for k in range(n):
        ta = (a[k] - a0) * inv_da
        if not (ta == ta and b[k] == b[k]):
            F[k] = np.nan
            if deriv:
                Fa[k] = np.nan
                Fb[k] = np.nan
            continue
        ta = min(ta, top)
        ta = max(ta, 0.0)
        tb = (b[k] - b0) * inv_db
        ia = int(ta)
        ib = min(int(tb), nb - 1)
        ta -= ia
        tb -= ib
        c = coef[ia * nb + ib]                     # c[4 l + m]: coefficient of b^l a^m
        T0 = ((c[12] * tb + c[8]) * tb + c[4]) * tb + c[0]
        T1 = ((c[13] * tb + c[9]) * tb + c[5]) * tb + c[1]
        T2 = ((c[14] * tb + c[10]) * tb + c[6]) * tb + c[2]
        T3 = ((c[15] * tb + c[11]) * tb + c[7]) * tb + c[3]
        F[k] = ((T3 * ta + T2) * ta + T1) * ta + T0
        if deriv:
            Fa[k] = ((3.0 * T3 * ta + 2.0 * T2) * ta + T1) * inv_da
            S0 = (3.0 * c[12] * tb + 2.0 * c[8]) * tb + c[4]
            S1 = (3.0 * c[13] * tb + 2.0 * c[9]) * tb + c[5]
            S2 = (3.0 * c[14] * tb + 2.0 * c[10]) * tb + c[6]
            S3 = (3.0 * c[15] * tb + 2.0 * c[11]) * tb + c[7]
            Fb[k] = (((S3 * ta + S2) * ta + S1) * ta + S0) * inv_db
    return F, Fa, Fb
