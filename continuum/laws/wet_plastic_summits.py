"""Discrete elastic-plastic summits that adhere with the wet work of adhesion inside their bridges: force and loop.

The plastic counterpart of `continuum.laws.wet_summits`. A realisation of Thornton-Ning summits
(`continuum.laws.plastic_rough.PlasticDiscreteRoller`: `PlasticSummitLaw`, JKR closed forms, or
`PlasticBranchSummitLaw`, the construction on Maugis-Dugdale / DMT) carries one bridge per summit
(`continuum.laws.discrete_bridges`); inside its bridge a summit's solids touch under liquid, so it follows the same
plastic summit law rebuilt at W_wet = gamma_1L + gamma_2L - gamma_12 (same E*, tip radius beta, limiting contact
pressure p_y, range z0): its jump-in, plastic line, flattened branch, release point and loop are the wet ones.

The plastic state carried across a class change is the summit's deepest approach delta_max. Thornton & Ning (Powder
Technol. 99 (1998) 154) parameterise a summit's plastic state by its deepest state alone: the contact radius a*^2 =
a_y^2 + beta (delta_max - delta_y) and force F* on the plastic line fix the flattened radius R_p (the law's
unloading curve through (a*, F*)) and the residual approach delta_p. Mesarovic & Johnson (J. Mech. Phys. Solids 48
(2000) 2009) show the adhesive unloading of a plastically flattened sphere is governed by that maximum state and
the unloading adhesion, and that R_p (the effective radius of the flattened profile seen by the elastic unloading)
depends on the adhesion as well as on the geometry. Each class therefore takes its own flattening from the one
carried number, R_p(delta_max; W) and delta_p(delta_max; W) in its own law, and stays exactly its law: its unloading
branch passes through its own deepest state, so a summit reloaded past delta_max meets its class's plastic line
without a force jump, and its plastic work W_p(delta_max) is that class's (Thornton-Ning's W_in - U_R). Keeping
(R_p, delta_p) themselves instead would put the summit, after a class change, on a branch that misses its new
class's deepest state (a force jump on reloading and a plastic line started from the wrong point). The price: at
fixed delta_max, R_p and delta_p differ between the classes (the residual approach moves when a bridge forms); the
difference is the adhesive part of Thornton-Ning's flattening and vanishes as W_wet -> dgamma (tested: W_wet =
dgamma is the dry law) and as p_y -> inf (no flattening: the elastic wet class, tested).

Energy books (as `continuum.laws.wet_summits`): a summit that changes class keeps its approach delta, its attached
flag and delta_max; its stored energy jumps from its old class's U(delta) (its approach branch if it let go under
its old class, which books its old loop) to its new class's, and the difference is booked with the dissipation as
the liquid's work on the contact. Then it follows its new class's rule as every summit does, booking what the dry
plastic law books: plastic work W_p(delta_max) growth, U_A - U_R at a jump in, U_R - U_A at a let-go (the loop of its
R_p curve). So E_kin + E_pot + stored + booked stays constant (tested on a humid plastic member), and with W_wet =
dgamma the law is the dry plastic law whatever summits are bridged (tested).

`WetPlasticSummits` is a `PlasticDiscreteRoller` whose first `k_wet` summits (the bridged prefix, set before every
evaluation by `WetPlasticDiscreteRoller`) follow `wet`. One attached flag and one delta_max per summit are the
history, as in the dry law. Compiled after t_a: `continuum.laws.wet_plastic_compiled`,
`continuum.numerics.wet_plastic_kernel` (the same arithmetic), for `PlasticBranchSummitLaw` classes; JKR
Thornton-Ning summits, which have no compiled form dry either, run in Python.

Rigid substrate only (the plastic discrete law and the bridges both see rigid geometry).
"""
from __future__ import annotations

import numpy as np

from .discrete_bridges import DiscreteBridges
from .plastic_rough import PlasticDiscreteRoller
from .wet_plastic_compiled import take_back, wet_plastic_form
from .wet_summits import WetDiscreteRoller


def _class_state(law, delta, dm0, held):
    """One class's trial state for summits at approach delta (m) with deepest approach dm0 (m) and committed attached
    flags `held`: (attached, new delta_max, force N, stored energy J, R_p before the step) (the rule of
    `PlasticSummitsPunch._trial`)."""
    r_p, d_p = law.flattening(dm0)
    eps = delta - d_p
    att = (eps >= law.jump_in(r_p)) | (held & (eps > law.jump_out(r_p)))
    dm = np.where(att, np.maximum(dm0, delta), dm0)
    f, en = law.state(delta, dm, att) if delta.size else (np.zeros(0), np.zeros(0))
    return att, dm, np.asarray(f, float), np.asarray(en, float), r_p


class WetPlasticSummits(PlasticDiscreteRoller):
    """The plastic discrete roller `dry` whose first `k_wet` summits follow `wet` (the same plastic summit law at
    W_wet). Build with `WetPlasticSummits.from_dry`."""

    @classmethod
    def from_dry(cls, dry: PlasticDiscreteRoller, wet) -> "WetPlasticSummits":
        law = cls.__new__(cls)
        law.__dict__.update(dry.__dict__)
        law.delta_max = dry.delta_max.copy()
        law.wet = wet
        law.name = dry.name + "+wet_summits"
        law.k_wet = law.k_trial = 0
        law.switched = 0.0
        law._wet_seen = False
        law._approach_reach = max(float(dry.law.approach_reach), float(wet.approach_reach))
        law.touch_gap = law._approach_reach
        law._reach0 = max(law._approach_reach, *(float(-x.jump_out(np.array([x.radius]))[0]) for x in (dry.law, wet)))
        law._reach = max(law._reach0, dry._reach)
        law._attached, law._met = dry._attached.copy(), dry._met.copy()
        law._memo = None
        return law

    def forget_history(self) -> None:
        super().forget_history()
        self._reach = self._reach0            # set by `from_dry`, the only constructor

    def reset(self) -> None:
        super().reset()
        self.k_wet = self.k_trial = 0
        self.switched = 0.0
        self._wet_seen = False

    def set_wet_prefix(self, k: int) -> None:
        """The trial state's bridged summits: the first `k` of the kept ones."""
        self.k_trial = int(k)

    def _classes(self, k: int):
        """(law, slice) of the two classes over the first k summits at the trial state."""
        kw = min(self.k_trial, k)
        return (self.wet, slice(0, kw)), (self.law, slice(kw, k))

    # ------------------------------------------------------------------ the trial state
    def _trial(self, gap):
        """(k, delta, attached, deepest approach, jumps booked now, plastic work change, force, energy, switch work)
        over the first k summits, the first k_trial on the wet class.

        A summit whose class changed goes from its committed state to the trial approach under its old class (it
        lets go there if beyond the old release point, booking the old loop), changes class at that approach
        (keeping delta, delta_max and its attached flag; the jump of its stored energy booked), then follows the new
        class's rule like every other summit (jump in, let go, plastic growth, each booked by the new class)."""
        key = (gap, self.k_trial)
        if self._memo is not None and self._memo[0] == key:
            return self._memo[1]
        n = self.heights.size
        last = int(np.flatnonzero(self._attached)[-1]) + 1 if self._attached.any() else 0
        k = max(self._prefix(gap), last, min(self.k_trial, n))
        delta = self.heights[:k] - self.z_top - gap
        dm0, held = self.delta_max[:k], self._attached[:k].copy()
        lo, hi = min(self.k_wet, k), min(self.k_trial, k)
        lo, hi = min(lo, hi), max(lo, hi)
        jumps = dw = switch = 0.0
        if hi > lo:
            old, new = (self.wet, self.law) if self.k_wet > lo else (self.law, self.wet)
            d, m0, h = delta[lo:hi], dm0[lo:hi], held[lo:hi]
            r_o, dp_o = old.flattening(m0)
            h_o = h & (d - dp_o > old.jump_out(r_o))
            let_go = h & ~h_o
            if let_go.any():
                jumps += float(np.sum(old.out_switch(r_o[let_go])))
            e_old = np.asarray(old.state(d, m0, h_o)[1], float)
            e_new = np.asarray(new.state(d, m0, h_o)[1], float)
            switch = float(np.sum(e_old - e_new))
            held[lo:hi] = h_o
        att, dm = np.zeros(k, bool), dm0.copy()
        f, en, r_p = np.zeros(k), np.zeros(k), np.zeros(k)
        for law, sl in self._classes(k):
            att[sl], dm[sl], f[sl], en[sl], r_p[sl] = _class_state(law, delta[sl], dm0[sl], held[sl])
            h, a = held[sl], att[sl]
            lost, gained, grew = h & ~a, a & ~h, dm[sl] > dm0[sl]
            if lost.any():
                jumps += float(np.sum(law.out_switch(r_p[sl][lost])))
            if gained.any():
                jumps += float(np.sum(law.in_switch(r_p[sl][gained])))
            if grew.any():
                dw += float(np.sum(law.plastic_work(dm[sl][grew])) - np.sum(law.plastic_work(dm0[sl][grew])))
        out = (k, delta, att, dm, jumps, dw, float(np.sum(f)), float(np.sum(en)), switch)
        self._memo = (key, out)
        return out

    def _values(self, gap):
        k, _, _, _, jumps, dw, f, en, switch = self._trial(gap)
        return f, en, jumps, dw

    def dissipated(self, gap):
        _, _, _, _, jumps, dw, _, _, switch = self._trial(gap)
        return self._w_total + dw - self._w0 + self._loops + jumps + self.switched + switch

    def accept(self, gap):
        if -gap > self.depth_keep:
            raise ValueError(f"discrete plastic roller: approach {-gap:.3g} m beyond the kept summits' depth "
                             f"{self.depth_keep:.3g} m")
        k, _, att, dm, jumps, dw, _, _, switch = self._trial(gap)
        self._loops += jumps
        self._w_total += dw
        self.switched += switch
        self._attached[:k], self.delta_max[:k] = att, dm
        self._met[:k] |= att
        self.k_wet = self.k_trial
        self._wet_seen = self._wet_seen or self.k_wet > 0
        self._memo = None
        self.max_contacts = max(self.max_contacts, int(att.sum()))
        for law, sl in self._classes(k):
            a = att[sl]
            if a.any():
                self._reach = max(self._reach, float(np.max(-law.jump_out(law.flattening(dm[sl][a])[0]))))

    def on_release(self):
        """Every summit still attached lets go: the loop of its class's R_p curve."""
        n = self.heights.size
        kw = min(self.k_wet, n)
        total = self._w_total - self._w0 + self._loops + self.switched
        for law, sl in ((self.wet, slice(0, kw)), (self.law, slice(kw, n))):
            held = self._attached[sl]
            if held.any():
                total += float(np.sum(law.out_switch(law.flattening(self.delta_max[sl][held])[0])))
        return total

    def release_gap(self):
        """Beyond it no summit holds or pulls: the dry law's rule, and once summits have been bridged in this
        contact the wet one's too (before that the law is its dry law, release included)."""
        dry = self._release_gap_of(self.law)
        return max(dry, self._release_gap_of(self.wet)) if self._wet_seen else dry

    def compiled(self, t0: float):
        """Before any summit is bridged: the dry plastic law's compiled form (`LAW_PLASTIC`), which the wrapper stops
        at t_a; None once summits are bridged (the wrapper issues the wet form) or for JKR Thornton-Ning summits."""
        return None if self.k_wet else super().compiled(t0)

    def diagnostics(self):
        return {**super().diagnostics(), "wet_summits": {"work_of_adhesion_wet": self.wet.work_of_adhesion,
                                                         "switch_work": self.switched}}

    def describe(self):
        return {**super().describe(), "name": self.name,
                "inside_bridges": {"work_of_adhesion": self.wet.work_of_adhesion, "summit_law": self.wet.describe(),
                                   "plastic_state_carried": "deepest approach delta_max (each class its own R_p, "
                                                            "delta_p)",
                                   "why": "bridged summits adhere under liquid (continuum.laws.wet_plastic_summits)"}}


class WetPlasticDiscreteRoller(WetDiscreteRoller):
    """`WetRoughRoller` round a `WetPlasticSummits`: the bridges' prefix handed to the summits before each
    evaluation; compiled up to t_a by the dry plastic kernel, after it by `continuum.numerics.wet_plastic_kernel`."""

    def compiled(self, t0: float):
        if self.t == 0.0:                    # at touch: the dry form up to t_a
            self._issued = "dry"
            return super(WetDiscreteRoller, self).compiled(t0)
        form = wet_plastic_form(self, t0)
        self._issued = "wet" if form is not None else "none"
        return form

    def compiled_commit(self, state, last_accept: float) -> None:
        if self._issued == "wet":
            take_back(self, state, last_accept)
        else:
            super(WetDiscreteRoller, self).compiled_commit(state, last_accept)


def wet_plastic_summit_roller(dry: PlasticDiscreteRoller, wet, source, parameters: dict) -> WetPlasticDiscreteRoller:
    """`dry` (plastic summits on the realisation of the elastic discrete roller `source`) with a bridge on each
    summit and the summits inside bridges on `wet` (the same plastic summit law at W_wet); `parameters`: the scene's
    meniscus parameters (the bridges take no DMT solid pull: the summit law carries the solids' adhesion)."""
    if source.use_half_space:
        raise ValueError("wet summit laws inside bridges run on a rigid substrate (physics.half_space = 'off')")
    law = WetPlasticSummits.from_dry(dry, wet)
    p = {**parameters, "solid_pull": 0.0}
    bridges = DiscreteBridges(source, p["bridge_pull_off"], p["kelvin_gap"], p["condensation_time"],
                              p["growth_length"])
    inside = (f"plastic summit law at W_wet = {wet.work_of_adhesion:.4g} J/m^2: force and loop, delta_max carried "
              "(continuum.laws.wet_plastic_summits)")
    record = {**p, "bridges_on": "each summit of the realisation (continuum.laws.discrete_bridges)",
              "solids_inside_bridges": inside}
    return WetPlasticDiscreteRoller(law, bridges, record)
