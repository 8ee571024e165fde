"""Contact modulus of summits coated with a thin compliant layer (a SAM on each surface), SI.

A layer of thickness t and plane-strain modulus E'_f = E_f/(1 - nu_f^2) on a substrate of plane-strain modulus
E'_s responds to a contact of radius a like a homogeneous half-space of an equivalent modulus E'(a/t). Perriot &
Barthel (J. Mater. Res. 19 (2004) 600) computed it exactly (integral formulation of the axisymmetric contact to a
coated half-space, moduli ratios 0.01-100) and fitted

    E'(x) = E'_f + (E'_s - E'_f) / (1 + (k0/x)^n),   x = a/t,   n = 1.27,
    log10 k0 = -0.093 + 0.792 log10(E'_s/E'_f) + 0.05 [log10(E'_s/E'_f)]^2.

Limits: a/t -> 0 (a contact inside the layer) gives E'_f; a/t -> inf (a thin layer under a wide contact) gives
E'_s. In between, for a compliant layer on a stiff substrate, the layer acts as a thin confined (Winkler) layer
in series with the substrate, which sets the transition radius: 1/(2aE') = 1/(2aE'_s) + t/(M pi a^2) halves the
substrate's modulus at a/t = 2E'_s/(pi M), M the layer's confined modulus; k0 follows the same trend (Bec et al.,
Phil. Mag. A 74 (1996) 1061 write the same series model with edge corrections).

Two coated bodies in contact: each deforms under the same pressure, so their compliances add,
1/E*(a) = 1/E'_1(a/t) + 1/E'_2(a/t) (Johnson's convention: E* of two identical half-spaces is E'/2).

A summit contact's radius changes along its loop, and with it E*(a). The summit laws (JKR, DMT, Maugis-Dugdale)
are homogeneous-half-space laws; they run with the equivalent modulus frozen at the radius that carries the
adhesive loop: the JKR zero-load contact radius a_0 = (9 pi dgamma beta^2 / (2 E*(a_0)))^(1/3) (Johnson, Kendall
& Roberts 1971), solved together with E*(a_0) (:func:`coated_summit_modulus`). This is the JKR-on-a-coated-
substrate problem (Johnson & Sridhar, J. Phys. D 27 (1994) 429; Shull, Mater. Sci. Eng. R 36 (2002) 1) with the
compliance's variation across the loop left out: exact in both limits, and the layer's effect on the loop enters
through E*^(-2/3) (loop ~ beta^(4/3) dgamma^(5/3) E*^(-2/3)). Without adhesion the reference radius is the Hertz
radius of a summit pressed by one sigma, sqrt(beta sigma).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

#: Perriot & Barthel's exponent n and the coefficients of log10 k0 in log10(E'_s/E'_f).
PB_EXPONENT = 1.27
PB_K0_COEFFS = (-0.093, 0.792, 0.05)


def plane_strain_modulus(youngs_modulus: float, poisson_ratio: float) -> float:
    """E' = E / (1 - nu^2) (Pa)."""
    return youngs_modulus / (1.0 - poisson_ratio * poisson_ratio)


def transition_ratio(e_film: float, e_substrate: float) -> float:
    """Perriot & Barthel's k0: the a/t where E' is halfway (on their fitted curve) between the two moduli."""
    r = math.log10(e_substrate / e_film)
    c0, c1, c2 = PB_K0_COEFFS
    return 10.0 ** (c0 + c1 * r + c2 * r * r)


def equivalent_modulus(a_over_t, e_film: float, e_substrate: float):
    """Perriot & Barthel's equivalent plane-strain modulus (Pa) of a coated half-space at contact radius / layer
    thickness `a_over_t` (vectorised); e_film and e_substrate are plane-strain moduli (Pa)."""
    x = np.asarray(a_over_t, float)
    k0 = transition_ratio(e_film, e_substrate)
    with np.errstate(divide="ignore", over="ignore"):
        ratio = np.where(x > 0, (k0 / np.where(x > 0, x, 1.0)) ** PB_EXPONENT, np.inf)
    out = e_film + (e_substrate - e_film) / (1.0 + ratio)
    return float(out) if out.ndim == 0 else out


def coated_pair_modulus(a, thickness: float, e_film: float, e_substrate_1: float, e_substrate_2: float):
    """Contact modulus E* (Pa) of two bodies, each with a layer of `thickness` (m) and plane-strain modulus
    e_film on a substrate of plane-strain modulus e_substrate_i, at contact radius `a` (m; vectorised)."""
    x = np.asarray(a, float) / thickness
    inv = 1.0 / equivalent_modulus(x, e_film, e_substrate_1) + 1.0 / equivalent_modulus(x, e_film, e_substrate_2)
    out = 1.0 / inv
    return float(out) if np.ndim(out) == 0 else out


def jkr_zero_load_radius(radius: float, work_of_adhesion: float, e_star: float) -> float:
    """JKR contact radius at zero load, a_0 = (9 pi dgamma beta^2 / (2 E*))^(1/3) (m)."""
    return (9.0 * math.pi * work_of_adhesion * radius * radius / (2.0 * e_star)) ** (1.0 / 3.0)


def coated_summit_modulus(radius: float, work_of_adhesion: float, sigma: float, thickness: float,
                          e_film: float, e_substrate_1: float, e_substrate_2: float) -> tuple[float, float]:
    """(E* Pa, reference contact radius m) of coated summits of tip radius `radius` (m).

    With adhesion (work_of_adhesion > 0) the reference radius is the JKR zero-load radius solved together with
    E*(a) (a root between the radii of the two homogeneous limits, which bracket it); without, sqrt(beta sigma)."""
    def pair(a):
        return coated_pair_modulus(a, thickness, e_film, e_substrate_1, e_substrate_2)

    if work_of_adhesion <= 0.0:
        a = math.sqrt(radius * sigma)
        return pair(a), a
    e_lo = 1.0 / (2.0 / e_film)
    e_hi = 1.0 / (1.0 / e_substrate_1 + 1.0 / e_substrate_2)
    a_lims = sorted((jkr_zero_load_radius(radius, work_of_adhesion, e_lo),
                     jkr_zero_load_radius(radius, work_of_adhesion, e_hi)))
    target = 9.0 * math.pi * work_of_adhesion * radius * radius / 2.0

    def residual(log_a):
        a = math.exp(log_a)
        return (a ** 3 * pair(a) - target) / target

    if a_lims[1] <= a_lims[0] * (1.0 + 1e-12):
        a = a_lims[0]
    else:
        a = math.exp(brentq(residual, math.log(a_lims[0]), math.log(a_lims[1]), xtol=1e-14, rtol=1e-13))
    return pair(a), a
