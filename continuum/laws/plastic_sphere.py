"""Adhesive elastic-plastic sphere (Thornton & Ning 1998) with the flattening carried between impacts.

What it is
----------
The contact law of `continuum.reference.thornton_ning` as a driver law: a sphere of radius R, work
of adhesion w and contact modulus E* against a flat, with limiting contact pressure p_y.

* Elastic loading is JKR on R (the contact forms at delta = 0 and jumps onto the JKR curve,
  `continuum.laws.jkr.JKRSphere`) up to the yield approach delta_y, where the JKR centre pressure
  reaches p_y (`thornton_ning.yield_radius`).
* Plastic loading follows the straight line F = F_y + pi p_y R (delta - delta_y), with
  a^2 = a_y^2 + R (delta - delta_y).
* Unloading (and elastic reloading) follows JKR about the flattened radius
  R_p = 4E*a*^3 / (3 (F* + sqrt(8 pi w E* a*^3))), shifted by the plastic approach
  delta_p = delta* - delta_JKR(a*; R_p), so that it passes through the maximum (delta*, F*).
  Reloading past delta* rejoins the plastic line (perfect plasticity: the same line).
* Detachment follows `physics.detachment` on the R_p branch (the fold, or P = -P_c(R_p)).

The flattening (R_p, delta_p, delta*) belongs to the body's contact spot, so it is kept from one
impact to the next (the driver calls `reset` before each contact; `forget_history` returns to
the virgin sphere). On a later impact the sphere meets the flattened spot at delta = delta_p
(gap -delta_p); until then it flies free. It jumps onto the JKR curve at the instant of that meeting,
known in closed form from the touch speed and gravity (`prepare`) and given to the driver as a time
event, so that no integrator step straddles the jump (a force discontinuity inside a step would
stall the step-size control).

Energy bookkeeping: the stored energy is the JKR energy of the current elastic branch from its
touch point (`continuum.reference.jkr.energy_from_radius`); the plastic loss of a contact is the
work done on it (JKR energy to delta_y plus the area under the plastic line) less the energy the
new unloading branch stores at delta*. The release books that loss plus the energy the branch
still stores at detachment (its Fuller-Tabor loop). Both are booked from the law's own terms,
so the driver's energy audit tests the motion against them.

Sources: C. Thornton & Z. Ning, Powder Technol. 99 (1998) 154-162; K. L. Johnson, K. Kendall &
A. D. Roberts, Proc. R. Soc. Lond. A 324 (1971) 301; K. N. G. Fuller & D. Tabor, Proc. R. Soc.
Lond. A 345 (1975) 327. Why this law and not Mesarovic-Johnson or Kogut-Etsion: see the docstring
of `continuum.reference.thornton_ning`.
"""
from __future__ import annotations

import math

from ..reference import jkr as ref
from ..reference import thornton_ning as tn
from .base import ContactLaw
from .jkr import JKRSphere


class PlasticJKRSphere(ContactLaw):
    """Thornton-Ning sphere: radius R (m), work of adhesion w > 0 (J/m^2), E* (Pa), limiting pressure p_y (Pa)."""

    name = "plastic_jkr_sphere"
    has_history = True
    time_dependent = True  # only to place the jump onto the flattened spot (time_events)
    bound_is_final = True  # attached, the law is elastic (JKR on R_p) below delta*, which it cannot pass again

    def __init__(self, radius: float, work_of_adhesion: float, e_star: float, limiting_pressure: float,
                 detachment: str = "displacement"):
        if not work_of_adhesion > 0.0:
            raise ValueError(f"work_of_adhesion = {work_of_adhesion!r}: the adhesive plastic law needs w > 0")
        self.radius, self.work_of_adhesion, self.e_star = float(radius), float(work_of_adhesion), float(e_star)
        self.limiting_pressure = tn.check_limiting_pressure(limiting_pressure, radius, work_of_adhesion, e_star)
        self.detachment = detachment
        p = self._p()
        self.yield_radius = float(tn.yield_radius(self.limiting_pressure, *p))
        self.yield_force = float(ref.force_from_radius(self.yield_radius, *p))
        self.yield_approach = float(ref.approach_from_radius(self.yield_radius, *p))
        self.plastic_slope = math.pi * self.limiting_pressure * self.radius
        self.forget_history()

    def _p(self, radius: float | None = None):
        return (self.radius if radius is None else radius), self.work_of_adhesion, self.e_star

    # ------------------------------------------------------------------ state
    def forget_history(self) -> None:
        """The virgin sphere: elastic branch JKR on R from delta = 0, plastic line from delta_y."""
        self._branch = JKRSphere(self.radius, self.work_of_adhesion, self.e_star, self.detachment)
        self._offset = 0.0                     # delta_p of the current elastic branch (m)
        self._limit = self.yield_approach      # delta beyond which the plastic line holds (m)
        self._impacts_yielded = 0
        self._t_attach = 0.0                   # contact time at which the sphere meets the flattened spot (s)
        self.reset()

    def prepare(self, mass, speed, gravity):
        """The contact time at which free flight from the touch (speed m/s down, gravity m/s^2) reaches the
        flattened spot, delta = delta_p: speed t + g t^2/2 = delta_p."""
        d = max(self._offset, 0.0)
        self._t_attach = 2.0 * d / (speed + math.sqrt(speed * speed + 2.0 * gravity * d)) if d > 0.0 else 0.0

    def set_time(self, t_contact):
        self._t = t_contact

    def time_events(self):
        return [self._t_attach] if self._offset > 0.0 else []

    def reset(self) -> None:
        """A new contact on the same spot: the flattening stays, the contact's own loss starts at 0."""
        self._t = 0.0
        self._attached = self._offset <= 0.0
        self._loss = 0.0                       # plastic loss of this contact, accepted states (J)
        self._yielded_now = False

    def _line(self, delta: float) -> float:
        return self.yield_force + self.plastic_slope * (delta - self.yield_approach)

    def _flattened(self, delta: float) -> tuple[float, float, float]:
        """(R_p, delta_p, a*) of the unloading branch that starts at delta on the plastic line."""
        a = math.sqrt(self.yield_radius**2 + self.radius * (delta - self.yield_approach))
        hertz = self._line(delta) + math.sqrt(8.0 * math.pi * self.work_of_adhesion * self.e_star * a**3)
        r_p = 4.0 * self.e_star * a**3 / (3.0 * hertz)
        return r_p, delta - float(ref.approach_from_radius(a, *self._p(r_p))), a

    def _plastic_trial(self, delta: float) -> tuple[float, float]:
        """(energy the new branch would store, this contact's plastic loss) at delta > self._limit."""
        d0 = self._limit
        work = (self._branch.stored_energy(self._offset - d0)
                + (self._line(d0) + 0.5 * self.plastic_slope * (delta - d0)) * (delta - d0))
        r_p, _, a = self._flattened(delta)
        stored = float(ref.energy_from_radius(a, *self._p(r_p)))
        return stored, self._loss + work - stored

    # ------------------------------------------------------------------ ContactLaw
    def force(self, gap):
        if not self._attached:
            return 0.0
        if -gap >= self._limit:
            return self._line(-gap)
        return self._branch.force(gap + self._offset)

    def stiffness(self, gap):
        if not self._attached:
            return 0.0
        if -gap >= self._limit:
            return self.plastic_slope
        return self._branch.stiffness(gap + self._offset)

    def stored_energy(self, gap):
        if not self._attached:
            return 0.0
        if -gap > self._limit:
            return self._plastic_trial(-gap)[0]
        return self._branch.stored_energy(gap + self._offset)

    def dissipated(self, gap):
        if self._attached and -gap > self._limit:
            return self._plastic_trial(-gap)[1]
        return self._loss

    def release_gap(self):
        return self._branch.release_gap() - self._offset

    def on_release(self):
        return self._loss + self._branch.on_release()

    def accept(self, gap):
        delta = -gap
        if delta > self._limit:
            _, loss = self._plastic_trial(delta)
            r_p, d_p, _ = self._flattened(delta)
            self._branch = JKRSphere(r_p, self.work_of_adhesion, self.e_star, self.detachment)
            self._offset, self._limit, self._loss = d_p, delta, loss
            if not self._yielded_now:
                self._yielded_now = True
                self._impacts_yielded += 1
        # the driver accepts the state at the time event and restarts there; (t0 + t_attach) - t0 may round
        # below t_attach, hence the relative 1e-6 (the sphere moves 1e-6 delta_p in that time)
        if not self._attached and self._t >= self._t_attach * (1.0 - 1e-6):
            self._attached = True

    def length_scale(self, mass, speed):
        hertz = (15.0 * mass * speed**2 / (16.0 * self.e_star * math.sqrt(self.radius))) ** 0.4
        plastic = speed * math.sqrt(mass / self.plastic_slope)
        return max(min(hertz, plastic), self._branch.delta_c, self.yield_approach)

    def diagnostics(self):
        """The flattening, and a*/R at the deepest plastic state against the law's small-strain bound
        (`thornton_ning.LAW_RANGE_RADIUS_RATIO`): beyond it the law is used outside the range it was derived for."""
        out = {"impacts_yielded": self._impacts_yielded, "plastic_radius": self._branch.radius,
               "plastic_approach": self._offset, "max_plastic_approach": max(self._limit, self.yield_approach)}
        if self._impacts_yielded:
            a = math.sqrt(self.yield_radius**2 + self.radius * (self._limit - self.yield_approach))
            out.update(max_contact_radius_ratio=a / self.radius, law_range_radius_ratio=tn.LAW_RANGE_RADIUS_RATIO,
                       beyond_law_range=a / self.radius > tn.LAW_RANGE_RADIUS_RATIO)
        return out

    def describe(self):
        return {"name": self.name, "source": "Thornton & Ning (1998): JKR loading to yield, plastic line "
                "pi p_y R, JKR unloading about the flattened radius R_p; Fuller & Tabor (1975) detachment",
                "radius": self.radius, "work_of_adhesion": self.work_of_adhesion, "e_star": self.e_star,
                "limiting_pressure": self.limiting_pressure, "detachment": self.detachment,
                "yield_radius": self.yield_radius, "yield_force": self.yield_force,
                "yield_approach": self.yield_approach, "plastic_slope": self.plastic_slope}
