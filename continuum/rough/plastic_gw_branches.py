"""GW mean field of adhesive elastic-plastic summits on any summit law of the Tabor range (Maugis-Dugdale, DMT).

What it is
----------
`continuum.rough.plastic_summits.PlasticGWSurface` sums Thornton-Ning JKR summits, which touch and let go at the
flattened summit's own surface and its fold. Its generalisation here sums `PlasticBranchSummitLaw` summits
(`continuum.rough.plastic_branches`: Thornton & Ning's construction applied to the law's own loop), which also
feel the approach branch's attraction before contact (Maugis-Dugdale: out to the reach h(R_p)) and jump in and
out at the law's jump points of their flattened radius, delta_p + delta_in(R_p) and delta_p + delta_out(R_p).

History (d, d_c, d_p) as for JKR summits, with one more number: d_0, the deepest separation before this contact
(`PlasticGWPunch` keeps it). A summit of height z has u = z - d_p, approach delta = u - (d - d_p), flattening
(R_p(u), delta_p(u)) (virgin for u <= 0: the summits below d_p were never pressed). The contact is one monotonic
approach then one monotonic retreat, so

    met in this contact   <=>  m(u) = u - delta_p(u) - delta_in(R_p(u))  >= d_c - d_p,
    not yet let go        <=>  h(u) = u - delta_p(u) - delta_out(R_p(u)) >  d - d_p,
    attracting (unattached) <=> r(u) = u - delta_p(u) + reach(R_p(u))    >  d - d_p.

(A summit that deepened in this contact met it with its earlier flattening, yet the condition holds in u: it
was pressed past u >= 0 >= delta_in at d_p, hence met; one that did not deepen has u = u_0.) m, h, r increase
in u (delta_p grows more slowly than u, the jump points and the reach grow with R_p; tested), so the attached
summits are u >= u_att = max(u_m, u_h) (retreat branch R, Thornton-Ning's line where delta = u > delta_y) and the
attracting ones u_r < u < u_att (approach branch A):

    p = n [ int_{u_r}^{u_att} F_A + int_{u_att}^{z_top - d_p} F_R ] phi(d_p + u) du,   E likewise with U_A, U_R.

Losses: the plastic work W_p(d_p) - W_p(d_0), the jump-in terms U_A - U_R of every summit met in this contact,
at the flattening it met with (R_p(u_0), u_0 = u - (d_0 - d_p)), and the jump-out terms U_R - U_A of those that
let go (R_p(u)); work = stored + losses exactly, as on each discrete summit (`continuum.laws.plastic_rough.
PlasticSummitsPunch`), so the driver's energy audit tests the motion against them. With p_y = inf every summit is
the elastic law's and the sums are the elastic GW mean field of that law (`continuum.rough.gw_branches`, threshold
zeta = d_c + delta_in; tested to 1e-7).

Speed: a law with a compiled form (`compiled_form`, `continuum.rough.plastic_kernel`'s tables) has its edges and
its sums over each summit set evaluated by `continuum.rough.plastic_gw_kernel` (one compiled call per set, the
same nodes, weights and summit states); `compiled = False` on an instance keeps the NumPy form, the reference the
compiled one is tested against. With compiled sums the contact law (`continuum.laws.plastic_rough.PlasticGWPunch`)
also runs whole contacts in the compiled contact phase (`plastic_gw_kernel.law_value`, kernel kind
`LAW_PLASTIC_GW`); its edges at the top summit (`release_separation`, `touch_separation`) then use the compiled edge
functions, so both paths find the same release gap.

Quadrature: the same geometric Gauss-Legendre panels in u as the JKR surface, from each set's lower edge, with its
lower truncation and node bound (`PlasticGWSurface`). The summit law is tabulated to its `delta_max`; a trial stage
of the integrator deeper than that evaluates the summits with the flattening at the table's end, and an accepted
state there is refused (`check_depth`), as on the discrete roller.

Sources: C. Thornton & Z. Ning, Powder Technol. 99 (1998) 154-162; J. A. Greenwood & J. B. P. Williamson, Proc. R.
Soc. Lond. A 295 (1966) 300; D. Maugis, J. Colloid Interface Sci. 150 (1992) 243; S. D. Mesarovic & K. L. Johnson,
J. Mech. Phys. Solids 48 (2000) 2009.
"""
from __future__ import annotations

import math

import numpy as np

from . import plastic_gw_kernel as kernel
from .plastic_kernel import _law_tables
from .plastic_summits import _GL_W, _GL_X, PlasticGWSurface, RollerFootprint

__all__ = ["PlasticBranchGWSurface", "BranchRollerFootprint"]


def _at(fn, r):
    return float(np.asarray(fn(np.array([r])), float)[0])


class PlasticBranchGWSurface(PlasticGWSurface):
    """GW mean field of `PlasticBranchSummitLaw` summits: Gaussian heights of rms sigma (m), density n (1/m^2),
    truncated at z_max sigma. Values per unit nominal area, functions of (d, d_c, d_p) and, for the losses, d_0."""

    #: the tabulated laws are piecewise linear between their table points: panels of sigma/8 keep the quadrature
    #: within 1e-7 of the exact integral of the table (tests/continuum/test_plastic_mean_field.py)
    panel_width = 0.125
    #: the compiled sums interpolate the footprint kernel's 24-node sum in a table (`plastic_gw_kernel.
    #: footprint_table`, within 1e-12 of the sum) over z_top - z up to FOOTPRINT_DEPTH u_table + FOOTPRINT_MARGIN
    #: sigma; False (on the class, before a surface is built): they sum it at every node, as the NumPy form does
    footprint_tabulated = True
    FOOTPRINT_DEPTH, FOOTPRINT_MARGIN = 1.1, 10.0

    def __init__(self, law, sigma: float, density: float, z_max: float, *footprint):
        super().__init__(law, sigma, density, z_max, *footprint)      # (radius, length) of a `RollerFootprint`
        beta = law.radius
        self._in0, self._out0 = _at(law.jump_in, beta), _at(law.jump_out, beta)
        self._reach0 = _at(law.reach_of, beta)
        #: deepest approach the summit law is tabulated to (m)
        self.u_table = float(getattr(law, "delta_max", math.inf))
        #: sums and edges by the compiled kernel (`plastic_gw_kernel`); False: the NumPy form (the reference)
        self.compiled = bool(getattr(law, "compiled_form", False)) and math.isfinite(self.u_table)
        if self.compiled:
            self._P, tables = _law_tables(law)
            none = np.zeros(1)              # the kernel's tables, without the discrete summits' own rows
            self._T = (none, none, *tables[:3], none, *tables[3:])
            self._reach_ratio = _at(law.reach_of, 1.0)          # reach(R_p) = cbrt(R_p) * ratio
            self._footprint = isinstance(self, RollerFootprint)
            tx, tw = getattr(self, "_tx", np.empty(0)), getattr(self, "_tw", np.empty(0))
            # the footprint kernel's node sum tabulated over the depths a contact reaches (the summit law's table
            # and the reach below it); deeper nodes sum it directly
            kt = (kernel.footprint_table(self.z_top, self.sigma, self.FOOTPRINT_DEPTH * self.u_table
                                         + self.FOOTPRINT_MARGIN * self.sigma, tx, tw)
                  if self._footprint and self.footprint_tabulated else np.empty(0))
            self._tx_tw = (tx, tw, kt)
            self._C = np.array([self._first, self.panel_width * self.sigma, float(self._root_at_top), self.u_table,
                                self.density, self.sigma, self.z_top, getattr(self, "length", 0.0),
                                getattr(self, "roller_radius", 0.0), self._reach_ratio, self.z_floor,
                                float(self._clip_floor), self._in0, self._out0, self._reach0])

    def _inverse_edge(self, kind: int, method, value, offset):
        """`_inverse` of edge `kind` (`plastic_gw_kernel.edge`: 0 recovery, 1 met, 2 hold, 3 reach), compiled if so."""
        if self.compiled:
            return kernel.inverse(kind, value, offset, self._C, self._P, self._T)
        return self._inverse(method, value, offset)

    # ------------------------------------------------------------------ summit sets
    def _flat(self, u):
        """(R_p, delta_p) of summits of deepest approach u (m): virgin below 0, the table's end beyond it."""
        return self.law.flattening(np.clip(np.asarray(u, float), 0.0, self.u_table))

    def recovery(self, u):
        """g(u) = u - delta_p(u): summit u is touched (eps = 0, where the law's curve has a kink) at d - d_p = g(u)."""
        return np.asarray(u, float) - self._flat(u)[1]

    def met_edge(self, u):
        """m(u) = u - delta_p - delta_in(R_p): summit u met this contact iff m(u) >= d_c - d_p."""
        r_p, d_p = self._flat(u)
        return np.asarray(u, float) - d_p - self.law.jump_in(r_p)

    def hold(self, u):
        """h(u) = u - delta_p - delta_out(R_p): summit u, met, holds while h(u) > d - d_p."""
        r_p, d_p = self._flat(u)
        return np.asarray(u, float) - d_p - self.law.jump_out(r_p)

    def reach_edge(self, u):
        """r(u) = u - delta_p + reach(R_p): summit u attracts while r(u) > d - d_p."""
        r_p, d_p = self._flat(u)
        return np.asarray(u, float) - d_p + self.law.reach_of(r_p)

    def sets(self, d, d_c, d_p):
        """(u_att, u_r) (m): summits u >= u_att are attached, u_r < u < u_att on the approach branch."""
        u_met = (self._inverse_edge(1, self.met_edge, d_c - d_p, -self._in0) if math.isfinite(d_c)
                 else math.inf)
        if not math.isfinite(d):
            return math.inf, math.inf
        u_held = self._inverse_edge(2, self.hold, d - d_p, -self._out0)
        return max(u_met, u_held), self._inverse_edge(3, self.reach_edge, d - d_p, self._reach0)

    # ------------------------------------------------------------------ values
    def _values(self, d, d_c, d_p, weight):
        if self.compiled:
            return kernel.state_values(d, d_c, d_p, weight is not PlasticGWSurface._weight and self._footprint,
                                       self._C, self._offsets(), _GL_X, _GL_W, *self._tx_tw, self._P, self._T)
        u_att, u_r = self.sets(d, d_c, d_p)
        touch = (self._inverse(self.recovery, d - d_p, 0.0),)     # the summits at eps = 0: the curves' kink
        p = energy = count = 0.0
        for lo, hi, attached in ((u_att, math.inf, True), (u_r, u_att, False)):
            u, w = self._nodes(*self._span(lo, d_p, hi), breaks=touch)
            if u.size == 0:
                continue
            q = weight(self, u, w, d_p)
            f, en = self._summits(u - (d - d_p), np.clip(u, 0.0, self.u_table), attached)
            p, energy = p + float(q @ f), energy + float(q @ en)
            count += float(q.sum()) if attached else 0.0
        return p, energy, count

    def _set_sum(self, what, lo, hi, d_p, shift):
        """`plastic_gw_kernel.set_sum` of `what` over the summits lo < u < hi (m), this surface's weight."""
        return kernel.span_sum(what, lo, hi, math.nan, d_p, shift, self._footprint, self._C, self._offsets(), _GL_X,
                                _GL_W, *self._tx_tw, self._P, self._T)

    def _summits(self, delta, delta_max, attached: bool):
        """(force N, stored energy J) of summits at approach delta (m), deepest approach delta_max (m), all on the
        retreat branch (`attached`) or all on the approach branch: `PlasticBranchSummitLaw.state` for one branch."""
        law = self.law
        r_p, d_p = law.flattening(delta_max)
        branch = "retreat" if attached else "approach"
        eps = delta - d_p
        f, en = law.branch_force(eps, r_p, branch), law.branch_energy(eps, r_p, branch)
        if attached and math.isfinite(law.yield_approach):
            line = (delta >= delta_max) & (delta_max > law.yield_approach)
            f = np.where(line, law.yield_force + law.plastic_slope * (delta - law.yield_approach), f)
        return f, en

    def state(self, d, d_c, d_p):
        """(pressure Pa (+ compressive), stored energy J/m^2, attached summits 1/m^2) at separation d (m)."""
        return self._values(d, d_c, d_p, type(self)._weight)

    def axis_state(self, d, d_c, d_p):
        """(pressure Pa, contacts 1/m^2) with the Gaussian density whatever this surface's weight."""
        p, _, count = self._values(d, d_c, d_p, PlasticGWSurface._weight)
        return p, count

    def plastic_work(self, d_p):
        if self.compiled:
            return self._set_sum(kernel.PLASTIC_WORK, max(self.law.yield_approach, 0.0), math.inf, d_p, 0.0)[0]
        u, w = self._nodes(*self._span(max(self.law.yield_approach, 0.0), d_p))
        return float(self._weight(u, w, d_p) @ self.law.plastic_work(np.minimum(u, self.u_table))) if u.size else 0.0

    def jumps(self, d, d_c, d_p, d_0):
        """Jump terms (J/m^2) booked in this contact at separation d (m): U_A - U_R of every summit met (at the
        flattening it met with, from d_0, the deepest separation before the contact) and U_R - U_A of those that
        let go."""
        if not math.isfinite(d_c):
            return 0.0
        u_met = self._inverse_edge(1, self.met_edge, d_c - d_p, -self._in0)
        if self.compiled:
            u_held = self._inverse_edge(2, self.hold, d - d_p, -self._out0) if math.isfinite(d) else math.inf
            return (self._set_sum(kernel.IN_SWITCH, u_met, math.inf, d_p, d_0 - d_p)[0]
                    + self._set_sum(kernel.OUT_SWITCH, u_met, max(u_held, u_met), d_p, 0.0)[0])
        u, w = self._nodes(*self._span(u_met, d_p))
        if u.size == 0:
            return 0.0
        total = float(self._weight(u, w, d_p) @ self.law.in_switch(self._flat(u - (d_0 - d_p))[0]))
        u_held = self._inverse(self.hold, d - d_p, -self._out0) if math.isfinite(d) else math.inf
        u, w = self._nodes(*self._span(u_met, d_p, max(u_held, u_met)))
        if u.size:
            total += float(self._weight(u, w, d_p) @ self.law.out_switch(self._flat(u)[0]))
        return total

    def released(self, d, d_c, d_p):
        raise TypeError("PlasticBranchGWSurface books its jumps with `jumps(d, d_c, d_p, d_0)`")

    # ------------------------------------------------------------------ contact ends
    def _edge(self, kind: int, method, u):
        """Edge function `kind` (`plastic_gw_kernel.edge`) at u, compiled if so (the compiled contact phase then
        finds the same release gap, `plastic_gw_kernel.law_release_gap`)."""
        if self.compiled:
            return kernel.edge(u, kind, self.u_table, self._reach_ratio, self._P, self._T)
        return float(method(u))

    def release_separation(self, d_c, d_p):
        """d - d_p (m) beyond which no summit holds or attracts (d_c = inf: none met yet)."""
        u_top = self.z_top - d_p
        edge = self._edge(3, self.reach_edge, u_top)
        return max(self._edge(2, self.hold, u_top), edge) if math.isfinite(d_c) else edge

    def touch_separation(self, d_p):
        """d - d_p (m) at which the tallest summit starts to attract."""
        return self._edge(3, self.reach_edge, self.z_top - d_p)

    def check_depth(self, d_p):
        if self.z_top - d_p > self.u_table * (1.0 + 1e-12):
            raise ValueError(f"plastic summits: approach {self.z_top - d_p:.3g} m beyond the summit law's table "
                             f"({self.u_table:.3g} m)")


class BranchRollerFootprint(PlasticBranchGWSurface, RollerFootprint):
    """The same summits under a rigid roller of radius R and length l (m): `RollerFootprint`'s kernel K(z) in place
    of phi (the footprint integral, values per roller), the sets and losses of `PlasticBranchGWSurface`."""
