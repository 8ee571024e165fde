"""A non-adhesive elastic-plastic summit: Thornton-Ning's construction with no adhesion (Hertz to yield, the plastic
line, Hertz unloading about the flattened radius). The summit law inside a bridge where the wet work of adhesion is
W_wet <= 0 (`continuum.laws.wet_plastic_summits`): under liquid the solids then do not adhere, as the elastic wet
class is Hertz there.

Closed forms (C. Thornton, J. Appl. Mech. 64 (1997) 383; C. Thornton & Z. Ning, Powder Technol. 99 (1998) 154 with
w = 0), for a sphere of tip radius beta, contact modulus E*, limiting contact pressure p_y, under displacement
control:

* elastic loading is Hertz, F = 4E* sqrt(beta) delta^(3/2) / 3, a^2 = beta delta, centre pressure 2E*a/(pi beta);
  it yields where that reaches p_y: a_y = pi beta p_y / (2E*), delta_y = a_y^2/beta, F_y = 4E* a_y^3/(3 beta);
* plastic loading is the line F = F_y + pi p_y beta (delta - delta_y), a*^2 = a_y^2 + beta (delta - delta_y);
* unloading and reloading are Hertz about R_p = 4E* a*^3/(3 F*) (the jkr law's R_p with w = 0), shifted by
  delta_p = delta* - a*^2/R_p; the summit touches and lets go at delta_p (no loop, no jump);
* stored energy U = 8E* sqrt(R_p) (delta - delta_p)^(5/2) / 15; plastic work W_p = U_beta(delta_y) + F_y D +
  pi p_y beta D^2/2 - U_Rp(delta*), D = delta* - delta_y.

The interface is that of `continuum.rough.plastic_summits.PlasticSummitLaw` (vectorised over summits); no compiled
form (the Python stepper runs a contact that needs it after t_a).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["HertzPlasticSummitLaw"]


class HertzPlasticSummitLaw:
    """One summit's Thornton-Ning law without adhesion: tip radius beta (m), contact modulus E* (Pa), limiting contact
    pressure p_y (Pa; math.inf: Hertz)."""

    work_of_adhesion = 0.0
    approach_reach = 0.0
    max_stretch = 0.0
    compiled_form = False

    def __init__(self, radius: float, e_star: float, limiting_pressure: float):
        self.radius, self.e_star, self.limiting_pressure = float(radius), float(e_star), float(limiting_pressure)
        self.plastic_slope = math.pi * self.limiting_pressure * self.radius
        if math.isinf(self.limiting_pressure):
            self.yield_radius = self.yield_force = self.yield_approach = math.inf
            return
        a_y = math.pi * self.radius * self.limiting_pressure / (2.0 * self.e_star)
        self.yield_radius, self.yield_approach = a_y, a_y * a_y / self.radius
        self.yield_force = 4.0 * self.e_star * a_y**3 / (3.0 * self.radius)

    def _hertz(self, eps, r_p):
        """(force N, energy J) of Hertz on radius r_p at eps = delta - delta_p (m): 0 out of contact."""
        e = np.maximum(np.asarray(eps, float), 0.0)
        k = 4.0 * self.e_star * np.sqrt(r_p) / 3.0
        return k * e * np.sqrt(e), 0.4 * k * e * e * np.sqrt(e)

    def flattening(self, delta_max):
        """(R_p, delta_p) (m) after the deepest approach delta_max (m): (beta, 0) unyielded."""
        dm = np.asarray(delta_max, float)
        r_p, d_p = np.full(dm.shape, self.radius), np.zeros(dm.shape)
        if not math.isfinite(self.yield_approach):
            return r_p, d_p
        over = np.maximum(dm - self.yield_approach, 0.0)
        y = over > 0.0
        if np.any(y):
            a2 = self.yield_radius**2 + self.radius * over[y]
            f = self.yield_force + self.plastic_slope * over[y]
            r_p[y] = 4.0 * self.e_star * a2 * np.sqrt(a2) / (3.0 * f)
            d_p[y] = dm[y] - a2 / r_p[y]
        return r_p, d_p

    def jump_in(self, r_p):
        """delta_in (m, relative to delta_p): touch."""
        return np.zeros_like(np.asarray(r_p, float))

    def jump_out(self, r_p):
        """delta_out (m, relative to delta_p): the summit lets go where it touched (no adhesion)."""
        return np.zeros_like(np.asarray(r_p, float))

    def in_switch(self, r_p):
        return np.zeros_like(np.asarray(r_p, float))

    def out_switch(self, r_p):
        return np.zeros_like(np.asarray(r_p, float))

    def reach_of(self, r_p):
        return np.zeros_like(np.asarray(r_p, float))

    def state(self, delta, delta_max, attached):
        """(force N, stored energy J): Hertz about (R_p, delta_p), Thornton's plastic line on a new deepest approach;
        nothing where not attached."""
        delta, dm, att = np.broadcast_arrays(np.asarray(delta, float), np.asarray(delta_max, float),
                                             np.asarray(attached, bool))
        r_p, d_p = self.flattening(dm)
        f, u = self._hertz(delta - d_p, r_p)
        if math.isfinite(self.yield_approach):
            line = att & (delta >= dm) & (dm > self.yield_approach)
            f = np.where(line, self.yield_force + self.plastic_slope * (delta - self.yield_approach), f)
        return np.where(att, f, 0.0), np.where(att, u, 0.0)

    def plastic_work(self, delta_max):
        """W_p (J) absorbed by a summit loaded to delta_max (m)."""
        dm = np.asarray(delta_max, float)
        if not math.isfinite(self.yield_approach):
            return np.zeros(dm.shape)
        d = np.maximum(dm - self.yield_approach, 0.0)
        u_y = float(self._hertz(self.yield_approach, self.radius)[1])
        r_p, d_p = self.flattening(np.maximum(dm, self.yield_approach))
        stored = self._hertz(np.maximum(dm, self.yield_approach) - d_p, r_p)[1]
        return np.where(d > 0.0, u_y + self.yield_force * d + 0.5 * self.plastic_slope * d * d - stored, 0.0)

    def range_radius_ratio(self, delta_max):
        """a*/R_p at the deepest state delta_max (m)."""
        dm = np.asarray(delta_max, float)
        r_p, d_p = self.flattening(dm)
        return np.sqrt(np.maximum(dm - d_p, 0.0) * r_p) / r_p

    def describe(self) -> dict:
        return {"name": "thornton_hertz_summit", "radius": self.radius, "work_of_adhesion": 0.0, "e_star": self.e_star,
                "limiting_pressure": self.limiting_pressure, "yield_radius": self.yield_radius,
                "yield_force": self.yield_force, "yield_approach": self.yield_approach,
                "plastic_slope": self.plastic_slope,
                "source": "Thornton (1997), Thornton & Ning (1998) with no adhesion: Hertz to a centre pressure p_y, "
                          "plastic line pi p_y beta, Hertz unloading about R_p = 4E*a*^3/3F* shifted by delta_p"}
