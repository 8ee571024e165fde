"""Greenwood-Williamson rough surface of JKR summits with Fuller-Tabor hysteresis (paper §4.2).

Model (SI; heights and separations in metres)
---------------------------------------------
Summit heights z have the Gaussian density phi(z) of std sigma about the summit mean plane (paper
eq 9), truncated at z_max (the tallest summit expected in the nominal footprint; no
renormalisation: the missing mass is ~1/N). There are n summits per m^2, identical spheres of tip
radius beta. At local separation d (summit mean plane to the smooth counter-surface) a summit of
height z has approach delta = z - d. Fuller-Tabor: it feels nothing until delta = 0, then sits on the
JKR stable branch P_JKR(delta) (``continuum.reference.jkr``) until, on retreat, delta < -Delta, the
release stretch: Delta = delta_c (displacement-controlled release, default) or 3^{-2/3} delta_c
(P = -P_c, ``detachment="load"``).

History is one threshold per location: summits with z >= zeta* are attached. After a step at
separation d, zeta* <- zeta_eff(d, zeta*) = max(min(zeta*, d), d - Delta), zeta* = +inf initially.
This is exact for any gap history (lower summits always let go first). Every quantity at a trial
(d, zeta*) uses zeta_eff, so a trial state never holds summits stretched past release nor touching
but unattached summits. Per unit nominal area::

    p(d, zeta*)  = n int_{zeta_eff}^{z_max} P_JKR(z - d) phi(z) dz          (Pa, + = compressive)
    e(d, zeta*)  = n int_{zeta_eff}^{z_max} U_JKR(z - d) phi(z) dz          (J/m^2; U_JKR(0) = 0)
    A_r/A_0      = n int_{zeta_eff}^{z_max} pi a(z - d)^2 phi(z) dz
    contacts     = n int_{zeta_eff}^{z_max} phi(z) dz                       (1/m^2)
    dissipation  = n U_JKR(-Delta) [Phi_t(zeta_new) - Phi_t(zeta_old)]      (J/m^2, zeta rising)

with Phi_t(z) = int_{-inf}^{min(z, z_max)} phi. U_JKR(-Delta) is the Fuller-Tabor loop area.

Fast evaluation
---------------
Exactly decomposed (Hertz part + JKR correction + the branch of the threshold: approach, release or
inside the stretched window) into 1-D tables in h = d/sigma and a 2-D window table in (h, w),
w = sqrt((xi + x_r)/x_r), all piecewise-cubic Hermite with exact node derivatives, built by
Gauss-Legendre quadrature in the JKR variable s = sqrt(a/a0) (layout: `gw_layout`; closed forms:
`summits`). The law is continuous where a threshold changes branch. Derivation, table errors
(`table_error` against the adaptive quadrature of `gw_reference`) and costs: docs/rough-gw.md.
States deeper than the tables (d < -20 sigma) are integrated on the fly with fixed Gauss-Legendre nodes.
Values (pressure, energy, contact fraction) run compiled, one state at a time (`gw_kernel`: the footprint
tables of the rigid roller evaluate ~1e5-1e7 states); derivatives and parts run in NumPy (`_integral_numpy`,
the kernel's reference).

The constructor builds the tables (`continuum.rough.gw_tables.GWTables`, a mixin of the surface); the values
are evaluated by the compiled `continuum.rough.gw_kernel` (pressure, energy, area) or, for derivatives and the
compressive/tensile parts, by `_integral_numpy`, the reference.

Sources: J. A. Greenwood & J. B. P. Williamson, Proc. R. Soc. Lond. A 295 (1966) 300-319;
K. N. G. Fuller & D. Tabor, Proc. R. Soc. Lond. A 345 (1975) 327-342; K. L. Johnson, K. Kendall &
A. D. Roberts, Proc. R. Soc. Lond. A 324 (1971) 301-313; Abramowitz & Stegun ch. 19 / DLMF §12.5
(parabolic-cylinder functions); E. J. Gumbel, *Statistics of Extremes* (1958) §3.1 (characteristic
largest value).
"""
from __future__ import annotations

import math
import time

import numpy as np

from ..physics import jkr_kernel as jk
from ..physics.jkr_kernel import reduced_curve_minus_hertz as _g_of_s
from ..reference import jkr as _jkr
from . import gw_kernel
from .gw_layout import _H_DEEP, _H_ZERO, _HERTZ_NU, _T_CUT, RESOLUTIONS
from .gw_reference import table_error
from .gw_tables import GWTables
from .summits import _GH_W, _GH_X, TENSILE_ONSET, SummitStatistics, _gauss_mass, _out, _s_of_x, gw_integral

_NO_BRANCH = np.zeros(0, np.int8)      # `gw_kernel.integral` records no branches
# ==============================================================================================
# The surface
# ==============================================================================================
class GWJKRSurface(GWTables):
    """Pressure, stiffness, energy, dissipation and contact measures of a GW surface of JKR summits.

    Parameters
    ----------
    stats : SummitStatistics
        sigma (m), summit density n (1/m^2), summit tip radius beta (m).
    work_of_adhesion : float
        Dupre work of adhesion Delta gamma (J/m^2). 0 gives Hertz summits without hysteresis
        (Delta = 0, no adhesive tables).
    e_star : float
        Contact modulus E* (Pa), Johnson's convention.
    z_max : float or None
        Truncation of the summit heights, in units of sigma (``expected_max_height``); None or inf:
        untruncated.
    detachment : "displacement" | "load"
        Release at delta = -delta_c (default, the paper's) or at P = -P_c (delta = -3^{-2/3} delta_c).
    resolution : "fast" | "standard" | "reference" | float
        Table node spacing multiplier (RESOLUTIONS); the error scales like its 4th power.

    All methods take separations d and thresholds zeta in metres (arrays broadcast; zeta may be
    +inf = nothing attached yet) and are vectorised. Results are per unit nominal area.
    The tables cover d >= -20 sigma (``table_range``; the rough model refuses impacts deeper than
    10 sigma below the mean plane, and the rigid law's footprint tables reach 1.5 x that); deeper
    states (summits compressed by more than 20 sigma) are evaluated by fixed Gauss-Legendre
    quadrature of the defining integrals on the fly (exact, ~50 us per state; not expected).
    """

    #: the `continuum.rough.surface.SummitSurface` interface: JKR (or Hertz) summits touch before they
    #: attract, and tables evaluate them
    kind = "tabulated"
    law_name = "jkr"
    attach_stretch = 0.0
    reach = 0.0

    def __init__(self, stats: SummitStatistics, work_of_adhesion: float, e_star: float, z_max=None,
                 detachment: str = "displacement", resolution="standard"):
        t_start = time.perf_counter()
        if detachment not in ("displacement", "load"):
            raise ValueError(f"detachment = {detachment!r}: must be 'displacement' or 'load'")
        if not (math.isfinite(work_of_adhesion) and work_of_adhesion >= 0.0):
            raise ValueError(f"work_of_adhesion = {work_of_adhesion!r}: must be >= 0 (J/m^2)")
        if not (math.isfinite(e_star) and e_star > 0.0):
            raise ValueError(f"e_star = {e_star!r}: must be > 0 (Pa)")
        scale = RESOLUTIONS.get(resolution, resolution) if isinstance(resolution, str) else float(resolution)
        if isinstance(scale, str) or not (0.05 <= float(scale) <= 8.0):
            raise ValueError(f"resolution = {resolution!r}: use one of {sorted(RESOLUTIONS)} or a "
                             "spacing multiplier in [0.05, 8]")
        self.stats = stats
        self.work_of_adhesion = float(work_of_adhesion)
        self.e_star = float(e_star)
        self.detachment = detachment
        self.resolution = resolution
        self._scale = float(scale)
        sigma, beta, n = stats.sigma, stats.radius, stats.density
        self.sigma, self.density, self.radius = sigma, n, beta
        self._tmax = math.inf if z_max is None or not math.isfinite(z_max) else float(z_max)
        if self._tmax < -5.0:
            raise ValueError(f"z_max = {z_max!r} (units of sigma): a truncation below -5 sigma leaves "
                             "essentially no summits")
        self.truncated = math.isfinite(self._tmax)
        #: tallest summit above the mean plane (m); inf when untruncated
        self.z_max = self._tmax * sigma
        self.adhesive = self.work_of_adhesion > 0.0
        g = self.work_of_adhesion
        if self.adhesive:
            #: JKR separation approach under displacement control delta_c (m), paper eq 7
            self.delta_c = float(_jkr.critical_approach(beta, g, e_star))
            #: load-controlled pull-off force of one summit P_c = 1.5 pi beta dgamma (N), paper eq 6
            self.pull_off_force = float(_jkr.pull_off_force(beta, g))
            self._xr = 1.0 if detachment == "displacement" else -_jkr.LOAD_DETACH_APPROACH_RATIO
            #: release stretch Delta (m): delta_c or 3^{-2/3} delta_c
            self.release_stretch = self._xr * self.delta_c
            #: Fuller-Tabor loop energy of one summit U_JKR(-Delta) (J)
            self.loop_energy = float(_jkr.loop_area(beta, g, e_star, detachment=detachment))
            self._lam = self.delta_c / sigma
        else:
            self.delta_c = self.pull_off_force = self.release_stretch = self.loop_energy = 0.0
            self._xr, self._lam = 0.0, 0.0
        self._dn = self.release_stretch / sigma
        root_beta = math.sqrt(beta)
        # per-area scales: Hertz (sigma units) and JKR (P_c, P_c delta_c, pi beta delta_c)
        self._hs = np.array([n * 4.0 / 3.0 * e_star * root_beta * sigma**1.5,
                             n * 8.0 / 15.0 * e_star * root_beta * sigma**2.5,
                             n * math.pi * beta * sigma])
        self._as = np.array([n * self.pull_off_force, n * self.pull_off_force * self.delta_c,
                             n * math.pi * beta * self.delta_c])
        self._ttop = min(self._tmax, _T_CUT)
        self._hlo = _H_DEEP
        self._hlo2 = -_T_CUT          # window table (t = h + lam x <= h): no summits below
        self._hband = self._tmax - self._lam * TENSILE_ONSET
        self._inv_sigma = 1.0 / sigma
        #: separations (m) covered by the tables; below d_min fixed quadrature is used
        self.table_range = (self._hlo * sigma, math.inf)
        self._build()
        #: wall time of the constructor including all tables (s)
        self.build_seconds = time.perf_counter() - t_start

    # ------------------------------------------------------------------------------ evaluation
    def effective_threshold(self, d, zeta):
        """zeta_eff = max(min(zeta, d), d - Delta) (m): attached summits are z >= zeta_eff.

        Also the history update: after an accepted step at separation d, store zeta <- zeta_eff.
        """
        d = np.asarray(d, float)
        return _out(np.maximum(np.minimum(np.asarray(zeta, float), d), d - self.release_stretch))

    def _lookup(self, h, j, deriv):
        """1-D table of quantity j at h: columns V (N, K), d/dh (or None), coordinate a, u, r."""
        if self.truncated:
            u = self._tmax - h
            np.maximum(u, 0.0, out=u)
            r = np.sqrt(u)
            a = r * self._inv_dx1
            np.minimum(a, self._n1, out=a)      # deeper than the tables: replaced by `_deep` (no overflow)
        else:
            u = r = None
            a = (np.minimum(h, _H_ZERO) - self._x10) * self._inv_dx1
        i = a.astype(np.intp)
        np.minimum(i, self._n1 - 1, out=i)
        np.maximum(i, 0, out=i)
        t = np.repeat(a - i, self._k1).reshape(-1, self._k1)
        c0, c1, c2, c3 = np.take(self._t1q[j], i, axis=1)           # each (N, K), contiguous
        V = ((c3 * t + c2) * t + c1) * t + c0
        if not deriv:
            return V, None, a, u, r
        dV = ((3.0 * c3 * t + 2.0 * c2) * t + c1)
        if self.truncated:
            dV *= (-0.5 * self._inv_dx1 / np.maximum(r, 1e-300))[:, None]     # d/dh = -(1/2r) d/dr
        else:
            dV *= self._inv_dx1
        return V, dV, a, u, r

    def _deep(self, h, j, k, a, V, dV):
        """Points k deeper than the tables (h < -10): exact fixed-node quadrature, patched in place.

        Hertz: closed form (untruncated) or int_{-9.5}^{t_max} (t-h)^nu phi dt; G: int (q - q_H) phi;
        Wr = A0 = 0 (the summit mass below -8.5 sigma is < 1e-17). Returns (H, dH/dh).
        """
        nu = _HERTZ_NU[j]
        hk = h[k]
        tn, wphi = self._deep_nodes
        z = tn[None, :] - hk[:, None]                               # t - h > 0.5
        if self.truncated:
            H = (z**nu) @ wphi
            dH = -nu * ((z ** (nu - 1.0)) @ wphi)
        else:
            H = gw_integral(nu, hk)
            dH = -nu * gw_integral(nu - 1.0, hk)
        if self.adhesive:
            x = z / self._lam
            sv = _s_of_x(x)
            V[k, 1] = _g_of_s(sv)[j] @ wphi
            V[k, 2:] = 0.0
            if dV is not None:
                gp = jk.reduced_curve_minus_hertz_slopes(sv, x)
                dV[k, 1] = -(gp[j] @ wphi) / self._lam
                dV[k, 2:] = 0.0
        return H, dH

    def _integral(self, j, d, zeta, deriv=False, parts=False):
        """Quantity j (0 pressure, 1 energy, 2 area fraction) per unit area (SI) and d/dd, or parts.

        Values alone (the footprint tables' and most callers' case) come from the compiled kernel
        (`gw_kernel.integral`, the same arithmetic one state at a time); with `deriv` or `parts` from
        `_integral_numpy`, which is also the reference the kernel is tested against (tests/continuum/test_gw_kernel.py).
        """
        if deriv or parts:
            return self._integral_numpy(j, d, zeta, deriv, parts)
        d = np.asarray(d, dtype=float)
        zeta = np.asarray(zeta, dtype=float)
        if d.shape != zeta.shape:
            d, zeta = np.broadcast_arrays(d, zeta)
        shape = d.shape
        return self._kernel_values(j, d.reshape(-1), zeta.reshape(-1)).reshape(shape), None

    def _kernel_values(self, j, d, zeta, branch=None):
        """`gw_kernel.integral` of quantity j at flat d, zeta (m); `branch`: an int8 array of d's size to record
        each state's branch in (tests), or None."""
        d = np.require(d, float, ["C", "W"])           # one compiled specialisation: contiguous, writeable
        zeta = np.require(zeta, float, ["C", "W"])
        P, t1q, *tables = self._kernel_tables(j)
        e = gw_kernel.log_hertz(d, P, t1q)
        np.exp(e, out=e)                                # NumPy's exp, as `_integral_numpy` takes it (gw_kernel)
        return gw_kernel.integral(j, d, zeta, e, P, t1q, *tables, _NO_BRANCH if branch is None else branch)

    def _kernel_tables(self, j):
        """(P, t1q, wcoef, end, band, deep_t, deep_w, gh_x, gh_w) of quantity j for `gw_kernel.integral`: the
        surface's scalars (`gw_kernel.P_*`) and its tables, as built (placeholders where a surface has none)."""
        cache = self.__dict__.setdefault("_kernel_cache", {})
        if j not in cache:
            K = gw_kernel
            P = np.zeros(K.P_SIZE)
            P[K.P_INV_SIGMA], P[K.P_TRUNCATED], P[K.P_ADHESIVE] = self._inv_sigma, self.truncated, self.adhesive
            P[K.P_TMAX], P[K.P_HLO], P[K.P_X10] = self._tmax, self._hlo, self._x10
            P[K.P_INV_DX1], P[K.P_N1], P[K.P_NU] = self._inv_dx1, self._n1, _HERTZ_NU[j]
            P[K.P_HS], P[K.P_AS] = self._hs[j], self._as[j]
            P[K.P_DN], P[K.P_LAM], P[K.P_XR] = self._dn, self._lam, self._xr
            none2 = np.zeros((4, 1))
            wcoef, end, band = np.zeros((1, 16)), none2, none2
            if self.adhesive:
                t2 = self._t2[j]
                P[K.P_INV_L] = 1.0 / self._L
                P[K.P_W_A0], P[K.P_W_INV_DA], P[K.P_W_NA] = t2.a0, t2.inv_da, t2.na
                P[K.P_W_B0], P[K.P_W_INV_DB], P[K.P_W_NB] = t2.b0, t2.inv_db, t2.nb
                P[K.P_END_X0], P[K.P_END_INV_DX], P[K.P_END_N] = self._end_x0, self._end_inv_dx, self._end_n
                wcoef, end = t2.coef, self._end[j]
                if self.truncated:
                    P[K.P_BAND_N], band = self._band_n, self._band[j]
            tn, wphi = self._deep_nodes
            tables = (self._t1q[j], wcoef, end, band, tn, wphi, _GH_X, _GH_W)
            cache[j] = (P,) + tuple(np.require(a, float, ["C", "W"]) for a in tables)
        return cache[j]

    def _integral_numpy(self, j, d, zeta, deriv=False, parts=False):
        """`_integral` in NumPy: every branch vectorised over the states (the reference of `gw_kernel.integral`)."""
        d = np.asarray(d, dtype=float)
        zeta = np.asarray(zeta, dtype=float)
        if d.shape != zeta.shape:
            d, zeta = np.broadcast_arrays(d, zeta)
        shape = d.shape
        h = d.reshape(-1) * self._inv_sigma
        V, dV, H, dH = self._hertz_integral(h, j, deriv)
        hs = self._hs[j]
        if not self.adhesive:
            val = hs * H
            if parts:
                return val.reshape(shape), np.zeros(shape)
            return val.reshape(shape), ((hs * self._inv_sigma) * dH).reshape(shape) if deriv else None
        As = self._as[j]
        zt = zeta.reshape(-1) * self._inv_sigma
        rel = zt <= h - self._dn
        app = zt >= h
        fix = ~(rel | app)
        if self.truncated:
            above = h > self._tmax         # only stretched summits there: handled below
            fix &= ~above
        G, Wr, A0 = V[:, 1], V[:, 2], V[:, 3]
        val = hs * H + As * (G + Wr * rel)
        dval = hs * dH + As * (dV[:, 1] + dV[:, 2] * rel) if deriv else None
        tens = As * (A0 + Wr * rel) if parts else None
        nf = np.count_nonzero(fix)
        kf = np.flatnonzero(fix) if nf else None          # threshold inside the window (d <= z_max)
        kb = None
        if self.truncated:
            # d > z_max: only stretched summits remain (none at all on approach: G = H = 0 there)
            beyond = above & ~app
            if np.count_nonzero(beyond):
                k = np.flatnonzero(beyond)
                vk, dk, m, band_b, dband_b = self._beyond_top(j, h[k], zt[k], deriv)
                val[k] = vk
                if deriv:
                    dval[k] = dk
                if m.size:
                    kb = k[m]                                 # window thresholds above z_max
        if kf is not None or kb is not None:
            self._add_window(j, h, zt, kf, kb, band_b if kb is not None else None,
                             dband_b if kb is not None else None, V, dV, val, dval, tens, deriv, parts)
        if parts and self.truncated:       # within x0 delta_c of z_max no summit is compressive
            tens = np.where(h > self._hband, val, tens)
        if parts:
            return (val - tens).reshape(shape), tens.reshape(shape)
        return val.reshape(shape), (dval * self._inv_sigma).reshape(shape) if deriv else None

    def _hertz_integral(self, h, j, deriv):
        """The table lookup at h = d/sigma and the Hertz integral H_j (with dH/dh), the states deeper than the
        tables integrated on the fly: (V, dV, H, dH)."""
        V, dV, a, u, r = self._lookup(h, j, deriv)
        e = np.exp(V[:, 0])
        dH = None
        if self.truncated:
            un = (u * r, u * u * r, u)[j]                         # u^nu, nu = 3/2, 5/2, 1
            uen = un * e
            H = uen * u
            if deriv:
                dH = H * dV[:, 0] - (_HERTZ_NU[j] + 1.0) * uen
            deep = h < self._hlo
        else:
            H = e
            if deriv:
                dH = e * dV[:, 0]
            deep = a < 0.0
        if np.count_nonzero(deep):
            k = np.flatnonzero(deep)
            H[k], hd = self._deep(h, j, k, a, V, dV)
            if deriv:
                dH[k] = hd
        return V, dV, H, dH

    def _add_window(self, j, h, zt, kf, kb, band_b, dband_b, V, dV, val, dval, tens, deriv, parts):
        """Add, in place, the summits whose threshold lies inside the stretched window: `kf`, the states with
        d <= z_max, and `kb`, those above z_max whose window thresholds lie above it (`band_b`, `dband_b`: their
        band column from `_beyond_top`). One bicubic evaluation for all of them: A(h, xi_eff), and A(h, xi_top)
        above z_max."""
        As, lam = self._as[j], self._lam
        Wr, A0 = V[:, 2], V[:, 3]
        hf = h[kf] if kf is not None else h[:0]
        hb = h[kb] if kb is not None else h[:0]
        A, Ah, Axi = self._window(j, np.concatenate([hf, hb, hb]),
                                  np.concatenate([(zt[kf] - hf) / lam if kf is not None else hf,
                                                  (zt[kb] - hb) / lam if kb is not None else hb,
                                                  (self._tmax - hb) / lam]), deriv)
        n1, n2 = hf.size, hf.size + hb.size
        E, dE = self._window_end(j, np.concatenate([hf, hb]), deriv)
        xr = self._xr
        if kf is not None:
            # int_xi^0 = A(h, xi), corrected to meet the release column Wr exactly at xi = -x_r:
            # + s (Wr - E1), s = -xi/x_r (`_window_end`); at xi = 0 both vanish (approach branch)
            s = np.clip((hf - zt[kf]) / (lam * xr), 0.0, 1.0)
            Af = A[:n1] + s * (Wr[kf] - E[:n1])
            val[kf] += As * Af
            if deriv:
                dval[kf] += As * (Ah[:n1] - Axi[:n1] / lam + s * (dV[kf, 2] - dE[:n1])
                                  + (Wr[kf] - E[:n1]) / (lam * xr))
            if parts:
                tens[kf] = As * (A0[kf] + Af)
        if kb is not None:
            # int_{xi_eff}^{xi_top} = A(h, xi_eff) - A(h, xi_top), corrected linearly in xi_eff to meet
            # the band column T_rel at xi_eff = -x_r (it is 0 at xi_eff = xi_top either way):
            # + c M, c = (xi_top - xi_eff)/(xi_top + x_r), M = T_rel - (E1 - A(h, xi_top)).
            # M and its first w-derivative vanish at the band's end (xi_top = -x_r), so M/(xi_top + x_r)
            # stays bounded.
            on = zt[kb] < self._tmax                    # else every summit has let go
            span = (self._tmax - hb) / lam + xr         # xi_top + x_r > 0 (live band points)
            c = np.clip((self._tmax - zt[kb]) / (lam * np.maximum(span, 1e-300)), 0.0, 1.0)
            M = band_b - (E[n1:] - A[n2:])
            val[kb] = As * (A[n1:n2] - A[n2:] + c * M) * on
            if deriv:
                dtop = Ah[n2:] - Axi[n2:] / lam
                dM = dband_b - dE[n1:] + dtop
                dc = np.where(span > 1e-9 * xr, c / (lam * np.maximum(span, 1e-300)), 0.0)
                dval[kb] = As * ((Ah[n1:n2] - Axi[n1:n2] / lam) - dtop + c * dM + dc * M) * on

    def _window(self, j, h, xi, deriv):
        """A_j(h, xi) from the 2-D table, with dA/dh and dA/dxi (dimensionless)."""
        w = (xi + self._xr) * (1.0 / self._L)
        np.minimum(w, 1.0, out=w)
        np.maximum(w, 0.0, out=w)
        np.sqrt(w, out=w)
        A, Ah, Aw = self._t2[j](h, w, deriv=deriv)
        if not deriv:
            return A, None, None
        return A, Ah, Aw / (2.0 * self._L * np.maximum(w, 1e-150))

    def _window_end(self, j, h, deriv):
        """The 2-D table at the window's release end, E1 = A_j(h, -x_r), and dE1/dh (or None).

        Inside the window the table gives A(h, xi) = int_xi^0 q phi lam dx. At xi = 0 it is exactly 0
        (a node column), as on the approach branch; at xi = -x_r it should equal the release column
        Wr(h), but the 2-D and 1-D tables carry independent interpolation errors (~ the table error,
        1e-9 - 1e-6 n P_c), so the law would jump by that much wherever a threshold switches between
        the window and the release branch. The correction s (Wr - E1), s = -xi/x_r, linear in xi and
        of the size of the table error, removes the mismatch: the law is continuous in d and zeta
        (the coupled pressure-deflection solve needs it: a jump is a residual no iteration can
        reduce; docs/halfspace.md).
        """
        a = (h - self._end_x0) * self._end_inv_dx
        np.minimum(a, self._end_n * (1.0 - 1e-15), out=a)
        np.maximum(a, 0.0, out=a)
        i = a.astype(np.intp)
        t = a - i
        c0, c1, c2, c3 = np.take(self._end[j], i, axis=1)
        E = ((c3 * t + c2) * t + c1) * t + c0
        if not deriv:
            return E, None
        return E, ((3.0 * c3 * t + 2.0 * c2) * t + c1) * self._end_inv_dx

    def _beyond_top(self, j, h, zt, deriv):
        """Truncated surface, d > z_max, threshold below d: only stretched summits remain.

        Release thresholds: the 1-D band table T_rel (zero beyond z_max + Delta). Returns
        (value, d/dh, m, T_rel[m], dT_rel/dh[m]) where m indexes the points whose threshold lies inside
        the window and that still hold summits: the caller adds A(h, xi_eff) - A(h, xi_top) for them
        (2-D table), corrected to meet T_rel at xi_eff = -x_r.
        """
        lam, xr = self._lam, self._xr
        val = np.zeros(h.size)
        dval = np.zeros(h.size) if deriv else None
        w2 = ((self._tmax - h) / lam + xr) * (1.0 / xr)         # band coordinate squared
        live = w2 > 0.0
        if not np.count_nonzero(live):
            return val, dval, np.zeros(0, np.intp), np.zeros(0), np.zeros(0) if deriv else None
        k = np.flatnonzero(live)
        hk, ztk = h[k], zt[k]
        wb = np.sqrt(w2[k])
        a = wb * self._band_n
        i = a.astype(np.intp)
        np.minimum(i, self._band_n - 1, out=i)
        t = a - i
        c0, c1, c2, c3 = np.take(self._band[j], i, axis=1)
        rel = ztk <= hk - self._dn
        As = self._as[j]
        band = ((c3 * t + c2) * t + c1) * t + c0
        val[k] = As * band * rel
        dband = None
        if deriv:
            dwdh = -0.5 / (lam * xr * np.maximum(wb, 1e-150))      # h = z_max + lam x_r (1 - w^2)
            dband = ((3.0 * c3 * t + 2.0 * c2) * t + c1) * (self._band_n * dwdh)
            dval[k] = As * dband * rel
        win = ~rel
        return val, dval, k[win], band[win], dband[win] if deriv else None

    # ------------------------------------------------------------------------------ public API
    def pressure(self, d, zeta):
        """Nominal pressure p(d, zeta) (Pa; + = compressive) at separations d (m), thresholds zeta (m)."""
        return _out(self._integral(0, d, zeta)[0])

    def stiffness(self, d, zeta):
        """dp/dd (Pa/m) at fixed stored zeta, including the motion of zeta_eff with d (Newton coupling)."""
        return _out(self._integral(0, d, zeta, deriv=True)[1])

    def pressure_and_stiffness(self, d, zeta):
        """(p, dp/dd) (Pa, Pa/m): p as `pressure` gives it (compiled), dp/dd from the NumPy form (`stiffness`)."""
        return _out(self._integral(0, d, zeta)[0]), _out(self._integral(0, d, zeta, deriv=True)[1])

    def pressure_parts(self, d, zeta):
        """(compressive, tensile) parts of p (Pa): summits with P_JKR > 0 and with P_JKR < 0."""
        c, t = self._integral(0, d, zeta, parts=True)
        return _out(c), _out(t)

    def energy(self, d, zeta):
        """Stored elastic + surface energy of the attached summits per nominal area (J/m^2), U(touch) = 0."""
        return _out(self._integral(1, d, zeta)[0])

    def contact_fraction(self, d, zeta):
        """Real contact area / nominal area, n int pi a^2 phi dz over attached summits (1)."""
        return _out(self._integral(2, d, zeta)[0])

    def contacts(self, d, zeta):
        """Attached summits per unit nominal area (1/m^2), n int_{zeta_eff}^{z_max} phi."""
        te = np.asarray(self.effective_threshold(d, zeta), float) / self.sigma
        return _out(self.density * _gauss_mass(te, self._tmax))

    def dissipation(self, zeta_old, zeta_new):
        """Energy lost per nominal area (J/m^2) when the threshold rises from zeta_old to zeta_new (m).

        n U_JKR(-Delta) [Phi_t(zeta_new) - Phi_t(zeta_old)] where zeta_new > zeta_old, else 0 (summits
        attach at U = 0, so a falling threshold costs nothing).
        """
        zo = np.asarray(zeta_old, float) / self.sigma
        zn = np.asarray(zeta_new, float) / self.sigma
        if not self.adhesive:
            return _out(np.zeros(np.broadcast(zo, zn).shape))
        up = zn > zo
        top = self._tmax                                        # Phi_t: no summits above z_max
        m = _gauss_mass(np.where(up, np.minimum(zo, top), 0.0), np.where(up, np.minimum(zn, top), 0.0))
        return _out(np.where(up, self.density * self.loop_energy * m, 0.0))

    def table_error(self, n_points: int = 48, seed: int = 0, h_range=None,
                    quantities=("pressure", "energy", "contact_fraction")):
        """Measured table error against scipy.integrate.quad of the defining integrals
        (`continuum.rough.gw_reference.table_error`, which says how the states are drawn and the norm)."""
        return table_error(self, n_points, seed, h_range, quantities)

    def describe(self) -> dict:
        return {"sigma": self.sigma, "density": self.density, "radius": self.radius,
                "work_of_adhesion": self.work_of_adhesion, "e_star": self.e_star,
                "z_max": self.z_max, "detachment": self.detachment, "resolution": self.resolution,
                "delta_c": self.delta_c, "release_stretch": self.release_stretch,
                "sigma_over_delta_c": self.sigma / self.delta_c if self.adhesive else math.inf,
                "build_seconds": self.build_seconds}
