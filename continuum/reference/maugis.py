"""DMT and Maugis-Dugdale reference solutions for one spherical asperity.

All quantities are SI. ``radius`` is the asperity tip radius beta (m), ``work_of_adhesion`` is
Dupre's Delta gamma (J/m^2), ``e_star`` is Johnson's contact modulus E* (Pa), ``sigma0`` the
Dugdale cohesive stress (Pa), ``a`` the contact radius (m), ``delta`` the approach (m; negative =
asperity stretched). K = 4 E*/3 is Maugis' modulus (it appears only in the stated conversions).

DMT (Derjaguin, Muller & Toporov 1975; Maugis 2000 §5)
------------------------------------------------------
Hertz deformation plus the adhesive force of a rigid sphere just touching, for delta >= 0:

    P(delta) = (4/3) E* sqrt(beta) delta^{3/2} - 2 pi beta dgamma,    pull-off 2 pi beta dgamma.

It has no hysteresis (no jump in, no jump out: the contact radius shrinks continuously to zero).

Maugis-Dugdale (Maugis, J. Colloid Interface Sci. 150 (1992) 243; Johnson & Greenwood,
J. Colloid Interface Sci. 192 (1997) 326)
----------------------------------------------------------------------------------------------
Attraction is a constant tensile stress sigma0 acting where the gap is below h0, with
dgamma = sigma0 h0. The contact has radius a and the cohesive zone extends to c = m a, m >= 1.
Dimensional equations (Johnson & Greenwood 1997, Johnson's E*):

    P     = 4 E* a^3/(3 beta) - 2 sigma0 a^2 [sqrt(m^2-1) + m^2 arctan sqrt(m^2-1)]
    delta = a^2/beta - (2 sigma0 a / E*) sqrt(m^2-1)
    dgamma = (sigma0 a^2/(pi beta)) [sqrt(m^2-1) + (m^2-2) arctan sqrt(m^2-1)]
             + (4 sigma0^2 a/(pi E*)) [sqrt(m^2-1) arctan sqrt(m^2-1) - m + 1]

(the last is "gap at r = c equals h0"). Normalisation (Maugis 1992) gives the parametric
equations::

    A      = a     / (pi dgamma beta^2 / K)^{1/3} = a (4 E*/(3 pi dgamma beta^2))^{1/3}
    Pbar   = P     / (pi dgamma beta)
    Dbar   = delta / (pi^2 dgamma^2 beta / K^2)^{1/3} = delta (16 E*^2/(9 pi^2 dgamma^2 beta))^{1/3}
    lambda = 2 sigma0 (beta/(pi dgamma K^2))^{1/3} = sigma0 (9 beta/(2 pi dgamma E*^2))^{1/3}

    (lambda A^2/2)[t + (m^2-2) arctan t] + (4 lambda^2 A/3)[t arctan t - m + 1] = 1,  t = sqrt(m^2-1)
    Pbar = A^3 - lambda A^2 [t + m^2 arctan t]
    Dbar = A^2 - (4/3) lambda A t

Derivation of the constants: Pbar A^3-term = K a^3/(pi dgamma beta^2) * ... requires
a_scale^3 = pi dgamma beta^2/K; the adhesive force 2 sigma0 a^2 [...] equals pi dgamma beta
lambda A^2 [...] iff lambda = 2 sigma0 (beta/(pi dgamma K^2))^{1/3}; delta's a^2/beta term fixes
delta_scale = a_scale^2/beta = (pi^2 dgamma^2 beta/K^2)^{1/3}, and then (4/3) lambda A t in delta
units is (4/3)(3/2) sigma0 a t / E* = 2 sigma0 a t/E* as required; the energy equation's terms are
(lambda A^2/2) = sigma0 a^2/(pi dgamma beta) and 4 lambda^2 A/3 = 4 sigma0^2 a/(pi dgamma E*).
NOTE: lambda = 2 sigma0 (beta/(pi dgamma E*^2))^{1/3} (i.e. with E* in place of K) is NOT the same
number: it is (16/9)^{1/3} = 1.2114 times larger. Johnson & Greenwood's form
sigma0 (9 beta/(2 pi dgamma E*^2))^{1/3} is the one that agrees with Maugis' K form, and gives
lambda = 1.16 mu (Tabor) for sigma0 = 1.03 dgamma/z0.

Limits confirming the scales: lambda -> inf gives m -> 1 with lambda t -> sqrt(3/(2A)), hence
Pbar = A^3 - sqrt(6 A^3), Dbar = A^2 - sqrt(8A/3), which is exactly JKR (P = 4E*a^3/(3beta) -
sqrt(8 pi dgamma E* a^3), delta = a^2/beta - sqrt(2 pi dgamma a/E*)) in these units, minimum
Pbar = -3/2. lambda -> 0 gives m -> inf with m A -> 2/sqrt(pi lambda) and Pbar -> A^3 - 2, DMT
(Dbar -> A^2 - (8/3) sqrt(lambda/pi), so the approach converges only like sqrt(lambda)).
As A -> 0 at fixed lambda, m A -> C with (pi lambda/4) C^2 + (4 lambda^2/3)(pi/2 - 1) C = 1 and
Pbar -> -(pi lambda/2) C^2, Dbar -> -(4/3) lambda C (-> -2 and 0 as lambda -> 0). The
load-controlled pull-off (minimum of Pbar) lies at A > 0, slightly below this end value.

Root-finding is done in t = sqrt(m^2-1) >= 0, with t - arctan t by series for small t and
1 - m = -t^2/(1 + m), so that the large-lambda (t -> 0) limit keeps full precision. The root is compiled
(`continuum.reference.maugis_kernel`: scipy's brentq algorithm step for step, same bracket and tolerances); the scipy
form stays here as its reference (`_t_of_A_scipy`, `_pdt_scipy`; the two agree to a few ulp, the difference of
NumPy's and libm's arctan).
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from . import maugis_kernel as _k

__all__ = [
    "dmt_force_from_approach",
    "dmt_pull_off_force",
    "md_parameter",
    "md_scales",
    "md_m_of_A",
    "md_force_and_approach",
    "md_curve",
    "md_pull_off_force",
]


def _out(x):
    x = np.asarray(x)
    return x[()] if x.ndim == 0 else x


def _arr(*args):
    return [np.asarray(a, float) for a in args]


# ----------------------------------------------------------------------------------------------
# DMT
# ----------------------------------------------------------------------------------------------
def dmt_pull_off_force(radius, work_of_adhesion):
    """DMT pull-off force 2 pi beta dgamma (N). radius beta (m), work_of_adhesion dgamma (J/m^2)."""
    b, g = _arr(radius, work_of_adhesion)
    return _out(2.0 * np.pi * b * g)


def dmt_force_from_approach(delta, radius, work_of_adhesion, e_star):
    """DMT load P = (4/3) E* sqrt(beta) delta^{3/2} - 2 pi beta dgamma (N), for delta >= 0 (m).

    Hertz deformation (a = sqrt(beta delta)) plus the constant adhesive force. Out of contact
    (delta < 0) the force depends on the range of the attraction, which DMT does not specify:
    raises ValueError. radius beta (m), work_of_adhesion dgamma (J/m^2), e_star (Pa).
    """
    d = np.asarray(delta, float)
    if np.any(~(d >= 0.0)):
        raise ValueError("DMT force is defined only in contact, delta >= 0")
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    return _out(4.0 / 3.0 * e * np.sqrt(b) * d**1.5 - 2.0 * np.pi * b * g)


# ----------------------------------------------------------------------------------------------
# Maugis-Dugdale
# ----------------------------------------------------------------------------------------------
def md_parameter(radius, work_of_adhesion, e_star, sigma0):
    """Maugis' transition parameter lambda = sigma0 (9 beta/(2 pi dgamma E*^2))^{1/3}
    = 2 sigma0 (beta/(pi dgamma K^2))^{1/3}, K = 4E*/3 (dimensionless).

    radius beta (m), work_of_adhesion dgamma (J/m^2), e_star E* (Pa), sigma0 (Pa).
    """
    b, g, e, s = _arr(radius, work_of_adhesion, e_star, sigma0)
    return _out(s * np.cbrt(9.0 * b / (2.0 * np.pi * g * e * e)))


def md_scales(radius, work_of_adhesion, e_star):
    """Scales (a_s, P_s, delta_s) with A = a/a_s, Pbar = P/P_s, Dbar = delta/delta_s:
    a_s = (3 pi dgamma beta^2/(4 E*))^{1/3} (m), P_s = pi dgamma beta (N),
    delta_s = a_s^2/beta = (9 pi^2 dgamma^2 beta/(16 E*^2))^{1/3} (m)."""
    b, g, e = _arr(radius, work_of_adhesion, e_star)
    a_s = np.cbrt(3.0 * np.pi * g * b * b / (4.0 * e))
    return _out(a_s), _out(np.pi * g * b), _out(a_s * a_s / b)


def _t_minus_atan(t):
    """t - arctan t without cancellation (series for t < 0.1, 12 terms: error < 1e-26 t^3)."""
    if t < 0.1:
        # t^3 (1/3 - t^2/5 + t^4/7 - ...), Horner in t^2
        t2 = t * t
        acc = 0.0
        for k in range(12, 0, -1):
            acc = (-1.0) ** (k + 1) / (2 * k + 1) + t2 * acc
        return t * t2 * acc
    return t - np.arctan(t)


def _brackets(t):
    """Return (m, atan t, B1, B2, B3) with
    B1 = t + (m^2-2) arctan t, B2 = t arctan t - m + 1, B3 = t + m^2 arctan t."""
    m = np.sqrt(1.0 + t * t)
    at = np.arctan(t)
    b1 = _t_minus_atan(t) + t * t * at          # t - at + t^2 at
    b2 = t * at - t * t / (1.0 + m)
    b3 = t + m * m * at
    return m, at, b1, b2, b3


def _energy_residual(t, A, lam):
    _, _, b1, b2, _ = _brackets(t)
    return 0.5 * lam * A * A * b1 + 4.0 / 3.0 * lam * lam * A * b2 - 1.0


def _check(A, lam):
    if not (np.all(A > 0.0) and np.all(np.isfinite(A)) and lam > 0.0 and np.isfinite(lam)):
        bad = A[~((A > 0.0) & np.isfinite(A))]
        got = f"A={float(bad.flat[0])!r}" if bad.size else "every A valid"
        raise ValueError(f"need finite A > 0 and lambda > 0 (got {got}, lambda={lam!r})")


def _t_of_A_scipy(A, lam):
    """Root t = sqrt(m^2-1) >= 0 of the Maugis energy equation (scalar A > 0, lam > 0) by scipy's brentq: the
    reference form of the compiled root (`continuum.reference.maugis_kernel.t_of_A`), kept for its test."""
    _check(np.asarray(A, float), lam)
    # residual(0) = -1 and it increases monotonically to +inf: expand the bracket.
    hi = 1.0
    while _energy_residual(hi, A, lam) < 0.0:
        hi *= 2.0
    return brentq(_energy_residual, 0.0, hi, args=(A, lam), xtol=_k.T_XTOL, rtol=_k.T_RTOL, maxiter=_k.T_MAXITER)


def _pdt_scipy(A, lam):
    """(Pbar, Dbar, t) at scalar A from `_t_of_A_scipy`: the reference form of `maugis_kernel.pdt`."""
    t = _t_of_A_scipy(A, lam)
    _, _, _, _, b3 = _brackets(t)
    return A**3 - lam * A * A * b3, A * A - 4.0 / 3.0 * lam * A * t, t


def _solve(A, lam):
    """(Pbar, Dbar, t) arrays shaped like A from the compiled root (`maugis_kernel.solution`)."""
    A = np.asarray(A, float)
    lam = float(lam)
    _check(A, lam)
    p, d, t = _k.solution(np.ascontiguousarray(A).ravel(), lam)
    return p.reshape(A.shape), d.reshape(A.shape), t.reshape(A.shape)


def _pd(A, lam):
    p, d, _ = _k.pdt(float(A), float(lam))
    return p, d


def md_m_of_A(A, lam):
    """m = c/a >= 1 solving Maugis' equation
    (lam A^2/2)[t + (m^2-2) arctan t] + (4 lam^2 A/3)[t arctan t - m + 1] = 1, t = sqrt(m^2-1).

    A: normalised contact radius (> 0), lam: Maugis parameter (> 0). Vectorised over A; by brentq
    in t (for large lambda m - 1 is small: use md_force_and_approach, which works in t).
    """
    _, _, t = _solve(A, lam)
    return _out(np.sqrt(1.0 + t * t))


def md_force_and_approach(A, lam):
    """Normalised (Pbar, Dbar) at normalised contact radius A > 0 for Maugis parameter lam > 0:
    Pbar = A^3 - lam A^2 [t + m^2 arctan t], Dbar = A^2 - (4/3) lam A t, t = sqrt(m^2-1).

    Pbar = P/(pi dgamma beta), Dbar = delta/(9 pi^2 dgamma^2 beta/(16 E*^2))^{1/3} (see md_scales).
    """
    p, d, _ = _solve(A, lam)
    return _out(p), _out(d)


def md_solution(A, lam):
    """(Pbar, Dbar, m) at normalised contact radii A > 0: `md_force_and_approach` and `md_m_of_A` from one root of
    Maugis' equation per A (the same numbers; a tabulated summit law needs all three at ~2000 radii)."""
    p, d, t = _solve(A, lam)
    return _out(p), _out(d), _out(np.sqrt(1.0 + t * t))


def md_curve(radius, work_of_adhesion, e_star, sigma0, n=200, A_min=1e-3, A_max=3.0):
    """Maugis-Dugdale curve: arrays (a, P, delta) in SI (m, N, m) for n normalised contact radii
    A spaced quadratically in [A_min, A_max] (denser at small A, where the curve turns).

    radius beta (m), work_of_adhesion dgamma (J/m^2), e_star (Pa), sigma0 (Pa); h0 = dgamma/sigma0.
    Both the stable and the unstable parts are returned (the caller selects by dP/d delta).
    """
    lam = float(md_parameter(radius, work_of_adhesion, e_star, sigma0))
    u = np.linspace(0.0, 1.0, int(n))
    A = A_min + (A_max - A_min) * u * u
    pbar, dbar = md_force_and_approach(A, lam)
    a_s, p_s, d_s = md_scales(radius, work_of_adhesion, e_star)
    return A * a_s, pbar * p_s, dbar * d_s


def _pull_off_normalised(lam):
    """min over A > 0 of Pbar(A; lam) (negative); the end value at A -> 0 is -(pi lam/2) C^2."""
    # coarse scan then bounded refinement around the best grid point
    A = np.geomspace(1e-4, 3.0, 200)
    p = _solve(A, lam)[0]
    i = int(np.argmin(p))
    if i == 0:  # not met for lam >= 1e-4 (checked); fall back to the A -> 0 end value
        q = 4.0 / 3.0 * lam * lam * (np.pi / 2.0 - 1.0)
        r = np.pi * lam / 4.0
        c = 2.0 / (q + np.sqrt(q * q + 4.0 * r))
        return float(min(-np.pi * lam / 2.0 * c * c, p[0]))
    lo, hi = A[i - 1], A[min(i + 1, len(A) - 1)]
    res = minimize_scalar(lambda x: _pd(x, lam)[0], bounds=(lo, hi), method="bounded",
                          options={"xatol": 1e-12 * hi})
    return float(min(res.fun, p[i]))


def md_pull_off_force(radius, work_of_adhesion, e_star, sigma0, control="load"):
    """Maugis-Dugdale pull-off force (N, positive), load control: -min_A P(A).

    Tends to 2 pi beta dgamma (DMT) as lambda -> 0 and 1.5 pi beta dgamma (JKR) as lambda -> inf.
    radius beta (m), work_of_adhesion dgamma (J/m^2), e_star (Pa), sigma0 (Pa). Only
    control="load" is implemented.
    """
    if control != "load":
        raise ValueError(f"control = {control!r}: only 'load' is implemented")
    lam = float(md_parameter(radius, work_of_adhesion, e_star, sigma0))
    b, g = _arr(radius, work_of_adhesion)
    return _out(-_pull_off_normalised(lam) * np.pi * b * g)
