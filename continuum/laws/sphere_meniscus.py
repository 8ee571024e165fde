"""A smooth sphere with a capillary bridge: any smooth-sphere law plus one condensed water bridge.

What it is
----------
The sphere's own law (Hertz, JKR, DMT, Maugis-Dugdale or Thornton-Ning, chosen by the Tabor parameter as
without humidity) carries the solids' contact; one bridge at the contact adds the capillary attraction of
`continuum.wet.menisci`, the same constant-Kelvin-radius law the rough summits use with beta = the sphere's
radius R (Butt & Kappl, Adv. Colloid Interface Sci. 146 (2009) 48, sphere-plane at constant r_K;
Israelachvili, Intermolecular and Surface Forces, 3rd ed. (2011) ch. 17):

    F(g) = F0 (1 - g/D_K),  0 <= g <= D_K,      F0 = 2 pi R gamma (cos t1 + cos t2)  (= 4 pi R gamma cos t),
    D_K = r_K (cos t1 + cos t2),  r_K = gamma V_m / (R_g T ln(1/RH)),

valid for r_K << R; the bridge ruptures at D_K, where its force and energy are zero. Inside the bridge the
solids touch under the liquid: with ``menisci.solid_adhesion = 'wet'`` a compressed contact loses the solid
pull 2 pi R (dgamma - max(W_wet, 0)) (`continuum.wet.menisci.solid_pull_inside_bridge`, DMT's force, the rough
summits' construction), so a DMT sphere's wet pull-off is 2 pi R dgamma when W_wet >= 0 (Israelachvili eq
17.25) and F0 when the liquid wets between the solids; 'additive' keeps the dry adhesion beside the bridge.

When the bridge is there
------------------------
A meniscus narrower than a molecule is not a liquid: no bridge where r_K is below the scene's cutoff
(``menisci.min_kelvin_radius``, one water molecule by default; the decision is `continuum.model.decisions`).
A bridge condenses only after the solids touch, on the rough model's clock (`continuum.wet.menisci.bridgeable_gap`:
nothing before the condensation time t_a, then every gap up to h_mw(t) = min(h1 ln(t/t_a), D_K)); it is
not there on the approach. Formation books -U(g_f) (work the condensing liquid does, the rough law's
`formation`), rupture at D_K books nothing, so E_kin + E_pot + stored + booked stays constant.

Inside a bridge the solids may part and touch again (the sphere's own release and touch): its loop is booked
where it lets go, as without the bridge, and the contact of the whole ends where the bridge ruptures.

Quasi-static pull-off (`pull_off`): the largest attraction along a slow retreat with the bridge in
equilibrium with the vapour (a dwell longer than t_a), the AFM measurement.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from ..wet import menisci as men
from .base import ContactLaw


@dataclass(frozen=True)
class SphereBridge:
    """One sphere-flat bridge: pull at touch f0 (N), Kelvin gap d_k (m), condensation time t_a (s), growth
    length h1 (m) of h_mw(t) and the solid pull a compressed contact loses inside it (N)."""

    f0: float
    d_k: float
    t_a: float
    growth_length: float
    solid_pull: float = 0.0

    def force(self, gap: float) -> float:
        """Attraction (N, >= 0 outside contact) at `gap` (m)."""
        return float(men.bridge_force(gap, self.f0, self.d_k, self.solid_pull))

    def energy(self, gap: float) -> float:
        """Energy (J, <= 0 outside contact), zero at rupture."""
        return float(men.bridge_energy(gap, self.f0, self.d_k, self.solid_pull))

    def can_form(self, gap: float, t: float) -> bool:
        """Whether a bridge condenses at `gap` after a contact time `t` (s)."""
        return gap < self.d_k and gap <= men.bridgeable_gap(t, self.t_a, self.growth_length, self.d_k)


class WetSphere(ContactLaw):
    """`dry` (a smooth-sphere law in vapour) plus one SphereBridge; `wet` is the sphere's law for solids touching
    under the liquid (``menisci.solid_adhesion = 'wet'``: the same law at the wet work of adhesion; 'additive':
    `dry` itself). `record` is the meniscus record (result.json)."""

    has_history = True
    bound_is_final = True      # held by an attraction that only grows (a bridge) or a lossless elastic branch
    time_dependent = True
    #: While a bridge can still form, the sphere moves at most this fraction of D_K per step at twice the
    #: impact speed: the formation is booked at the step's end (`continuum.laws.wet` uses the same bound).
    STEP_FRACTION_OF_KELVIN_GAP = 0.05

    def __init__(self, dry: ContactLaw, wet: ContactLaw, bridge: SphereBridge, record: dict):
        self.dry, self.wet, self.bridge, self.record = dry, wet, bridge, record
        self.name = dry.name + "+meniscus"
        self.touch_gap = dry.touch_gap
        self.contacts_with_bridge = 0
        self.longest_contact = 0.0
        self.wetted = False
        self.reset()

    # -- state
    def reset(self) -> None:
        if self.wetted:
            self.contacts_with_bridge += 1
        for law in {id(self.dry): self.dry, id(self.wet): self.wet}.values():
            law.reset()
        self.t = 0.0
        self.solid = self.dry            # the solids' law: dry until a bridge condenses, then wet to the end
        self.attached = True             # the solids touch (the contact starts at the dry law's touch)
        self.wetted = False              # a bridge condensed in this contact
        self.bridge_up = False           # the bridge stands at the accepted state
        self.formation = 0.0             # the bridges' formation work booked this contact (J)
        self.wetting = 0.0               # energy booked where the solids' law turned wet (J, either sign)
        self.booked = 0.0                # the solids' losses of their releases inside the bridge (J)

    def forget_history(self) -> None:
        self.dry.forget_history()
        self.wet.forget_history()

    def set_time(self, t_contact: float) -> None:
        self.t = t_contact

    def time_events(self) -> list[float]:
        return [self.bridge.t_a]

    def max_step(self, speed: float) -> float:
        if self.bridge_up or self.t < self.bridge.t_a:
            return math.inf
        return self.STEP_FRACTION_OF_KELVIN_GAP * self.bridge.d_k / (2.0 * max(speed, 1e-300))

    def prepare(self, mass, speed, gravity):
        """Prepare the solids' laws at the impact's speed, after sizing what they tabulate for the speed the bridge
        can add (its energy at touch F0 D_K / 2, taken four times over: it pulls the sphere deeper than the
        impact alone; a law that tabulates nothing ignores the first call, one that keeps its largest table
        keeps it through the second)."""
        boosted = math.sqrt(speed * speed + 4.0 * self.bridge.f0 * self.bridge.d_k / mass)
        for law in {id(self.dry): self.dry, id(self.wet): self.wet}.values():
            law.prepare(mass, boosted, gravity)
            law.prepare(mass, speed, gravity)

    # -- which parts act at a trial state
    def _new_bridge(self, gap: float) -> bool:
        return not self.bridge_up and self.bridge.can_form(gap, self.t)

    def _on(self, law: ContactLaw, attached: bool, gap: float) -> bool:
        return gap <= (law.release_gap() if attached else law.touch_gap)

    def _solid(self, gap: float) -> tuple[ContactLaw, bool]:
        """The solids' law at a trial state and whether the solids touch there."""
        if self._new_bridge(gap) and not self.wetted and self.wet is not self.dry:
            touching = self._on(self.solid, self.attached, gap)
            return self.wet, touching and gap <= self.wet.release_gap()
        return self.solid, self._on(self.solid, self.attached, gap)

    def _wetting(self, gap: float) -> float:
        """Energy booked (J) where the solids' law turns wet at `gap`: what the dry law stores and has lost there,
        less what the wet law stores (the vapour's work; zero for 'additive')."""
        if self.wetted or self.wet is self.dry:
            return 0.0
        out = 0.0
        if self._on(self.solid, self.attached, gap):
            out += self.solid.stored_energy(gap) + self.solid.dissipated(gap)
        if self._solid(gap)[1]:
            out -= self.wet.stored_energy(gap)
        return out

    def _bridge_on(self, gap: float) -> bool:
        return (self.bridge_up or self._new_bridge(gap)) and gap < self.bridge.d_k

    # -- ContactLaw
    def force(self, gap):
        law, on = self._solid(gap)
        f = law.force(gap) if on else 0.0
        return f - (self.bridge.force(gap) if self._bridge_on(gap) else 0.0)

    def stiffness(self, gap):
        law, on = self._solid(gap)
        k = law.stiffness(gap) if on else 0.0
        if self._bridge_on(gap):
            k -= self.bridge.f0 / (self.bridge.d_k if gap > 0.0 else 2.0 * self.bridge.d_k)
        return k

    def stored_energy(self, gap):
        law, on = self._solid(gap)
        u = law.stored_energy(gap) if on else 0.0
        return u + (self.bridge.energy(gap) if self._bridge_on(gap) else 0.0)

    def dissipated(self, gap):
        out = self.formation + self.wetting + self.booked
        if self._new_bridge(gap):
            return out + self._wetting(gap) - self.bridge.energy(gap)
        if self._on(self.solid, self.attached, gap):
            out += self.solid.dissipated(gap)
        elif self.attached:              # a trial state past the solids' release: its loss, as the release books it
            out += self.solid.on_release()
        return out

    def accept(self, gap):
        if self._new_bridge(gap):
            if not self.wetted and self.wet is not self.dry:
                self.wetting += self._wetting(gap)
                self.attached = self._solid(gap)[1]
                self.solid = self.wet
            self.formation -= self.bridge.energy(gap)
            self.wetted = self.bridge_up = True
        elif self.bridge_up and gap >= self.bridge.d_k:
            self.bridge_up = False       # ruptured: U = 0, nothing to book
        if self.attached and gap > self.solid.release_gap():
            self.booked += self.solid.on_release()
            self.solid.reset()
            self.attached = False
        elif not self.attached and gap <= self.solid.touch_gap:
            self.attached = True
        if self.attached:
            self.solid.accept(gap)
        self.longest_contact = max(self.longest_contact, self.t)

    def release_gap(self):
        own = self.solid.release_gap()
        return max(own, self.bridge.d_k) if self.bridge_up else own

    def on_release(self):
        return self.formation + self.wetting + self.booked + (self.solid.on_release() if self.attached else 0.0)

    def length_scale(self, mass, speed):
        return max(self.dry.length_scale(mass, speed), self.bridge.d_k)

    def diagnostics(self):
        out = dict(self.dry.diagnostics())
        out["menisci"] = {"longest_contact_s": max(self.longest_contact, self.t),
                          "condensation_time_s": self.bridge.t_a,
                          "contacts_with_bridge": self.contacts_with_bridge + (1 if self.wetted else 0)}
        return out

    def quasi_static_pull_off(self) -> dict:
        """`pull_off` of the wet solids with the bridge, and of the dry solids without it (N)."""
        wet, dry = pull_off(self.wet, self.bridge), pull_off(self.dry, None)
        return {**wet, "dry_pull_off_force": dry["pull_off_force"],
                "assumes": "slow retreat, bridge in equilibrium with the vapour (dwell longer than t_a)"}

    def describe(self):
        return {**self.dry.describe(), "name": self.name, "menisci": self.record,
                "solids_in_the_bridge": self.wet.describe(), "quasi_static": self.quasi_static_pull_off()}


# ----------------------------------------------------------------------------- quasi-static pull-off
#: Points of the grid on which the retreat's largest attraction is bracketed before it is refined.
PULL_OFF_GRID = 4001


def pull_off(dry: ContactLaw, bridge: SphereBridge | None) -> dict:
    """Largest attraction (N) on a slow retreat of the solids' law `dry` with the bridge in equilibrium.

    The attraction is -F_dry(g) (on the law's attached branch, up to its release) plus the bridge's F(g)
    (`bridge` None: none), maximised over g in [-depth, max(release, D_K)] on a grid and refined by bounded
    Brent search inside the best grid cell. The retreat starts at depth = twice the law's adhesive length scale
    (a tenth of D_K without adhesion): the attraction peaks near the touch, since deeper the elastic force
    grows as depth^(3/2) against the bridge's linear gain. Returns the force, the gap where it is reached and
    its two parts.
    """
    scale = dry.length_scale(0.0, 0.0)
    depth = 2.0 * scale if scale > 0.0 else 0.1 * (bridge.d_k if bridge is not None else 0.0)
    release = dry.release_gap()
    top = max(release, bridge.d_k if bridge is not None else release)

    def parts(g: float) -> tuple[float, float]:
        solid = -dry.force(g) if g <= release else 0.0
        return solid, (bridge.force(g) if bridge is not None else 0.0)

    def attraction(g: float) -> float:
        return sum(parts(g))

    grid = np.linspace(-depth, top, PULL_OFF_GRID)
    values = np.array([attraction(g) for g in grid])
    i = int(np.argmax(values))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    best_g, best = float(grid[i]), float(values[i])
    if hi > lo:
        res = minimize_scalar(lambda g: -attraction(g), bounds=(lo, hi), method="bounded",
                              options={"xatol": 1e-9 * (top + depth)})
        if -res.fun > best:
            best_g, best = float(res.x), float(-res.fun)
    solid, capillary = parts(best_g)
    return {"pull_off_force": best, "gap": best_g, "solid_part": float(solid), "bridge_part": capillary,
            "retreat_from_gap": -depth}
