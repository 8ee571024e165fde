"""Discrete summits that adhere with the wet work of adhesion inside their bridges: force and hysteresis loop.

Inside a capillary bridge the two solids touch under liquid, so a bridged summit's solid-solid law is the dry one
with W_wet = gamma_1L + gamma_2L - gamma_12 in place of dgamma (Dupre in the liquid, `continuum.wet.menisci.
wet_work_of_adhesion`; Israelachvili 2011 §17.7, Butt & Kappl 2009): its force, its jump-in and release points,
and the loop it dissipates when it lets go (a JKR loop scales as W^(5/3): at W_wet / dgamma = 0.15 it is 0.04 of
the dry one). The rigid mean field of JKR/Hertz summits splits its footprint integral at the bridge boundary
(`continuum.laws.wet_mean_field`); the other mean fields correct only the force (a DMT pull taken from compressed
bridged summits, `continuum.laws.wet`). On a discrete realisation each summit carries its own law, and this one does.

`WetSummitRoller` is a `DiscreteRoughRoller` (the dry law at dgamma, its realisation, its history flags) whose first
`k_wet` summits (sorted by effective height) follow a second summit law at W_wet: the bridged summits are exactly
such a prefix (`continuum.laws.discrete_bridges`), set before every evaluation by `WetDiscreteRoller`. The wet law is
a `DiscreteRoughRoller` on the same kept summits built at W_wet (closed-form JKR, or the tabulated Maugis-Dugdale /
DMT branches at W_wet with the same range z0; Hertz where W_wet <= 0): its per-summit functions are reused as they
are, so both classes of summits run the same code.

Energy books. A summit that changes class (a bridge forms on it, or breaks) keeps its approach delta: its stored
energy jumps from its old class's U(delta) to its new class's (0 if it is beyond the new release point and lets
go). The difference is the work the condensing (or evaporating) liquid does on the contact, booked with the
dissipation like the bridges' own formation work, so E_kin + E_pot + stored + booked stays constant. A summit
that lets go inside its bridge books its wet loop; outside, the dry one.

Rigid substrate only (the bridges see rigid geometry too); before the first bridge the law is its dry law
(`compiled`: the dry kernel, stopped at t_a by the wrapper), after it the compiled summits with their bridges
(`continuum.laws.wet_summits_compiled`, `continuum.numerics.wet_discrete_kernel`: the same arithmetic).
"""
from __future__ import annotations

import numpy as np

from .discrete_bridges import DiscreteBridges
from .discrete_roller import DiscreteRoughRoller
from .wet import WetRoughRoller
from .wet_summits_compiled import take_back, wet_form


class WetSummitRoller(DiscreteRoughRoller):
    """The discrete law `dry` whose first `k_wet` summits adhere by `wet` (a DiscreteRoughRoller on the same kept
    summits at W_wet). Build with `WetSummitRoller.from_dry`."""

    @classmethod
    def from_dry(cls, dry: DiscreteRoughRoller, wet: DiscreteRoughRoller) -> "WetSummitRoller":
        if dry.use_half_space:
            raise ValueError("wet summit laws inside bridges run on a rigid substrate (physics.half_space = 'off'): "
                             "the bridges see rigid geometry")
        law = cls.__new__(cls)
        law.__dict__.update(dry.__dict__)
        law.wet = wet
        law.name = dry.name + "+wet_summits"
        law.k_wet = 0                 # committed: summits [0, k_wet) are bridged
        law.k_trial = 0               # the trial state's bridged prefix
        law.detached_wet = 0
        law.switched = 0.0            # work booked when summits changed class (J)
        law.end_gap = max(dry.end_gap, wet.end_gap)
        return law

    def reset(self) -> None:
        super().reset()
        self.k_wet = self.k_trial = self.detached_wet = 0
        self.switched = 0.0

    def set_wet_prefix(self, k: int) -> None:
        """The trial state's bridged summits: the first `k` of the kept ones."""
        self.k_trial = int(k)

    def _state(self, gap: float):
        key = (gap, self.k_trial)
        if self._cache_gap == key:
            return self._cache
        state = self._evaluate(gap)
        self._cache_gap, self._cache = key, state
        return state

    # ------------------------------------------------------------------ the trial state, two classes of summits
    def _summits_at(self, gap: float, de_lo: float, de_of=None):
        """Trial state over the summits attached or within reach: the first kw (bridged) by the wet law, the rest by
        the dry one (each slice with its class's jump-in, release and reach); the history rule applied, not
        committed."""
        base = self.z_top + gap
        w = self.wet
        if base < self.z_top - self.depth_keep:
            self._deepen(2.0 * (self.z_top - base))
            w.given_summits = (self.sx, self.sy, self.sz)
            w._realise(self.depth_keep)
        k = max(self.k_att, self._count_above(base - max(self._reach, w._reach)), min(self.k_trial, self.eff.size))
        kw = min(self.k_trial, k)
        delta = self.eff[:k] - base
        att = np.empty(k, bool)
        force = np.zeros(k)
        free = np.zeros(k, bool)
        q = {}
        for cls, law, sl in (("wet", w, slice(0, kw)), ("dry", self, slice(kw, k))):
            d = delta[sl]
            a = (self.attached[sl] | (d >= law._delta_in)) & (d >= -law.release_stretch)
            att[sl] = a
            q[cls] = law._laws(d[a])
            f = np.zeros(d.size)
            f[a] = q[cls]["force"]
            if law.slaw is not None:
                fr = ~a & (d >= -law._reach)
                if fr.any():
                    f[fr] = law.slaw.force(d[fr], "approach")
                free[sl] = fr
            force[sl] = f
        wet = np.zeros(k, bool)
        wet[:kw] = True
        q.update({"att_dry": att & ~wet, "att_wet": att & wet, "free_dry": free & ~wet, "free_wet": free & wet,
                  "delta": delta})
        return k, delta, att, q, force, None

    def _energies(self, s) -> np.ndarray:
        """Stored energy (J) of each of the first k summits at a trial state (its class's branch)."""
        q, delta = s["q"], s["delta"]
        e = np.zeros(delta.size)
        e[q["att_dry"]] = self._energy(q["dry"])
        e[q["att_wet"]] = self.wet._energy(q["wet"])
        if self.slaw is not None and np.any(q["free_dry"]):
            e[q["free_dry"]] = self.slaw.energy(delta[q["free_dry"]], "approach")
        if self.wet.slaw is not None and np.any(q["free_wet"]):
            e[q["free_wet"]] = self.wet.slaw.energy(delta[q["free_wet"]], "approach")
        return e

    def _stiffness(self, q: dict) -> np.ndarray:
        return np.concatenate([super()._stiffness(q["dry"]), self.wet._stiffness(q["wet"])])

    def _area(self, q: dict) -> np.ndarray:
        n = q["att_dry"].size
        area = np.zeros(n)
        area[q["att_dry"]] = super()._area(q["dry"])
        area[q["att_wet"]] = self.wet._area(q["wet"])
        return area[q["att_dry"] | q["att_wet"]]

    def stored_energy(self, gap):
        return float(np.sum(self._energies(self._state(gap))))

    # ------------------------------------------------------------------ history and books
    def _changed(self, s) -> tuple[int, int]:
        """Index range [lo, hi) of the summits whose class differs between the committed and the trial state."""
        k = s["delta"].size
        a, b = min(self.k_wet, k), min(self.k_trial, k)
        return min(a, b), max(a, b)

    def _books(self, s) -> tuple[int, int, float]:
        """(dry releases, wet releases, switch work J) a trial state would add to the committed books."""
        k = s["delta"].size
        lo, hi = self._changed(s)
        released = self.attached[:k] & ~s["att"]
        released[lo:hi] = False                  # a summit that changed class is booked by its energy jump
        kw = min(self.k_trial, k)
        n_wet = int(np.count_nonzero(released[:kw]))
        n_dry = int(np.count_nonzero(released)) - n_wet
        switch = 0.0
        if hi > lo:
            delta = s["delta"][lo:hi]
            new = self._energies(s)[lo:hi]
            was_wet = self.k_wet > lo
            old_law = self.wet if was_wet else self
            held = self.attached[lo:hi] & (delta >= -old_law.release_stretch)
            let_go = int(np.count_nonzero(self.attached[lo:hi] & ~held))    # released under their old class
            n_wet, n_dry = (n_wet + let_go, n_dry) if was_wet else (n_wet, n_dry + let_go)
            old = np.zeros(hi - lo)
            if np.any(held):
                old[held] = old_law._energy(old_law._laws(delta[held]))
            free = ~self.attached[lo:hi] & (delta >= -old_law._reach)
            if old_law.slaw is not None and np.any(free):
                old[free] = old_law.slaw.energy(delta[free], "approach")
            switch = float(np.sum(old - new))
        return n_dry, n_wet, switch

    def dissipated(self, gap):
        n_dry, n_wet, switch = self._books(self._state(gap))
        return ((self.detached + n_dry) * self.loop_energy + (self.detached_wet + n_wet) * self.wet.loop_energy
                + self.switched + switch)

    def accept(self, gap):
        s = self._state(gap)
        n_dry, n_wet, switch = self._books(s)
        k, att = s["delta"].size, s["att"]
        self.detached += n_dry
        self.detached_wet += n_wet
        self.switched += switch
        self.attached[:k] = att
        self.k_wet = self.k_trial
        idx = np.flatnonzero(att)
        self.k_att = int(idx[-1]) + 1 if idx.size else 0
        self._cache_gap = None
        self.max_contacts = max(self.max_contacts, int(idx.size))
        self.max_depth = max(self.max_depth, float(-gap))
        if -gap > self.strip_depth:
            self.beyond_strip = True

    def on_release(self):
        """Every summit still attached lets go: its class's loop."""
        kw = min(self.k_wet, self.attached.size)
        self.detached_wet += int(np.count_nonzero(self.attached[:kw]))
        self.detached += int(np.count_nonzero(self.attached[kw:]))
        self.attached[:] = False
        self.k_att = 0
        self._cache_gap = None
        return self.detached * self.loop_energy + self.detached_wet * self.wet.loop_energy + self.switched

    def compiled(self, t0: float):
        """The dry kernel while no summit is bridged (the wrapper stops it at t_a)."""
        return super().compiled(t0) if self.k_wet == 0 else None

    def snapshot(self, gap: float) -> dict:
        return super().snapshot(gap)

    def diagnostics(self):
        return {**super().diagnostics(), "wet_summits": {"work_of_adhesion_wet": self.wet.work_of_adhesion,
                                                         "loop_energy_wet": self.wet.loop_energy,
                                                         "loop_energy_dry": self.loop_energy}}

    def describe(self):
        return {**super().describe(), "name": self.name,
                "inside_bridges": {"work_of_adhesion": self.wet.work_of_adhesion, "summit_law": self.wet.name,
                                   "loop_energy_per_summit": self.wet.loop_energy,
                                   "why": "bridged summits adhere under liquid (continuum.laws.wet_summits)"}}


class WetDiscreteRoller(WetRoughRoller):
    """`WetRoughRoller` round a `WetSummitRoller`: before each evaluation the bridges' prefix at (gap, t) is handed
    to the summits, so bridged summits adhere with W_wet."""

    #: the compiled form issued last in this contact: 'dry' up to t_a, 'wet' after it
    _issued: str = "dry"

    def _sync(self, gap: float) -> None:
        self.dry.set_wet_prefix(self.bridges.prefix(gap, self.t))

    def force(self, gap):
        self._sync(gap)
        return super().force(gap)

    def stiffness(self, gap):
        self._sync(gap)
        return super().stiffness(gap)

    def stored_energy(self, gap):
        self._sync(gap)
        return super().stored_energy(gap)

    def dissipated(self, gap):
        self._sync(gap)
        return super().dissipated(gap)

    def accept(self, gap):
        self._sync(gap)
        super().accept(gap)

    def diagnostics(self):
        """The wet law's, with what the solids inside a bridge follow (each member's record says it)."""
        out = super().diagnostics()
        out["menisci"] = {**out["menisci"], "solids_inside_bridges": self.record["solids_inside_bridges"]}
        return out

    def compiled(self, t0: float):
        """At touch the dry kernel, stopped at t_a; from t_a on (the driver asks again once it has accepted the
        state at t_a) the summits with their bridges (`continuum.numerics.wet_discrete_kernel`)."""
        if self.t == 0.0:                    # at touch: the dry form up to t_a
            self._issued = "dry"
            return super().compiled(t0)
        self._issued = "wet"
        return wet_form(self, t0)

    def compiled_commit(self, state, last_accept: float) -> None:
        if self._issued == "wet":
            take_back(self, state, last_accept)
        else:
            super().compiled_commit(state, last_accept)


def wet_summit_roller(dry: DiscreteRoughRoller, wet: DiscreteRoughRoller, parameters: dict) -> WetDiscreteRoller:
    """`dry` with a bridge on each summit and the summits inside bridges on `wet`'s law (`parameters`: the scene's
    meniscus parameters; the bridges take no DMT solid pull, the wet summit law carries the solid adhesion)."""
    law = WetSummitRoller.from_dry(dry, wet)
    p = {**parameters, "solid_pull": 0.0}
    bridges = DiscreteBridges(law, p["bridge_pull_off"], p["kelvin_gap"], p["condensation_time"], p["growth_length"])
    inside = f"summit law at W_wet = {wet.work_of_adhesion:.4g} J/m^2: force and loop (continuum.laws.wet_summits)"
    return WetDiscreteRoller(law, bridges, {**p, "bridges_on": "each summit of the realisation "
                                            "(continuum.laws.discrete_bridges)", "solids_inside_bridges": inside})
