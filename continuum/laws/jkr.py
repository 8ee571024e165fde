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
        # scalar fast path (the driver calls the law one value at a time); see _sqrt_radius
        self._k = 4.0 * e_star / 3.0
        self._adh = math.sqrt(8.0 * math.pi * work_of_adhesion * e_star)
        self._c = math.sqrt(2.0 * math.pi * work_of_adhesion / e_star)
        self._u_fold = (radius * self._c / 4.0) ** (1.0 / 3.0)
        a_touch = float(ref.contact_radius_at_touch(radius, work_of_adhesion, e_star))
        self._energy_at_touch = self._energy_of_radius(a_touch)
        self._cache = (None, self._u_fold)

    def _delta(self, gap):
        # Trial steps of the integrator may overshoot the release event slightly; the stable
        # branch ends at -delta_c, so clamp there (the event ends the contact before it matters).
        return max(-gap, -self.delta_c)

    def _p(self):
        return self.radius, self.work_of_adhesion, self.e_star

    def _sqrt_radius(self, delta: float) -> float:
        """u = sqrt(a) on the stable branch: largest root of u^4 - c beta u - beta delta = 0.

        Newton's method on this convex quartic converges monotonically to the largest root from
        any start right of the fold u_c (where d delta/da = 0), so it is warm-started from the
        previous call. Within 1e-6 delta_c of the fold the root is double and Newton slows down:
        there the reference's closed-form (Ferrari) solution is used instead.
        """
        if self._cache[0] == delta:
            return self._cache[1]
        if delta + self.delta_c < 1e-6 * self.delta_c:
            u = math.sqrt(float(ref.radius_from_approach(delta, *self._p())))
        else:
            beta = self.radius
            u = jk.sqrt_radius_newton(delta, beta, self._c * beta, max(self._cache[1], self._u_fold * (1.0 + 1e-3),
                                                                      (2.0 * beta * max(delta, 0.0)) ** 0.25))
        self._cache = (delta, u)
        return u

    def force(self, gap):
        u = self._sqrt_radius(self._delta(gap))
        a = u * u
        return self._k * a * a * a / self.radius - self._adh * a * u

    def stiffness(self, gap):
        delta = self._delta(gap)
        if delta <= -self.delta_c:
            return -math.inf  # the stable branch's dP/d(delta) diverges to -inf at the fold
        a = self._sqrt_radius(delta) ** 2
        dp_da = 3.0 * self._k * a * a / self.radius - 1.5 * self._adh * math.sqrt(a)
        dd_da = 2.0 * a / self.radius - 0.5 * self._c / math.sqrt(a)
        return dp_da / dd_da

    def stored_energy(self, gap):
        a = self._sqrt_radius(self._delta(gap)) ** 2
        return self._energy_of_radius(a) - self._energy_at_touch

    def _energy_of_radius(self, a: float) -> float:
        """Antiderivative of P(a) d(delta)/da (J), `continuum.physics.jkr_kernel.energy_of_radius`."""
        return jk.energy_of_radius(a, self.radius, self._k, self._c, self._adh, self.work_of_adhesion)

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
