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

from ..physics import jkr_kernel as jk
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
        # scalar path (the driver calls the law one value at a time): the JKR kernel's scalar root in
        # s = sqrt(a/a0), the one the discrete summits use (compiled there), so P, U and dP/d delta are explicit
        self._delta0 = float(ref.approach_scale(radius, work_of_adhesion, e_star))   # the reference's, bit for bit
        self._pscale = math.pi * work_of_adhesion * radius           # P = pscale s^3 (8/3 s^3 - 4)
        self._cache: tuple[float | None, float, float] = (None, 0.0, 1.0)

    def _delta(self, gap):
        # Trial steps of the integrator may overshoot the release event slightly; the stable
        # branch ends at -delta_c, so clamp there (the event ends the contact before it matters).
        return max(-gap, -self.delta_c)

    def _root(self, delta: float) -> tuple[float, float]:
        """(d, s) on the stable branch at approach delta (m): d = delta/delta0 clamped to the fold and
        s = sqrt(a/a0), by `continuum.physics.jkr_kernel.stable_root_scalar` (cached for the last delta). Within
        1e-6 delta_c of the fold, where the root is double and the scalar root skips its polish, the reference's
        checked root (`solve_s`, two polishes) is used instead."""
        if self._cache[0] != delta:
            d, s = jk.stable_root_scalar(delta / self._delta0)
            if delta + self.delta_c < 1e-6 * self.delta_c:
                s = float(jk.solve_s(d, "stable")[0])
            self._cache = (delta, d, s)
        return self._cache[1], self._cache[2]

    def force(self, gap):
        _, s = self._root(self._delta(gap))
        s3 = s * s * s
        return self._pscale * s3 * (8.0 / 3.0 * s3 - 4.0)

    def stiffness(self, gap):
        delta = self._delta(gap)
        if delta <= -self.delta_c:
            return -math.inf  # the stable branch's dP/d(delta) diverges to -inf at the fold
        _, s = self._root(delta)
        s3 = s * s * s
        if 4.0 * s3 - 1.0 <= 0.0:   # within rounding of the fold, where the root is double
            return -math.inf
        return float(jk.stiffness_of_s(s, s3, self._pscale / self._delta0))

    def stored_energy(self, gap):
        d, s = self._root(self._delta(gap))
        return float(jk.energy_of_s(d, s, self._pscale * self._delta0))

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
