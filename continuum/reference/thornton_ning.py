"""Thornton-Ning adhesive elastic-plastic normal impact of a sphere on a rigid flat, in closed form.

What it is
----------
The Thornton & Ning (1998) contact law for adhesive, elastic-perfectly-plastic spheres, and the
energy bookkeeping of one normal impact under it: yield radius and velocity, restitution e(v),
the energy lost to plasticity and to adhesion, and the capture (sticking) velocity. Every
quantity is an exact closed form (a cubic for the yield radius, a quadratic for the maximum
approach, the JKR energy integral for loading and unloading); only the capture velocity needs a
scalar root of those closed forms. SI units; ``radius`` R is the sphere radius (the flat is flat
and rigid, the sphere's mass m = 4/3 pi R^3 rho is the impact mass), ``work_of_adhesion`` w is
Dupre's Delta gamma, ``e_star`` Johnson's contact modulus, ``limiting_pressure`` p_y the
limiting contact pressure.

The law (Thornton & Ning 1998; Thornton 1997 without adhesion)
--------------------------------------------------------------
* Elastic loading is JKR: F = 4E*a^3/(3R) - sqrt(8 pi w E* a^3), delta = a^2/R - sqrt(2 pi w a/E*),
  the contact forming at delta = 0 with a = a0 = (2 pi w R^2/E*)^{1/3} (zero-range adhesion).
* Yield starts when the JKR pressure at the contact centre reaches p_y,
  p_c(a) = 2E*a/(pi R) - sqrt(2 w E*/(pi a)) = p_y, at a = a_y (F_y, delta_y the JKR values there).
* Plastic loading keeps the pressure capped at p_y: F = F_y + pi p_y (a^2 - a_y^2) with
  a^2 - a_y^2 = R (delta - delta_y), i.e. a straight line of slope pi p_y R in delta.
* Unloading is elastic JKR about a flattened sphere of radius R_p > R, fixed at the maximum
  (F*, a*) by the Hertzian part of the load, R_p = 4E*a*^3 / (3 (F* + sqrt(8 pi w E* a*^3))),
  and shifted by the plastic approach delta_p so that it starts at (delta*, F*). The pull-off force
  grows to (3/2) pi w R_p: plasticity both dissipates energy and strengthens the bond.
* Detachment follows the project's JKR convention (``continuum.reference.jkr``): at the fold of
  the unloading curve (displacement control, the default: an impacting sphere carries on past
  the load maximum) or at its load-controlled pull-off point.

With w = 0 the law is Thornton's (1997) and e(v) equals his printed closed form (reproduced by
`restitution_thornton1997`); with p_y -> infinity it is JKR with Fuller-Tabor hysteresis and the
capture velocity is Thornton & Ning's V_s = 1.84 (w^5/(rho^3 E*^2 R^5))^{1/6} (the exact
coefficient is `ELASTIC_CAPTURE_COEFFICIENT` = 1.8402 for displacement-controlled detachment).
Above yield at high speed e falls as v^{-1/4} (Johnson 1985 §11.5; Thornton 1997), here with
e v^{1/4} -> (6 sqrt3/5)^{1/2} (5/24)^{1/8} V_y0^{1/4}, V_y0 the non-adhesive yield velocity.

Energy bookkeeping (exact): kinetic energy in = W_in(delta*) = U_R(a_y) + F_y D + pi p_y R D^2/2
(D = delta* - delta_y, U_R the JKR energy from the touch point, `jkr.energy_from_radius`), which
fixes D by a quadratic; energy recovered on rebound W_out = U_Rp(a*) - U_Rp(a_detach). Then
e^2 = W_out / (m v^2 / 2); the sphere is captured when W_out <= 0.

Why this model (and not the others)
-----------------------------------
* Mesarovic & Johnson (J. Mech. Phys. Solids 48 (2000) 2009) analyse the elastic unloading, with
  Maugis-Dugdale adhesion, of a sphere flattened by plastic loading: the pull-off force rises with
  the flattening, as in Thornton & Ning's R_p construction, and how it rises depends on an
  adhesion (Tabor-type) parameter. They give unloading and pull-off, not a closed-form e(v).
* Kogut & Etsion (J. Colloid Interface Sci. 261 (2003) 372) fit finite-element results for an
  adhesive elastic-plastic microcontact under loading (DMT-type adhesion outside the contact, on
  their finite-element loading fits for 1 <= delta/delta_c <= 110), with no unloading branch,
  hence no restitution or capture velocity.
* Thornton & Ning give loading, unloading and detachment, reduce exactly to the two closed forms
  the project already trusts (JKR hysteresis; Thornton 1997 without adhesion), have a single
  plastic parameter p_y, and were built for this problem (the stick/bounce of micro-spheres).
  Their idealisations: perfect plasticity (no hardening), a^2 = R delta kept during plastic
  loading, a centre-pressure yield criterion, and a truncated Hertzian pressure whose prefactor
  finite-element analyses of plastic sphere impact are the check on.

Sources: C. Thornton & Z. Ning, Powder Technol. 99 (1998) 154-162; C. Thornton, J. Appl. Mech.
64 (1997) 383-386; K. L. Johnson, *Contact Mechanics* (1985) §5.5, §6.2, §11.5; D. Tabor, *The
Hardness of Metals* (1951) (constraint factor H ~ 2.8 Y); K. L. Johnson, K. Kendall & A. D. Roberts,
Proc. R. Soc. Lond. A 324 (1971) 301; D. Maugis & H. M. Pollock, Acta Metall. 32 (1984) 1323.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from nanoimpact.errors import InputError

from . import jkr

__all__ = [
    "ELASTIC_CAPTURE_COEFFICIENT",
    "TABOR_CONSTRAINT_FACTOR",
    "ImpactEnergy",
    "LAW_RANGE_RADIUS_RATIO",
    "adhesive_stress_scale",
    "contact_radius_ratio",
    "capture_velocity",
    "capture_velocity_elastic",
    "check_limiting_pressure",
    "impact",
    "limiting_contact_pressure",
    "restitution",
    "restitution_thornton1997",
    "sphere_mass",
    "yield_radius",
    "yield_velocity",
    "yield_velocity_nonadhesive",
]

#: Tabor's constraint factor H / Y for a fully plastic indentation (Tabor 1951): the limiting
#: contact pressure taken from a tensile yield strength Y is p_y = 2.8 Y (see limiting_contact_pressure).
TABOR_CONSTRAINT_FACTOR = 2.8


def sphere_mass(radius, density):
    """Mass of a sphere m = 4/3 pi R^3 rho (kg)."""
    r = np.asarray(radius, float)
    return 4.0 / 3.0 * np.pi * r**3 * np.asarray(density, float)


def _fold_or_pulloff_radius(radius, w, e_star, detachment):
    """Contact radius (m) where a JKR contact of sphere radius `radius` lets go on unloading."""
    if detachment == "displacement":
        return np.cbrt(np.pi * w * radius**2 / (8.0 * e_star))      # fold, s^3 = 1/4
    if detachment == "load":
        return np.cbrt(9.0 * np.pi * w * radius**2 / (8.0 * e_star))  # P = -P_c, s^3 = 3/4
    raise InputError("detachment", detachment, "must be 'displacement' or 'load'")


def capture_velocity_elastic(radius, work_of_adhesion, e_star, density, detachment="displacement"):
    """Elastic (JKR, Fuller-Tabor) capture velocity V_s = sqrt(2 W_loop / m) (m/s).

    W_loop is one JKR approach-retreat loop (`jkr.loop_area`); a sphere slower than V_s sticks.
    Equals Thornton & Ning's V_s = 1.84 (w^5/(rho^3 E*^2 R^5))^{1/6} for displacement control.
    """
    loop = jkr.loop_area(radius, work_of_adhesion, e_star, detachment)
    return np.sqrt(2.0 * loop / sphere_mass(radius, density))


#: V_s / (w^5/(rho^3 E*^2 R^5))^{1/6} for displacement-controlled detachment: Thornton & Ning's 1.84.
ELASTIC_CAPTURE_COEFFICIENT = float(capture_velocity_elastic(1.0, 1.0, 1.0, 1.0))


#: Largest a*/R at which the law is used as derived: its Hertz/JKR relations are exact for the paraboloid
#: z = r^2/2R, and a sphere departs from its paraboloid by (a/R)^2/4 of the height at the contact edge (2.3 % at
#: a/R = 0.3, 9 % at 0.6): beyond 0.3 (a declared bound, the small-strain range of Hertz theory, Johnson 1985 §4.2)
#: a point is flagged as outside the range the law was derived for (a_y < R/2 is `check_limiting_pressure`'s).
LAW_RANGE_RADIUS_RATIO = 0.3


def contact_radius_ratio(velocity, radius, work_of_adhesion, e_star, density, limiting_pressure,
                         detachment="displacement"):
    """a*/R at the deepest state of an impact at `velocity` (m/s): compare with LAW_RANGE_RADIUS_RATIO."""
    res = impact(velocity, radius, work_of_adhesion, e_star, density, limiting_pressure, detachment)
    out = np.asarray(res.max_contact_radius, float) / float(radius)
    return float(out.ravel()[0]) if np.ndim(velocity) == 0 else out


def adhesive_stress_scale(radius, work_of_adhesion, e_star):
    """Centre pressure of the JKR contact at first touch, p_a = E* a0 / (pi R) (Pa).

    = (2 w E*^2 / (pi^2 R))^{1/3}. The centre pressure p_c(a) rises with a, so a limiting
    pressure below p_a means the contact yields on snap-in, under adhesion alone (Maugis &
    Pollock, Acta Metall. 32 (1984) 1323): outside the Thornton-Ning construction.
    """
    r, w, e = (np.asarray(x, float) for x in (radius, work_of_adhesion, e_star))
    return np.cbrt(2.0 * w * e * e / (np.pi**2 * r))


def check_limiting_pressure(limiting_pressure, radius, work_of_adhesion, e_star,
                            key="limiting_pressure"):
    """Raise InputError (naming `key`) unless p_a < p_y < E*; returns p_y as a float.

    p_a is `adhesive_stress_scale`; p_y >= E* would put yield beyond the small-strain range
    (a_y > R/2) in which the Hertz/JKR relations hold.
    """
    p = float(limiting_pressure)
    pa = float(adhesive_stress_scale(radius, work_of_adhesion, e_star))
    if not np.isfinite(p) or p <= pa:
        raise InputError(key, p, f"the limiting contact pressure must exceed the adhesive stress scale "
                         f"E* a0/(pi R) = {pa:.4g} Pa (below it the contact yields on snap-in)")
    if p >= float(e_star):
        raise InputError(key, p, f"the limiting contact pressure must be below E* = {float(e_star):.4g} Pa")
    return p


def limiting_contact_pressure(yield_strength=None, hardness=None, youngs_modulus=None,
                              prefix="surfaces.body"):
    """Limiting contact pressure p_y (Pa) from a yield strength or a hardness (exactly one).

    Choices, each with its reason: p_y = H (the hardness is the mean pressure under a fully plastic
    indentation, the state the truncated pressure of Thornton-Ning tends to at large plastic
    strain); p_y = 2.8 Y (Tabor's constraint factor, the same state reached from a tensile yield
    strength). First yield (p_0 = 1.6 Y, Johnson 1985 §6.2) then comes later than von Mises' onset:
    a single p_y cannot hold both. The elastic modulus is required beside either key because p_y
    only means something against E* (yield radius a_y ~ pi R p_y / (2 E*)). Raises InputError
    naming the key.
    """
    given = {k: v for k, v in (("yield_strength", yield_strength), ("hardness", hardness))
             if v is not None}
    if len(given) != 1:
        raise InputError(f"{prefix}.yield_strength/hardness", tuple(given) or None,
                         "give exactly one of yield_strength and hardness")
    (name, value), = given.items()
    if youngs_modulus is None:
        raise InputError(f"{prefix}.{name}", value, f"needs {prefix}.youngs_modulus: a limiting "
                         "contact pressure is placed against the elastic modulus")
    value = float(value)
    if not np.isfinite(value) or value <= 0.0:
        raise InputError(f"{prefix}.{name}", value, "must be a positive finite pressure (Pa)")
    return value if name == "hardness" else TABOR_CONSTRAINT_FACTOR * value


def yield_radius(limiting_pressure, radius, work_of_adhesion, e_star):
    """Contact radius a_y (m) at which the JKR centre pressure reaches p_y.

    Solves 2E*a/(pi R) - sqrt(2 w E*/(pi a)) = p_y: with u = sqrt(a) the depressed cubic
    u^3 - q u - c = 0, q = pi R p_y/(2E*), c = pi R sqrt(2 w E*/pi)/(2E*), which has exactly one
    positive root (Descartes), taken by Cardano (one real root) or the trigonometric form.
    For w = 0: a_y = pi R p_y / (2E*) (Johnson 1985 §6.2).
    """
    p, r, w, e = np.broadcast_arrays(*(np.asarray(x, float) for x in
                                       (limiting_pressure, radius, work_of_adhesion, e_star)))
    q = np.pi * r * p / (2.0 * e)
    c = np.pi * r * np.sqrt(2.0 * w * e / np.pi) / (2.0 * e)
    disc = (c / 2.0) ** 2 - (q / 3.0) ** 3
    with np.errstate(invalid="ignore"):
        sq = np.sqrt(np.maximum(disc, 0.0))
        u_card = np.cbrt(c / 2.0 + sq) + np.cbrt(c / 2.0 - sq)
        arg = np.clip((3.0 * c / (2.0 * q)) * np.sqrt(3.0 / np.maximum(q, 1e-300)), -1.0, 1.0)
        u_trig = 2.0 * np.sqrt(q / 3.0) * np.cos(np.arccos(arg) / 3.0)
    u = np.where(disc > 0.0, u_card, u_trig)
    for _ in range(2):  # Newton polish of u^3 - q u - c = 0 on the positive root
        u = u - (u**3 - q * u - c) / (3.0 * u * u - q)
    a = u * u
    return a[()] if a.ndim == 0 else a


def _jkr_energy(a, radius, w, e_star):
    """JKR energy from the touch point (J), or the Hertz energy (8/15) E* a^5 / R^2 when w = 0."""
    if np.all(np.asarray(w) == 0.0):
        return 8.0 / 15.0 * e_star * np.asarray(a, float) ** 5 / radius**2
    return np.asarray(jkr.energy_from_radius(a, radius, w, e_star), float)


def yield_velocity(limiting_pressure, radius, work_of_adhesion, e_star, density):
    """Impact speed at which the contact first yields, V_y = sqrt(2 U_R(a_y) / m) (m/s).

    U_R(a_y) is the JKR energy from touch to the yield radius; where it is <= 0 (adhesion alone
    pulls the sphere past yield) V_y = 0. For w = 0 it is Thornton's (1997)
    V_y = (pi^2/sqrt(40)) (p_y^5/(E*^4 rho))^{1/2} = 1.56 (p_y^5/(E*^4 rho))^{1/2}.
    """
    ay = yield_radius(limiting_pressure, radius, work_of_adhesion, e_star)
    uy = _jkr_energy(ay, radius, work_of_adhesion, e_star)
    return np.sqrt(np.maximum(2.0 * uy / sphere_mass(radius, density), 0.0))


def yield_velocity_nonadhesive(limiting_pressure, e_star, density):
    """Thornton's (1997) yield velocity without adhesion, V_y0 = (pi^2/sqrt 40) sqrt(p_y^5/(E*^4 rho))."""
    p, e, rho = (np.asarray(x, float) for x in (limiting_pressure, e_star, density))
    return np.pi**2 / np.sqrt(40.0) * np.sqrt(p**5 / (e**4 * rho))


def restitution_thornton1997(velocity, yield_velocity_0):
    """Thornton's (1997) printed restitution of an elastic-perfectly-plastic sphere, no adhesion.

    e = (6 sqrt3/5)^{1/2} [1 - (1/6) r^2]^{1/2} [r / (r + 2 sqrt(6/5 - r^2/5))]^{1/4},
    r = V_y/V, for V > V_y (e = 1 below). Independent of this module's energy bookkeeping.
    """
    v = np.asarray(velocity, float)
    r = np.minimum(np.asarray(yield_velocity_0, float) / v, 1.0)
    e = (np.sqrt(6.0 * np.sqrt(3.0) / 5.0) * np.sqrt(1.0 - r * r / 6.0)
         * (r / (r + 2.0 * np.sqrt(6.0 / 5.0 - r * r / 5.0))) ** 0.25)
    return e[()] if e.ndim == 0 else e


@dataclass(frozen=True)
class ImpactEnergy:
    """One normal impact under the Thornton-Ning law (arrays over the impact velocities; SI).

    kinetic_energy m v^2/2 (J); yielded: the contact passed a_y; max_contact_radius a* (m);
    max_force F* (N); plastic_radius R_p (m, = R if not yielded); plastic_approach delta_p (m);
    plastic_loss = m v^2/2 - U_Rp(a*) (J, the energy not stored in the unloading JKR curve);
    adhesive_loss = U_Rp(a_detach) (J, the unloading JKR hysteresis); rebound_energy
    W_out = m v^2/2 - plastic_loss - adhesive_loss (J, <= 0 means captured); restitution
    e = sqrt(max(W_out, 0) / (m v^2/2)); captured = W_out <= 0.
    """

    velocity: np.ndarray
    kinetic_energy: np.ndarray
    yielded: np.ndarray
    max_contact_radius: np.ndarray
    max_force: np.ndarray
    plastic_radius: np.ndarray
    plastic_approach: np.ndarray
    plastic_loss: np.ndarray
    adhesive_loss: np.ndarray
    rebound_energy: np.ndarray
    restitution: np.ndarray
    captured: np.ndarray


def _elastic_max_radius(ke, radius, w, e_star):
    """Contact radius a* where the JKR (Hertz for w = 0) energy from touch equals ke >= 0 (m).

    Vectorised bisection on the rising part of U(a) (beyond the P = 0 point, where U has its
    minimum); 200 halvings reach the last bit.
    """
    ke = np.asarray(ke, float)
    if w == 0.0:
        return (15.0 * ke * radius**2 / (8.0 * e_star)) ** 0.2
    a0 = jkr.contact_radius_at_touch(radius, w, e_star)
    lo = np.full_like(ke, a0 * 1.5 ** (2.0 / 3.0))   # P = 0 at s^3 = 3/2, U minimal there
    hi = lo * 2.0
    while np.any(_jkr_energy(hi, radius, w, e_star) < ke):
        hi = np.where(_jkr_energy(hi, radius, w, e_star) < ke, hi * 2.0, hi)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        below = _jkr_energy(mid, radius, w, e_star) < ke
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return 0.5 * (lo + hi)


def _plastic_maximum(ke, p_y, radius, w, e_star, a_y):
    """(a*, F*, delta*) at the end of plastic loading that absorbed kinetic energy ke (> U_R(a_y)).

    W_in = U_R(a_y) + F_y D + pi p_y R D^2 / 2 = ke, solved for D = delta* - delta_y (quadratic).
    """
    f_y = jkr.force_from_radius(a_y, radius, w, e_star)
    k_p = np.pi * p_y * radius
    extra = ke - _jkr_energy(a_y, radius, w, e_star)
    d = 2.0 * extra / (f_y + np.sqrt(f_y * f_y + 2.0 * k_p * extra))  # cancellation-free root
    a_max = np.sqrt(a_y * a_y + radius * d)
    return a_max, f_y + k_p * d, jkr.approach_from_radius(a_y, radius, w, e_star) + d


def impact(velocity, radius, work_of_adhesion, e_star, density, limiting_pressure,
           detachment="displacement"):
    """Normal impact of a sphere on a rigid flat under the Thornton-Ning law (see module docstring).

    velocity (m/s, array); radius R (m); work_of_adhesion w (J/m^2); e_star (Pa); density (kg/m^3);
    limiting_pressure p_y (Pa; np.inf for purely elastic JKR); detachment 'displacement' or 'load'.
    Returns an ImpactEnergy. Raises InputError (naming limiting_pressure) when p_y is not above
    the adhesive stress scale.
    """
    v = np.atleast_1d(np.asarray(velocity, float))
    r, w, e = float(radius), float(work_of_adhesion), float(e_star)
    ke = 0.5 * float(sphere_mass(r, density)) * v * v
    a_det_r = _fold_or_pulloff_radius(r, w, e, detachment)
    loop_r = _jkr_energy(a_det_r, r, w, e) if w > 0.0 else 0.0
    elastic = np.isinf(limiting_pressure)
    if not elastic:
        p_y = check_limiting_pressure(limiting_pressure, r, w, e)
        a_y = float(yield_radius(p_y, r, w, e))
        yielded = ke > _jkr_energy(a_y, r, w, e)
    else:
        yielded = np.zeros_like(v, bool)
    a_max = _elastic_max_radius(np.where(yielded, 0.0, ke), r, w, e)
    f_max = jkr.force_from_radius(a_max, r, w, e)
    r_p, delta_p = np.full_like(v, r), np.zeros_like(v)
    plastic_loss, adhesive_loss = np.zeros_like(v), np.full_like(v, loop_r)
    if np.any(yielded):
        ap, fp, dp = _plastic_maximum(ke[yielded], p_y, r, w, e, a_y)
        rp = 4.0 * e * ap**3 / (3.0 * (fp + np.sqrt(8.0 * np.pi * w * e * ap**3)))
        a_max[yielded], f_max[yielded], r_p[yielded] = ap, fp, rp
        delta_p[yielded] = dp - jkr.approach_from_radius(ap, rp, w, e)
        a_det = np.minimum(_fold_or_pulloff_radius(rp, w, e, detachment), ap)
        stored = _jkr_energy(ap, rp, w, e)
        plastic_loss[yielded] = ke[yielded] - stored
        adhesive_loss[yielded] = _jkr_energy(a_det, rp, w, e) if w > 0.0 else 0.0
    w_out = ke - plastic_loss - adhesive_loss
    with np.errstate(invalid="ignore", divide="ignore"):
        e_rest = np.where(w_out > 0.0, np.sqrt(np.maximum(w_out, 0.0) / ke), 0.0)
    return ImpactEnergy(v, ke, yielded, a_max, f_max, r_p, delta_p, plastic_loss, adhesive_loss,
                        w_out, e_rest, w_out <= 0.0)


def restitution(velocity, radius, work_of_adhesion, e_star, density, limiting_pressure,
                detachment="displacement"):
    """Coefficient of restitution e(v) under the Thornton-Ning law (0 when captured)."""
    e = impact(velocity, radius, work_of_adhesion, e_star, density, limiting_pressure,
               detachment).restitution
    return e[0] if np.ndim(velocity) == 0 else e


def capture_velocity(radius, work_of_adhesion, e_star, density, limiting_pressure,
                     detachment="displacement"):
    """Capture velocity (m/s): below it the sphere sticks (W_out <= 0), above it rebounds.

    Equals `capture_velocity_elastic` when the contact does not yield below that speed; otherwise
    the root of W_out(v) = 0 above the yield velocity (brentq on the closed forms, bracket grown
    by doubling; relative tolerance 1e-12).
    """
    v_el = float(capture_velocity_elastic(radius, work_of_adhesion, e_star, density, detachment))
    if np.isinf(limiting_pressure):
        return v_el
    v_y = float(yield_velocity(limiting_pressure, radius, work_of_adhesion, e_star, density))
    if v_y >= v_el:
        return v_el

    def w_out(v):
        return float(impact(v, radius, work_of_adhesion, e_star, density, limiting_pressure,
                            detachment).rebound_energy[0])

    lo, hi = max(v_y, 1e-300), max(v_el, v_y, 1e-300) * 2.0
    while w_out(hi) <= 0.0:
        lo, hi = hi, hi * 2.0
    return brentq(w_out, lo, hi, xtol=1e-300, rtol=1e-12)
