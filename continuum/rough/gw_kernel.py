"""Compiled evaluation of the GW surface's tables: `GWJKRSurface._integral` without derivative or parts, in numba.

The rigid rough roller's footprint tables (`continuum.laws.rough_rigid.RigidRoughRoller._integrate`) evaluate the
surface's pressure and energy at ~1e5-1e6 states (d, zeta) per build. In NumPy (`GWJKRSurface._integral_numpy`)
that is a few dozen passes over arrays of the states, with gathers, masks and index sets per branch: memory-bound,
~1/3 of `nanoimpact paper`'s CPU. `integral` does the same arithmetic one state at a time, reading the
surface's own tables (passed as arrays: no Python object enters the kernel), every branch included:

* the 1-D table in h = d/sigma (log of the Hertz integral, and for adhesive surfaces the columns G, Wr, A0), or in
  r = sqrt(z_max/sigma - h) when truncated (`GWJKRSurface._lookup`);
* states deeper than the tables, h < -20: fixed-node quadrature of the defining integrals (`GWJKRSurface._deep`;
  untruncated Hertz by the Gauss-Hermite branch of `summits.gw_integral`, the only one it takes there);
* the threshold's branch: approach (zeta_eff = d), release (zeta_eff = d - Delta), inside the stretched window
  (2-D table A(h, xi) plus the correction s (Wr - E1) that meets the release column, `GWJKRSurface._window`,
  `_window_end`);
* truncated surfaces above z_max (`GWJKRSurface._beyond_top`): the band table for release thresholds,
  A(h, xi) - A(h, xi_top) corrected to meet the band for thresholds inside the window, nothing beyond
  z_max + Delta or once every summit has let go.

The operations are those of the NumPy form in the same order, and the exp of the log-Hertz column is NumPy's, taken
between two compiled passes (`log_hertz`, then `integral`: `GWJKRSurface._kernel_values`). So within the tables
the two forms agree bit for bit on the machine this was written on (the contacts' step acceptances follow the
footprint tables to the last bit: docs/rough-gw.md); elsewhere, to round-off (below the tables the quadrature's sums
are a loop, not BLAS; another CPU's compiler may fuse a multiply-add). tests/continuum/test_gw_kernel.py compares them
branch by branch. NaN separations, and NaN thresholds of adhesive surfaces, give NaN (the NumPy form raises on some).
Divisions follow NumPy's error model (inf or NaN, no exception).

The surface's scalars travel in one float vector (`P_*` indices, built by `GWJKRSurface._kernel_tables`), so one
compiled specialisation serves every surface; `continuum.numerics.compiled_contact.warm_up` loads it.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..physics.jkr_kernel import D_C, S_FOLD
from .gw_layout import _H_ZERO

__all__ = ["integral", "log_hertz", "P_SIZE", "BRANCH_NAMES", "BRANCH_DEEP"]

#: Indices of the parameter vector P (floats; counts and flags stored as floats).
(P_INV_SIGMA, P_TRUNCATED, P_ADHESIVE, P_TMAX, P_HLO, P_X10, P_INV_DX1, P_N1, P_NU, P_HS, P_AS, P_DN, P_LAM, P_XR,
 P_INV_L, P_W_A0, P_W_INV_DA, P_W_NA, P_W_B0, P_W_INV_DB, P_W_NB, P_END_X0, P_END_INV_DX, P_END_N,
 P_BAND_N) = range(25)
P_SIZE = 25

#: Branch codes `integral` writes per state when asked (a record for tests; BRANCH_DEEP is added to the code of a
#: state deeper than the tables, which still takes its threshold's branch).
(BRANCH_NAN, BRANCH_HERTZ, BRANCH_APPROACH, BRANCH_RELEASE, BRANCH_WINDOW, BRANCH_ABOVE_APPROACH, BRANCH_BAND_RELEASE,
 BRANCH_BAND_WINDOW, BRANCH_BAND_EMPTY, BRANCH_BAND_GONE) = range(10)
BRANCH_DEEP = 16
BRANCH_NAMES = {BRANCH_NAN: "nan", BRANCH_HERTZ: "hertz", BRANCH_APPROACH: "approach", BRANCH_RELEASE: "release",
                BRANCH_WINDOW: "window", BRANCH_ABOVE_APPROACH: "above z_max, approach",
                BRANCH_BAND_RELEASE: "above z_max, release (band)", BRANCH_BAND_WINDOW: "above z_max, window",
                BRANCH_BAND_EMPTY: "above z_max, every summit let go", BRANCH_BAND_GONE: "beyond z_max + Delta"}

_SQRT2PI = math.sqrt(2.0 * math.pi)


@njit(cache=True, error_model="numpy")
def _cell(a, n):
    """Cell index of the coordinate a on n unit cells, clamped to [0, n - 1] (NumPy's astype-then-clip, with the
    clamp taken before the conversion so that an infinite a stays defined)."""
    return int(min(max(a, 0.0), n - 1.0))


@njit(cache=True, error_model="numpy")
def _cubic(c, i, t):
    """Cubic Hermite cell i of a (4, ncell) monomial table at local t: Horner, as `GWJKRSurface._window_end`."""
    return ((c[3, i] * t + c[2, i]) * t + c[1, i]) * t + c[0, i]


@njit(cache=True, error_model="numpy")
def _bicubic(coef, a0, inv_da, na, b0, inv_db, nb, a, b):
    """Value of `gw_layout._Hermite2D` at (a, b): a clamped to the grid, Horner in b then in a
    (`gw_layout._hermite2d_eval`'s value path, same operations)."""
    ta = (a - a0) * inv_da
    ta = min(ta, na * (1.0 - 1e-15))
    ta = max(ta, 0.0)
    tb = (b - b0) * inv_db
    ia = int(ta)
    ib = min(int(tb), int(nb) - 1)
    ta -= ia
    tb -= ib
    c = coef[ia * int(nb) + ib]                   # c[4 l + m]: coefficient of b^l a^m
    T0 = ((c[12] * tb + c[8]) * tb + c[4]) * tb + c[0]
    T1 = ((c[13] * tb + c[9]) * tb + c[5]) * tb + c[1]
    T2 = ((c[14] * tb + c[10]) * tb + c[6]) * tb + c[2]
    T3 = ((c[15] * tb + c[11]) * tb + c[7]) * tb + c[3]
    return ((T3 * ta + T2) * ta + T1) * ta + T0


@njit(cache=True, error_model="numpy")
def _window(P, wcoef, h, xi):
    """A_j(h, xi) = int_xi^0 q phi lam dx from the 2-D table in w = sqrt((xi + x_r)/x_r) (`GWJKRSurface._window`)."""
    w = (xi + P[P_XR]) * P[P_INV_L]
    w = min(w, 1.0)
    w = max(w, 0.0)
    w = math.sqrt(w)
    return _bicubic(wcoef, P[P_W_A0], P[P_W_INV_DA], P[P_W_NA], P[P_W_B0], P[P_W_INV_DB], P[P_W_NB], h, w)


@njit(cache=True, error_model="numpy")
def _window_end(P, end, h):
    """E1(h) = A_j(h, -x_r), the 2-D table's release column as a cubic in h (`GWJKRSurface._window_end`)."""
    a = (h - P[P_END_X0]) * P[P_END_INV_DX]
    a = min(a, P[P_END_N] * (1.0 - 1e-15))
    a = max(a, 0.0)
    i = int(a)
    return _cubic(end, i, a - i)


@njit(cache=True, error_model="numpy")
def _stable_s(x):
    """Stable-branch JKR root s = sqrt(a/a0) at delta/delta_c = x (`summits._s_of_x`: `jkr_kernel.solve_s`,
    Ferrari's resolvent cubic by Cardano and two checked Newton polishes; a0 = delta0 = 1 in its units)."""
    d = max(x * D_C, -D_C)
    rad = max(1.0 / 256.0 + d ** 3 / 27.0, 0.0)
    cc = np.cbrt(1.0 / 16.0 + math.sqrt(rad))
    dd = -d / (3.0 * cc)
    m = 0.125 / (cc * cc + d / 3.0 + dd * dd)
    w = math.sqrt(2.0 * m)
    disc = math.sqrt(max(2.0 / w - w * w, 0.0))
    s = 0.5 * (w + disc)
    for _ in range(2):
        f = s ** 4 - s - d
        fp = 4.0 * s ** 3 - 1.0
        s_new = s - f / fp if fp != 0.0 else math.inf
        if math.isfinite(s_new) and abs(s_new ** 4 - s_new - d) <= abs(f) and s_new >= S_FOLD:
            s = s_new
    return s


@njit(cache=True, error_model="numpy")
def _curve_minus_hertz(j, s):
    """Quantity j of JKR minus Hertz in JKR units at s >= 1 (`jkr_kernel.reduced_curve_minus_hertz`)."""
    s3 = s ** 3
    if j == 0:
        s15 = s * math.sqrt(s)
        c = max(s3 - 1.0, 0.0)
        return 16.0 / 9.0 * s15 * (3.0 * s3 * s3 - 3.0 * s3 + 1.0) / (s15 ** 3 + c * math.sqrt(c)) - 8.0 / 3.0 * s3
    if j == 1:
        s4 = s3 * s
        x = (s ** 4 - s) / D_C
        fh = 16.0 / 9.0 * (x * D_C) ** 1.5
        u = (2.0 / 3.0) / D_C * (((16.0 / 15.0 * s3 - 8.0 / 3.0) * s3 + 1.0) * s4 + 0.6)
        return u - 0.4 * x * fh
    return s / D_C


@njit(cache=True, error_model="numpy")
def _deep_hertz(h, nu, truncated, deep_t, deep_w, gh_x, gh_w):
    """Hertz integral below the tables (h < -20): int_{-9.5}^{t_max} (t - h)^nu phi dt on the fixed nodes
    (truncated), or E[(Z - h)^nu] by 60-point Gauss-Hermite (untruncated; `summits.gw_integral`, h < -12)."""
    acc = 0.0
    if truncated:
        for m in range(deep_t.size):
            acc += (deep_t[m] - h) ** nu * deep_w[m]
        return acc
    for m in range(gh_x.size):
        acc += max(gh_x[m] - h, 0.0) ** nu * gh_w[m]
    return acc / _SQRT2PI


@njit(cache=True, error_model="numpy")
def _deep_g(j, h, lam, deep_t, deep_w):
    """G below the tables: int (q - q_H)(x) phi(t) dt on the fixed nodes, x = (t - h)/lam (`GWJKRSurface._deep`)."""
    acc = 0.0
    for m in range(deep_t.size):
        acc += _curve_minus_hertz(j, _stable_s((deep_t[m] - h) / lam)) * deep_w[m]
    return acc


@njit(cache=True, error_model="numpy")
def _band_value(P, band, h):
    """(live, T_rel(h)): the band table of release thresholds above z_max, in w = sqrt(w2),
    w2 = ((z_max - d)/delta_c + x_r)/x_r (`GWJKRSurface._beyond_top`); not live beyond z_max + Delta."""
    w2 = ((P[P_TMAX] - h) / P[P_LAM] + P[P_XR]) * (1.0 / P[P_XR])
    if not w2 > 0.0:
        return False, 0.0
    a = math.sqrt(w2) * P[P_BAND_N]
    i = min(int(a), int(P[P_BAND_N]) - 1)
    return True, _cubic(band, i, a - i)


@njit(cache=True, error_model="numpy")
def _locate(P, h):
    """(cell i, local t, a, u, r) of the 1-D table at h (`GWJKRSurface._lookup`): in h, or in r = sqrt(u),
    u = max(z_max/sigma - h, 0), when truncated (a clamped to the table's end; deeper states are replaced)."""
    u = r = 0.0
    if P[P_TRUNCATED] != 0.0:
        u = max(P[P_TMAX] - h, 0.0)
        r = math.sqrt(u)
        a = min(r * P[P_INV_DX1], P[P_N1])
    else:
        a = (min(h, _H_ZERO) - P[P_X10]) * P[P_INV_DX1]
    i = _cell(a, P[P_N1])
    return i, a - i, a, u, r


@njit(cache=True, error_model="numpy")
def log_hertz(d, P, t1q):
    """The 1-D table's first column at separations d (m): log of the (scaled) Hertz integral, whose exp `integral`
    takes as an argument. The exp is left to NumPy (`np.exp`, as `_integral_numpy` takes it) so that the values of
    the two forms are the same to the last bit wherever the rest of the arithmetic is (the footprint tables, and the
    step acceptances of the contacts run on them, follow their last bit)."""
    out = np.empty(d.size)
    inv_sigma = P[P_INV_SIGMA]
    for k in range(d.size):
        h = d[k] * inv_sigma
        if h != h:
            out[k] = np.nan
            continue
        i, t, _, _, _ = _locate(P, h)
        out[k] = ((t1q[3, i, 0] * t + t1q[2, i, 0]) * t + t1q[1, i, 0]) * t + t1q[0, i, 0]
    return out


@njit(cache=True, error_model="numpy")
def integral(j, d, zeta, e, P, t1q, wcoef, end, band, deep_t, deep_w, gh_x, gh_w, branch):
    """Quantity j (0 pressure, 1 energy, 2 contact fraction) per unit nominal area at separations d and thresholds
    zeta (m, flat float arrays of one size): `GWJKRSurface._integral_numpy(j, d, zeta)` state by state.

    e: exp of `log_hertz(d, P, t1q)`. P: the surface's scalars (P_* indices; P_HS, P_AS, P_NU those of quantity j).
    Tables of quantity j: t1q the 1-D table's monomial coefficients (4, ncell, K), K = 4 columns (log Hertz, G, Wr,
    A0) or 1 (Hertz summits); wcoef the 2-D window table (`_Hermite2D.coef`), end its release column (4, ncell),
    band the band table (4, ncell); deep_t, deep_w the fixed nodes and weights x phi below the tables; gh_x, gh_w
    the Gauss-Hermite rule of `summits.gw_integral`. Surfaces without a table pass any array of its type.
    `branch`: int8 array of d's size to record each state's branch in (BRANCH_*), or of size 0."""
    n = d.size
    out = np.empty(n)
    record = branch.size == n
    inv_sigma = P[P_INV_SIGMA]
    truncated = P[P_TRUNCATED] != 0.0
    adhesive = P[P_ADHESIVE] != 0.0
    tmax, hlo = P[P_TMAX], P[P_HLO]
    nu, hs, As = P[P_NU], P[P_HS], P[P_AS]
    dn, lam, xr = P[P_DN], P[P_LAM], P[P_XR]
    for k in range(n):
        h = d[k] * inv_sigma
        zt = zeta[k] * inv_sigma
        if h != h or (adhesive and zt != zt):
            out[k] = np.nan
            if record:
                branch[k] = BRANCH_NAN
            continue
        # ---- the 1-D table (`_lookup`) and the Hertz integral
        i, t, a, u, r = _locate(P, h)
        if truncated:
            un = u * r if j == 0 else (u * u * r if j == 1 else u)     # u^nu, nu = 3/2, 5/2, 1
            H = un * e[k] * u
            deep = h < hlo
        else:
            H = e[k]
            deep = a < 0.0
        G = Wr = 0.0
        if adhesive:
            G = ((t1q[3, i, 1] * t + t1q[2, i, 1]) * t + t1q[1, i, 1]) * t + t1q[0, i, 1]
            Wr = ((t1q[3, i, 2] * t + t1q[2, i, 2]) * t + t1q[1, i, 2]) * t + t1q[0, i, 2]
        code = 0
        if deep:                                        # below the tables: the defining integrals on fixed nodes
            code = BRANCH_DEEP
            H = _deep_hertz(h, nu, truncated, deep_t, deep_w, gh_x, gh_w)
            if adhesive:
                G = _deep_g(j, h, lam, deep_t, deep_w)
                Wr = 0.0
        if not adhesive:
            out[k] = hs * H
            if record:
                branch[k] = code + BRANCH_HERTZ
            continue
        # ---- the threshold's branch
        rel = zt <= h - dn
        app = zt >= h
        relf = 1.0 if rel else 0.0
        val = hs * H + As * (G + Wr * relf)
        if truncated and h > tmax:
            if app:
                code += BRANCH_ABOVE_APPROACH
            else:                                       # only stretched summits remain (`_beyond_top`)
                live, band_b = _band_value(P, band, h)
                if not live:
                    val = 0.0
                    code += BRANCH_BAND_GONE
                elif rel:
                    val = As * band_b * relf
                    code += BRANCH_BAND_RELEASE
                else:
                    # A(h, xi_eff) - A(h, xi_top) + c M, corrected to meet the band at xi_eff = -x_r
                    a1 = _window(P, wcoef, h, (zt - h) / lam)
                    a2 = _window(P, wcoef, h, (tmax - h) / lam)
                    e1 = _window_end(P, end, h)
                    on = 1.0 if zt < tmax else 0.0
                    span = (tmax - h) / lam + xr
                    c = min(max((tmax - zt) / (lam * max(span, 1e-300)), 0.0), 1.0)
                    M = band_b - (e1 - a2)
                    val = As * (a1 - a2 + c * M) * on
                    code += BRANCH_BAND_WINDOW if zt < tmax else BRANCH_BAND_EMPTY
        elif rel:
            code += BRANCH_RELEASE
        elif app:
            code += BRANCH_APPROACH
        else:
            # inside the window: A(h, xi) + s (Wr - E1), s = -xi/x_r, meeting the release column at xi = -x_r
            a1 = _window(P, wcoef, h, (zt - h) / lam)
            e1 = _window_end(P, end, h)
            s = min(max((h - zt) / (lam * xr), 0.0), 1.0)
            val += As * (a1 + s * (Wr - e1))
            code += BRANCH_WINDOW
        out[k] = val
        if record:
            branch[k] = code
    return out
