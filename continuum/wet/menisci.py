"""Capillary bridges at summits: Kelvin radius, bridge force and energy, and when bridges form.

All SI: lengths m, forces N, energies J, times s, angles rad. Pure functions; the rough-contact
law that uses them is ``continuum.laws.wet.WetRoughRoller``. Derivation: docs/model.md, "Menisci".

Bridge force (constant Kelvin radius, r_K << beta)
--------------------------------------------------
A condensed bridge in equilibrium with the vapour has the mean curvature fixed by the Kelvin
equation. For r_K << beta the azimuthal curvature (radius ~ sqrt(beta r_K)) is negligible against
the meridional one, so the meridional radius is the Kelvin radius

    r_K = gamma V_m / (R_g T ln(1/RH))                     (Israelachvili 2011 §17.7; Butt & Kappl 2009)

and the liquid is at the Laplace pressure -gamma/r_K. A circular meridian meeting the two faces at
contact angles theta1, theta2 spans the local gap D_K = r_K (cos theta1 + cos theta2) (the Kelvin
gap), so a sphere of tip radius beta at gap g (closest distance) is wetted where
g + x^2/(2 beta) <= D_K, i.e. over pi x_m^2 = 2 pi beta (D_K - g). The force is pressure times area:

    F(g) = 2 pi beta gamma (cos t1 + cos t2) (1 - g/D_K)           0 <= g <= D_K
    F(g) = 2 pi beta gamma (cos t1 + cos t2) (1 - g/(2 D_K))       g < 0 (summit compressed by -g)

F0 = 2 pi beta gamma (cos t1 + cos t2) is the classical sphere-flat capillary adhesion
(Israelachvili eq 17.23 for theta1 = theta2). For g < 0 the wetted annulus is the disc minus the
contact area pi a^2 with a^2 = beta (-g) (Hertz contact radius; JKR's is larger by at most the
adhesive neck, an error below (a_JKR^2 - a_H^2)/(2 beta D_K) of F0, stated in docs/model.md).
The bridge ruptures at g = D_K, where its force is zero (constant curvature: a slow separation
keeps the bridge in equilibrium with the vapour). Its energy U(g) = -int_g^{D_K} F dg' is

    U(g) = -F0 (D_K - g)^2 / (2 D_K)                           0 <= g <= D_K
    U(g) = -F0 (D_K/2 - g + g^2/(4 D_K))                       g < 0

so dU/dg = F (F pulls the surfaces together), U(D_K) = 0: rupture costs nothing and the whole
work a bridge does on the body is -U(g_formed), booked when it forms.

Solid-solid adhesion inside a bridge (``menisci.solid_adhesion``)
-----------------------------------------------------------------
Where a bridge stands, the two solids touch under liquid, not in vapour. The work to separate them
across the liquid L is (Dupre in a medium; Israelachvili 2011 §17.7, Butt & Kappl 2009 §2.6)

    W_wet = gamma_1L + gamma_2L - gamma_12,

and with Young's gamma_iL = gamma_i - gamma_lv cos theta_i and the dry Dupre W = gamma_1 + gamma_2 - gamma_12
(the scene's work of adhesion dgamma)

    W_wet = dgamma - gamma_lv (cos theta1 + cos theta2).

A negative W_wet means the liquid pushes the solids apart (it wets between them): no solid-solid
adhesion is left. For a summit in contact the DMT solid pull is 2 pi beta W, so replacing dgamma by
max(W_wet, 0) inside a bridge takes 2 pi beta (dgamma - max(W_wet, 0)) from each compressed bridged
summit; where W_wet >= 0 that is exactly F0, so the sphere-flat wet pull-off is the dry one,
2 pi beta dgamma (Israelachvili 2011 eq 17.25 for r_K << beta), not dry + F0 (the paper's additive
eq 14). That DMT force correction keeps the summits' dry loop; where the summit law itself can be rebuilt at
W_wet (discrete summits, `continuum.laws.wet_summits`; the rigid mean field of JKR summits,
`continuum.laws.wet_mean_field`) it is, force and loop, and the bridges take no solid pull.

When bridges form (paper eq 12, corrected; Riedo et al. PRL 88 (2002) 185505)
-----------------------------------------------------------------------------
Condensation is thermally activated: filling a gap h costs a barrier proportional to the volume
condensed, so the time to bridge h grows exponentially with h, and the largest gap bridged
after a contact time t grows with ln t. No bridge forms before t_a; after it

    h_mw(t) = min(h1 ln(t/t_a), D_K),   t >= t_a,

and summits whose gap is at most h_mw (including every summit in contact) carry a bridge. The
growth length h1 = 1/(n_w d_w^2 ln(1/RH)) treats the condensing column as one water molecule's
cross-section d_w^2 = n_w^{-2/3} (n_w = 33.4 nm^-3): h1 = 0.31 nm / ln(1/RH) (a scene can set it).
t_a is 25 us by default (the paper, after Riedo et al.). The 'nucleation' option computes it from
Szoszkiewicz & Riedo, PRL 95 (2005) 135502: t_a = tau0 exp(dE/kT), dE = 7.8e-20 J at 40 % RH scaled
by ln(1/RH)/ln(1/0.4) (the barrier is proportional to the chemical-potential drop), tau0 fixed by
their 4.2 ms at 299 K (tau0 = 2.6e-11 s, an attempt frequency of 38 GHz, inside their 4-250 GHz).
It gives 0.65 ms at 332 K, against their measured 0.7 ms.
"""
from __future__ import annotations

import math

import numpy as np

#: Molar gas constant (J/(mol K)) and Boltzmann constant (J/K), CODATA 2018 exact values.
R_GAS = 8.314462618
K_BOLTZMANN = 1.380649e-23
#: Number density of liquid water at 298 K (1/m^3): 997 kg/m^3 / 18.015 g/mol * N_A.
WATER_NUMBER_DENSITY = 3.334e28
#: Szoszkiewicz & Riedo (2005): nucleation barrier (J) at 40 % RH and the time measured at 299 K (s).
NUCLEATION_BARRIER_40 = 7.8e-20
NUCLEATION_TIME_299K = 4.2e-3
NUCLEATION_REFERENCE_RH = 0.4
NUCLEATION_REFERENCE_T = 299.0
#: Szoszkiewicz & Riedo (2005): the attempt frequencies their Arrhenius fit allows (Hz), 4-250 GHz. The estimate's
#: prefactor tau0 is known only within 1/250 GHz .. 1/4 GHz: the range of t_a its inputs allow at given RH and T.
NUCLEATION_ATTEMPT_FREQUENCIES = (4e9, 250e9)
#: Their measured nucleation times at 40 % RH (K -> s), the ends of their temperature range.
NUCLEATION_MEASURED = {299.0: 4.2e-3, 332.0: 0.7e-3}
#: One water molecule's diameter d_w = n_w^(-1/3) (m, 0.31 nm): the default smallest Kelvin radius a smooth
#: sphere's bridge is given (``menisci.min_kelvin_radius``). The Kelvin and Laplace equations describe a
#: continuum liquid; Israelachvili (2011, §17.7) finds them holding down to menisci of a few molecular
#: diameters, so a meniscus narrower than one molecule is not modelled as a bridge.
WATER_MOLECULE_DIAMETER = WATER_NUMBER_DENSITY ** (-1.0 / 3.0)


def kelvin_radius(relative_humidity: float, temperature: float, surface_tension: float,
                  molar_volume: float) -> float:
    """Kelvin radius r_K = gamma V_m / (R T ln(1/RH)) (m). RH in (0, 1), T (K), gamma (N/m), V_m (m^3/mol)."""
    if not 0.0 < relative_humidity < 1.0:
        raise ValueError(f"relative_humidity = {relative_humidity!r}: must be in (0, 1) for a finite Kelvin radius")
    return surface_tension * molar_volume / (R_GAS * temperature * math.log(1.0 / relative_humidity))


def wetting_sum(theta1: float, theta2: float) -> float:
    """cos theta1 + cos theta2 (angles in rad): > 0 for a bridge that pulls, <= 0 for none."""
    return math.cos(theta1) + math.cos(theta2)


def kelvin_gap(r_kelvin: float, theta1: float, theta2: float) -> float:
    """D_K = r_K (cos theta1 + cos theta2) (m): the largest gap a bridge spans (0 if hydrophobic)."""
    return max(r_kelvin * wetting_sum(theta1, theta2), 0.0)


def bridge_pull_off(radius: float, surface_tension: float, theta1: float, theta2: float) -> float:
    """F0 = 2 pi beta gamma (cos theta1 + cos theta2) (N): a bridge's pull at touch (beta = summit radius, m)."""
    return 2.0 * math.pi * radius * surface_tension * max(wetting_sum(theta1, theta2), 0.0)


def solid_liquid_work(surface_tension: float, theta: float, measured: float | None = None) -> float:
    """W_SL = gamma_S + gamma_L - gamma_SL (J/m^2) of one face: `measured` where given (MD thermodynamic
    integration), else Young-Dupre gamma_lv (1 + cos theta). Only the measured value can exceed 2 gamma_lv
    (complete wetting, where Young's angle is 0 and the excess is the spreading coefficient S = W_SL - 2 gamma_lv)."""
    return float(measured) if measured is not None else surface_tension * (1.0 + math.cos(theta))


def wet_work_of_adhesion(work_of_adhesion: float, surface_tension: float, theta1: float, theta2: float,
                         solid_liquid: tuple[float | None, float | None] = (None, None)) -> float:
    """W_wet = gamma_1L + gamma_2L - gamma_12 = dgamma + 2 gamma_lv - W_1L - W_2L (J/m^2): the solids' work of
    adhesion under the liquid (Dupre in a medium; Israelachvili 2011 §17.7, Butt & Kappl 2009 §2.6), with each face's
    W_iL from `solid_liquid` where measured, else from its angle (then W_wet = dgamma - gamma_lv (cos t1 + cos t2)).
    Two different solids take one W_iL each. Negative: the liquid separates them."""
    w1 = solid_liquid_work(surface_tension, theta1, solid_liquid[0])
    w2 = solid_liquid_work(surface_tension, theta2, solid_liquid[1])
    return work_of_adhesion + 2.0 * surface_tension - w1 - w2


def solid_pull_inside_bridge(radius: float, work_of_adhesion: float, surface_tension: float, theta1: float,
                             theta2: float, choice: str,
                             solid_liquid: tuple[float | None, float | None] = (None, None)) -> float:
    """Solid-solid pull (N, >= 0) a bridge takes from each compressed summit it wets: 2 pi beta (dgamma - max(W_wet, 0))
    for choice 'wet', 0 for 'additive' (the paper's eq 14: the bridge adds to the dry adhesion)."""
    if choice == "additive":
        return 0.0
    if choice != "wet":
        raise ValueError(f"menisci.solid_adhesion = {choice!r}: 'wet' or 'additive'")
    w_wet = wet_work_of_adhesion(work_of_adhesion, surface_tension, theta1, theta2, solid_liquid)
    return 2.0 * math.pi * radius * (work_of_adhesion - max(w_wet, 0.0))


def bridge_force(gap, f0: float, d_k: float, solid_pull: float = 0.0):
    """Attractive force (N) of one bridge at summit gap `gap` (m; < 0 = compressed), less the solid pull it takes
    from a compressed summit (`solid_pull_inside_bridge`, N; 0 for the paper's additive law)."""
    g = np.asarray(gap, float)
    out = np.where(g <= 0.0, f0 * (1.0 - g / (2.0 * d_k)) - solid_pull, f0 * (1.0 - g / d_k))
    return np.where(g < d_k, out, 0.0)


def bridge_energy(gap, f0: float, d_k: float, solid_pull: float = 0.0):
    """Energy (J) of one bridge, U(g) = -int_g^{D_K} F dg', zero at rupture (F with its `solid_pull`, N)."""
    g = np.asarray(gap, float)
    inside = -f0 * (d_k - g) ** 2 / (2.0 * d_k)
    compressed = -f0 * (0.5 * d_k - g + g * g / (4.0 * d_k)) - solid_pull * g
    return np.where(g < d_k, np.where(g <= 0.0, compressed, inside), 0.0)


#: U(g) and F(g) as polynomials a0 + a1 g + a2 g^2 on the two pieces, in units of F0 (force) and
#: F0 D_K (energy), with g in units of D_K: (compressed g <= 0, stretched 0 < g < 1).
def bridge_polynomials(kind: str, solid: float = 0.0) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """Coefficients (a0, a1, a2) of the normalised bridge law on (g <= 0, 0 < g < 1); kind 'force'/'energy'.

    `solid` = the solid pull a bridge takes from a compressed summit (`solid_pull_inside_bridge`) over F0: a
    constant -solid F0 on g <= 0, and its energy -solid F0 (-g) there (U stays continuous at g = 0)."""
    if kind == "force":
        return (1.0 - solid, -0.5, 0.0), (1.0, -1.0, 0.0)
    if kind == "energy":
        return (-0.5, 1.0 - solid, -0.25), (-0.5, 1.0, -0.5)
    raise ValueError(f"kind = {kind!r}: 'force' or 'energy'")


def default_growth_length(relative_humidity: float) -> float:
    """h1 = 1/(n_w^{1/3} ln(1/RH)) (m): one molecule's cross-section as the condensing column."""
    return 1.0 / (WATER_NUMBER_DENSITY ** (1.0 / 3.0) * math.log(1.0 / relative_humidity))


def nucleation_condensation_time(relative_humidity: float, temperature: float) -> float:
    """t_a = tau0 exp(dE(RH)/kT) (s) from Szoszkiewicz & Riedo (2005), see the module docstring."""
    barrier = NUCLEATION_BARRIER_40 * math.log(1.0 / relative_humidity) / math.log(1.0 / NUCLEATION_REFERENCE_RH)
    tau0 = NUCLEATION_TIME_299K * math.exp(-NUCLEATION_BARRIER_40 / (K_BOLTZMANN * NUCLEATION_REFERENCE_T))
    return tau0 * math.exp(barrier / (K_BOLTZMANN * temperature))


def nucleation_time_range(relative_humidity: float, temperature: float) -> tuple[float, float]:
    """(shortest, longest) t_a (s) the nucleation estimate allows at (RH, T): its barrier dE(RH) with the attempt time
    tau0 anywhere in Szoszkiewicz & Riedo's 1/250 GHz .. 1/4 GHz (`NUCLEATION_ATTEMPT_FREQUENCIES`)."""
    barrier = NUCLEATION_BARRIER_40 * math.log(1.0 / relative_humidity) / math.log(1.0 / NUCLEATION_REFERENCE_RH)
    boltzmann = math.exp(barrier / (K_BOLTZMANN * temperature))
    lo, hi = NUCLEATION_ATTEMPT_FREQUENCIES
    return boltzmann / hi, boltzmann / lo


def bridgeable_gap(t_contact: float, t_a: float, growth_length: float, d_k: float) -> float:
    """h_mw(t) (m): -inf before t_a (no bridge), then min(h1 ln(t/t_a), D_K)."""
    if t_contact < t_a:
        return -math.inf
    return min(growth_length * math.log(t_contact / t_a), d_k)
