"""A smooth sphere on the approach and retreat branches of a tabulated adhesive law (DMT, Maugis-Dugdale).

What it is
----------
The sphere (radius R, contact modulus E*, work of adhesion w) follows the branches of
`continuum.rough.branch_laws.SummitLaw` (the same construction the rough model's summits use):
approach branch A from the free state (force zero beyond the reach h0 of the attraction; DMT and JKR
have no reach), with its jump in at delta_in; after the deepest approach has passed delta_in, the
retreat branch R down to its jump out at delta_out, then A again (for Maugis-Dugdale the non-contact
cohesive zone still pulls until the reach). The contact ends where the force ends: at max(-delta_out,
h0) in gap on retreat. Under displacement control (the impact: the sphere carries on past the load
extremum) this is Maugis' (2000, §5.3) stability rule; load-controlled release is not defined for
these branches.

Why: the Tabor parameter mu = (R w^2 / (E*^2 z0^3))^{1/3} of sub-micron spheres of stiff materials is
0.1-1, where JKR (mu > 5) overstates the loop and DMT (mu < 0.1) has none (Johnson & Greenwood, J.
Colloid Interface Sci. 192 (1997) 326). Maugis-Dugdale spans the range (Maugis, J. Colloid Interface
Sci. 150 (1992) 243).

Energy: the stored energy is the branch's own integral of P d(delta) (zero for the free sphere); the
loop energy U_R(delta_out) - U_A(delta_out) is dissipated at the jump out, booked from the law's
tabulated loop, so the driver's audit tests the motion against it. Branches are tabulated to an
approach of twice the Hertz impact depth plus ten JKR separations (rebuilt if a faster impact needs
more); a state beyond the table raises instead of extrapolating.
"""
from __future__ import annotations

import math

import numpy as np

from ..reference import jkr as jkr_ref
from .base import ContactLaw


class BranchSphere(ContactLaw):
    """Sphere of radius R (m), work of adhesion w > 0 (J/m^2), E* (Pa) under law `name` ('dmt' or
    'maugis_dugdale'; range z0 (m) of the attraction for Maugis-Dugdale)."""

    has_history = True
    bound_is_final = True  # attached, it moves along one branch; energy only falls, so it cannot leave later

    def __init__(self, name: str, radius: float, work_of_adhesion: float, e_star: float, z0: float):
        if name not in ("dmt", "maugis_dugdale"):
            raise ValueError(f"law {name!r}: 'dmt' or 'maugis_dugdale'")
        self.name = f"{name}_sphere"
        self.law_name, self.radius, self.work_of_adhesion, self.e_star, self.z0 = (
            name, float(radius), float(work_of_adhesion), float(e_star), float(z0))
        self._delta_c = float(jkr_ref.critical_approach(radius, work_of_adhesion, e_star))
        self.law = None
        self._build(10.0 * self._delta_c)
        self.touch_gap = self.law.reach
        self.reset()

    def _build(self, delta_max: float) -> None:
        from ..rough.branch_laws import make_summit_law
        self.law = make_summit_law(self.law_name, self.radius, self.work_of_adhesion, self.e_star, z0=self.z0,
                                   delta_max=delta_max)
        self._tables = {k: (b.delta, b.force, b.energy) for k, b in (("approach", self.law.approach),
                                                                      ("retreat", self.law.retreat))}

    def prepare(self, mass, speed, gravity):
        hertz = (15.0 * mass * speed**2 / (16.0 * self.e_star * math.sqrt(self.radius))) ** 0.4
        need = 2.0 * hertz + 10.0 * self._delta_c
        if need > self.law.delta_max:
            self._build(need)

    def reset(self):
        self._retreat = False      # on R (the deepest approach of this contact passed delta_in)
        self._jumped_in = False    # this contact has been on R: it ends at the jump out or at the reach
        self._loss = 0.0           # loops completed in this contact (J)

    def _branch(self, delta: float) -> str:
        return "retreat" if self._retreat and delta >= self.law.delta_out else "approach"

    def _at(self, delta: float, column: int) -> float:
        table = self._tables[self._branch(delta)]
        return float(np.interp(delta, table[0], table[column]))

    # ------------------------------------------------------------------ ContactLaw
    def force(self, gap):
        return self._at(-gap, 1)

    def stiffness(self, gap):
        d, f, _ = self._tables[self._branch(-gap)]
        k = min(max(int(np.searchsorted(d, -gap)), 1), d.size - 1)
        return float((f[k] - f[k - 1]) / (d[k] - d[k - 1]))

    def stored_energy(self, gap):
        return self._at(-gap, 2)

    def dissipated(self, gap):
        jumping = self._retreat and -gap < self.law.delta_out
        return self._loss + (self.law.loop_energy if jumping else 0.0)

    def release_gap(self):
        return max(-self.law.delta_out, self.law.reach) if self._jumped_in else self.law.reach

    def on_release(self):
        return self.dissipated(self.release_gap() + 1.0)

    def accept(self, gap):
        delta = -gap
        if delta > self.law.delta_max:
            raise RuntimeError(f"{self.name}: approach {delta:.4g} m beyond the tabulated {self.law.delta_max:.4g} m")
        if not self._retreat and delta > self.law.delta_in:
            self._retreat = self._jumped_in = True
        elif self._retreat and delta < self.law.delta_out:
            self._retreat = False
            self._loss += self.law.loop_energy

    def length_scale(self, mass, speed):
        hertz = (15.0 * mass * speed**2 / (16.0 * self.e_star * math.sqrt(self.radius))) ** 0.4
        return max(hertz, self.law.reach, abs(self.law.delta_out), self._delta_c)

    def describe(self):
        return {**self.law.describe(), "name": self.name, "law": self.law_name, "z0": self.z0,
                "detachment": "displacement", "touch_gap": self.touch_gap,
                "source": "Maugis (1992) / DMT (1975) branches with fold-following jumps "
                          "(continuum/rough/branch_laws.py), Johnson & Greenwood (1997) Dugdale stress"}
