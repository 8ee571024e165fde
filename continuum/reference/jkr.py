"""Closed-form JKR reference solutions for one spherical asperity, with Fuller-Tabor hysteresis.

All quantities are SI. ``radius`` is the asperity tip radius beta (m) (the founding paper reuses R),
``work_of_adhesion`` is Dupré's Delta gamma = gamma_1 + gamma_2 - gamma_12 (J/m^2) (the paper's
"+ gamma_12" is a typo), ``e_star`` is Johnson's contact modulus (Pa), ``a`` the contact radius (m)
and ``delta`` the approach (m; negative = asperity stretched). Functions are pure NumPy and
vectorised; a 0-d result is returned as a NumPy scalar.

JKR relations (Johnson, Kendall & Roberts 1971; Johnson, *Contact Mechanics* 1985 §5.5)::

    P(a)     = 4 E* a^3 / (3 beta) - sqrt(8 pi dgamma E* a^3)
    delta(a) = a^2 / beta - sqrt(2 pi dgamma a / E*)
    P_c      = (3/2) pi beta dgamma                         (load-controlled pull-off, eq 6)
    delta_c  = (3/4) (pi^2 dgamma^2 beta / E*^2)^{1/3}       (separation under displacement
             = (1/(3 beta)) (9 beta P_c / (4 E*))^{2/3}       control; paper eq 7)

Internal nondimensionalisation (used for the exact inverse and the energy)
-------------------------------------------------------------------------
a0 = (2 pi dgamma beta^2 / E*)^{1/3} is the contact radius at zero approach, delta0 = a0^2/beta,
s = sqrt(a/a0) and d = delta/delta0. Then exactly

    d = s^4 - s,     P = pi dgamma beta (8/3 s^6 - 4 s^3),     P/P_c = 16/9 s^6 - 8/3 s^3,

delta_c = (3/4) 4^{-1/3} delta0 (the minimum of s^4 - s, at s^3 = 1/4, P = -5/9 P_c), the touch
point is s = 1 (delta = 0, P = -8/9 P_c) and the load-controlled pull-off is s^3 = 3/4
(P = -P_c, delta = -3^{-2/3} delta_c). Inverting d = s^4 - s is the depressed quartic
s^4 - s - d = 0 (u = sqrt(a): u^4 - c beta u - beta delta = 0, c = sqrt(2 pi dgamma/E*)), solved by
Ferrari's method: the resolvent cubic m^3 + d m - 1/8 = 0 has exactly one real root for
d > -delta_c/delta0 (its discriminant vanishes exactly at the fold), found by Cardano in a
cancellation-free form; then s = (w +/- sqrt(2/w - w^2))/2 with w = sqrt(2 m), "+" the stable
(larger-a) branch, "-" the unstable one; two Newton steps polish the root.

Energy along the stable branch, U(delta) = int_0^delta P d delta' (J), zero at the touch point:

    U = pi dgamma beta delta0 [16/15 s^10 - 8/3 s^7 + s^4 + 3/5]
      = pi dgamma beta delta0 (s - 1) h(s),
    h(s) = 16/15 (s^9 + s^8 + s^7) - 8/5 (s^6 + s^5 + s^4) - 3/5 (s^3 + s^2 + s + 1),

with s - 1 = d / (s (s^2 + s + 1)) evaluated without cancellation. The Fuller-Tabor loop (approach
along P = 0 up to delta = 0, jump onto the JKR curve, retreat along the stable branch to the
detachment approach) encloses U(detachment): 0.93550... P_c delta_c when detaching at -delta_c
(displacement control) and 0.46201... P_c delta_c at P = -P_c (load control).

Paper normalisations (eqs 5 and 8, as corrected in docs/paper-notes.md)
-----------------------------------------------------------------------
abar = a (4 E* / (9 pi dgamma beta^2))^{1/3} = (8/9)^{1/3} s^2;
eq 5: Pbar = P/(3 pi dgamma beta) = abar^3 - sqrt(2 abar^3),
      deltabar = delta (16 E*^2/(9 pi^2 dgamma^2 beta))^{1/3} = 3^{2/3} abar^2 (1 - (2 sqrt2/3) abar^{-3/2});
eq 8: P/P_c = 2 (abar^3 - sqrt(2 abar^3)),
      delta/delta_c = (324^{1/3}/3) abar^2 (1 - (2 sqrt2/3) abar^{-3/2}),   324^{1/3}/3 = 12^{1/3}.

Sources: K. L. Johnson, K. Kendall & A. D. Roberts, Proc. R. Soc. Lond. A 324 (1971) 301-313;
K. L. Johnson, *Contact Mechanics* (1985) §5.5; K. N. G. Fuller & D. Tabor, Proc. R. Soc. Lond.
A 345 (1975) 327-342; D. Maugis, *Contact, Adhesion and Rupture of Elastic Solids* (Springer,
2000), ch. 5 (JKR energy, normalisation and stability under load/displacement control).
"""
from __future__ import annotations

import numpy as np

from ..physics import jkr_kernel as _k

__all__ = [
    "LOOP_AREA_DISPLACEMENT",
    "LOOP_AREA_LOAD",
    "LOAD_DETACH_APPROACH_RATIO",
    "contact_radius_at_touch",
    "pull_off_force",
    "critical_approach",
    "critical_approach_eq7",
    "force_from_radius",
    "approach_from_radius",
    "energy_from_radius",
    "radius_from_approach",
    "force_from_approach",
    "stiffness_from_approach",
    "energy_from_approach",
    "touch_force",
    "critical_approach_force",
    "load_controlled_detach_approach",
    "load_controlled_detach_radius",
    "loop_area",
    "normalised_radius",
    "eq5_force",
    "eq5_approach",
    "eq8_force",
    "eq8_approach",
    "normalised_force_from_approach",
]

# The reduced-variable JKR kernel (continuum.physics.jkr_kernel): d_c = delta_c / delta0, the checked
# root of s^4 - s = d, h(s) and the energy/slope in s. This module adds the SI wrappers and named points.
_DC = _k.D_C
_solve_s = _k.solve_s
_h = _k.h_of_s


def _out(x):
    x = np.asarray(x)
    return x[()] if x.ndim == 0 else x


def _arr(*args):
    return [np.asarray(a, float) for a in args]


# ----------------------------------------------------------------------------------------------
# Scales
# ----------------------------------------------------------------------------------------------
def contact_radius_at_touch(radius, work_of_adhesion, e_star):
    """Contact radius at zero approach a0 = (2 pi dgamma beta^2 / E*)^{1/3} (m).

    radius beta (m), work_of_adhesion dgamma (J/m^2), e_star (Pa).
    """
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    return _out(np.cbrt(2.0 * np.pi * g * b * b / e))


def approach_scale(radius, work_of_adhesion, e_star):
    """delta0 = a0^2 / beta = (4 pi^2 dgamma^2 beta / E*^2)^{1/3} (m): the approach unit of the reduced curve
    delta/delta0 = s^4 - s (`continuum.physics.jkr_kernel`); delta_c = (3/4) 4^{-1/3} delta0."""
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    return _out(np.cbrt(4.0 * np.pi**2 * g * g * b / (e * e)))


def pull_off_force(radius, work_of_adhesion):
    """Load-controlled JKR pull-off force P_c = (3/2) pi beta dgamma (N) (paper eq 6).

    radius beta (m), work_of_adhesion dgamma (J/m^2).
    """
    b, g = _arr(radius, work_of_adhesion)
    return _out(1.5 * np.pi * b * g)


def critical_approach(radius, work_of_adhesion, e_star):
    """JKR separation distance under displacement control delta_c = (3/4)(pi^2 dgamma^2 beta/E*^2)^{1/3} (m).

    The stable branch ends at delta = -delta_c (P = -5/9 P_c). radius beta (m),
    work_of_adhesion dgamma (J/m^2), e_star (Pa).
    """
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    return _out(0.75 * np.cbrt(np.pi**2 * g * g * b / (e * e)))


def critical_approach_eq7(radius, work_of_adhesion, e_star):
    """delta_c in the paper's eq 7 form (1/(3 beta)) (9 beta P_c / (4 E*))^{2/3} (m); equals critical_approach."""
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    pc = 1.5 * np.pi * b * g
    return _out((9.0 * b * pc / (4.0 * e)) ** (2.0 / 3.0) / (3.0 * b))


# ----------------------------------------------------------------------------------------------
# Parametric (in a) relations
# ----------------------------------------------------------------------------------------------
def force_from_radius(a, radius, work_of_adhesion, e_star):
    """JKR load P = 4 E* a^3/(3 beta) - sqrt(8 pi dgamma E* a^3) (N) (paper eq 4).

    a: contact radius (m); radius beta (m); work_of_adhesion dgamma (J/m^2); e_star (Pa).
    Accepts complex a (for complex-step differentiation).
    """
    a = np.asarray(a)
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    return _out(4.0 * e * a**3 / (3.0 * b) - np.sqrt(8.0 * np.pi * g * e) * a * np.sqrt(a))


def approach_from_radius(a, radius, work_of_adhesion, e_star):
    """JKR approach delta = a^2/beta - sqrt(2 pi dgamma a / E*) (m).

    a (m), radius beta (m), work_of_adhesion dgamma (J/m^2), e_star (Pa). Accepts complex a.
    """
    a = np.asarray(a)
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    return _out(a * a / b - np.sqrt(2.0 * np.pi * g / e) * np.sqrt(a))


def energy_from_radius(a, radius, work_of_adhesion, e_star):
    """Energy U = int_0^delta(a) P d delta' (J) along the JKR curve, zero at the touch point a = a0.

    U = pi dgamma beta delta0 (s - 1) h(s), s = sqrt(a/a0) (see module docstring). On the stable
    branch (a >= 4^{-2/3} a0, i.e. s^3 >= 1/4) this equals energy_from_approach. a (m), radius beta (m),
    work_of_adhesion dgamma (J/m^2), e_star (Pa). Accepts complex a.
    """
    a = np.asarray(a)
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    a0 = np.cbrt(2.0 * np.pi * g * b * b / e)
    d0 = a0 * a0 / b
    s = np.sqrt(a / a0)
    sm1 = (a - a0) / (a0 * (s + 1.0))
    return _out(np.pi * g * b * d0 * sm1 * _h(s))


# ----------------------------------------------------------------------------------------------
# Exact inverse: s^4 - s - d = 0 by Ferrari / Cardano (continuum.physics.jkr_kernel.solve_s)
# ----------------------------------------------------------------------------------------------
def radius_from_approach(delta, radius, work_of_adhesion, e_star, branch="stable"):
    """Contact radius a (m) at approach delta (m), the exact inverse of approach_from_radius.

    Solves u^4 - c beta u - beta delta = 0 (u = sqrt(a), c = sqrt(2 pi dgamma/E*)) in closed form
    (Ferrari's resolvent cubic, Cardano) plus at most two Newton polishing steps.
    branch="stable": the larger root, valid for delta >= -delta_c; branch="unstable": the smaller
    root, valid for -delta_c <= delta <= 0. Raises ValueError outside these ranges.
    radius beta (m), work_of_adhesion dgamma (J/m^2), e_star (Pa).
    """
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    d0 = approach_scale(b, g, e)
    a0 = np.cbrt(2.0 * np.pi * g * b * b / e)
    s, _ = _solve_s(np.asarray(delta, float) / d0, branch)
    return _out(a0 * s * s)


def force_from_approach(delta, radius, work_of_adhesion, e_star, branch="stable"):
    """JKR load P (N) at approach delta (m) on the chosen branch (see radius_from_approach).

    P = (pi dgamma beta)(8/3 s^6 - 4 s^3) with s = sqrt(a/a0). radius beta (m),
    work_of_adhesion dgamma (J/m^2), e_star (Pa).
    """
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    s, _ = _solve_s(np.asarray(delta, float) / approach_scale(b, g, e), branch)
    s3 = s**3
    return _out(np.pi * g * b * s3 * (8.0 / 3.0 * s3 - 4.0))


def stiffness_from_approach(delta, radius, work_of_adhesion, e_star, branch="stable"):
    """Tangent stiffness dP/d delta = (dP/da)/(d delta/da) (N/m) on the chosen branch.

    = (pi dgamma beta / delta0) 4 s^2 (4 s^3 - 3)/(4 s^3 - 1). At delta = -delta_c (the fold,
    d delta/da = 0) the stiffness is infinite: returns -np.inf on the stable branch (its limit
    there: dP/d delta < 0 for -delta_c < delta < the P = -P_c point) and +np.inf on the unstable one.
    "At -delta_c" means within 16 eps above it (the rounding of critical_approach, either side of
    the exact fold) or up to 1e-12 below it; just outside, |dP/d delta| ~ 0.4714 P_c/delta_c /
    sqrt(delta/delta_c + 1) is large but finite. radius beta (m), work_of_adhesion dgamma (J/m^2),
    e_star (Pa).
    """
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    d0 = approach_scale(b, g, e)
    s, at_fold = _solve_s(np.asarray(delta, float) / d0, branch)
    s3 = s**3
    den = 4.0 * s3 - 1.0
    at_fold = at_fold | ((den <= 0.0) if branch == "stable" else (den >= 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        k = _k.stiffness_of_s(s, s3, np.pi * g * b / d0)
    # Both branches meet at the fold with a vertical tangent: dP/d delta -> -inf along the stable
    # branch (P rises from -P_c to -5/9 P_c as delta falls to -delta_c), +inf along the unstable one.
    sign = -1.0 if branch == "stable" else 1.0
    return _out(np.where(at_fold, sign * np.inf, k))


def energy_from_approach(delta, radius, work_of_adhesion, e_star):
    """Energy U(delta) = int_0^delta P d delta' (J) along the stable branch, U(0) = 0.

    Closed form in s = sqrt(a/a0): U = pi dgamma beta delta0 (s - 1) h(s), with s - 1 taken as
    d/(s(s^2 + s + 1)) so that small |delta| keeps full relative precision. Valid for
    delta >= -delta_c. U > 0 for delta < 0 (stretching against P < 0); for small delta > 0, U < 0
    (P is still tensile) and U turns positive only once the contact is compressive enough.
    radius beta (m), work_of_adhesion dgamma (J/m^2), e_star (Pa).
    """
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    d0 = approach_scale(b, g, e)
    dn = np.asarray(delta, float) / d0
    s, _ = _solve_s(dn, "stable")
    return _out(_k.energy_of_s(np.maximum(dn, -_DC), s, np.pi * g * b * d0))


# ----------------------------------------------------------------------------------------------
# Named points
# ----------------------------------------------------------------------------------------------
def touch_force(radius, work_of_adhesion):
    """JKR load at zero approach P(delta = 0) = -(8/9) P_c = -(4/3) pi beta dgamma (N).

    radius beta (m), work_of_adhesion dgamma (J/m^2).
    """
    b, g = _arr(radius, work_of_adhesion)
    return _out(-4.0 / 3.0 * np.pi * b * g)


def critical_approach_force(radius, work_of_adhesion):
    """JKR load at the displacement-controlled separation P(-delta_c) = -(5/9) P_c (N).

    radius beta (m), work_of_adhesion dgamma (J/m^2).
    """
    b, g = _arr(radius, work_of_adhesion)
    return _out(-5.0 / 6.0 * np.pi * b * g)


def load_controlled_detach_radius(radius, work_of_adhesion, e_star):
    """Contact radius at P = -P_c (load-controlled pull-off), a = (9 pi dgamma beta^2/(8 E*))^{1/3} (m)."""
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    return _out(np.cbrt(9.0 * np.pi * g * b * b / (8.0 * e)))


def load_controlled_detach_approach(radius, work_of_adhesion, e_star):
    """Approach at P = -P_c (m): delta = -3^{-2/3} delta_c = -0.4807... delta_c (exact, from s^3 = 3/4).

    radius beta (m), work_of_adhesion dgamma (J/m^2), e_star (Pa).
    """
    a = load_controlled_detach_radius(radius, work_of_adhesion, e_star)
    return approach_from_radius(a, radius, work_of_adhesion, e_star)


#: delta / delta_c at the load-controlled pull-off, -3^{-2/3}, from the exact point s^3 = 3/4.
LOAD_DETACH_APPROACH_RATIO = float(
    (0.75 ** (4.0 / 3.0) - 0.75 ** (1.0 / 3.0)) / _DC
)


def _loop_coefficient(s):
    """U(s)/(P_c delta_c) for a stable-branch point s (dimensionless)."""
    d = s**4 - s
    # pi dgamma beta delta0 / (P_c delta_c) = (2/3) / d_c
    return float((2.0 / 3.0) / _DC * _k.s_minus_one(d, s) * _h(np.float64(s)))


#: Fuller-Tabor loop area / (P_c delta_c), detachment at -delta_c (displacement control): 0.93550...
LOOP_AREA_DISPLACEMENT = _loop_coefficient(4.0 ** (-1.0 / 3.0))
#: Fuller-Tabor loop area / (P_c delta_c), detachment at P = -P_c (load control): 0.46201...
LOOP_AREA_LOAD = _loop_coefficient(0.75 ** (1.0 / 3.0))


def loop_area(radius, work_of_adhesion, e_star, detachment="displacement"):
    """Energy lost per approach-retreat cycle of one asperity (J), Fuller-Tabor hysteresis.

    = int_{delta_d}^0 (-P) d delta on the stable branch = U(delta_d), with detachment approach
    delta_d = -delta_c (detachment="displacement") or the P = -P_c point (detachment="load").
    Equals LOOP_AREA_DISPLACEMENT or LOOP_AREA_LOAD times P_c delta_c.
    radius beta (m), work_of_adhesion dgamma (J/m^2), e_star (Pa).
    """
    if detachment == "displacement":
        coef = LOOP_AREA_DISPLACEMENT
    elif detachment == "load":
        coef = LOOP_AREA_LOAD
    else:
        raise ValueError(f"detachment = {detachment!r}: must be 'displacement' or 'load'")
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    return _out(coef * 1.5 * np.pi * b * g * 0.75 * np.cbrt(np.pi**2 * g * g * b / (e * e)))


# ----------------------------------------------------------------------------------------------
# Paper normalisations (eqs 5 and 8, corrected)
# ----------------------------------------------------------------------------------------------
def normalised_radius(a, radius, work_of_adhesion, e_star):
    """abar = a (4 E* / (9 pi dgamma beta^2))^{1/3} (dimensionless). a (m), radius beta (m),
    work_of_adhesion dgamma (J/m^2), e_star (Pa)."""
    a = np.asarray(a, float)
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    return _out(a * np.cbrt(4.0 * e / (9.0 * np.pi * g * b * b)))


def eq5_force(abar):
    """Paper eq 5: Pbar = P/(3 pi dgamma beta) = abar^3 - sqrt(2 abar^3) (dimensionless)."""
    abar = np.asarray(abar, float)
    return _out(abar**3 - np.sqrt(2.0 * abar**3))


def eq5_approach(abar):
    """Paper eq 5 (exponent corrected): deltabar = delta (16 E*^2/(9 pi^2 dgamma^2 beta))^{1/3}
    = 3^{2/3} abar^2 (1 - (2 sqrt2/3) abar^{-3/2}) (dimensionless)."""
    abar = np.asarray(abar, float)
    return _out(3.0 ** (2.0 / 3.0) * (abar**2 - 2.0 * np.sqrt(2.0) / 3.0 * np.sqrt(abar)))


def eq8_force(abar):
    """Paper eq 8: P/P_c = 2 (abar^3 - sqrt(2 abar^3)) (dimensionless)."""
    return _out(2.0 * np.asarray(eq5_force(abar)))


def eq8_approach(abar):
    """Paper eq 8: delta/delta_c = (324^{1/3}/3) abar^2 (1 - (2 sqrt2/3) abar^{-3/2}) (dimensionless);
    324^{1/3}/3 = 12^{1/3} = 2.289..."""
    abar = np.asarray(abar, float)
    return _out(np.cbrt(324.0) / 3.0 * (abar**2 - 2.0 * np.sqrt(2.0) / 3.0 * np.sqrt(abar)))


def normalised_force_from_approach(delta_over_delta_c, branch="stable"):
    """P/P_c as a function of delta/delta_c (paper eq 8's "Pbar = fn(deltabar)"), exact.

    Two branches exist for -1 <= delta/delta_c <= 0: the stable (larger-a) one, used by the
    contact law, and the unstable one (e.g. at delta = -0.5 delta_c: -0.9998 P_c stable,
    -0.036 P_c unstable). Root-finding: the closed-form quartic inverse of radius_from_approach,
    in the variable s with d = (delta/delta_c) d_c, d_c = (3/4) 4^{-1/3}. Raises ValueError for
    delta/delta_c < -1 (and > 0 on the unstable branch).
    """
    x = np.asarray(delta_over_delta_c, float)
    s, _ = _solve_s(x * _DC, branch)
    s3 = s**3
    return _out(s3 * (16.0 / 9.0 * s3 - 8.0 / 3.0))
