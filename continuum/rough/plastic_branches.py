"""An adhesive elastic-plastic summit under any summit law of the Tabor range (JKR, Maugis-Dugdale, DMT).

What it is
----------
Thornton & Ning's (1998) construction, which they built on JKR, applied to the summit's own elastic law L
(`continuum.rough.branch_laws`: the approach and retreat branches, with their jumps, of a sphere of radius R):

* elastic loading follows L on the summit's radius beta up to the yield approach delta_y, where the pressure at
  the centre of the contact reaches the limiting contact pressure p_y. The centre pressure of each law
  (Johnson & Greenwood 1997 for Maugis-Dugdale: the Hertz pressure less the Dugdale zone's pull at r = 0):

      JKR  p_0 = 2E*a/(pi R) - sqrt(2 w E*/(pi a))
      MD   p_0 = 2E*a/(pi R) - (sigma0/pi) arccos(2/m^2 - 1)        (m = c/a, Maugis' zone ratio)
      DMT  p_0 = 2E*a/(pi R)                                          (the attraction acts outside the contact)

  (MD tends to JKR as lambda -> inf and to DMT as lambda -> 0, so the criterion is one across the range);
* plastic loading is Thornton-Ning's line F = F_y + pi p_y beta (delta - delta_y), a^2 = a_y^2 + beta (delta -
  delta_y);
* unloading and reloading follow L about a flattened radius R_p, shifted by a residual approach delta_p, with R_p
  fixed so that L's curve of radius R_p passes through the deepest state (a*, F*): F_L(a*; R_p) = F*, and
  delta_p = delta* - delta_L(a*; R_p). For JKR this is Thornton-Ning's R_p = 4E*a*^3/(3(F* + sqrt(8 pi w E*
  a*^3))) exactly (tests/continuum/test_plastic_branches.py checks it against `continuum.rough.plastic_summits`);
  F_L(a*; R) falls with R for every law (the Hertz term 4E*a^3/(3R) falls, the adhesive term does not grow), so
  R_p is unique. The flattened summit then jumps in and out at L's own jump points of radius R_p (delta_p +
  delta_in(R_p), delta_p + delta_out(R_p)), feels L's non-contact attraction (Maugis-Dugdale) on approach, and
  loses L's loop of radius R_p per contact: the pull-off rises with the flattening as Mesarovic & Johnson (2000)
  found for Maugis-Dugdale unloading of a plastically flattened sphere.

Evaluating L at radius R_p: JKR and DMT are self-similar in Maugis' scales (a_s = (pi w R^2/K)^{1/3},
p_s = pi w R, d_s = a_s^2/R, K = 4E*/3), so the summit's own table on beta, rescaled, is exact. Maugis-Dugdale is
self-similar only at fixed lambda = sigma0 (9R/(2 pi w E*^2))^{1/3}, which grows as R^{1/3}: L is tabulated at
radii R_k = beta 2^{k/2} (lambda steps of 2^{1/6}) up to the largest R_p the table range needs, and a summit of
R_p between R_k and R_k+1 takes the weighted mean (linear in log R) of the two scaled curves, force and energy
alike, so that F = dU/d(delta) holds on the mean curve too. The jumps of the mean curve are the weighted means
of the nodes' jump points; a summit switching branch at delta_in books U_A - U_R there and U_R - U_A at
delta_out (the sum is the mean curve's loop; at a node each term is L's own, the first zero), so the energy
audit is exact for the mean curve. The interpolation error against L built at R_p itself is measured in
tests/continuum/test_plastic_branches.py.

The flattening (R_p, delta_p) is a function of D = delta_max - delta_y alone, tabulated on 400 points (D^2
spacing up to the law's table range) and interpolated linearly; the plastic work is W_in(D) - U_R(delta*; R_p)
with W_in = U_A(delta_y; beta) + F_y D + pi p_y beta D^2/2 (the work done along the loading path) and U_R the
stored energy of the branch the summit is on, so work = stored + plastic + booked jumps exactly.
With p_y = inf no summit yields and every function is L's own on beta (bit for bit: tests).

Range: the construction rests on the small-strain relations of L (a << R); `range_radius_ratio` gives a*/R_p at
the deepest state, which callers compare with `continuum.reference.thornton_ning.LAW_RANGE_RADIUS_RATIO`.

Sources: C. Thornton & Z. Ning, Powder Technol. 99 (1998) 154-162; D. Maugis, J. Colloid Interface Sci. 150
(1992) 243; K. L. Johnson & J. A. Greenwood, J. Colloid Interface Sci. 192 (1997) 326; L. Kogut & I. Etsion,
J. Colloid Interface Sci. 261 (2003) 372 (adhesive elastic-plastic microcontacts, loading only); S. D. Mesarovic &
K. L. Johnson, J. Mech. Phys. Solids 48 (2000) 2009 (Maugis-Dugdale unloading of a flattened sphere).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from ..reference import maugis as md_ref
from . import flattening_kernel as fk
from .branch_laws import DUGDALE_FACTOR, make_summit_law

__all__ = ["PlasticBranchSummitLaw", "NODE_RATIO"]

#: Ratio of neighbouring tabulation radii of a Maugis-Dugdale summit (lambda steps of NODE_RATIO^(1/3)).
NODE_RATIO = math.sqrt(2.0)
#: Points of the flattening table in D = delta_max - delta_y.
FLATTENING_POINTS = 400


class PlasticBranchSummitLaw:
    """One summit's Thornton-Ning construction on law `name` ('jkr', 'maugis_dugdale', 'dmt'): tip radius beta
    (m), work of adhesion w > 0 (J/m^2), contact modulus E* (Pa), limiting contact pressure p_y (Pa; inf:
    elastic), interaction range z0 (m, Maugis-Dugdale), table range delta_max (m). Vectorised over summits."""

    #: the law has a compiled form (`continuum.rough.plastic_kernel`)
    compiled_form = True

    def __init__(self, name: str, radius: float, work_of_adhesion: float, e_star: float, limiting_pressure: float,
                 *, z0: float = 0.3e-9, delta_max: float):
        if not work_of_adhesion > 0.0:
            raise ValueError(f"work_of_adhesion = {work_of_adhesion!r}: the adhesive plastic summit needs w > 0")
        self.name, self.radius, self.work_of_adhesion = name, float(radius), float(work_of_adhesion)
        self.e_star, self.limiting_pressure, self.z0 = float(e_star), float(limiting_pressure), float(z0)
        self.delta_max = float(delta_max)
        self.sigma0 = DUGDALE_FACTOR * self.work_of_adhesion / self.z0
        self.self_similar = name in ("jkr", "dmt")
        self.node_ratio = NODE_RATIO
        self._laws = [self._law(self.radius)]
        self._kind = fk.LAW_CODES[name]
        base = self._laws[0]
        #: stretch (m) at which the approach branch starts to pull (Maugis-Dugdale: h0; JKR, DMT: 0)
        self.approach_reach = float(base.reach)
        self.plastic_slope = math.pi * self.limiting_pressure * self.radius
        if math.isinf(self.limiting_pressure):
            self.yield_radius = self.yield_force = self.yield_approach = math.inf
            self._d = np.zeros(1)
            self.max_stretch = max(self.approach_reach, -float(base.delta_out))
            return
        a_y = self._yield_radius()
        f_y, d_y = self.force_approach(a_y, self.radius)
        if not d_y > base.delta_in:
            raise ValueError(f"limiting pressure {self.limiting_pressure:.4g} Pa: the summit would yield before it "
                             f"snaps into contact (delta_y {d_y:.3g} m <= delta_in {base.delta_in:.3g} m)")
        self.yield_radius, self.yield_force, self.yield_approach = a_y, f_y, d_y
        self._u_y = float(base.energy(d_y, "retreat"))
        d_top = max(self.delta_max - d_y, 0.0)
        self._d = d_top * np.linspace(0.0, 1.0, FLATTENING_POINTS) ** 2
        r_p, d_p = fk.flattening_table(self._kind, self.radius, a_y, f_y, d_y, self.plastic_slope, self._d,
                                       self.work_of_adhesion, self.e_star, self.sigma0)
        self._r_p, self._d_p = r_p, d_p
        while not self.self_similar and self._laws[-1].radius_tip < r_p[-1]:
            self._laws.append(self._law(self.radius * NODE_RATIO ** len(self._laws)))
        self.max_stretch = max(self.approach_reach, float(np.max(-self.jump_out(r_p))))

    # ------------------------------------------------------------------ the elastic law on radius R
    def _law(self, radius):
        return make_summit_law(self.name, radius, self.work_of_adhesion, self.e_star, z0=self.z0,
                               delta_max=self.delta_max)

    def _lambda(self, radius):
        return float(md_ref.md_parameter(radius, self.work_of_adhesion, self.e_star, self.sigma0))

    def force_approach(self, a: float, radius: float) -> tuple[float, float]:
        """(F N, delta m) of L's contact of radius a (m) on a sphere of radius `radius` (m)."""
        f, d = fk.force_approach(self._kind, float(a), float(radius), self.work_of_adhesion, self.e_star,
                                 self.sigma0)
        return float(f), float(d)

    def centre_pressure(self, a: float, radius: float) -> float:
        """Pressure (Pa, + compressive) at the centre of L's contact of radius a (m) on radius `radius` (m)."""
        w, e = self.work_of_adhesion, self.e_star
        hertz = 2.0 * e * a / (math.pi * radius)
        if self.name == "jkr":
            return hertz - math.sqrt(2.0 * w * e / (math.pi * a))
        if self.name == "dmt":
            return hertz
        a_s = float(md_ref.md_scales(radius, w, e)[0])
        m = float(md_ref.md_m_of_A(a / a_s, self._lambda(radius)))
        return hertz - self.sigma0 / math.pi * math.acos(min(max(2.0 / (m * m) - 1.0, -1.0), 1.0))

    def _yield_radius(self) -> float:
        beta, p_y = self.radius, self.limiting_pressure
        lo = 1e-6 * math.pi * beta * p_y / (2.0 * self.e_star)
        hi = math.pi * beta * p_y / self.e_star
        while self.centre_pressure(hi, beta) < p_y:
            hi *= 2.0
        if self.centre_pressure(lo, beta) >= p_y:
            raise ValueError(f"limiting pressure {p_y:.4g} Pa: below the summit's adhesive stress at first contact")
        return brentq(lambda a: self.centre_pressure(a, beta) - p_y, lo, hi, xtol=1e-16 * hi, rtol=1e-13)

    # ------------------------------------------------------------------ the curve of radius R_p
    def _nodes(self, r_p):
        """(index k, weight t of node k+1) of each R_p between the tabulation radii (k = 0, t = 0 at beta)."""
        s = np.asarray(r_p, float) / self.radius
        if self.self_similar or len(self._laws) == 1:
            return np.zeros(s.shape, int), np.zeros(s.shape)
        x = np.log(np.maximum(s, 1.0)) / math.log(NODE_RATIO)
        k = np.minimum(np.floor(x).astype(int), len(self._laws) - 2)
        return k, np.clip(x - k, 0.0, 1.0)

    def _scaled(self, fn, eps, r_p, *args):
        """Weighted mean over the bracketing nodes of law_k's `fn`(delta, ...) at eps (m) scaled from R_p to R_k:
        delta_k = eps (R_k/R_p)^{1/3}; forces scale as R, energies as R^{4/3} (returned per `fn`'s kind)."""
        eps, r_p = np.broadcast_arrays(np.asarray(eps, float), np.asarray(r_p, float))
        if np.all(r_p == self.radius):       # unflattened summits: node 0's own curve, scale 1
            return np.asarray(fn(self._laws[0], eps, np.ones(eps.shape)), float) * np.ones(eps.shape)
        k, t = self._nodes(r_p)
        out = np.zeros(eps.shape)
        for kk in np.unique(k):
            sel = k == kk
            for j, wgt in ((kk, 1.0 - t[sel]), (kk + 1, t[sel])):
                if j >= len(self._laws) or not np.any(wgt):
                    continue
                law = self._laws[j]
                s = r_p[sel] / law.radius_tip                       # R_p / R_k
                out[sel] += wgt * fn(law, eps[sel] / np.cbrt(s), s)
        return out

    def branch_force(self, eps, r_p, branch: str):
        """Force (N) of a summit flattened to R_p at eps = delta - delta_p (m) on `branch` ('approach'/'retreat')."""
        return self._scaled(lambda law, d, s: s * law.force(d, branch), eps, r_p)

    def branch_energy(self, eps, r_p, branch: str):
        """Stored energy (J) on `branch`, zero for the free summit."""
        return self._scaled(lambda law, d, s: s ** (4.0 / 3.0) * law.energy(d, branch), eps, r_p)

    def jump_in(self, r_p):
        """delta_in (m, relative to delta_p): the approach branch jumps onto the retreat branch there."""
        return self._scaled(lambda law, d, s: np.cbrt(s) * law.delta_in, np.zeros_like(np.asarray(r_p, float)), r_p)

    def jump_out(self, r_p):
        """delta_out (m, relative to delta_p, <= delta_in): the retreat branch lets go there."""
        return self._scaled(lambda law, d, s: np.cbrt(s) * law.delta_out, np.zeros_like(np.asarray(r_p, float)),
                            r_p)

    def reach_of(self, r_p):
        """Stretch (m) below delta_p beyond which a summit flattened to R_p exerts nothing on approach: exact for
        the self-similar laws (JKR, DMT: 0), and for Maugis-Dugdale the bound cbrt(R_p) max_k reach_k/cbrt(R_k)
        over the tabulation radii (a node's curve scaled to R_p reaches cbrt(R_p/R_k) reach_k, and the mean curve
        pulls where either bracketing node does), which grows with R_p, so the attracting summits of a mean field
        are those above one edge."""
        r_p = np.asarray(r_p, float)
        ratio = max(law.reach / np.cbrt(law.radius_tip) for law in self._laws)
        return np.cbrt(r_p) * ratio

    def in_switch(self, r_p):
        """U_A - U_R (J) at delta_in: booked when a summit jumps in (0 at a tabulation radius)."""
        e = self.jump_in(r_p)
        return self.branch_energy(e, r_p, "approach") - self.branch_energy(e, r_p, "retreat")

    def out_switch(self, r_p):
        """U_R - U_A (J) at delta_out: booked when a summit lets go."""
        e = self.jump_out(r_p)
        return self.branch_energy(e, r_p, "retreat") - self.branch_energy(e, r_p, "approach")

    # ------------------------------------------------------------------ plastic state
    def flattening(self, delta_max):
        """(R_p, delta_p) (m) after the deepest approach delta_max (m): (beta, 0) unyielded."""
        dm = np.asarray(delta_max, float)
        if not math.isfinite(self.yield_approach):
            return np.full(dm.shape, self.radius), np.zeros(dm.shape)
        over = np.maximum(dm - self.yield_approach, 0.0)
        if np.any(over > self._d[-1] * (1.0 + 1e-12)):
            raise ValueError(f"plastic summit: approach {float(np.max(dm)):.3g} m beyond the law's table "
                             f"({self.delta_max:.3g} m)")
        r_p, d_p = np.full(dm.shape, self.radius), np.zeros(dm.shape)
        yielded = over > 0.0
        if np.any(yielded):
            r_p[yielded] = np.interp(over[yielded], self._d, self._r_p)
            d_p[yielded] = np.interp(over[yielded], self._d, self._d_p)
        return r_p, d_p

    def range_radius_ratio(self, delta_max):
        """a*/R_p (yielded) or a/beta (elastic) at the deepest state delta_max (m): the strain the law is used at."""
        dm = np.asarray(delta_max, float)
        r_p, d_p = self.flattening(dm)
        a = np.sqrt(np.maximum(self.branch_contact(dm - d_p, r_p), 0.0))
        return a / r_p

    def branch_contact(self, eps, r_p):
        """Squared true contact radius (m^2) on the retreat branch at eps."""
        return self._scaled(lambda law, d, s: np.cbrt(s) ** 4 * law.contact_radius(d, "retreat") ** 2, eps, r_p)

    def plastic_work(self, delta_max):
        """W_p (J) absorbed by a summit loaded to delta_max (m): W_in - the stored energy at the deepest state."""
        dm = np.asarray(delta_max, float)
        if not math.isfinite(self.yield_approach):
            return np.zeros(dm.shape)
        d = np.maximum(dm - self.yield_approach, 0.0)
        w_in = self._u_y + self.yield_force * d + 0.5 * self.plastic_slope * d * d
        r_p, d_p = self.flattening(np.maximum(dm, self.yield_approach))
        stored = self.branch_energy(np.maximum(dm, self.yield_approach) - d_p, r_p, "retreat")
        return np.where(d > 0.0, w_in - stored, 0.0)

    def state(self, delta, delta_max, attached):
        """(force N, stored energy J) of summits at approach delta (m) with deepest approach delta_max (m) on the
        retreat branch (`attached`) or the approach branch; on the plastic line (delta = delta_max > delta_y)
        the force is Thornton-Ning's F_y + pi p_y beta (delta - delta_y)."""
        delta, dm, att = np.broadcast_arrays(np.asarray(delta, float), np.asarray(delta_max, float),
                                             np.asarray(attached, bool))
        r_p, d_p = self.flattening(dm)
        eps = delta - d_p
        f = np.where(att, self.branch_force(eps, r_p, "retreat"), self.branch_force(eps, r_p, "approach"))
        u = np.where(att, self.branch_energy(eps, r_p, "retreat"), self.branch_energy(eps, r_p, "approach"))
        line = att & (delta >= dm) & (dm > self.yield_approach)
        if np.any(line):
            f = np.where(line, self.yield_force + self.plastic_slope * (delta - self.yield_approach), f)
        return f, u

    def describe(self) -> dict:
        return {"name": f"thornton_ning_{self.name}_summit", "summit_law": self.name, "radius": self.radius,
                "work_of_adhesion": self.work_of_adhesion, "e_star": self.e_star,
                "limiting_pressure": self.limiting_pressure, "yield_radius": self.yield_radius,
                "yield_force": self.yield_force, "yield_approach": self.yield_approach,
                "plastic_slope": self.plastic_slope, "tabulation_radii": [law.radius_tip for law in self._laws],
                "source": f"Thornton & Ning (1998) construction on the {self.name} summit law: elastic to a centre "
                          "pressure p_y, plastic line pi p_y beta, unloading on the law's curve of the flattened "
                          "radius R_p through (a*, F*), shifted by delta_p, with its own jumps "
                          "(continuum.rough.plastic_branches)"}
