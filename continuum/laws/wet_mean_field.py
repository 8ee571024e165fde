"""The rigid mean field with two classes of summits: inside a capillary bridge the wet work of adhesion, force and loop.

Inside a bridge two solids touch under liquid, so a bridged summit adheres with W_wet = gamma_1L + gamma_2L - gamma_12
instead of dgamma (Dupre in the liquid, `continuum.wet.menisci.wet_work_of_adhesion`; Israelachvili 2011 §17.7,
Butt & Kappl 2009): its JKR force, its release point and the loop it dissipates when it lets go. The discrete
summits do this one summit at a time (`continuum.laws.wet_summits`); this is the same law for the Greenwood-Williamson
mean field on a rigid substrate, written with the dry law's footprint tables (`continuum.laws.rough_rigid`).

Derivation (docs/model.md, "The wet loop in the mean field")
--------------------------------------------------------------
On a rigid substrate a summit of height z at x sits at u = z - z_top - x^2/2R below the roller's datum parabola and
has approach delta = u - h at the driver's gap h; u <= 0. Every footprint sum is a one-dimensional integral over u,
sum q(delta) = int q(u - h) rho(u) du, with rho(u) = -dS/du and S(a) the number of summits with u >= a (the dry
law's first-approach count at gap a). The rigid law's table at window r is T(h, r) = int_{delta >= -r} q(delta)
rho(h + delta) d delta: its window is a lower cutoff in delta, 0 <= r <= Delta. The bridged summits are u >= s (the
bridges' offset, `continuum.laws.wet.MeniscusBridges`, after t_a s <= h - h_mw(t) <= h), so the split integral is a
difference of tables at the two works of adhesion, no third table dimension:

    wet  (u >= s):        attached u >= a_w = max(s, h - Delta_w, h_min)    ->  T_wet(h, h - a_w)
    dry  (u <  s):        attached a_d <= u < b_d, a_d = max(h - Delta_d, h_min)
                                                                        ->  T_dry(h, h - a_d) - T_dry(h, h - b_d)

(h_min: the deepest gap of the contact; the path is one approach and one retreat, as for the dry law.) The wet
lower bound needs no history of its own when Delta_wet <= Delta_dry (W_wet <= dgamma, required): a summit that let
go dry did so below -Delta_dry <= -Delta_wet, and one that let go wet is below -Delta_wet for good. A dry summit
is either never bridged or lost its bridge at gap D_K (bridges break there): if D_K <= Delta_wet it was still
attached and stays attached dry (b_d = s); if D_K > Delta_wet it had let go inside its bridge, so the dry summits
that can still be attached are the never-bridged ones (b_d = s_min, the lowest offset of the contact).

Books. Between the committed state A and a trial state B the law books (1) the loops of the summits that let go
with the classes of A held fixed (each class its loop, U(-Delta) per summit, the counts from S), and (2) at h_B the
jump of the stored energy when the classes change from A's to B's, E(h_B; classes of A) - E(h_B; classes of B):
a summit that changes class keeps delta; beyond its new class's release point it lets go and its old energy is
booked. E_kin + E_pot + stored + booked stays constant (the discrete law's rule, `wet_summits`). Until the first
bridge the books are the dry law's closed form (the compiled dry kernel runs the contact to t_a and hands back no
gap). A class boundary above the trial gap (s_A > h_B: the first steps after t_a on approach) needs T at a cutoff
delta > 0: T(h, 0) less a thin band int_0^c q rho by Gauss-Legendre, q the closed-form JKR summit, rho from the
count table.

Limits: rigid substrate, JKR (or Hertz, W_wet <= 0) tabulated summits (`GWJKRSurface`), which touch before they
attract (no jump-in stretch, no reach); W_wet <= dgamma. Runs in Python after t_a (before it, compiled: the dry
kernel). The footprint profiles (`snapshot`) are the dry law's.
"""
from __future__ import annotations

import math

import numpy as np

from ..reference import jkr as _jkr
from .rough_rigid import RigidRoughRoller
from .wet import MeniscusBridges, WetRoughRoller

_BAND_X, _BAND_W = np.polynomial.legendre.leggauss(8)


def _summit_quantity(surface, what: str, delta: np.ndarray) -> np.ndarray:
    """Force (N, + compressive) or stored energy (J, U(0) = 0) of one summit of `surface` at approaches delta >= 0:
    JKR's stable branch at the surface's work of adhesion, Hertz where it has none (Johnson 1985 §5.1)."""
    beta, w, e = surface.radius, surface.work_of_adhesion, surface.e_star
    if w > 0.0:
        if what == "force":
            return np.asarray(_jkr.force_from_approach(delta, beta, w, e), float)
        return np.asarray(_jkr.energy_from_approach(delta, beta, w, e), float)
    d = np.maximum(delta, 0.0)
    if what == "force":
        return 4.0 / 3.0 * e * math.sqrt(beta) * d ** 1.5
    return 8.0 / 15.0 * e * math.sqrt(beta) * d ** 2.5


class TwoClassRigidRoller(RigidRoughRoller):
    """The rigid mean field `dry` (at dgamma) whose summits with u >= s follow `wet` (the same roller at W_wet).

    Build with `from_dry`. The trial state's offset s is set before every evaluation (`set_boundary`, by
    `WetMeanFieldRoller`); s = inf (no bridge) is the dry law itself."""

    @classmethod
    def from_dry(cls, dry: RigidRoughRoller, wet: RigidRoughRoller, kelvin_gap: float) -> "TwoClassRigidRoller":
        for law, what in ((dry, "dry"), (wet, "wet")):
            s = law.surface
            if s.kind != "tabulated" or law.attach_stretch != 0.0 or law.reach != 0.0:
                raise ValueError(f"the two-class mean field takes tabulated JKR/Hertz summits ({what} surface: "
                                 f"{s.kind} {s.law_name}, jump-in {law.attach_stretch!r} m, reach {law.reach!r} m)")
        if wet.surface.work_of_adhesion > dry.surface.work_of_adhesion:
            raise ValueError(f"W_wet = {wet.surface.work_of_adhesion!r} > dgamma = {dry.surface.work_of_adhesion!r} "
                             "J/m^2: the two-class mean field needs the wet release point inside the dry one")
        law = cls.__new__(cls)
        law.__dict__.update(dry.__dict__)
        law.wet = wet
        law.name = dry.name + "+wet_summits"
        law.kelvin_gap = float(kelvin_gap)
        law.delta_dry, law.delta_wet = float(dry.release_stretch), float(wet.release_stretch)
        law.loop_dry, law.loop_wet = float(dry.surface.loop_energy), float(wet.surface.loop_energy)
        #: bridges break at D_K: beyond the wet release point the summits that lose them have let go (b_d = s_min)
        law.keep_dry_on_break = law.kelvin_gap <= law.delta_wet
        law.s_trial = math.inf
        law.reset()
        return law

    # ------------------------------------------------------------------ state
    def reset(self) -> None:
        super().reset()
        self.s = self.s_min = math.inf          # committed offset, lowest offset of the contact
        self.h_acc = math.nan                   # committed gap (Python accepts after the first bridge)
        self.books = 0.0                        # loops and class-change work booked since the first bridge (J)
        self.loops = [0.0, 0.0]                 # summits let go (dry, wet) since the first bridge
        self.switched = 0.0                     # class-change work booked (J)
        self.s_trial = math.inf                 # no bridge until the wrapper says so (run bare, this is the dry law)
        self._trial = None

    def set_boundary(self, s: float) -> None:
        """The trial state's bridged summits: u >= s (m; inf = none)."""
        self.s_trial = float(s)

    def size_for(self, depth: float, speed: float) -> None:
        super().size_for(depth, speed)
        self.wet.size_for(depth, speed)

    # ------------------------------------------------------------------ the split integral
    def _n_above(self, a: float) -> float:
        """S(a): summits with u >= a (0 above the tallest, u <= 0)."""
        return self._first_approach_count(a) if a < 0.0 else 0.0

    def _between(self, a: float, b: float) -> float:
        """Summits with a <= u < b."""
        return self._n_above(a) - self._n_above(b) if b > a else 0.0

    def _density(self, u: np.ndarray) -> np.ndarray:
        """rho(u) = -dS/du (1/m): the count table's derivative, a central difference of the integral beyond it."""
        out = np.empty(u.size)
        for k, x in enumerate(u):
            if x < self._h_lo:
                e = 1e-6 * self.sigma
                out[k] = -(self._n_above(x + e) - self._n_above(x - e)) / (2.0 * e)
            else:
                out[k] = -float(self._count(x, 1))
        return out

    def _table(self, law: RigidRoughRoller, what: str, h: float, r: float) -> float:
        """T(h, r) = int_{delta >= -r} q rho of `law` (0 <= r <= its Delta): its table, or its integral below it."""
        r = min(max(r, 0.0), law.release_stretch)
        if h - r >= 0.0:                          # no summit reaches delta >= -r
            return 0.0
        if h < law._h_lo:
            return law._exact("pressure" if what == "force" else "energy", h, r)
        spline = law._force if what == "force" else law._energy
        return float(spline.ev(h, law._w(r)))

    def _above(self, law: RigidRoughRoller, what: str, h: float, c: float) -> float:
        """int_{delta >= c} q rho of `law` for any c >= -Delta (c > 0: T(h, 0) less the band (0, c) by
        Gauss-Legendre on the closed-form summit)."""
        if not math.isfinite(c):
            return 0.0
        if c <= 0.0:
            return self._table(law, what, h, -c)
        full = self._table(law, what, h, 0.0)
        top = min(c, -h)                          # summits end at u = 0
        if not top > 0.0:
            return full
        half = 0.5 * top
        delta = half + half * _BAND_X
        band = half * float(np.dot(_BAND_W, _summit_quantity(law.surface, what, delta) * self._density(h + delta)))
        return full - band

    def _bounds(self, h: float, s: float, s_min: float, h_min: float):
        """(a_w, a_d, b_d): wet attached u >= a_w (inf: no wet summit), dry attached a_d <= u < b_d."""
        a_w = max(s, h - self.delta_wet, h_min)
        a_d = max(h - self.delta_dry, h_min)
        b_d = s if self.keep_dry_on_break else s_min
        return a_w, a_d, b_d

    def _split(self, what: str, h: float, s: float, s_min: float, h_min: float) -> float:
        """Force (N) or stored energy (J) of the two classes at gap h with offsets s, s_min and deepest gap h_min."""
        a_w, a_d, b_d = self._bounds(h, s, s_min, h_min)
        out = self._above(self.wet, what, h, a_w - h) if math.isfinite(a_w) else 0.0
        if b_d > a_d:
            out += self._above(self, what, h, a_d - h) - self._above(self, what, h, b_d - h)
        return out

    def _attached_counts(self, h: float, s: float, s_min: float, h_min: float) -> tuple[float, float]:
        """(dry, wet) summits attached."""
        a_w, a_d, b_d = self._bounds(h, s, s_min, h_min)
        return self._between(a_d, b_d), self._n_above(a_w) if math.isfinite(a_w) else 0.0

    def _pending(self, gap: float) -> tuple[float, float, float]:
        """(dry let-go, wet let-go, class-change work J) a trial state at `gap` adds to the committed books."""
        key = (gap, self.s_trial)
        if self._trial is not None and self._trial[0] == key:
            return self._trial[1]
        s_b = self.s_trial
        h_min = min(self.h_min, gap)
        if not math.isfinite(self.s):
            # no bridge yet: the dry law's closed form (every touched summit not attached has let go)
            n_att = self._attached_counts(gap, math.inf, math.inf, h_min)[0]
            n_dry, n_wet = max(self._n_above(h_min) - n_att, 0.0) if math.isfinite(h_min) else 0.0, 0.0
        else:
            # (1) the classes of A held: the summits that let go between h_A and h_B
            h_a = self.h_acc
            aw_a, ad_a, bd_a = self._bounds(h_a, self.s, self.s_min, self.h_min)
            aw_b, ad_b, _ = self._bounds(gap, self.s, self.s_min, h_min)
            n_wet = max(self._n_above(aw_a) - self._n_above(aw_b), 0.0)
            n_dry = max(self._between(ad_a, bd_a) - self._between(ad_b, bd_a), 0.0)
        # (2) at h_B the classes change from A's to B's: the jump of the stored energy
        s_min_b = min(self.s_min, s_b)
        switch = 0.0
        if s_b != self.s or s_min_b != self.s_min:
            switch = (self._split("energy", gap, self.s, self.s_min, h_min)
                      - self._split("energy", gap, s_b, s_min_b, h_min))
        out = (n_dry, n_wet, switch)
        self._trial = (key, out)
        return out

    # ------------------------------------------------------------------ ContactLaw
    def force(self, gap):
        if not math.isfinite(self.s_trial) and not math.isfinite(self.s):
            return super().force(gap)
        if gap >= self.end_gap:
            return 0.0
        return self._split("force", gap, self.s_trial, min(self.s_min, self.s_trial), min(self.h_min, gap))

    def stiffness(self, gap):
        if not math.isfinite(self.s_trial) and not math.isfinite(self.s):
            return super().stiffness(gap)
        e = 1e-6 * self.sigma
        s, s_min, h_min = self.s_trial, min(self.s_min, self.s_trial), min(self.h_min, gap)
        return -(self._split("force", gap + e, s, s_min, h_min)
                 - self._split("force", gap - e, s, s_min, min(h_min, gap - e))) / (2.0 * e)

    def stored_energy(self, gap):
        if not math.isfinite(self.s_trial) and not math.isfinite(self.s):
            return super().stored_energy(gap)
        return self._split("energy", gap, self.s_trial, min(self.s_min, self.s_trial), min(self.h_min, gap))

    def dissipated(self, gap):
        n_dry, n_wet, switch = self._pending(gap)
        return self.books + n_dry * self.loop_dry + n_wet * self.loop_wet + switch

    def accept(self, gap):
        if gap < self._h_lo:
            self.beyond_tables += 1
        if math.isfinite(self.s_trial):
            # from the first bridged state on the books accumulate (until then they are the dry closed form)
            n_dry, n_wet, switch = self._pending(gap)
            self.books += n_dry * self.loop_dry + n_wet * self.loop_wet + switch
            self.loops[0] += n_dry
            self.loops[1] += n_wet
            self.switched += switch
        if gap < self.h_min:
            self.h_min = gap
            self.count_min = self._n_above(gap)
        self.s = self.s_trial
        self.s_min = min(self.s_min, self.s)
        self.h_acc = gap
        self._trial = None
        n = self._attached_counts(gap, self.s, self.s_min, self.h_min)
        self.max_contacts = max(self.max_contacts, n[0] + n[1])

    def on_release(self):
        """Every summit still attached lets go: its class's loop."""
        if not math.isfinite(self.s):
            return super().on_release()
        n_dry, n_wet = self._attached_counts(self.h_acc, self.s, self.s_min, self.h_min)
        self.loops[0] += n_dry
        self.loops[1] += n_wet
        self.books += n_dry * self.loop_dry + n_wet * self.loop_wet
        self.h_acc, self.h_min = math.inf, math.inf       # nothing attached any more
        return self.books

    def compiled(self, t0: float):
        """The dry kernel while no summit is bridged (the wrapper stops it at t_a)."""
        return super().compiled(t0) if not math.isfinite(self.s) else None

    def diagnostics(self):
        return {**super().diagnostics(),
                "wet_summits": {"work_of_adhesion_wet": self.wet.surface.work_of_adhesion,
                                "loop_energy_wet": self.loop_wet, "loop_energy_dry": self.loop_dry,
                                "wet_table_build_seconds": self.wet.build_seconds}}

    def describe(self):
        return {**super().describe(), "name": self.name,
                "inside_bridges": {"work_of_adhesion": self.wet.surface.work_of_adhesion,
                                   "loop_energy_per_summit": self.loop_wet,
                                   "why": "bridged summits adhere under liquid, force and loop "
                                          "(continuum.laws.wet_mean_field)",
                                   "profiles": "footprint profiles (snapshot) are the dry law's"}}


class WetMeanFieldRoller(WetRoughRoller):
    """`WetRoughRoller` round a `TwoClassRigidRoller`: before each evaluation the bridges' offset at (gap, t) is handed
    to the summits, so bridged summits adhere with W_wet; the bridges take no DMT solid pull (the wet summit law
    carries the solid adhesion)."""

    def _sync(self, gap: float) -> None:
        self.dry.set_boundary(self.bridges.offset(gap, self.t))

    def force(self, gap):
        self._sync(gap)
        return super().force(gap)

    def stiffness(self, gap):
        if not math.isfinite(self.bridges.offset(gap, self.t)):
            self._sync(gap)
            return super().stiffness(gap)
        e = 1e-6 * max(self.bridges.d_k, abs(gap))
        return -(self.force(gap + e) - self.force(gap - e)) / (2.0 * e)

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
        out = super().diagnostics()
        out["menisci"] = {**out["menisci"], "solids_inside_bridges": self.record["solids_inside_bridges"]}
        return out


def wet_mean_field_roller(dry: RigidRoughRoller, wet: RigidRoughRoller, bridges: MeniscusBridges,
                          parameters: dict) -> WetMeanFieldRoller:
    """`dry` (the rigid mean field at dgamma) with `bridges` and its bridged summits on `wet` (the same roller at
    max(W_wet, 0)); `parameters`: the scene's meniscus parameters."""
    law = TwoClassRigidRoller.from_dry(dry, wet, parameters["kelvin_gap"])
    bridges.set_solid_pull(0.0)
    inside = (f"summit law at W_wet = {wet.surface.work_of_adhesion:.4g} J/m^2: force and loop "
              "(continuum.laws.wet_mean_field)")
    return WetMeanFieldRoller(law, bridges, {**parameters, "solid_pull": 0.0, "solids_inside_bridges": inside})
