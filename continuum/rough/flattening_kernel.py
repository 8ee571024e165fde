"""Compiled flattening table of Thornton-Ning's construction on a summit law (`continuum.rough.plastic_branches`).

For each plastic depth D = delta_max - delta_y of the table, the deepest state is a*^2 = a_y^2 + beta D,
F* = F_y + pi p_y beta D (Thornton & Ning, Powder Technol. 99 (1998) 154), and the flattened radius R_p >= the
previous one solves F_L(a*; R_p) = F* (F_L falls with R), with delta_p = delta_y + D - delta_L(a*; R_p). The
root is scipy's brentq algorithm step for step (`continuum.physics.brent.brent_step`; the bracket [R, 1.5 R]
doubled until it holds the root, xtol 1e-14 hi, rtol 1e-13, maxiter 100) on the law's own contact: JKR's and DMT's
closed forms, Maugis-Dugdale's compiled root (`continuum.reference.maugis_kernel`). One call builds the whole table
instead of ~400 Python root finds with a few dozen NumPy calls each; tests/continuum/test_summit_law_build.py
compares it with scipy's brentq on the same equation.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..physics.brent import brent_step
from ..reference import maugis_kernel as mk

#: Law codes of `force_approach`.
LAW_JKR, LAW_DMT, LAW_MAUGIS_DUGDALE = 0, 1, 2
LAW_CODES = {"jkr": LAW_JKR, "dmt": LAW_DMT, "maugis_dugdale": LAW_MAUGIS_DUGDALE}
#: scipy.optimize.brentq's settings of the flattened radius (xtol is XTOL_PER_HI times the bracket's top).
XTOL_PER_HI, RTOL, MAXITER = 1e-14, 1e-13, 100


@njit(cache=True)
def force_approach(kind, a, radius, w, e_star, sigma0):
    """(F N, delta m) of law `kind`'s contact of radius a (m) on a sphere of radius `radius` (m): JKR
    (`continuum.reference.jkr`), DMT (Hertz less 2 pi w R), Maugis-Dugdale (sigma0 Pa)."""
    if kind == LAW_JKR:
        return (4.0 * e_star * a ** 3.0 / (3.0 * radius) - np.sqrt(8.0 * np.pi * w * e_star) * a * np.sqrt(a),
                a * a / radius - np.sqrt(2.0 * np.pi * w / e_star) * np.sqrt(a))
    if kind == LAW_DMT:
        return 4.0 * e_star * a ** 3.0 / (3.0 * radius) - 2.0 * math.pi * w * radius, a * a / radius
    return mk.force_approach(a, radius, w, e_star, sigma0)


@njit(cache=True)
def flattened_radius(kind, a, f, start, w, e_star, sigma0):
    """R_p >= start with F_L(a; R_p) = f (F_L falls with R): `start` itself when F_L(a; start) <= f."""
    lo, hi = start, 1.5 * start
    glo = force_approach(kind, a, lo, w, e_star, sigma0)[0] - f
    if glo <= 0.0:
        return lo
    ghi = force_approach(kind, a, hi, w, e_star, sigma0)[0] - f
    while ghi > 0.0:
        lo, hi, glo = hi, 2.0 * hi, ghi
        ghi = force_approach(kind, a, hi, w, e_star, sigma0)[0] - f
    xtol = XTOL_PER_HI * hi
    xpre, xcur, fpre, fcur = lo, hi, glo, ghi
    if fcur == 0.0:
        return xcur
    xblk = fblk = spre = scur = 0.0
    for _ in range(MAXITER):
        done, xpre, xcur, xblk, fpre, fblk, spre, scur = brent_step(xpre, xcur, xblk, fpre, fcur, fblk, spre, scur,
                                                                    xtol, RTOL)
        if done:
            return xcur
        fcur = force_approach(kind, a, xcur, w, e_star, sigma0)[0] - f
    raise ValueError("flattened radius: brentq did not converge in 100 iterations")


@njit(cache=True)
def flattening_table(kind, beta, a_y, f_y, d_y, slope, d, w, e_star, sigma0):
    """(R_p, delta_p) (m) at the plastic depths d (m, d[0] = 0, increasing) of a summit of tip radius beta that
    yielded at contact radius a_y (m), force f_y (N), approach d_y (m), plastic slope pi p_y beta (N/m)."""
    n = d.size
    r_p = np.empty(n)
    d_p = np.zeros(n)
    r_p[0] = beta
    for i in range(1, n):
        dd = d[i]
        a = math.sqrt(a_y * a_y + beta * dd)
        r_p[i] = flattened_radius(kind, a, f_y + slope * dd, r_p[i - 1], w, e_star, sigma0)
        d_p[i] = d_y + dd - force_approach(kind, a, r_p[i], w, e_star, sigma0)[1]
    return r_p, d_p
