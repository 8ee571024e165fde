"""A smooth sphere on the approach and retreat branches of a tabulated adhesive law (DMT, Maugis-Dugdale).

What it is
----------
The sphere (radius R, contact modulus E*, work of adhesion w) follows the branches of
`continuum.rough.branch_laws.SummitLaw` (the same construction the rough model's summits use). For
DMT, and for Maugis-Dugdale over the range of its Tabor parameter where `auto` picks it, the approach
branch jumps in where the attraction is first felt (delta_in = -h0, the reach of the Dugdale zone; 0
for DMT) and the retreat branch jumps out to the free state (delta_out <= -h0): the contact starts at
gap h0 on the retreat branch R (which, above delta_in, is the approach branch too) and ends at the
jump out, like JKR's. Under displacement control (the impact: the sphere carries on past the load
extremum) this is Maugis' (2000, §5.3) stability rule; load-controlled release is not defined for
these branches. A law whose jumps fall inside the force range (a jump in after a stretch of the
non-contact branch, or a jump out onto it) is refused: the driver locates jumps only at a contact's
start and end.

Why: the Tabor parameter mu = (R w^2 / (E*^2 z0^3))^{1/3} of sub-micron spheres of stiff materials is
0.1-1, where JKR (mu > 5) overstates the loop and DMT (mu < 0.1) has none (Johnson & Greenwood, J.
Colloid Interface Sci. 192 (1997) 326). Maugis-Dugdale spans the range (Maugis, J. Colloid Interface
Sci. 150 (1992) 243).

Energy: the stored energy is R's integral of P d(delta), zero at the touch (where A and R meet the free
state); the loop U_R(delta_out) - U_A(delta_out) = U_R(delta_out) is booked at the jump out from the
law's own representation of R (a C1 cubic through the table, see `_build`; `loop_energy_used`), so
the driver's audit tests the motion against it. Branches are tabulated to an approach of twice the
Hertz impact depth plus ten JKR separations (rebuilt if a faster impact needs more); a state beyond
the table raises instead of extrapolating.
"""
from __future__ import annotations

import math

import numpy as np

from ..reference import jkr as jkr_ref
from .base import ContactLaw


class BranchSphere(ContactLaw):
    """Sphere of radius R (m), work of adhesion w > 0 (J/m^2), E* (Pa) under law `name` ('dmt' or
    'maugis_dugdale'; range z0 (m) of the attraction for Maugis-Dugdale)."""

    bound_is_final = True  # on one elastic branch while attached: a lossless oscillation once it turns back
    #: Smallest distance between the nodes of the retreat branch's cubic, over the contact's length scale (_build).
    NODE_SPACING = 1e-4

    def __init__(self, name: str, radius: float, work_of_adhesion: float, e_star: float, z0: float):
        if name not in ("dmt", "maugis_dugdale"):
            raise ValueError(f"law {name!r}: 'dmt' or 'maugis_dugdale'")
        self.name = f"{name}_sphere"
        self.law_name, self.radius, self.work_of_adhesion, self.e_star, self.z0 = (
            name, float(radius), float(work_of_adhesion), float(e_star), float(z0))
        self._delta_c = float(jkr_ref.critical_approach(radius, work_of_adhesion, e_star))
        self._build(10.0 * self._delta_c)
        self.touch_gap = self.law.reach

    def _build(self, delta_max: float) -> None:
        from ..rough.branch_laws import make_summit_law
        law = make_summit_law(self.law_name, self.radius, self.work_of_adhesion, self.e_star, z0=self.z0,
                              delta_max=delta_max)
        scale = max(law.reach, self._delta_c)
        if law.delta_in > -law.reach + 1e-9 * scale or law.delta_out > -law.reach + 1e-9 * scale:
            raise ValueError(f"{self.name}: jumps inside the force range (delta_in = {law.delta_in:.4g} m, "
                             f"delta_out = {law.delta_out:.4g} m, reach {law.reach:.4g} m); not modelled")
        r = law.retreat
        # R starts at its fold (delta_out), where P - P_out ~ sqrt(delta - delta_out) and the table's segments
        # shrink to 1e-18 m (DMT's R begins with the free point below its jump instead). A contact of a sub-micron
        # sphere lasts ~1e-9 s, and the driver's clock resolves ~1e-16 t: segments that short, and the kinks of
        # a piecewise-linear force, ask for steps it cannot take. So the force is the shape-preserving cubic
        # (PCHIP, C1) through the table thinned to nodes `NODE_SPACING` of the contact's length scale apart, the
        # stored energy its exact antiderivative (the audit closes), and the loop booked is what R stores at the
        # release (`loop_energy_used`, recorded beside the table's).
        from scipy.interpolate import PchipInterpolator
        spacing = self.NODE_SPACING * scale
        keep, last = [], -np.inf
        for i in range(1 if r.force[0] == 0.0 else 0, r.delta.size):
            if r.delta[i] - last >= spacing or i == r.delta.size - 1:
                keep.append(i)
                last = r.delta[i]
        self.law = law
        self._force = PchipInterpolator(r.delta[keep], r.force[keep], extrapolate=True)
        self._slope, self._energy = self._force.derivative(), self._force.antiderivative()
        self._d0, self._d_end = float(r.delta[keep[0]]), float(r.delta[keep[-1]])
        self._u_touch = float(self._energy(-law.reach))        # stored energy zero at the touch (delta = -h0)
        self.loop_energy_used = self._u(self._d0)

    def _u(self, delta: float) -> float:
        return float(self._energy(delta)) - self._u_touch

    def prepare(self, mass, speed, gravity):
        hertz = (15.0 * mass * speed**2 / (16.0 * self.e_star * math.sqrt(self.radius))) ** 0.4
        need = 2.0 * hertz + 10.0 * self._delta_c
        if need > self.law.delta_max:
            self._build(need)

    # ------------------------------------------------------------------ ContactLaw
    def _delta(self, gap: float) -> float:
        delta = -gap
        if delta > self._d_end:
            raise RuntimeError(f"{self.name}: approach {delta:.4g} m beyond the tabulated {self._d_end:.4g} m")
        return max(delta, self._d0)        # trial steps may overshoot the release slightly

    def force(self, gap):
        return float(self._force(self._delta(gap)))

    def stiffness(self, gap):
        return float(self._slope(self._delta(gap)))

    def stored_energy(self, gap):
        return self._u(self._delta(gap))

    def release_gap(self):
        return -self._d0

    def on_release(self):
        """The loop: what R stores at the release (A, the free state there, stores nothing)."""
        return self.loop_energy_used

    def length_scale(self, mass, speed):
        hertz = (15.0 * mass * speed**2 / (16.0 * self.e_star * math.sqrt(self.radius))) ** 0.4
        return max(hertz, self.law.reach, abs(self._d0), self._delta_c)

    def describe(self):
        return {**self.law.describe(), "name": self.name, "law": self.law_name, "z0": self.z0,
                "detachment": "displacement", "touch_gap": self.touch_gap, "loop_energy_used": self.loop_energy_used,
                "source": "Maugis (1992) / DMT (1975) branches with fold-following jumps "
                          "(continuum/rough/branch_laws.py), Johnson & Greenwood (1997) Dugdale stress"}

