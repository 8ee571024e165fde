"""Compiled root of Maugis' energy equation (`continuum.reference.maugis`): the same equation, the same variable
t = sqrt(m^2 - 1), the same bracket and scipy's brentq algorithm with the same tolerances, step for step
(`continuum.physics.brent.brent_step`, scipy's brentq.c), so the numbers are those of the scipy form that
`continuum.reference.maugis` keeps as its reference (`_t_of_A_scipy`; tests/continuum/test_maugis_kernel.py compares
both) at a small fraction of the cost: a tabulated Maugis-Dugdale summit law needs the root at ~2000 contact radii,
and Thornton-Ning's flattening of a plastic summit (`continuum.rough.plastic_branches`) at thousands more.

Equations (Maugis, J. Colloid Interface Sci. 150 (1992) 243; Johnson & Greenwood, J. Colloid Interface Sci. 192
(1997) 326), normalised as in `continuum.reference.maugis`:

    (lambda A^2/2)[t + (m^2-2) arctan t] + (4 lambda^2 A/3)[t arctan t - m + 1] = 1,  t = sqrt(m^2-1)
    Pbar = A^3 - lambda A^2 [t + m^2 arctan t],   Dbar = A^2 - (4/3) lambda A t
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..physics.brent import brent_step

#: scipy.optimize.brentq's settings of the Python form (`continuum.reference.maugis._t_of_A_scipy`).
T_XTOL, T_RTOL, T_MAXITER = 1e-300, 1e-15, 500


@njit(cache=True)
def t_minus_atan(t):
    """t - arctan t without cancellation (series for t < 0.1, 12 terms: error < 1e-26 t^3)."""
    if t < 0.1:
        t2 = t * t
        acc = 0.0
        for k in range(12, 0, -1):
            acc = (-1.0) ** (k + 1) / (2 * k + 1) + t2 * acc
        return t * t2 * acc
    return t - math.atan(t)


@njit(cache=True)
def energy_residual(t, A, lam):
    """Left side of Maugis' energy equation minus 1 at t = sqrt(m^2-1): -1 at t = 0, increasing to +inf."""
    m = math.sqrt(1.0 + t * t)
    at = math.atan(t)
    b1 = t_minus_atan(t) + t * t * at          # t + (m^2-2) arctan t
    b2 = t * at - t * t / (1.0 + m)            # t arctan t - m + 1
    return 0.5 * lam * A * A * b1 + 4.0 / 3.0 * lam * lam * A * b2 - 1.0


@njit(cache=True)
def t_of_A(A, lam):
    """Root t >= 0 of Maugis' energy equation at normalised contact radius A > 0 (lam > 0): the bracket [0, hi]
    with hi doubled from 1 until the residual is >= 0, then brentq (xtol 1e-300, rtol 1e-15, maxiter 500)."""
    if not (A > 0.0 and lam > 0.0 and math.isfinite(A) and math.isfinite(lam)):
        raise ValueError("Maugis' equation needs A > 0 and lambda > 0 (finite)")
    hi = 1.0
    while energy_residual(hi, A, lam) < 0.0:
        hi *= 2.0
    xpre, xcur = 0.0, hi
    fpre = energy_residual(xpre, A, lam)
    fcur = energy_residual(xcur, A, lam)
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    xblk = fblk = spre = scur = 0.0
    for _ in range(T_MAXITER):
        done, xpre, xcur, xblk, fpre, fblk, spre, scur = brent_step(xpre, xcur, xblk, fpre, fcur, fblk, spre, scur,
                                                                    T_XTOL, T_RTOL)
        if done:
            return xcur
        fcur = energy_residual(xcur, A, lam)
    raise ValueError("Maugis' equation: brentq did not converge in 500 iterations")


@njit(cache=True)
def pdt(A, lam):
    """(Pbar, Dbar, t) at normalised contact radius A for Maugis parameter lam."""
    t = t_of_A(A, lam)
    m = math.sqrt(1.0 + t * t)
    b3 = t + m * m * math.atan(t)             # t + m^2 arctan t
    return A ** 3.0 - lam * A * A * b3, A * A - 4.0 / 3.0 * lam * A * t, t


@njit(cache=True)
def solution(A, lam):
    """Arrays (Pbar, Dbar, t) over the 1-d array of normalised contact radii A."""
    n = A.size
    p, d, t = np.empty(n), np.empty(n), np.empty(n)
    for i in range(n):
        p[i], d[i], t[i] = pdt(A[i], lam)
    return p, d, t


@njit(cache=True)
def scales(radius, w, e_star):
    """(a_s, P_s, delta_s, lambda / sigma0) of `continuum.reference.maugis.md_scales` / `md_parameter` (SI)."""
    a_s = np.cbrt(3.0 * np.pi * w * radius * radius / (4.0 * e_star))
    return a_s, np.pi * w * radius, a_s * a_s / radius, np.cbrt(9.0 * radius / (2.0 * np.pi * w * e_star * e_star))


@njit(cache=True)
def force_approach(a, radius, w, e_star, sigma0):
    """(P N, delta m) of the Maugis-Dugdale contact of radius a (m) on a sphere of radius `radius` (m)."""
    a_s, p_s, d_s, per_sigma = scales(radius, w, e_star)
    p, d, _ = pdt(a / a_s, sigma0 * per_sigma)
    return p * p_s, d * d_s
