"""Slow reference of the GW surface: its defining integrals by adaptive quadrature (scipy.integrate.quad),
for tests and `GWJKRSurface.table_error`. Per-summit laws from continuum.reference.jkr (Hertz if the work of
adhesion is 0).
"""
from __future__ import annotations

import math

import numpy as np
from scipy import integrate

from ..reference import jkr as _jkr
from .summits import _SQRT2PI, TENSILE_ONSET, _out

__all__ = ["quadrature_pressure", "quadrature_energy", "quadrature_contact_fraction", "table_error"]


def _summit_law(kind, stats, g, e_star):
    beta = stats.radius
    if g > 0:
        if kind == 0:
            return lambda dl: float(_jkr.force_from_approach(dl, beta, g, e_star))
        if kind == 1:
            return lambda dl: float(_jkr.energy_from_approach(dl, beta, g, e_star))
        return lambda dl: math.pi * float(_jkr.radius_from_approach(dl, beta, g, e_star)) ** 2
    rb = math.sqrt(beta)
    if kind == 0:
        return lambda dl: 4.0 / 3.0 * e_star * rb * dl**1.5
    if kind == 1:
        return lambda dl: 8.0 / 15.0 * e_star * rb * dl**2.5
    return lambda dl: math.pi * beta * dl


def _quadrature(kind, d, zeta, stats, g, e_star, z_max, detachment, part):
    sigma, n = stats.sigma, stats.density
    if g > 0:
        dc = float(_jkr.critical_approach(stats.radius, g, e_star))
        rel = dc if detachment == "displacement" else \
            -float(_jkr.load_controlled_detach_approach(stats.radius, g, e_star))
        pc = float(_jkr.pull_off_force(stats.radius, g))
        scale = [pc, pc * dc, math.pi * stats.radius * dc][kind]
        x0 = TENSILE_ONSET * dc
    else:
        dc = rel = 0.0
        scale = [4.0 / 3.0 * e_star * math.sqrt(stats.radius) * sigma**1.5,
                 8.0 / 15.0 * e_star * math.sqrt(stats.radius) * sigma**2.5,
                 math.pi * stats.radius * sigma][kind]
        x0 = 0.0
    law = _summit_law(kind, stats, g, e_star)
    tmax = math.inf if z_max is None or not math.isfinite(z_max) else float(z_max)
    d, zeta = np.broadcast_arrays(np.asarray(d, float), np.asarray(zeta, float))
    out = np.zeros(d.shape)
    for idx in np.ndindex(d.shape):
        dd, zz = float(d[idx]), float(zeta[idx])
        h = dd / sigma
        te = max(min(zz, dd), dd - rel) / sigma
        top = min(tmax, max(h, 0.0) + 13.0)
        lo, hi = te, top
        if part == "tensile":
            hi = min(hi, h + x0 / sigma)
        elif part == "compressive":
            lo = max(lo, h + x0 / sigma)
        if hi <= lo:
            continue

        def f(t):
            return law(sigma * (t - h)) * math.exp(-0.5 * t * t) / (_SQRT2PI * scale)

        cand = sorted(b for b in (h, h + dc / sigma, h + 5 * dc / sigma, h + 30 * dc / sigma,
                                  h + x0 / sigma, -4.0, -2.0, 0.0, 2.0, 4.0, 6.0) if lo < b < hi)
        brk = [lo]
        for b in cand + [hi]:                   # drop slivers (quad cannot converge on them)
            if b - brk[-1] > 1e-9:
                brk.append(b)
        brk[-1] = hi
        total = 0.0
        for a, b in zip(brk[:-1], brk[1:]):
            v, _ = integrate.quad(f, a, b, epsabs=1e-14, epsrel=1e-11, limit=400)
            total += v
        out[idx] = n * scale * total
    return _out(out)


def quadrature_pressure(d, zeta, stats, work_of_adhesion, e_star, z_max=None, detachment="displacement",
                        part="total"):
    """Reference p(d, zeta) (Pa) by scipy.integrate.quad of n int_{zeta_eff}^{z_max} P(z - d) phi dz.

    Same arguments as GWJKRSurface (z_max in units of sigma). part: "total", "compressive"
    (summits with P > 0) or "tensile". Per-summit laws from continuum.reference.jkr (Hertz if
    work_of_adhesion = 0). Slow: a Python loop of adaptive quadratures, for tests only.
    """
    return _quadrature(0, d, zeta, stats, work_of_adhesion, e_star, z_max, detachment, part)


def quadrature_energy(d, zeta, stats, work_of_adhesion, e_star, z_max=None, detachment="displacement"):
    """Reference stored energy (J/m^2) n int U_JKR(z - d) phi dz by adaptive quadrature (slow)."""
    return _quadrature(1, d, zeta, stats, work_of_adhesion, e_star, z_max, detachment, "total")


def quadrature_contact_fraction(d, zeta, stats, work_of_adhesion, e_star, z_max=None,
                                detachment="displacement"):
    """Reference real-contact fraction n int pi a(z - d)^2 phi dz by adaptive quadrature (slow)."""
    return _quadrature(2, d, zeta, stats, work_of_adhesion, e_star, z_max, detachment, "total")


def table_error(surface, n_points: int = 48, seed: int = 0, h_range=None,
                quantities=("pressure", "energy", "contact_fraction")) -> dict:
    """Measured table error of a `GWJKRSurface` against scipy.integrate.quad of the defining integrals.

    Random states: h = d/sigma uniform in h_range (default [-4, min(z_max, 6) + Delta/sigma],
    the range an impact uses; with truncation a quarter of them in the band
    z_max - 1.2114 delta_c < d < z_max + Delta), zeta* drawn in equal shares as +inf
    (approach), inside [d - Delta, d] (fixed threshold) and below d - Delta (releasing). Error norm:
    |X - X_quad| / max(|X_quad|, S) with S = n P_c (pressure), n P_c delta_c (energy),
    n pi beta delta_c (area); for work_of_adhesion = 0, S = 0 (pure relative error; states with
    X_quad = 0 are skipped). Returns {quantity: max error, "points": n, "norm": text}.
    """
    rng = np.random.default_rng(seed)
    if h_range is None:
        h_range = (-4.0, min(surface._tmax, 6.0) + surface._dn)
    h = rng.uniform(*h_range, n_points)
    if surface.truncated and surface.adhesive:     # a quarter in the band within x0 delta_c of z_max
        band = np.arange(n_points) % 4 == 3
        h[band] = rng.uniform(surface._hband, surface._tmax + surface._dn, np.count_nonzero(band))
    kind = np.arange(n_points) % 3
    zs = np.where(kind == 0, np.inf,
                  np.where(kind == 1, h - surface._dn * rng.uniform(0, 1, n_points),
                           h - surface._dn - rng.uniform(0, 1, n_points)))
    d, zeta = h * surface.sigma, zs * surface.sigma
    fns = {"pressure": (surface.pressure, quadrature_pressure, 0),
           "energy": (surface.energy, quadrature_energy, 1),
           "contact_fraction": (surface.contact_fraction, quadrature_contact_fraction, 2)}
    out = {"points": n_points, "h_range": tuple(h_range),
           "norm": "|X - X_quad| / max(|X_quad|, S), S = n P_c, n P_c delta_c, n pi beta delta_c"}
    for q in quantities:
        fast, slow, j = fns[q]
        x = fast(d, zeta)
        ref = slow(d, zeta, surface.stats, surface.work_of_adhesion, surface.e_star,
                   z_max=surface._tmax if surface.truncated else None, detachment=surface.detachment)
        s = surface._as[j] if surface.adhesive else 0.0
        den = np.maximum(np.abs(ref), s)
        ok = den > 0
        out[q] = float(np.max(np.abs(x - ref)[ok] / den[ok])) if np.any(ok) else 0.0
    return out
