"""JKR single-asperity (sphere) contact with Fuller-Tabor hysteresis.

On approach the sphere feels nothing until delta = 0, where it jumps onto the JKR curve
(P = -8/9 P_c). It then follows the stable JKR branch both ways. On retreat it lets go at
delta = -delta_c under displacement control (the paper's choice; Fuller & Tabor 1975) or at
P = -P_c, delta = -0.4807 delta_c, under load control (documented option). The energy lost in
one cycle is the area between the branches: 0.93550 P_c delta_c or 0.46201 P_c delta_c.

Sources: Johnson, Kendall & Roberts, Proc. R. Soc. A 324 (1971) 301; Fuller & Tabor, Proc. R.
Soc. A 345 (1975) 327; Maugis, *Contact, Adhesion and Rupture of Elastic Solids* (2000) ch. 5.
"""
from __future__ import annotations

import math

from ..reference import jkr as ref
from .base import ContactLaw


class JKRSphere(ContactLaw):
    """JKR sphere of tip radius beta (m) with work of adhesion (J/m^2) and E* (Pa)."""

    name = "jkr_sphere"

    def __init__(self, radius: float, work_of_adhesion: float, e_star: float, detachment: str = "displacement"):
        if detachment not in ("displacement", "load"):
            raise ValueError(f"detachment = {detachment!r}: must be 'displacement' or 'load'")
        self.radius, self.work_of_adhesion, self.e_star = radius, work_of_adhesion, e_star
        self.detachment = detachment
        self.pull_off_force = float(ref.pull_off_force(radius, work_of_adhesion))
        self.delta_c = float(ref.critical_approach(radius, work_of_adhesion, e_star))
        if detachment == "displacement":
            self.detach_approach = -self.delta_c
        else:
            self.detach_approach = float(ref.load_controlled_detach_approach(radius, work_of_adhesion, e_star))
        self.loop_energy = float(ref.loop_area(radius, work_of_adhesion, e_star, detachment=detachment))

    def _delta(self, gap):
        # Trial steps of the integrator may overshoot the release event slightly; the stable
        # branch ends at -delta_c, so clamp there (the event ends the contact before it matters).
        return max(-gap, -self.delta_c)

    def _p(self):
        return self.radius, self.work_of_adhesion, self.e_star

    def force(self, gap):
        return float(ref.force_from_approach(self._delta(gap), *self._p()))

    def stiffness(self, gap):
        return float(ref.stiffness_from_approach(self._delta(gap), *self._p()))

    def stored_energy(self, gap):
        return float(ref.energy_from_approach(self._delta(gap), *self._p()))

    def release_gap(self):
        return -self.detach_approach

    def on_release(self):
        return self.loop_energy

    def length_scale(self, mass, speed):
        hertz = (15.0 * mass * speed**2 / (16.0 * self.e_star * math.sqrt(self.radius))) ** 0.4
        return max(hertz, self.delta_c)

    def escape_velocity(self, mass: float) -> float:
        """Speed (m/s) below which the loop energy exceeds the impact kinetic energy (no gravity)."""
        return math.sqrt(2.0 * self.loop_energy / mass)

    def describe(self):
        return {"name": self.name, "source": "JKR (1971); Fuller & Tabor (1975) hysteresis",
                "radius": self.radius, "work_of_adhesion": self.work_of_adhesion, "e_star": self.e_star,
                "detachment": self.detachment, "pull_off_force": self.pull_off_force,
                "delta_c": self.delta_c, "detach_approach": self.detach_approach,
                "loop_energy": self.loop_energy}
