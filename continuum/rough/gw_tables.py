"""The tables of a GW-JKR surface (`continuum.rough.gw.GWJKRSurface`), built once by its constructor: the 1-D
columns in the gap h (Hertz part, adhesive part, release and area columns), the 2-D window table of summits
whose threshold lies inside the JKR window, and the band table above the tallest summit.

A mixin of `GWJKRSurface` (the methods read and set the surface's attributes); the layout (panels, node counts,
spline classes) is `continuum.rough.gw_layout`, the model and the sources are in `continuum.rough.gw`'s
docstring and `docs/rough-gw.md`.
"""
from __future__ import annotations

import math

import numpy as np

from ..physics.jkr_kernel import S_FOLD as _S_FOLD
from ..physics.jkr_kernel import S_LOAD as _S_LOAD
from ..physics.jkr_kernel import S_ZERO as _S_ZERO
from ..physics.jkr_kernel import dx_ds as _dx_ds
from ..physics.jkr_kernel import reduced_curve as _q_of_s
from ..physics.jkr_kernel import reduced_curve_minus_hertz as _g_of_s
from ..physics.jkr_kernel import x_of_s as _x_of_s
from .gw_layout import (
    _BUILD_BLOCK,
    _DH,
    _DT_PANEL,
    _GL_W,
    _GL_X,
    _H_ZERO,
    _HERTZ_NU,
    _T_CUT,
    _Cubic1D,
    _gl_nodes,
    _Hermite2D,
    _panels,
    _window_shape,
)
from .summits import _phi, _s_of_x, gw_integral

#: Tables built in this process, by what they are a function of (`GWTables._table_key`): a sweep, a bisection or
#: a regime estimate builds surfaces of the same summits again and again (a dozen per run, ~10 ms each).
_BUILT: dict = {}
#: Table sets kept (the oldest is dropped first): megabytes each at the standard resolution.
MAX_KEPT = 16


class GWTables:
    """Table building of `GWJKRSurface` (its constructor calls `_build`)."""

    # ------------------------------------------------------------------------------ build
    def _table_key(self) -> tuple:
        """Everything the tables depend on, all dimensionless (heights in sigma, the JKR window in delta_c): the
        spacing multiplier, the truncation, the table ranges, lambda = delta_c / sigma, the release point x_r and
        the detachment rule. Surfaces of the same key have the same tables bit for bit."""
        return (self._scale, self.truncated, self._tmax, self._hlo, self._hlo2, self._ttop, self.adhesive,
                self._lam, self._xr, self.detachment)

    def _build(self):
        """Set the tables (the attributes `_build_tables` sets), built once per key in this process and shared,
        read only, by every surface of that key."""
        key = self._table_key()
        tables = _BUILT.get(key)
        if tables is None:
            before = set(vars(self))
            self._build_tables()
            tables = {name: value for name, value in vars(self).items() if name not in before}
            if len(_BUILT) >= MAX_KEPT:
                _BUILT.pop(next(iter(_BUILT)))
            _BUILT[key] = tables
        vars(self).update(tables)

    def _build_tables(self):
        dh = _DH * self._scale
        if self.truncated:
            self._umax = self._tmax - self._hlo
            rmax = math.sqrt(self._umax)
            nr = max(8, int(math.ceil(2.0 * self._umax / dh)))
            r = np.linspace(0.0, rmax, nr + 1)
            self._rmax = rmax
            hnodes = self._tmax - r * r
            vals, ders = self._hertz_truncated(r)
            x0, dx = 0.0, rmax / nr
        else:
            nh = int(math.ceil((_H_ZERO - self._hlo) / dh))
            hnodes = np.linspace(self._hlo, _H_ZERO, nh + 1)
            vals, ders = self._hertz_untruncated(hnodes)
            x0, dx = self._hlo, (_H_ZERO - self._hlo) / nh
        if self.adhesive:
            self._build_window(dh)
            cols, dcols = self._compressed_columns(hnodes)       # (9, n): G, Wr, A0 per quantity
            if self.truncated:
                dcols = dcols * (-2.0 * r)                          # d/dr = -2 r d/dh
            vals, ders = np.vstack([vals, cols]), np.vstack([ders, dcols])
        t1 = _Cubic1D(x0, dx, vals, ders)
        self._t1 = t1
        self._x10, self._inv_dx1, self._n1 = t1.x0, 1.0 / t1.dx, t1.ncell
        # per-quantity coefficient blocks [log Hertz, G, Wr, A0] (one contiguous gather per call)
        self._t1q = [np.ascontiguousarray(t1.coef[:, [j, 3 + j, 6 + j, 9 + j] if self.adhesive else [j]]
                                          .transpose(2, 0, 1)) for j in range(3)]        # (4, ncell, K)
        self._k1 = 4 if self.adhesive else 1
        # fixed Gauss-Legendre nodes in t on [-9.5, t_top] for states deeper than the tables
        t_lo = -(_T_CUT + 1.0)               # no summit mass below (9.5 sigma: < 1e-20)
        tb = np.linspace(t_lo, self._ttop, int(math.ceil((self._ttop - t_lo) / _DT_PANEL)) + 1)
        tn, tw, _ = _gl_nodes(tb)
        self._deep_nodes = (tn, tw * _phi(tn))

    def _hertz_untruncated(self, h):
        """log F_nu(h) and its exact derivative -nu F_{nu-1}/F_nu (closed form, pbdv)."""
        vals, ders = [], []
        for nu in _HERTZ_NU:
            f = gw_integral(nu, h)
            vals.append(np.log(f))
            ders.append(-nu * gw_integral(nu - 1.0, h) / f)
        return np.array(vals), np.array(ders)

    def _hertz_truncated(self, r):
        """log J_nu and d/dr: J_nu(u) = u^{-nu-1} int_h^{t_max} (t-h)^nu phi dt = 2 int_0^1 y^{2nu+1} phi(t) dy,

        t = t_max - u (1 - y^2), u = r^2 (Gauss-Legendre panels spanning <= _DT_PANEL in t).
        """
        u = r * r
        umax = float(u[-1])
        yb = _panels(np.linspace(0.0, 1.0, 21), lambda y: umax * y * y, _DT_PANEL)
        y, w, _ = _gl_nodes(yb)
        t = self._tmax - u[:, None] * (1.0 - y * y)[None, :]
        ph = _phi(t)
        vals, ders = [], []
        for nu in _HERTZ_NU:
            ker = 2.0 * y ** (2.0 * nu + 1.0) * w
            j = ph @ ker
            dj = (ph * t) @ (ker * (1.0 - y * y))          # dJ/du
            vals.append(np.log(j))
            ders.append(2.0 * r * dj / j)
        return np.array(vals), np.array(ders)

    def _build_window(self, dh):
        """2-D tables A_k(h, w) = int_xi^0 q_k(x) phi(h + lam x) lam dx over the stretched window,
        xi = -x_r + x_r w^2 (w = 0: release, xi = -x_r; w = 1: approach, xi = 0, where A = 0 exactly).

        Cumulative Gauss-Legendre sums in s between the w-nodes; node derivatives exact:
        dA/dh = int q phi' lam dx, dA/dw = -lam q(xi) phi(h + lam xi) dxi/dw. Built in blocks of h
        rows so that the quadrature's temporaries stay below `_BUILD_BLOCK` floats (`table_size`).
        """
        lam, xr = self._lam, self._xr
        L = xr
        self._L = L
        h0, h1 = self._hlo2, self._ttop + lam * xr
        nh, nw, nsub, nband = _window_shape(lam, xr, self._ttop, self._scale)
        h = np.linspace(h0, h1, nh + 1)
        wn = np.linspace(0.0, 1.0, nw + 1)
        s = _s_of_x(-xr + L * wn * wn)
        s[0] = _S_FOLD if self.detachment == "displacement" else _S_LOAD
        s[-1] = 1.0
        xi = _x_of_s(s)
        sb = s[:-1, None] + np.diff(s)[:, None] * np.linspace(0.0, 1.0, nsub + 1)[None, :]
        lo, hi = sb[:, :-1].ravel(), sb[:, 1:].ravel()
        half = 0.5 * (hi - lo)
        sn = (((lo + hi) * 0.5)[:, None] + half[:, None] * _GL_X[None, :]).ravel()
        wt = (half[:, None] * _GL_W[None, :]).ravel()
        ker = _q_of_s(sn) * (lam * _dx_ds(sn) * wt)[None, :]        # (3, nodes)
        xs = lam * _x_of_s(sn)
        per = nsub * 8
        A = np.zeros((3, nh + 1, nw + 1))
        Ah = np.zeros_like(A)
        rows = max(1, _BUILD_BLOCK // max(sn.size, 1))
        for r0 in range(0, nh + 1, rows):
            r1 = min(nh + 1, r0 + rows)
            t = h[r0:r1, None] + xs[None, :]
            ph = _phi(t)
            pht = -ph * t
            for k in range(3):
                pan = (ph * ker[k]).reshape(r1 - r0, nw, per).sum(-1)
                panh = (pht * ker[k]).reshape(r1 - r0, nw, per).sum(-1)
                A[k, r0:r1, :-1] = np.cumsum(pan[:, ::-1], axis=1)[:, ::-1]
                Ah[k, r0:r1, :-1] = np.cumsum(panh[:, ::-1], axis=1)[:, ::-1]
            del t, ph, pht
        tj = h[:, None] + lam * xi[None, :]
        phj = _phi(tj)
        qj = _q_of_s(s)
        dxi_dw = 2.0 * L * wn
        Aw = -lam * qj[:, None, :] * phj[None] * dxi_dw[None, None, :]
        Ahw = lam * qj[:, None, :] * (phj * tj)[None] * dxi_dw[None, None, :]
        del phj, tj
        self._t2 = [_Hermite2D(h0, (h1 - h0) / nh, 0.0, 1.0 / nw, A[k], Ah[k], Aw[k], Ahw[k]) for k in range(3)]
        self._t2_range = (h0, h1)
        self._nw = nw
        # The bicubic restricted to the release end (w = 0, xi = -x_r) is exactly the cubic Hermite in h
        # through its node values and h-derivatives there: E1(h) = A(h, -x_r), which `_integral` uses to
        # make the window branch meet the release column Wr exactly (`_window_end`).
        te = _Cubic1D(h0, (h1 - h0) / nh, A[:, :, 0], Ah[:, :, 0])
        self._end = [np.ascontiguousarray(te.coef[:, j].T) for j in range(3)]          # (4, ncell)
        self._end_x0, self._end_inv_dx, self._end_n = h0, nh / (h1 - h0), nh
        del A, Ah, Aw, Ahw
        if self.truncated:
            self._build_band(nband)

    def _build_band(self, nw):
        """Truncated surface, z_max < d < z_max + Delta, all stretched summits attached (release).

        w in [0, 1] with xi_top = (z_max - d)/delta_c = -x_r + x_r w^2 (w = 0: the last summit lets
        go; w = 1: d = z_max). Column (3 quantities): T_rel = int_{-x_r}^{xi_top} q phi lam dx,
        analytic in w. Exact node derivatives:
        dT/dw = lam q(xi_top) phi(t_max) dxi/dw + (int q phi' lam dx) dh/dw, dh/dw = -lam dxi/dw.
        """
        lam, xr, tm = self._lam, self._xr, self._tmax
        wn = np.linspace(0.0, 1.0, nw + 1)
        xi = -xr + xr * wn * wn
        s = _s_of_x(xi)
        s_rel = _S_FOLD if self.detachment == "displacement" else _S_LOAD
        s[0], s[-1] = s_rel, 1.0
        h = tm - lam * _x_of_s(s)
        vals = np.zeros((3, nw + 1))
        ders = np.zeros((3, nw + 1))
        dxi_dw = 2.0 * xr * wn
        base = np.linspace(s_rel, 1.0, int(math.ceil((1.0 - s_rel) / 0.02)) + 1)
        for i in range(1, nw + 1):
            sb = _panels(np.append(base[base < s[i]], s[i]), lambda s_: lam * _x_of_s(s_), _DT_PANEL)
            sn, w, _ = _gl_nodes(sb)
            ker = _q_of_s(sn) * (lam * _dx_ds(sn) * w)[None, :]
            t = h[i] + lam * _x_of_s(sn)
            ph = _phi(t)
            vals[:, i] = ker @ ph
            ders[:, i] = ((ker @ (-ph * t)) * (-lam * dxi_dw[i])
                          + lam * _q_of_s(s[i:i + 1])[:, 0] * _phi(tm) * dxi_dw[i])
        tb = _Cubic1D(0.0, 1.0 / nw, vals, ders)
        self._band = [np.ascontiguousarray(tb.coef[:, j].T) for j in range(3)]      # (4, ncell)
        self._band_n = nw

    def _compressed_columns(self, hn):
        """1-D columns at the nodes hn (rows k = 3 quantities each) and their h-derivatives:

        G  = int_0^{x_top} (q - q_H) phi(h + lam x) lam dx, x_top = (t_top - h)/lam  (compressed summits)
        Wr = int_{-x_r}^0 q phi lam dx   (all stretched summits attached: the release branch)
        A0 = int_0^{x0} q phi lam dx     (compressed summits with P < 0)
        G is integrated in y = sqrt(s - 1) (q - q_H ~ x^{3/2} is analytic in y), Wr and A0 in s.
        """
        lam, ttop = self._lam, self._ttop
        out = np.zeros((9, hn.size))
        dout = np.zeros((9, hn.size))
        # ---- G
        ok = hn < ttop
        hv = hn[ok]
        if hv.size:
            xhi = (ttop - hv) / lam
            yhi = np.sqrt(np.maximum(_s_of_x(xhi) - 1.0, 0.0))
            ymax = float(np.max(yhi))
            base = np.linspace(0.0, ymax, int(math.ceil(ymax / 0.05)) + 1)
            yb = _panels(base, lambda y: lam * _x_of_s(1.0 + y * y), _DT_PANEL)
            y, w, pid = _gl_nodes(yb)
            sn = 1.0 + y * y
            kg = _g_of_s(sn) * (lam * _dx_ds(sn) * 2.0 * y * w)[None, :]
            t = hv[:, None] + lam * _x_of_s(sn)[None, :]
            k = np.clip(np.searchsorted(yb, yhi, side="right") - 1, 0, len(yb) - 2)
            full = pid[None, :] < k[:, None]                  # whole panels below the one holding yhi
            ph = _phi(t) * full
            G = ph @ kg.T
            dG = (-ph * t) @ kg.T
            ya = yb[k]
            yp = ya[:, None] + (yhi - ya)[:, None] * 0.5 * (1.0 + _GL_X[None, :])
            wp = (yhi - ya)[:, None] * 0.5 * _GL_W[None, :]
            sp = 1.0 + yp * yp
            tp = hv[:, None] + lam * _x_of_s(sp)
            php = _phi(tp)
            kp = _g_of_s(sp) * (lam * _dx_ds(sp) * 2.0 * yp * wp)[None]
            G += np.einsum("kij,ij->ik", kp, php)
            dG += np.einsum("kij,ij->ik", kp, -php * tp)
            dG -= (_g_of_s(1.0 + yhi * yhi) * _phi(ttop)).T      # the upper limit moves: dx_top/dh = -1/lam
            out[0:3, ok] = G.T
            dout[0:3, ok] = dG.T
        # ---- Wr and A0
        s_rel = _S_FOLD if self.detachment == "displacement" else _S_LOAD
        base = np.concatenate([np.linspace(s_rel, 1.0, int(math.ceil((1.0 - s_rel) / 0.05)) + 1),
                               np.linspace(1.0, _S_ZERO, int(math.ceil((_S_ZERO - 1.0) / 0.05)) + 1)[1:]])
        sb = _panels(base, lambda s_: lam * _x_of_s(s_), _DT_PANEL)
        sn, w, _ = _gl_nodes(sb)
        kq = _q_of_s(sn) * (lam * _dx_ds(sn) * w)[None, :]
        t = hn[:, None] + lam * _x_of_s(sn)[None, :]
        ph = _phi(t)
        pht = -ph * t
        up = sn > 1.0
        out[3:6] = (ph[:, ~up] @ kq[:, ~up].T).T
        dout[3:6] = (pht[:, ~up] @ kq[:, ~up].T).T
        out[6:9] = (ph[:, up] @ kq[:, up].T).T
        dout[6:9] = (pht[:, up] @ kq[:, up].T).T
        return out, dout
