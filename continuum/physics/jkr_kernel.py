"""The JKR kernel: one sphere's JKR curve in the reduced variable s = sqrt(a/a0), pure functions.

Every JKR evaluation of the project goes through this module: the closed-form reference
(`continuum.reference.jkr`, with argument checks and SI wrappers), the sphere law
(`continuum.laws.jkr`), the discrete summits (`continuum.laws.discrete_roller`) and the GW tables
(`continuum.rough.summits`, `continuum.rough.gw`). The derivation is written out in
`continuum.reference.jkr`'s docstring; in short, with a0 = (2 pi dgamma beta^2/E*)^{1/3},
delta0 = a0^2/beta, s = sqrt(a/a0) and d = delta/delta0::

    d = s^4 - s,   P = pi dgamma beta (8/3 s^6 - 4 s^3),
    dP/d delta = (pi dgamma beta/delta0) 4 s^2 (4 s^3 - 3)/(4 s^3 - 1),
    U = pi dgamma beta delta0 (s - 1) h(s),   s - 1 = d/(s (s^2 + s + 1)),
    h(s) = 16/15 (s^9 + s^8 + s^7) - 8/5 (s^6 + s^5 + s^4) - 3/5 (s^3 + s^2 + s + 1),

delta_c = D_C delta0 (the fold, s = S_FOLD), P = -P_c at s = S_LOAD, P = 0 at s = S_ZERO. The stable
root of s^4 - s = d comes in two evaluations of the same closed form (Ferrari's resolvent cubic by
Cardano): `solve_s`, checked and polished twice (the reference), and `stable_root` /
`stable_root_scalar`, unchecked with one polish, written in place for the discrete summits' hot loop (the
scalar one also serves the sphere law, `continuum.laws.jkr`). Each keeps its own order of operations.

Compiled forms: `stable_root_scalar` is compiled as it stands for the compiled discrete summits
(`continuum.numerics.kernel_laws._jkr_root`); the GW tables' numba kernel carries `solve_s`'s stable branch
and `reduced_curve_minus_hertz` in scalar form (`continuum.rough.gw_kernel._stable_s`, `_curve_minus_hertz`).
`tests/continuum/test_jkr_forms.py` compares every form with the others over the branch and with JKR's
closed-form pull-off and zero-load contact radius.
"""
from __future__ import annotations

import math

import numpy as np

#: delta_c / delta0 = (3/4) 4^{-1/3}: the fold of the stable branch (displacement-controlled release).
D_C = 0.75 * 4.0 ** (-1.0 / 3.0)
#: s at the fold (delta = -delta_c, P = -5/9 P_c).
S_FOLD = 4.0 ** (-1.0 / 3.0)
#: s at the load-controlled pull-off (P = -P_c).
S_LOAD = 0.75 ** (1.0 / 3.0)
#: s where the stable branch changes sign (P = 0).
S_ZERO = 1.5 ** (1.0 / 3.0)
#: Horner coefficients of h(s) = U / (pi dgamma beta delta0 (s - 1)).
H_COEF = (16.0 / 15.0, 16.0 / 15.0, 16.0 / 15.0, -1.6, -1.6, -1.6, -0.6, -0.6, -0.6, -0.6)
#: Relative slack for d slightly below -D_C (rounding in the caller's delta_c).
FOLD_RTOL = 1e-12
#: Band above -D_C that is the fold itself for the stiffness: delta = -critical_approach(...) lands
#: within about 2 eps of -D_C on either side (critical_approach and delta0 are rounded separately;
#: measured +-1.6 eps over 2e5 random parameter sets), so "at -delta_c" must not depend on which side
#: rounding puts it. 16 eps keeps a margin; the double root is unresolvable there anyway (s is only
#: good to sqrt(eps)).
FOLD_SNAP = 16.0 * np.finfo(float).eps


# ------------------------------------------------------------------------------------ energy and slope
def h_of_s(s):
    """h(s) = g(s)/(s - 1) with g = 16/15 s^10 - 8/3 s^7 + s^4 + 3/5 (Horner); a float stays a float."""
    acc = H_COEF[0] if isinstance(s, float) else np.zeros_like(s) + H_COEF[0]
    for ck in H_COEF[1:]:
        acc = acc * s + ck
    return acc


def s_minus_one(d, s):
    """s - 1 on the curve d = s^4 - s, as d/(s (s^2 + s + 1)) (no cancellation near the touch point)."""
    return d / (s * (s * s + s + 1.0))


def energy_of_s(d, s, scale):
    """U (J) at reduced approach d and root s; `scale` = pi dgamma beta delta0 (J)."""
    return scale * s_minus_one(d, s) * h_of_s(s)


def stiffness_of_s(s, s3, scale):
    """dP/d delta (N/m) at root s (s3 = s^3 as the caller computed it), the raw quotient: infinite or nan
    at the fold, which the caller marks; `scale` = pi dgamma beta / delta0 (N/m). Evaluate under
    np.errstate(divide='ignore', invalid='ignore')."""
    return scale * 4.0 * s * s * (4.0 * s3 - 3.0) / (4.0 * s3 - 1.0)


# ------------------------------------------------------------------------------------ the stable root
def solve_s(d, branch):
    """Roots s >= 0 of s^4 - s = d, checked. Returns (s, at_fold) arrays.

    branch 'stable': larger root, d >= -D_C; 'unstable': smaller root, -D_C <= d <= 0.
    Raises ValueError outside these ranges (d below the fold by more than FOLD_RTOL).
    """
    d = np.asarray(d, float)
    if branch not in ("stable", "unstable"):
        raise ValueError(f"branch = {branch!r}: must be 'stable' or 'unstable'")
    if np.any(~np.isfinite(d)):
        raise ValueError("approach must be finite")
    below = d < -D_C * (1.0 + FOLD_RTOL)
    if np.any(below):
        raise ValueError(
            "approach below -delta_c (the JKR separation distance, critical_approach): no JKR "
            f"contact exists there (min delta/delta_c = {float(np.min(d)) / D_C:.12g} < -1)"
        )
    if branch == "unstable" and np.any(d > 0.0):
        raise ValueError("the unstable JKR branch exists only for -delta_c <= delta <= 0")
    d = np.maximum(d, -D_C)
    # At the fold the resolvent's discriminant 1/256 + d^3/27 vanishes, but not in floating point
    # (D_C**3/27 is not exactly 1/256): decide "at the fold" on d itself, within FOLD_SNAP.
    at_fold = d <= -D_C * (1.0 - FOLD_SNAP)
    # resolvent cubic m^3 + d m - 1/8 = 0: C^3 = 1/16 + sqrt(1/256 + d^3/27), D = -d/(3C),
    # m = C + D = (C^3 + D^3)/(C^2 - C D + D^2) = (1/8)/(C^2 + d/3 + D^2).
    rad = np.maximum(1.0 / 256.0 + d**3 / 27.0, 0.0)
    cc = np.cbrt(1.0 / 16.0 + np.sqrt(rad))
    dd = -d / (3.0 * cc)
    m = 0.125 / (cc * cc + d / 3.0 + dd * dd)
    w = np.sqrt(2.0 * m)
    disc = np.sqrt(np.maximum(2.0 / w - w * w, 0.0))
    sign = 1.0 if branch == "stable" else -1.0
    s = 0.5 * (w + sign * disc)
    if branch == "unstable":
        # small root: s (1 - s^3) = -d, so s = -d / (1 - s^3) avoids the cancellation in w - disc.
        s = np.where(d < 0.0, -d / (1.0 - np.minimum(s, S_FOLD) ** 3), 0.0)
    # Newton polish on f(s) = s^4 - s - d, keeping a step only if it lowers |f| and stays on branch.
    for _ in range(2):
        f = s**4 - s - d
        fp = 4.0 * s**3 - 1.0
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            s_new = s - f / fp
            ok = np.isfinite(s_new) & (np.abs(s_new**4 - s_new - d) <= np.abs(f))
        ok &= (s_new >= S_FOLD) if branch == "stable" else ((s_new <= S_FOLD) & (s_new >= 0.0))
        s = np.where(ok, s_new, s)
    return s, at_fold


def stable_root(d):
    """Stable-branch s for reduced approaches `d` (a float array, clamped to >= -D_C in place), unchecked.

    The closed form of `solve_s` in place, with one Newton polish away from the fold (where the root
    is double): the discrete summits' hot loop, where the history rule never asks below the fold."""
    np.maximum(d, -D_C, out=d)
    t = d * d
    t *= d
    t *= 1.0 / 27.0
    t += 1.0 / 256.0
    np.maximum(t, 0.0, out=t)
    np.sqrt(t, out=t)
    t += 1.0 / 16.0
    cc = np.cbrt(t)                                   # Cardano: C
    dd = d / cc
    dd *= -1.0 / 3.0                                  # D = -d/(3C)
    den = cc * cc
    den += d * (1.0 / 3.0)
    dd *= dd
    den += dd
    w2 = 0.25 / den                                   # w^2 = 2m, m = (1/8)/(C^2 + d/3 + D^2)
    w = np.sqrt(w2)
    t = 2.0 / w
    t -= w2
    np.maximum(t, 0.0, out=t)
    np.sqrt(t, out=t)
    s = w
    s += t
    s *= 0.5                                          # stable (larger) root
    s3 = s * s * s
    fp = 4.0 * s3 - 1.0
    f = s3 * s
    f -= s
    f -= d
    step = np.zeros_like(s)
    np.divide(f, fp, out=step, where=fp > 1e-3)       # one Newton polish away from the fold
    s -= step
    return s


def stable_force_in_place(s, scale):
    """P (N) at roots `s` (array), scale = pi dgamma beta (N): ((8/3 s^3 - 4) s^3) scale, in new storage."""
    s3 = s * s * s
    force = 8.0 / 3.0 * s3
    force -= 4.0
    force *= s3
    force *= scale
    return force


def stable_root_scalar(d: float) -> tuple[float, float]:
    """(d clamped to >= -D_C, stable s) for one reduced approach: `stable_root` in scalar arithmetic.

    Plain float arithmetic that numba compiles as written (`continuum.numerics.kernel_laws._jkr_root`)."""
    d = max(d, -D_C)
    cc = math.cbrt(1.0 / 16.0 + math.sqrt(max(1.0 / 256.0 + d * d * d / 27.0, 0.0)))
    dd = -d / (3.0 * cc)
    w = math.sqrt(0.25 / (cc * cc + d / 3.0 + dd * dd))
    s = 0.5 * (w + math.sqrt(max(2.0 / w - w * w, 0.0)))
    s3 = s * s * s
    fp = 4.0 * s3 - 1.0
    if fp > 1e-3:
        s -= (s3 * s - s - d) / fp
    return d, s


# ------------------------------------------------------------------------------------ in units of the pull-off
def x_of_s(s):
    """delta/delta_c."""
    return (s**4 - s) / D_C


def dx_ds(s):
    """d(delta/delta_c)/ds."""
    return (4.0 * s**3 - 1.0) / D_C


def reduced_curve(s):
    """(P/P_c, U/(P_c delta_c), a^2/(beta delta_c)) on the JKR curve at s (stacked)."""
    s3 = s**3
    s4 = s3 * s
    f = s3 * (16.0 / 9.0 * s3 - 8.0 / 3.0)
    u = (2.0 / 3.0) / D_C * (((16.0 / 15.0 * s3 - 8.0 / 3.0) * s3 + 1.0) * s4 + 0.6)
    return np.stack([f, u, s4 / D_C])


def reduced_curve_minus_hertz(s):
    """JKR minus Hertz (same units as `reduced_curve`) for compressed summits, s >= 1; cancellation-free force."""
    s3 = s**3
    s15 = s * np.sqrt(s)
    c = np.maximum(s3 - 1.0, 0.0)
    x = x_of_s(s)
    fh = 16.0 / 9.0 * (x * D_C) ** 1.5
    gf = 16.0 / 9.0 * s15 * (3.0 * s3 * s3 - 3.0 * s3 + 1.0) / (s15**3 + c * np.sqrt(c)) - 8.0 / 3.0 * s3
    q = reduced_curve(s)
    return np.stack([gf, q[1] - 0.4 * x * fh, s / D_C])


def reduced_curve_minus_hertz_slopes(s, x):
    """d/dx of `reduced_curve_minus_hertz` at s (x = delta/delta_c, as the caller has it): [d(f - f_H)/dx,
    d(u - u_H)/dx = f - f_H, d(a^2/(beta delta_c) - its Hertz value)/dx]."""
    s3 = s**3
    gp = [8.0 * s * s * (4.0 / 3.0 * s3 - 1.0) * D_C / (4.0 * s3 - 1.0)
          - 8.0 / 3.0 * D_C**1.5 * np.sqrt(x),
          None, 1.0 / (4.0 * s3 - 1.0)]
    gp[1] = reduced_curve_minus_hertz(s)[0]
    return gp
